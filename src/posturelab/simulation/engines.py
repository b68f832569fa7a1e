"""The one entry point of a simulation, :func:`simulate`, and which engine runs it.

Both engines take the same :class:`~posturelab.simulation.setup.RunSetup` and return
the same :class:`~posturelab.simulation.results.SimulationResult`; they differ only in
how they integrate (``docs/simulators.md`` has the table of what each does). The options of
a run are declared once, in :class:`~posturelab.simulation.options.RunOptions`.
"""

from __future__ import annotations

import inspect
from typing import Any

from ..errors import ParameterError
from ..model.body import Body
from ..model.muscles import MuscleSet
from ..model.platform import Disturbance
from .options import ENGINE_DEFAULTS, ENGINES, OPTION_NAMES, RunOptions, engine_name
from .results import SimulationResult
from .setup import RunSetup, prepare_run

__all__ = ["simulate", "run_setup", "ENGINES", "engine_name", "ENGINE_DEFAULTS"]


def simulate(body: Body, muscles: MuscleSet, disturbance: Disturbance | None = None,
             duration: float | None = None, *, options: RunOptions | None = None,
             **keywords: Any) -> SimulationResult:
    """Simulate the nonlinear chain.

    Parameters
    ----------
    body : Body
        The chain.
    muscles : MuscleSet
        Muscle pairs (one-sided pairs switch exactly where their stretch crosses 0).
    disturbance : Disturbance, optional
        Platform motion; none by default.
    duration : float, optional
        Simulated time (5 by default, or ``options.duration``). [s]
    options : RunOptions, optional
        The run's options (:class:`~posturelab.simulation.options.RunOptions`: initial
        state, knee, fall criteria, torque limits, feedback delay, tilt, motor noise,
        engine, integrator, tolerances, output rate, budgets); the defaults when not given.
    **keywords
        Any field of :class:`~posturelab.simulation.options.RunOptions` by name, replacing
        that of ``options``: ``feedback_delay=0.1`` [s], ``initial_state=[...]`` [rad,
        rad/s], ``engine="reference"``, ``rtol=1e-8``, … (meanings, units and accepted
        ranges there). ``engine="compiled"`` (the default) runs the C engine (hundreds of
        times faster, built when posturelab is installed); ``"reference"`` the numpy model
        integrated by scipy (slow, obvious, the independent check); each at its own default
        tolerances and integrator unless ``rtol``, ``atol``, ``method`` say otherwise.

    Returns
    -------
    SimulationResult
        A fall is reported in ``fell``/``fall_time``/``status`` and the
        state at the fall is the last sample (off the regular grid); a failed
        integration in ``status == "failed"`` with a ``message``.

    Examples
    --------
    The paper's Fig. 3 run: a 1 m/s backward platform step, case 1, from the flexed posture
    (on the compiled engine, the default):

    >>> import posturelab as pl
    >>> run = pl.simulate(pl.paper_body(), pl.paper_muscles("1"), pl.VelocityStep.backward(1.0),
    ...                   duration=5.0, initial_state=[0.1, -0.1, 0.1, 0, 0, 0])
    >>> run.outcome.kind, run.fell
    ('recovered', False)
    >>> run.theta.shape  # samples at 1 kHz × link angles [rad]
    (5001, 3)
    >>> [round(float(a), 3) for a in run.max_abs_theta]  # [rad]
    [0.217, 0.216, 0.288]

    Fig. 9: forward, case 2 (no gastrocnemius) falls, here on the reference engine:

    >>> fall = pl.simulate(pl.paper_body(), pl.paper_muscles("2"), pl.VelocityStep.forward(1.0),
    ...                    duration=5.0, initial_state=[0.1, -0.1, 0.1, 0, 0, 0],
    ...                    engine="reference")
    >>> fall.outcome.kind, round(fall.fall_time, 2)  # [s]
    ('fell', 1.19)
    """
    if duration is not None:
        keywords["duration"] = duration
    unknown = [k for k in keywords if k not in OPTION_NAMES]
    if unknown:
        raise ParameterError(f"unknown option {unknown[0]!r} of simulate(); known: "
                             f"{', '.join(OPTION_NAMES)}")
    if options is None:
        options = RunOptions(**keywords)
    elif keywords:
        options = options.replace(**keywords)
    return run_setup(prepare_run(body, muscles, disturbance, options))


def run_setup(setup: RunSetup) -> SimulationResult:
    """Integrate a prepared run on the engine its options name, with their integrator."""
    method = setup.options.integrator()
    if setup.options.engine == "reference":
        from .reference import integrate_reference

        return integrate_reference(setup, method)
    from .compiled import integrate_compiled

    return integrate_compiled(setup, method)


def _signature() -> inspect.Signature:
    """simulate's signature as help() shows it: the model, then every option by name."""
    head = list(inspect.signature(simulate).parameters.values())[:5]
    fields = RunOptions.__dataclass_fields__
    return inspect.Signature(head + [
        inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=fields[name].default,
                          annotation=fields[name].type)
        for name in OPTION_NAMES if name != "duration"])


simulate.__signature__ = _signature()  # type: ignore[attr-defined]
