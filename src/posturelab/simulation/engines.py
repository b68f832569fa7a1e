"""The one entry point of a simulation, :func:`simulate`, and which engine runs it.

Both engines take the same :class:`~posturelab.simulation.setup.RunSetup` and return
the same :class:`~posturelab.simulation.results.SimulationResult`; they differ only in
how they integrate (``docs/simulators.md`` has the table of what each does).
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from ..errors import ParameterError
from ..model.body import Body
from ..model.muscles import MuscleSet
from ..model.noise import MotorNoise
from ..model.options import FallCriteria, KneeModel
from ..model.platform import Disturbance
from ..model.tilt import Tilt
from .results import SimulationResult
from .setup import prepare_run

__all__ = ["simulate", "ENGINES", "engine_name", "ENGINE_DEFAULTS"]

#: Engine names; "fast" is a former name of "compiled".
ENGINES = ("reference", "compiled")

#: Default (rtol [-], atol [rad, rad/s], method) of each engine; the compiled engine's
#: method depends on the run (posturelab.simulation.compiled.default_method).
ENGINE_DEFAULTS: dict[str, tuple[float, float, str | None]] = {
    "reference": (1e-8, 1e-10, "DOP853"),
    "compiled": (1e-6, 1e-9, None),
}


def engine_name(engine: str) -> str:
    """The canonical engine name ("fast" → "compiled"); an unknown name lists the known ones."""
    name = "compiled" if engine == "fast" else engine
    if name not in ENGINES:
        raise ParameterError(f"engine must be one of {', '.join(map(repr, ENGINES))}, got "
                             f"{engine!r}")
    return name


def simulate(
    body: Body,
    muscles: MuscleSet,
    disturbance: Disturbance | None = None,
    duration: float = 5.0,
    *,
    initial_state: np.ndarray | None = None,
    rates_from: Literal["upright", "posture"] = "upright",
    knee: KneeModel | None = None,
    fall: FallCriteria | None = None,
    torque_limits: np.ndarray | None = None,
    feedback_delay: float = 0.0,
    rtol: float | None = None,
    atol: float | None = None,
    sample_rate: float = 1000.0,
    method: str | None = None,
    max_switches: int = 10_000,
    description: str = "",
    engine: str = "compiled",
    tilt: Tilt | None = None,
    proprioceptive_weight: float = 1.0,
    tilt_axis_depth: float = 0.0,
    motor_noise: MotorNoise | None = None,
    max_steps: int | None = None,
    time_limit: float | None = None,
) -> SimulationResult:
    """Simulate the nonlinear chain.

    Parameters
    ----------
    body : Body
        The chain.
    muscles : MuscleSet
        Muscle pairs (one-sided pairs switch exactly where their stretch crosses 0).
    disturbance : Disturbance, optional
        Platform motion; none by default.
    duration : float
        Simulated time. [s]
    initial_state : array_like, shape (2N,), optional
        ``[Θ, Θ̇]`` before any velocity step; upright at rest by default. [rad], [rad/s]
    rates_from : {"upright", "posture"}
        Where J⁻¹H is evaluated for a velocity step (see
        :func:`~posturelab.simulation.setup.initial_state_for`).
    knee : KneeModel, optional
        Free (default), locked, or with a hyper-extension stop. Needs N >= 2.
    fall : FallCriteria, optional
        Fall criteria; default: any |θ_i| > π/3, no foot limit (the paper's model).
    torque_limits : array_like, shape (N,), optional
        Largest net muscle moment at the ankle, knee, hip, … (the sum of the
        pairs crossing each joint); ``inf`` for no limit. A joint saturates and
        lets go at events, never inside the right-hand side. [N·m]
    feedback_delay : float
        Neural delay τ [s]. With active gains in ``muscles`` it delays their part only
        (the intrinsic gains act at once); without any, every pair's whole torque
        responds to the state at t − τ (before t = 0, the state before any velocity
        step). See :func:`posturelab.model.muscles.feedback_gains`.
    rtol, atol : float, optional
        Integrator tolerances (relative [-], absolute [rad, rad/s]); by default
        1e-8 and 1e-10 for the reference engine, 1e-6 and 1e-9 for the compiled one.
    sample_rate : float
        Output samples per second. [Hz]
    method : str, optional
        The integrator: for the reference engine a scipy ``solve_ivp`` method
        ("DOP853", the default, "RK45", "Radau", …); for the compiled engine
        "Radau", "RK45" or "RK23" (by default Radau, or RK45 when the feedback is
        delayed: :func:`posturelab.simulation.compiled.default_method`).
    max_switches : int
        Guard against chattering: more switches than this fail the run.
    description : str
        Words stored in the result.
    engine : {"compiled", "reference"}
        ``compiled`` (the default): the C engine (hundreds of times faster, built when
        posturelab is installed); ``reference``: the numpy model integrated by scipy
        (slow, obvious, the independent check). Same model, events and result; each at
        its own default tolerances and integrator unless ``rtol``, ``atol``, ``method``
        say otherwise (``docs/simulators.md``).
    tilt : Tilt, optional
        Support-surface tilt α(t), positive toes-up, about the ankle axis
        (:mod:`posturelab.model.tilt`); none by default. [rad]
    proprioceptive_weight : float
        W in [0, 1]: the active part's error for pairs that span the foot is
        θ_hi + W·α (1: relative to the foot; 0: to the vertical). [-]
    tilt_axis_depth : float
        Distance of the tilt axis below the ankle, in [0, 1] [m]; 0 (the default) turns
        the surface about the ankle itself, otherwise the ankle moves on a circle about
        the axis (:func:`posturelab.model.tilt.axis_translation`). Needs a tilt whose rate
        has no jumps.
    motor_noise : MotorNoise, optional
        A seeded random torque added to each joint's net muscle moment, before the torque
        limits (:mod:`posturelab.model.noise`); none by default. [N·m]
    max_steps : int, optional
        The step budget: after this many accepted integrator steps the run stops as
        ``failed`` with a message saying so; by default 10⁶ + 10⁴ per simulated
        second (:func:`~posturelab.simulation.setup.default_step_budget`), far beyond
        what a legitimate run needs. [-]
    time_limit : float, optional
        A wall-clock budget of the integration: past it the run stops as ``failed``
        (the samples so far kept); none by default. The compiled engine looks at the
        clock every 256 attempted steps, so a run shorter than that always finishes. [s]

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
    name = engine_name(engine)
    d_rtol, d_atol, d_method = ENGINE_DEFAULTS[name]
    setup = prepare_run(
        body, muscles, disturbance, duration, initial_state=initial_state,
        rates_from=rates_from, knee=knee, fall=fall, torque_limits=torque_limits,
        feedback_delay=feedback_delay, rtol=d_rtol if rtol is None else rtol,
        atol=d_atol if atol is None else atol, sample_rate=sample_rate,
        max_switches=max_switches, description=description, tilt=tilt,
        proprioceptive_weight=proprioceptive_weight, tilt_axis_depth=tilt_axis_depth,
        motor_noise=motor_noise, max_steps=max_steps, time_limit=time_limit)
    method = d_method if method is None else method
    if name == "reference":
        from .reference import integrate_reference

        return integrate_reference(setup, method)
    from .compiled import integrate_compiled

    return integrate_compiled(setup, method)
