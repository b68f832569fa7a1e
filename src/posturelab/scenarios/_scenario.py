"""A scenario: a body, muscles, a platform motion and the run's options
(:class:`Scenario`, public through :mod:`posturelab.scenarios`)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from .._validation import reject_unknown_keys
from ..errors import ParameterError
from ..model.body import Body
from ..model.muscles import MuscleSet
from ..model.platform import Disturbance
from ..simulation.options import OPTION_NAMES, RunOptions

if TYPE_CHECKING:  # (the simulation loads when a scenario is run: --help stays light)
    from ..simulation.results import SimulationResult

__all__ = ["Scenario", "SCENARIO_DEFAULTS"]


#: A scenario's run options where it gives none: :class:`RunOptions`' defaults, but the
#: tolerances 1e-8 [-] and 1e-10 [rad, rad/s] on either engine (not each engine's own).
SCENARIO_DEFAULTS = RunOptions(rtol=1e-8, atol=1e-10)


@dataclass(frozen=True, init=False)
class Scenario:
    """Everything one simulation needs: the model, the platform motion and the run's options.

    The run's options (duration, initial state, knee, fall criteria, torque limits, feedback
    delay, tilt, motor noise, solver settings, …) are :attr:`options`, a
    :class:`~posturelab.simulation.options.RunOptions`, where each is declared; they read as
    attributes of the scenario too (``scenario.feedback_delay`` is
    ``scenario.options.feedback_delay``).

    Attributes
    ----------
    name : str
    source : str
        The paper figure or lab protocol it reproduces.
    body : Body
    muscles : MuscleSet
    disturbance : Disturbance
    options : RunOptions
        The run's options (by default :data:`SCENARIO_DEFAULTS`). A scenario's ``method``
        (``solver.method``) may name a scipy method that only the reference engine has;
        running it on the compiled engine (Radau, RK45, RK23) raises.
    case : str or None
        The Table I case, when the muscles come from one.
    """

    name: str
    source: str
    body: Body
    muscles: MuscleSet
    disturbance: Disturbance
    options: RunOptions  # (the defaults of these two are __init__'s: init=False)
    case: str | None

    def __init__(self, name: str, source: str, body: Body, muscles: MuscleSet,
                 disturbance: Disturbance, options: RunOptions | None = None,
                 case: str | None = None, **option_values: Any) -> None:
        """``Scenario(name, source, body, muscles, disturbance, options, case)``; run options
        may also be given by name (``duration=2.0, feedback_delay=0.1``, the former
        fields), replacing those of ``options``."""
        options = SCENARIO_DEFAULTS if options is None else options
        if option_values:
            options = options.replace(**option_values)
        for field, value in (("name", name), ("source", source), ("body", body),
                             ("muscles", muscles), ("disturbance", disturbance),
                             ("options", options), ("case", case)):
            object.__setattr__(self, field, value)

    def __getattr__(self, name: str) -> Any:
        """A run option read through the scenario (``scenario.duration``)."""
        if name in OPTION_NAMES:
            return getattr(self.options, name)
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def run(self, *, engine: str = "compiled", **overrides: Any) -> SimulationResult:
        """Simulate this scenario; keyword ``overrides`` replace fields (or options) first.

        ``engine="compiled"`` (the default; ``"fast"`` is its former name) runs the C
        engine, ``engine="reference"`` the numpy model integrated by scipy; both at the
        scenario's tolerances and with its ``solver.method`` (the engine's own integrator
        when it names none; :func:`posturelab.simulate`).

        Raises
        ------
        ParameterError
            ``solver.method`` names an integrator the engine does not have (the compiled
            engine has Radau, RK45 and RK23).
        """
        from ..simulation.engines import run_setup
        from ..simulation.setup import prepare_run

        sc = self.replace(**overrides) if overrides else self
        options = sc.run_options(engine)
        return run_setup(prepare_run(sc.body, sc.muscles, sc.disturbance, options))

    def run_options(self, engine: str = "compiled") -> RunOptions:
        """The options of a run of this scenario on ``engine``.

        Raises
        ------
        ParameterError
            The compiled engine and a ``solver.method`` it does not have.
        """
        from ..simulation.options import COMPILED_METHODS

        options = self.options.replace(engine=engine)
        if options.engine == "compiled" and options.method is not None \
                and options.method not in COMPILED_METHODS:
            raise ParameterError(
                f"scenario {self.name!r}: solver.method {options.method!r} runs on the "
                f"reference engine only; the compiled engine integrates with "
                f"{', '.join(COMPILED_METHODS)} (choose one of those, or run the reference "
                "engine: engine='reference', --engine reference)")
        return options

    def method_for(self, engine: str) -> str | None:
        """The scenario's ``solver.method`` for ``engine`` (None: the engine's own).

        Raises
        ------
        ParameterError
            The compiled engine and a method it does not have (it has Radau, RK45, RK23).
        """
        return self.run_options(engine).method

    def replace(self, **changes: Any) -> Scenario:
        """A copy with some fields or run options changed (``replace(duration=2.0)``);
        unknown names are rejected."""
        fields = {f.name for f in dataclasses.fields(self)}
        reject_unknown_keys("Scenario.replace()", changes, fields | set(OPTION_NAMES))
        own = {f: changes.get(f, getattr(self, f)) for f in fields}
        option_changes = {k: v for k, v in changes.items() if k not in fields}
        if option_changes:
            own["options"] = own["options"].replace(**option_changes)
        return Scenario(**own)
