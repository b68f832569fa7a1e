"""The options of one run, declared once: :class:`RunOptions`.

Every way of asking for a run parses into a :class:`RunOptions`: the keywords of
:func:`posturelab.simulate` (``simulate(body, muscles, disturbance, feedback_delay=0.1)``),
:func:`posturelab.simulate_batch` (the options its runs share), a :class:`~posturelab.Scenario`
(``Scenario.options``, read from a scenario file's ``[muscles]``, ``[tilt]``, ``[initial]``,
``[knee]``, ``[fall]``, ``[limits]`` and ``[solver]`` tables) and ``posturelab simulate``'s
options. The object is frozen and checked when it is made: each option's unit and accepted
range come from the parameter table (:data:`posturelab.parameters.QUANTITIES`,
:data:`posturelab.parameters.RUN_SETTINGS`) and a bad value raises one line naming the option,
the value and the range. What needs the body or the muscles (the initial state's length, a
limit per joint, a knee stop on one link, a tilt with one-sided pairs) is checked when the run
is set up (:func:`posturelab.simulation.setup.prepare_run`).

This module loads no engine (the command line's ``--help`` reads it).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from .._validation import finite_array
from ..errors import ParameterError
from ..model.joint_feedback import JointFeedback
from ..model.noise import MotorNoise
from ..model.options import FallCriteria, KneeModel
from ..model.tilt import Tilt
from ..parameters import (
    QUANTITIES,
    RUN_SETTINGS,
    TORQUE_FEEDBACK_TIME_CONSTANT,
    check_value,
    check_weights,
)
from .tolerances import DEFAULT_ATOL, DEFAULT_RTOL

__all__ = [
    "RunOptions",
    "ENGINES",
    "ENGINE_DEFAULTS",
    "COMPILED_METHODS",
    "REFERENCE_METHODS",
    "MAX_OUTPUT_SAMPLES",
    "BASE_STEP_BUDGET",
    "STEP_BUDGET_PER_SECOND",
    "default_step_budget",
    "engine_name",
    "option_names",
]

#: Engine names; "fast" is a former name of "compiled".
ENGINES = ("reference", "compiled")
#: Default (rtol [-], atol [rad, rad/s], method) of each engine; the compiled engine's
#: method depends on the run (posturelab.simulation.compiled.default_method).
ENGINE_DEFAULTS: dict[str, tuple[float, float, str | None]] = {
    "reference": (1e-8, 1e-10, "DOP853"),
    "compiled": (DEFAULT_RTOL, DEFAULT_ATOL, None),
}
#: The compiled engine's integrators (posturelab.simulation.compiled.METHODS).
COMPILED_METHODS = ("Radau", "RK45", "RK23")
#: The scipy ``solve_ivp`` methods a scenario file may name for the reference engine.
REFERENCE_METHODS = ("DOP853", "RK45", "RK23", "Radau", "BDF", "LSODA")
#: Most output samples of one run: the samples at 0, 1/sample_rate, … up to duration,
#: floor(duration × sample_rate) + 1 of them, at most the rows posturelab reads back
#: (posturelab._files.MAX_DATA_ROWS). [-]
MAX_OUTPUT_SAMPLES = 2_000_000
#: The step budget of a run when none is given: this many accepted integrator steps … [-]
BASE_STEP_BUDGET = 1_000_000
#: … and this many more per simulated second. [1/s]
STEP_BUDGET_PER_SECOND = 10_000


def default_step_budget(duration: float) -> int:
    """The step budget of a run of ``duration`` [s] when none is given. [-]

    10⁶ accepted steps plus 10⁴ per simulated second: a hundred times what the
    stiffest legitimate runs need (delayed feedback and motor noise cap the
    step near 1 ms), so that only a runaway integration meets it.
    """
    return int(BASE_STEP_BUDGET + STEP_BUDGET_PER_SECOND * math.ceil(duration))


def engine_name(engine: str) -> str:
    """The canonical engine name ("fast" → "compiled"); an unknown name lists the known ones."""
    name = "compiled" if engine == "fast" else engine
    if name not in ENGINES:
        raise ParameterError(f"engine must be one of {', '.join(map(repr, ENGINES))}, got "
                             f"{engine!r}")
    return name


def _option(default: Any, meaning: str, unit: str = "") -> Any:
    """A field of :class:`RunOptions`: its default, what it is and its unit (the bounds of a
    number are the parameter table's row of the same name)."""
    return field(default=default, metadata={"meaning": meaning, "unit": unit})


@dataclass(frozen=True)
class RunOptions:
    """Everything about one run except the body, the muscles and the platform motion.

    Each field is declared once here, with its meaning and unit (:func:`option_names`,
    ``dataclasses.fields(RunOptions)[i].metadata``); numbers are checked against the
    parameter table's bounds when the object is made. ``RunOptions(feedback_delay=0.1)``
    or :meth:`replace` (which checks again).

    Attributes
    ----------
    duration : float
        Simulated time. [s]
    initial_state : tuple of float, or None
        ``[Θ, Θ̇]`` before any velocity step; upright at rest by default. [rad], [rad/s]
    rates_from : {"upright", "posture"}
        Where J⁻¹H is evaluated for a velocity step
        (:func:`~posturelab.simulation.setup.initial_state_for`).
    knee : KneeModel
        Free (default), locked, or with a hyper-extension stop. Needs N >= 2.
    fall : FallCriteria
        Fall criteria; default: any |θ_i| > π/3, no foot limit (the paper's model).
    torque_limits : tuple, or None
        Largest net muscle moment at the ankle, knee, hip, … (the sum of the pairs crossing
        each joint), per joint: a number L (|τ_j| <= L; ``inf`` for no limit), a pair
        (lower, upper) with lower < 0 < upper (τ_j in [lower, upper]; at the ankle a
        positive moment is plantarflexion, pressing the centre of pressure toward the toes),
        or ``"foot"`` for the ankle: (m g x_heel, m g x_toe) from the body's weight and
        ``fall.base_of_support`` (:mod:`posturelab.model.limits`). A joint saturates and lets
        go at events. [N·m]
    feedback_delay : float
        Neural delay τ. With active gains in the muscles it delays their part only (the
        intrinsic gains act at once); without any, every pair's whole torque responds to
        the state at t − τ (before t = 0, the state before any velocity step). [s]
    proprioceptive_weight : float
        W in [0, 1]: the active part's error for pairs that span the foot is θ_hi + W·α
        (1: relative to the foot; 0: to the vertical). [-]
    visual_weight : float
        W_v in [0, 1], W_p + W_v <= 1 (the rest, 1 − W_p − W_v, graviceptive): under a
        visual-scene tilt v the active error of pairs that span the foot gains W_v·v. [-]
    visual_tilt : Tilt or None
        Visual-scene tilt v(t) about the ankle axis, positive toes-up like the surface
        (:mod:`posturelab.model.tilt` profiles); it acts only through the delayed active
        feedback (no mechanical effect). [rad]
    torque_feedback_gain : float
        K_t of Peterka 2002's torque feedback: each pair's active torque fed back positively
        through K_t/(τ_t s + 1) (docs/design.md; 0, the default: none). Needs a positive
        ``feedback_delay``; both engines carry the filter states. [-]
    torque_feedback_time_constant : float
        τ_t of its low-pass filter (default 17.4 s, PMC5664365 Table 1). [s]
    joint_feedback : JointFeedback or None
        A joint-space full-state controller, τ_ctrl = −F_θ Θ(t − τ) − F_ω Θ̇(t − τ), added to
        the pairs' moments before the torque limits (:mod:`posturelab.model.joint_feedback`;
        the preset ``multijoint-default``: :func:`posturelab.linear.lqr.multijoint_controller`).
        [N·m/rad], [N·m·s/rad]
    tilt : Tilt or None
        Support-surface tilt α(t), positive toes-up (:mod:`posturelab.model.tilt`). [rad]
    tilt_axis_depth : float
        Distance of the tilt axis below the ankle; 0 turns the surface about the ankle,
        otherwise the ankle moves on a circle about the axis (needs a tilt whose rate has
        no jumps). [m]
    motor_noise : MotorNoise or None
        A seeded random torque added to each joint's net moment before the limits. [N·m]
    engine : {"compiled", "reference"}
        ``compiled``: the C engine; ``reference``: the numpy model integrated by scipy
        (``docs/simulators.md``). "fast" is read as "compiled".
    method : str or None
        The integrator: a scipy ``solve_ivp`` method on the reference engine (DOP853 by
        default), Radau, RK45 or RK23 on the compiled one (by default Radau, or RK45 when
        the feedback is delayed); None for the engine's own.
    rtol, atol : float or None
        Integrator tolerances (relative [-], absolute [rad, rad/s]); None for the engine's
        own (:data:`ENGINE_DEFAULTS`).
    sample_rate : float
        Output samples per second. [Hz]
    max_switches : int
        Guard against chattering: more switches than this fail the run. [-]
    max_steps : int or None
        The step budget (accepted integrator steps before the run stops as ``failed``);
        None for :func:`default_step_budget`. [-]
    time_limit : float or None
        A wall-clock budget of the integration (the compiled engine looks at the clock
        every 256 attempted steps); None for none. [s]
    description : str
        Words stored in the result (the disturbance's own by default).
    """

    duration: float = _option(5.0, "simulated time", "s")
    initial_state: tuple[float, ...] | None = _option(
        None, "[Θ, Θ̇] before any velocity step (upright at rest)", "rad, rad/s")
    rates_from: Literal["upright", "posture"] = _option(
        "upright", "where J⁻¹H is evaluated for a velocity step")
    knee: KneeModel = _option(KneeModel(), "the knee: free, locked or with a stop")
    fall: FallCriteria = _option(FallCriteria(), "the fall criteria")
    torque_limits: tuple | None = _option(
        None, "largest net muscle moment per joint: L, (lower, upper) or 'foot' (inf: none)",
        "N·m")
    feedback_delay: float = _option(0.0, QUANTITIES["feedback_delay"].meaning, "s")
    proprioceptive_weight: float = _option(1.0, QUANTITIES["proprioceptive_weight"].meaning,
                                           "-")
    visual_weight: float = _option(0.0, QUANTITIES["visual_weight"].meaning, "-")
    visual_tilt: Tilt | None = _option(None, "visual-scene tilt, positive toes-up", "rad")
    torque_feedback_gain: float = _option(0.0, QUANTITIES["torque_feedback_gain"].meaning,
                                          "-")
    torque_feedback_time_constant: float = _option(
        TORQUE_FEEDBACK_TIME_CONSTANT, QUANTITIES["torque_feedback_time_constant"].meaning, "s")
    joint_feedback: JointFeedback | None = _option(
        None, "a joint-space full-state controller (delayed by feedback_delay)",
        "N·m/rad, N·m·s/rad")
    tilt: Tilt | None = _option(None, "support-surface tilt, positive toes-up", "rad")
    tilt_axis_depth: float = _option(0.0, RUN_SETTINGS["tilt_axis_depth"].meaning, "m")
    motor_noise: MotorNoise | None = _option(None, "seeded random joint torque", "N·m")
    engine: Literal["compiled", "reference"] = _option("compiled", "the engine")
    method: str | None = _option(None, "the integrator (None: the engine's own)")
    rtol: float | None = _option(None, RUN_SETTINGS["rtol"].meaning, "-")
    atol: float | None = _option(None, RUN_SETTINGS["atol"].meaning, "rad, rad/s")
    sample_rate: float = _option(1000.0, RUN_SETTINGS["sample_rate"].meaning, "Hz")
    max_switches: int = _option(10_000, RUN_SETTINGS["max_switches"].meaning, "-")
    max_steps: int | None = _option(None, RUN_SETTINGS["max_steps"].meaning, "-")
    time_limit: float | None = _option(None, RUN_SETTINGS["time_limit"].meaning, "s")
    description: str = _option("", "words stored in the result")

    def __post_init__(self) -> None:
        put = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        duration = _setting("duration", self.duration)
        put("duration", duration)
        if self.initial_state is not None:
            state = finite_array("initial_state [rad, rad/s]", self.initial_state, (None,))
            put("initial_state", tuple(state.tolist()))
        if self.rates_from not in ("upright", "posture"):
            raise ParameterError(f"rates_from must be 'upright' or 'posture', got "
                                 f"{self.rates_from!r}")
        put("knee", KneeModel() if self.knee is None else self.knee)
        _expect("knee", self.knee, KneeModel)
        put("fall", FallCriteria() if self.fall is None else self.fall)
        _expect("fall", self.fall, FallCriteria)
        if self.torque_limits is not None:
            put("torque_limits", _limit_tuple(self.torque_limits))
        put("feedback_delay", check_value("feedback_delay", self.feedback_delay))
        put("proprioceptive_weight", check_value("proprioceptive_weight",
                                                 self.proprioceptive_weight))
        put("visual_weight", check_weights(self.proprioceptive_weight, self.visual_weight))
        if self.visual_tilt is not None:
            _expect("visual_tilt", self.visual_tilt, Tilt)
        put("torque_feedback_gain", check_value("torque_feedback_gain",
                                                self.torque_feedback_gain))
        put("torque_feedback_time_constant", check_value("torque_feedback_time_constant",
                                                         self.torque_feedback_time_constant))
        if self.joint_feedback is not None:
            _expect("joint_feedback", self.joint_feedback, JointFeedback)
        depth = _setting("tilt_axis_depth", self.tilt_axis_depth)
        put("tilt_axis_depth", depth)
        if self.tilt is not None:
            _expect("tilt", self.tilt, Tilt)
            if depth > 0 and not self.tilt.rate_is_continuous:
                raise ParameterError("a tilt about an axis below the ankle needs a tilt rate "
                                     "without jumps (sine, raised cosine or measured), not "
                                     f"{type(self.tilt).__name__}")
        elif depth > 0:
            raise ParameterError("tilt_axis_depth [m] needs a tilt")
        if self.motor_noise is not None:
            _expect("motor_noise", self.motor_noise, MotorNoise)
        put("engine", engine_name(self.engine))
        if self.torque_feedback_gain > 0 and self.feedback_delay <= 0:
            raise ParameterError("torque_feedback_gain > 0 filters the delayed active "
                                 "torque: give a feedback_delay > 0")
        if self.method is not None and not isinstance(self.method, str):
            raise ParameterError(f"method must be the name of an integrator, got "
                                 f"{self.method!r:.60}")
        for name in ("rtol", "atol"):
            if getattr(self, name) is not None:
                put(name, _setting(name, getattr(self, name)))
        sample_rate = _setting("sample_rate", self.sample_rate)
        put("sample_rate", sample_rate)
        samples = math.floor(duration * sample_rate) + 1
        if samples > MAX_OUTPUT_SAMPLES:
            raise ParameterError(f"duration [s] {duration:g} at sample_rate [Hz] "
                                 f"{sample_rate:g} gives {samples:,} output samples "
                                 "(floor(duration × sample_rate) + 1, both ends); at most "
                                 f"{MAX_OUTPUT_SAMPLES:,}, the rows posturelab reads back "
                                 "(lower the sample rate or the duration)")
        if not _is_integer(self.max_switches) or self.max_switches < 0:
            raise ParameterError(f"max_switches must be an integer >= 0, got "
                                 f"{self.max_switches!r}")
        put("max_switches", int(self.max_switches))
        if self.max_steps is not None:
            put("max_steps", _step_budget(self.max_steps))
        if self.time_limit is not None:
            put("time_limit", _setting("time_limit", self.time_limit))
        if not isinstance(self.description, str):
            raise ParameterError(f"description must be a string, got {self.description!r:.60}")

    def replace(self, **changes: Any) -> RunOptions:
        """A copy with some options changed (checked again); an unknown name is refused
        listing the known ones."""
        unknown = [k for k in changes if k not in OPTION_NAMES]
        if unknown:
            raise ParameterError(f"unknown option {unknown[0]!r} of a run; known: "
                                 f"{', '.join(OPTION_NAMES)}")
        return dataclasses.replace(self, **changes)

    @classmethod
    def from_keywords(cls, where: str = "a run", **keywords: Any) -> RunOptions:
        """``RunOptions(**keywords)`` with an unknown keyword refused in one line naming
        ``where`` (the public functions' keyword API)."""
        unknown = [k for k in keywords if k not in OPTION_NAMES]
        if unknown:
            raise ParameterError(f"unknown option {unknown[0]!r} of {where}; known: "
                                 f"{', '.join(OPTION_NAMES)}")
        return cls(**keywords)

    @property
    def step_budget(self) -> int:
        """The step budget: ``max_steps``, or :func:`default_step_budget`. [-]"""
        return default_step_budget(self.duration) if self.max_steps is None else self.max_steps

    @property
    def wall_clock_limit(self) -> float:
        """``time_limit``, ``inf`` for none. [s]"""
        return math.inf if self.time_limit is None else self.time_limit

    @property
    def tolerances(self) -> tuple[float, float]:
        """(rtol [-], atol [rad, rad/s]): the given ones, else the engine's defaults."""
        d_rtol, d_atol, _ = ENGINE_DEFAULTS[self.engine]
        return (d_rtol if self.rtol is None else self.rtol,
                d_atol if self.atol is None else self.atol)

    def integrator(self) -> str | None:
        """The method that runs: ``method``, else the engine's default (None on the compiled
        engine: :func:`posturelab.simulation.compiled.default_method` chooses per run).

        Raises
        ------
        ParameterError
            The compiled engine and a method it does not have.
        """
        if self.engine == "compiled" and self.method is not None \
                and self.method not in COMPILED_METHODS:
            raise ParameterError(f"method must be one of "
                                 f"{', '.join(map(repr, COMPILED_METHODS))} for the compiled "
                                 f"engine, got {self.method!r}")
        return ENGINE_DEFAULTS[self.engine][2] if self.method is None else self.method


#: The names of the options, in declaration order.
OPTION_NAMES: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(RunOptions))


def option_names() -> tuple[str, ...]:
    """The names of :class:`RunOptions`' fields, in declaration order."""
    return OPTION_NAMES


def _setting(name: str, value: Any) -> float:
    """A number within the bounds of its row in :data:`posturelab.parameters.RUN_SETTINGS`:
    "duration [s] must be in (0, 86400] s, got 1e+308"."""
    q = RUN_SETTINGS[name]
    unit = "" if q.unit in ("-", "rad, rad/s") else q.unit
    label = f"{name} [{unit}]" if unit else name
    within = f"{q.interval()}{' ' + unit if unit else ''}"
    if isinstance(value, bool | np.bool_):  # (True is not 1 s)
        raise ParameterError(f"{label} must be a number in {within}, not a bool, got "
                             f"{value!r}")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{label} must be a number in {within}, got {value!r:.60}") from None
    low_ok = q.low < number if q.low_open else q.low <= number
    if isinstance(value, bool) or not (low_ok and number <= q.high and math.isfinite(number)):
        raise ParameterError(f"{label} must be in {within}, got {number!r}")
    return number


def _is_integer(value: Any) -> bool:
    return not isinstance(value, bool) and isinstance(value, int | np.integer)


def _step_budget(value: Any) -> int:
    """max_steps: an integer within the table's bounds."""
    high = int(RUN_SETTINGS["max_steps"].high)
    if not _is_integer(value) or not RUN_SETTINGS["max_steps"].low <= value <= high:
        raise ParameterError(f"max_steps must be an integer in [1, {high:,}], got "
                             f"{value!r:.60}")
    return int(value)


def _limit_tuple(value: Any) -> tuple:
    """Torque limits as a tuple with a float, a (lower, upper) pair or "foot" per joint (their
    values are checked per joint when the run is set up,
    :func:`posturelab.model.limits.torque_limit_array`)."""
    from ..model.limits import limit_entries

    return limit_entries(value)


def _expect(name: str, value: Any, kind: type) -> None:
    if not isinstance(value, kind):
        raise ParameterError(f"{name} must be a {kind.__name__}, got {type(value).__name__} "
                             f"{value!r:.60}")
