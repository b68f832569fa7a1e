"""The set-up of a run, shared by both engines: validation, the initial state, the knee at
its stop, which pairs act and which joints saturate at the start, a fall at the start, the
output grid and the breakpoints; and the words of each outcome.

:func:`prepare_run` turns the arguments of :func:`posturelab.simulate` into a frozen
:class:`RunSetup`; the reference and the compiled engines take that object and
differ only in how they integrate. :func:`model_response` evaluates the model
(numpy, :mod:`posturelab.model.dynamics`) with the switches of a run applied; the
reference engine's right-hand side is this function.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .._validation import finite_array, float_in_range
from ..errors import ParameterError
from ..model import switched
from ..model.body import Body
from ..model.dynamics import (
    constrained_velocity,
    gravity_vector,
    knee_constraint_row,
    mass_matrix,
    platform_vector,
)
from ..model.muscles import MuscleSet, muscle_set_gains
from ..model.noise import MotorNoise, TorqueSeries, motor_noise_series, torque_at
from ..model.options import FallCriteria, KneeModel, torque_limit_array
from ..model.platform import Disturbance, NoDisturbance
from ..model.tilt import (
    MAX_AXIS_DEPTH,
    Tilt,
    axis_translation,
    check_proprioceptive_weight,
    tilt_pair_gains,
)
from ..parameters import MAX_FEEDBACK_DELAY  # the parameter table's bound
from .outcome import check_starts_within

__all__ = [
    "RunSetup",
    "RUN_OPTIONS",
    "prepare_run",
    "initial_state_for",
    "model_response",
    "output_grid",
    "outcome_message",
    "DELAY_BREAKPOINT_MULTIPLES",
    "MAX_FEEDBACK_DELAY",
    "MAX_DURATION",
    "MAX_OUTPUT_SAMPLES",
    "MAX_STEP_BUDGET",
    "MAX_TIME_LIMIT",
    "default_step_budget",
]

#: With a feedback delay τ the motion is not smooth at t = kτ (the step at t = 0 reaches
#: the muscles at τ, its derivative at 2τ, …); every engine ends a step exactly at kτ for
#: k = 1 … this many (the order of the default integrators), and at t_i + kτ after each knee
#: impact t_i (the impact changes the rates at once). [-]
DELAY_BREAKPOINT_MULTIPLES = 5
#: Longest run (a day). [s]
MAX_DURATION = 86_400.0
#: Most output samples of one run (duration × sample_rate + 1). [-]
MAX_OUTPUT_SAMPLES = 20_000_000
#: The step budget of a run when none is given: this many accepted integrator steps … [-]
BASE_STEP_BUDGET = 1_000_000
#: … and this many more per simulated second. [1/s]
STEP_BUDGET_PER_SECOND = 10_000
#: The largest step budget a run may ask for. [-]
MAX_STEP_BUDGET = 10_000_000_000
#: The longest wall-clock time limit a run may ask for (a week). [s]
MAX_TIME_LIMIT = 604_800.0


def default_step_budget(duration: float) -> int:
    """The step budget of a run of ``duration`` [s] when none is given. [-]

    10⁶ accepted steps plus 10⁴ per simulated second: a hundred times what the
    stiffest legitimate runs need (delayed feedback and motor noise cap the
    step near 1 ms), so that only a runaway integration meets it.
    """
    return int(BASE_STEP_BUDGET + STEP_BUDGET_PER_SECOND * math.ceil(duration))

Status = Literal["completed", "fell", "failed"]


@dataclass(frozen=True, eq=False)
class RunSetup:
    """Everything both engines share about one run (built by :func:`prepare_run`).

    Attributes
    ----------
    body : Body
    muscles : MuscleSet
    disturbance : Disturbance
    duration : float
        Simulated time. [s]
    knee : KneeModel
    fall : FallCriteria
    torque_limits : numpy.ndarray, shape (N,), or None
        Largest net muscle moment per joint, ``inf`` where none; None if none limit. [N·m]
    feedback_delay : float
        Neural delay τ of the muscle feedback; 0 for none. [s]
    gains : numpy.ndarray, shape (4, P)
        The pair gains by when they act (:func:`posturelab.model.muscles.feedback_gains`):
        immediate stiffness and viscosity, delayed stiffness and viscosity.
        [N·m/rad], [N·m·s/rad], [N·m/rad], [N·m·s/rad]
    rtol, atol : float
        Integrator tolerances [-], [rad, rad/s].
    sample_rate : float
        Output samples per second. [Hz]
    max_switches : int
        More switches than this fail the run (chattering). [-]
    max_steps : int
        The step budget: more accepted integrator steps than this end the run as
        failed. [-]
    time_limit : float
        The wall-clock budget of the integration; ``inf`` for none. [s]
    description : str
        The run in words.
    before : numpy.ndarray, shape (2N,)
        ``[Θ, Θ̇]`` before any velocity step: what delayed feedback sees for t < 0.
        [rad], [rad/s]
    x0 : numpy.ndarray, shape (2N,)
        The state the integration starts from (after the step, on the knee constraint
        if the knee starts locked). [rad], [rad/s]
    locked0 : bool
        The knee starts locked (mode ``locked``, or at its stop and not flexing); with a
        stop, both engines release it at t = 0 when the free knee acceleration already
        points away from the stop (the knee-leaves-stop event is then past its root).
    active0 : numpy.ndarray, shape (P,)
        1 for each pair that acts at the start, 0 for a slack one-sided pair. [-]
    saturation0 : numpy.ndarray, shape (N,)
        ±1 for a joint whose moment starts beyond its limit, else 0. [-]
    grid : numpy.ndarray, shape (T,)
        Output sample times. [s]
    breakpoints : numpy.ndarray
        Corners of the platform profile inside (0, duration), sorted. [s]
    delay_breakpoints : numpy.ndarray
        kτ inside (0, duration) for k = 1 … :data:`DELAY_BREAKPOINT_MULTIPLES`. [s]
    max_step : float
        Largest integrator step: what resolves the profile, and τ with a delay (the
        past the feedback needs is then always computed). [s]
    fall_at_start : str or None
        Why the run falls at t = 0 (a fall criterion already violated), else None.
    knee_row : numpy.ndarray, shape (N,), or None
        The row C of the knee constraint when the knee can lock. [-]
    rates_from : {"upright", "posture"}
        Where J⁻¹H was evaluated for a velocity step.
    tilt : Tilt or None
        The support-surface tilt α(t) (:mod:`posturelab.model.tilt`), None for none.
    proprioceptive_weight : float
        W of the active part's error for pairs that span the foot. [-]
    tilt_gains : numpy.ndarray, shape (4, P), or None
        Pair gains on α(t), α̇(t), α(t − τ), α̇(t − τ)
        (:func:`posturelab.model.tilt.tilt_pair_gains`); None without a tilt.
        [N·m/rad], [N·m·s/rad], [N·m/rad], [N·m·s/rad]
    tilt_axis_depth : float
        Distance of the tilt axis below the ankle (0: the ankle's own axis). [m]
    velocity_jump : (float, float)
        The ankle's velocity change at t = 0: the disturbance's step and the start of a
        tilt about an axis below the ankle. [m/s]
    motor_noise : MotorNoise or None
        The motor noise of the run (:mod:`posturelab.model.noise`), None for none.
    motor_torque : TorqueSeries or None
        Its realisation over the run: added to each joint's moment before the limits. [N·m]
    """

    body: Body
    muscles: MuscleSet
    disturbance: Disturbance
    duration: float
    knee: KneeModel
    fall: FallCriteria
    torque_limits: np.ndarray | None
    feedback_delay: float
    gains: np.ndarray
    rtol: float
    atol: float
    sample_rate: float
    max_switches: int
    description: str
    before: np.ndarray
    x0: np.ndarray
    locked0: bool
    active0: np.ndarray
    saturation0: np.ndarray
    grid: np.ndarray
    breakpoints: np.ndarray
    delay_breakpoints: np.ndarray
    max_step: float
    fall_at_start: str | None
    knee_row: np.ndarray | None
    rates_from: str = "upright"
    tilt: Tilt | None = None
    proprioceptive_weight: float = 1.0
    tilt_gains: np.ndarray | None = None
    tilt_axis_depth: float = 0.0
    velocity_jump: tuple[float, float] = (0.0, 0.0)
    motor_noise: MotorNoise | None = None
    motor_torque: TorqueSeries | None = None
    max_steps: int = BASE_STEP_BUDGET
    time_limit: float = math.inf

    @property
    def n_links(self) -> int:
        """N. [-]"""
        return self.body.n_links

    def with_fall_criteria(self, **changes) -> RunSetup:
        """The same set-up with some fall criteria changed (fall_at_start recomputed)."""
        from dataclasses import replace

        new = replace(self, fall=replace(self.fall, **changes), fall_at_start=None)
        object.__setattr__(new, "fall_at_start", _fall_at_start(new))
        return new

    @property
    def stops(self) -> list[float]:
        """Every time a step must end on: breakpoints, kτ, and the end. [s]"""
        return sorted({*self.breakpoints.tolist(), *self.delay_breakpoints.tolist(),
                       self.duration})


@functools.lru_cache(maxsize=32)
def output_grid(duration: float, sample_rate: float) -> np.ndarray:
    """Output sample times 0, 1/rate, … up to ``duration`` (read-only, shared). [s]"""
    grid = np.arange(0.0, duration + 0.5 / sample_rate, 1.0 / sample_rate)
    grid = grid[grid <= duration + 1e-12]
    grid.setflags(write=False)
    return grid


def initial_state_for(
    body: Body,
    disturbance: Disturbance,
    initial_state: np.ndarray | None = None,
    rates_from: Literal["upright", "posture"] = "upright",
    extra_velocity: tuple[float, float] = (0.0, 0.0),
) -> np.ndarray:
    """Initial state after the disturbance's velocity step at t = 0.

    The step changes the rates by ΔΘ̇ = J⁻¹(−H Δẋ_d + G Δẏ_d), with J, H, G
    evaluated at upright (the paper's choice, ``rates_from="upright"``) or at
    the initial posture (``"posture"``, exact; erratum 5).

    Parameters
    ----------
    initial_state : array_like, shape (2N,), optional
        ``[Θ, Θ̇]`` before the step; upright at rest by default. [rad], [rad/s]
    extra_velocity : (float, float)
        A further jump of the ankle's velocity at t = 0 (a tilt about an axis below the
        ankle that starts turning at once). [m/s]
    """
    n = body.n_links
    x0 = (np.zeros(2 * n) if initial_state is None
          else finite_array("initial_state [rad, rad/s]", initial_state, (2 * n,)).copy())
    dv = tuple(float(a + b) for a, b in zip(disturbance.velocity_change, extra_velocity,
                                             strict=True))
    if dv != (0.0, 0.0):
        if rates_from not in ("upright", "posture"):
            raise ParameterError(
                f"rates_from must be 'upright' or 'posture', got {rates_from!r}"
            )
        ref = np.zeros(n) if rates_from == "upright" else x0[:n]
        J = mass_matrix(body, ref)
        gen = -platform_vector(body, ref) * dv[0] + gravity_vector(body, ref) * dv[1]
        x0[n:] += np.linalg.solve(J, gen)
    return x0


def check_step_budget(max_steps, duration: float) -> int:
    """A run's step budget: an integer in [1, :data:`MAX_STEP_BUDGET`], or None for
    :func:`default_step_budget`. [-]"""
    if max_steps is None:
        return default_step_budget(duration)
    if isinstance(max_steps, bool) or not isinstance(max_steps, int | np.integer) \
            or not 1 <= max_steps <= MAX_STEP_BUDGET:
        raise ParameterError(f"max_steps must be an integer in [1, {MAX_STEP_BUDGET:,}], got "
                             f"{max_steps!r:.60}")
    return int(max_steps)


def check_time_limit(time_limit) -> float:
    """A run's wall-clock budget in (0, :data:`MAX_TIME_LIMIT`] [s]; None for none (inf)."""
    if time_limit is None:
        return math.inf
    return float_in_range("time_limit [s]", time_limit, 0.0, MAX_TIME_LIMIT, include_low=False,
                          unit="s")


def _expect(name: str, value, kind: type) -> None:
    if not isinstance(value, kind):
        raise ParameterError(f"{name} must be a {kind.__name__}, got {type(value).__name__} "
                             f"{value!r:.60}")


#: The keyword options of a run and their defaults (meanings and units:
#: :func:`posturelab.simulate`).
RUN_OPTIONS: dict[str, object] = {
    "initial_state": None, "rates_from": "upright", "knee": None, "fall": None,
    "torque_limits": None, "feedback_delay": 0.0, "rtol": 1e-8, "atol": 1e-10,
    "sample_rate": 1000.0, "max_switches": 10_000, "description": "", "tilt": None,
    "proprioceptive_weight": 1.0, "tilt_axis_depth": 0.0, "motor_noise": None,
    "max_steps": None, "time_limit": None,
}


def _frozen(value):
    """A hashable form of an option value (arrays and lists as tuples)."""
    if isinstance(value, np.ndarray | list | tuple):
        return tuple(np.asarray(value, dtype=float).ravel().tolist())
    return value


@functools.lru_cache(maxsize=128)
def _prepare_cached(body, muscles, disturbance, duration, frozen_options) -> RunSetup:
    options = dict(frozen_options)
    for key in ("initial_state", "torque_limits"):
        if options.get(key) is not None:
            options[key] = np.array(options[key])
    return _prepare(body, muscles, disturbance, duration, **options)


def prepare_run(body: Body, muscles: MuscleSet, disturbance: Disturbance | None = None,
                duration: float = 5.0, **options) -> RunSetup:
    """Validate the arguments of a run and work out everything both engines share.

    Parameters are those of :func:`posturelab.simulate` (units there); the keyword
    options and their defaults are :data:`RUN_OPTIONS`. A set-up is immutable, so the
    same arguments (when every one is hashable: a measured profile is not) return the
    same object, computed once.

    Raises
    ------
    ParameterError
        An unknown option, an argument of the wrong type or outside its range, the knee
        beyond its stop, a muscle set for another number of links.
    """
    try:
        key = tuple(sorted((k, _frozen(v)) for k, v in options.items()))
        return _prepare_cached(body, muscles, disturbance, duration, key)
    except TypeError:  # something unhashable (a measured profile): set up afresh
        return _prepare(body, muscles, disturbance, duration, **options)


def _prepare(body: Body, muscles: MuscleSet, disturbance: Disturbance | None = None,
             duration: float = 5.0, **options) -> RunSetup:
    """:func:`prepare_run` without the memo."""
    from .._validation import reject_unknown_keys

    reject_unknown_keys("the options of a run", options, RUN_OPTIONS)
    o = {**RUN_OPTIONS, **options}
    initial_state, rates_from = o["initial_state"], o["rates_from"]
    knee, fall, torque_limits = o["knee"], o["fall"], o["torque_limits"]
    rtol, atol, sample_rate = o["rtol"], o["atol"], o["sample_rate"]
    max_switches, description = o["max_switches"], o["description"]
    tilt = o["tilt"]
    weight = check_proprioceptive_weight(o["proprioceptive_weight"])
    depth = float_in_range("tilt_axis_depth [m]", o["tilt_axis_depth"], 0.0, MAX_AXIS_DEPTH,
                           unit="m")
    if tilt is not None:
        _expect("tilt", tilt, Tilt)
        if muscles.one_sided_mask.any():
            raise ParameterError("a platform tilt cannot be combined with one-sided pairs "
                                 "(make them two-sided)")
        if depth > 0 and not tilt.rate_is_continuous:
            raise ParameterError("a tilt about an axis below the ankle needs a tilt rate "
                                 "without jumps (sine, raised cosine or measured), not "
                                 f"{type(tilt).__name__}")
    elif depth > 0:
        raise ParameterError("tilt_axis_depth [m] needs a tilt")
    _expect("body", body, Body)
    _expect("muscles", muscles, MuscleSet)
    disturbance = NoDisturbance() if disturbance is None else disturbance
    _expect("disturbance", disturbance, Disturbance)
    knee = KneeModel() if knee is None else knee
    _expect("knee", knee, KneeModel)
    fall = FallCriteria() if fall is None else fall
    _expect("fall", fall, FallCriteria)
    if muscles.n_links != body.n_links:
        raise ParameterError(
            f"muscle set is for {muscles.n_links} links but the body has {body.n_links}"
        )
    duration = float_in_range("duration [s]", duration, 0.0, MAX_DURATION, include_low=False,
                              unit="s")
    check_starts_within(disturbance, tilt, duration)
    noise = o["motor_noise"]
    motor_torque = None
    if noise is not None:
        _expect("motor_noise", noise, MotorNoise)
        motor_torque = motor_noise_series(noise, duration, body.n_links)
    rtol = float_in_range("rtol", rtol, 1e-14, 1e-1)
    atol = float_in_range("atol", atol, 1e-16, 1e-1)
    sample_rate = float_in_range("sample_rate [Hz]", sample_rate, 1.0, 1e6, unit="Hz")
    samples = math.floor(duration * sample_rate) + 1
    if samples > MAX_OUTPUT_SAMPLES:
        raise ParameterError(f"duration [s] × sample_rate [Hz] = {duration:g} × {sample_rate:g} "
                             f"gives {samples:,} output samples; at most "
                             f"{MAX_OUTPUT_SAMPLES:,} (lower the sample rate or the duration)")
    if isinstance(max_switches, bool) or not isinstance(max_switches, int | np.integer) \
            or max_switches < 0:
        raise ParameterError(f"max_switches must be an integer >= 0, got {max_switches!r}")
    max_steps = check_step_budget(o["max_steps"], duration)
    time_limit = check_time_limit(o["time_limit"])
    n = body.n_links
    if knee.mode != "free" and n < 2:
        raise ParameterError("knee mode 'locked' or 'stop' needs a body with at least 2 links")
    delay = float_in_range("feedback_delay [s]", o["feedback_delay"], 0.0, MAX_FEEDBACK_DELAY,
                           unit="s")
    limits = torque_limit_array(torque_limits, n)
    before = (np.zeros(2 * n) if initial_state is None
              else finite_array("initial_state [rad, rad/s]", initial_state, (2 * n,)).copy())
    jump = (0.0, 0.0)
    if tilt is not None and depth > 0:  # the ankle starts moving with the surface's rate
        jump = tuple(float(v) for v in axis_translation(tilt, depth, 0.0)[1])
    x0 = initial_state_for(body, disturbance, initial_state, rates_from, jump)
    knee_row = knee_constraint_row(n) if knee.mode != "free" else None
    locked0 = knee.mode == "locked"
    if knee.mode == "stop":
        kappa = x0[1] - x0[0]
        if kappa > knee.stop_angle + 1e-12:
            raise ParameterError(
                f"initial knee angle θ2 − θ1 = {kappa:g} rad is beyond the hyper-extension "
                f"stop ({knee.stop_angle:g} rad)"
            )
        locked0 = abs(kappa - knee.stop_angle) <= 1e-12 and (x0[n + 1] - x0[n]) >= 0
    if locked0:
        x0[n:] = constrained_velocity(body, x0[:n], x0[n:], knee_row)
    gains = muscle_set_gains(muscles, delay)
    active0 = start_activity(muscles, before if delay > 0 else x0, gains)  # (one-sided pairs have
    # no active gains: their whole feedback is delayed or none is)
    tilt_gains = None
    if tilt is not None:
        tilt_gains = tilt_pair_gains(muscle_set_gains(muscles, 1.0), muscles.spans_foot, delay,
                                     weight)
        tilt_gains.setflags(write=False)
    moments0 = start_moments(muscles, x0, before, active0, gains)
    if tilt is not None:
        moments0 = moments0 + tilt_torques(tilt, tilt_gains, delay, 0.0) @ muscles.crossing_matrix
    if motor_torque is not None:
        moments0 = moments0 + torque_at(motor_torque, 0.0)
    saturation0 = start_saturation(moments0, limits)
    corners = set(disturbance.breakpoints)
    if tilt is not None:  # the tilt's corners, and where the delayed part feels them
        tilt_corners = tilt.breakpoints(duration)
        corners |= set(tilt_corners) | {b + delay for b in tilt_corners if delay > 0}
    breakpoints = np.array(sorted({b for b in corners if 0.0 < b < duration}), dtype=float)
    delay_bps = np.array([k * delay for k in range(1, DELAY_BREAKPOINT_MULTIPLES + 1)
                          if delay > 0 and k * delay < duration])
    max_step = min(disturbance.max_step, duration, delay if delay > 0 else math.inf,
                   tilt.max_step if tilt is not None else math.inf,
                   noise.max_step if noise is not None else math.inf)
    for arr in (before, x0, active0, saturation0, breakpoints, delay_bps, gains):
        arr.setflags(write=False)
    setup = RunSetup(
        body=body, muscles=muscles, disturbance=disturbance, duration=duration, knee=knee,
        fall=fall, torque_limits=limits, feedback_delay=delay, gains=gains, rtol=rtol, atol=atol,
        sample_rate=sample_rate, max_switches=int(max_switches),
        description=description or disturbance.describe(), before=before, x0=x0,
        locked0=bool(locked0), active0=active0, saturation0=saturation0,
        grid=output_grid(duration, sample_rate), breakpoints=breakpoints,
        delay_breakpoints=delay_bps, max_step=max_step, fall_at_start=None, knee_row=knee_row,
        rates_from=rates_from, tilt=tilt, proprioceptive_weight=weight, tilt_gains=tilt_gains,
        tilt_axis_depth=depth, velocity_jump=tuple(
            float(a + b) for a, b in zip(disturbance.velocity_change, jump, strict=True)),
        motor_noise=noise, motor_torque=motor_torque, max_steps=max_steps,
        time_limit=time_limit,
    )
    object.__setattr__(setup, "fall_at_start", _fall_at_start(setup))
    return setup


# The switched model lives in posturelab.model.switched; these are its run-level forms.
start_activity = switched.start_activity
start_moments = switched.start_moments
start_saturation = switched.start_saturation
tilt_torques = switched.tilt_pair_torques


def switched_model(setup: RunSetup) -> switched.SwitchedModel:
    """The switched model of a run (:class:`posturelab.model.switched.SwitchedModel`), built
    once per set-up."""
    model = setup.__dict__.get("_switched_model")
    if model is None:
        model = switched.SwitchedModel(
            body=setup.body, muscles=setup.muscles, gains=setup.gains,
            disturbance=setup.disturbance, torque_limits=setup.torque_limits,
            feedback_delay=setup.feedback_delay, tilt=setup.tilt, tilt_gains=setup.tilt_gains,
            tilt_axis_depth=setup.tilt_axis_depth, motor_torque=setup.motor_torque,
            knee_row=setup.knee_row, knee=setup.knee, fall=setup.fall)
        object.__setattr__(setup, "_switched_model", model)
    return model


def pair_torque_if_acting(setup: RunSetup, j: int, feedback: np.ndarray) -> float:
    """M_j = k s + l ṡ of pair j on the state the muscles respond to, ``feedback`` (2N,).
    [N·m]"""
    n = setup.n_links
    e = setup.muscles.selection_matrix[j]
    return float(switched.pair_torque_formula(*switched.pair_gains(switched_model(setup), j),
                                              e @ feedback[:n], e @ feedback[n:]))


def pair_pulls_value(setup: RunSetup, j: int, feedback: np.ndarray) -> float:
    """min(M_j, k_j s_j) of a slack pull-only pair: positive once it is stretched and its
    torque pulls (k_j its stiffness, 1 N·m/rad if it has none). [N·m]"""
    n = setup.n_links
    stiffness = switched.pair_gains(switched_model(setup), j)[0]
    stretch = setup.muscles.selection_matrix[j] @ feedback[:n]
    return float(switched.pull_value_formula(pair_torque_if_acting(setup, j, feedback),
                                             stiffness, stretch))


def start_centre_of_pressure(setup: RunSetup, moments: np.ndarray, limits, saturation
                             ) -> np.ndarray:
    """Centre of pressure at t = 0 for runs that differ in their moments (..., N) [N·m],
    limits (..., N) [N·m] and saturation (..., N): x_p (...)
    (:func:`posturelab.model.switched.start_centre_of_pressure`). [m]"""
    return switched.start_centre_of_pressure(switched_model(setup), setup.x0, setup.locked0,
                                             moments, limits, saturation)


def model_response(setup: RunSetup, t: float, x: np.ndarray, feedback: np.ndarray,
                   active: np.ndarray, locked: bool, saturation: np.ndarray | None
                   ) -> tuple[np.ndarray, np.ndarray]:
    """The model at one state with the run's switches applied: (moments [N·m], Θ̈ [rad/s²])
    (:func:`posturelab.model.switched.model_response`)."""
    return switched.model_response(switched_model(setup), t, x, feedback, active, locked,
                                   saturation)


def raw_moments(setup: RunSetup, t: float, x: np.ndarray, feedback: np.ndarray,
                active: np.ndarray) -> np.ndarray:
    """Unsaturated net muscle moment per joint (:func:`posturelab.model.switched.raw_moments`).
    [N·m]"""
    return switched.raw_moments(switched_model(setup), t, x, feedback, active)


def platform_acceleration(setup: RunSetup, t) -> np.ndarray:
    """The ankle's acceleration (ẍ_d, ÿ_d) at ``t``, shape t.shape + (2,)
    (:func:`posturelab.model.switched.platform_acceleration`). [m/s²]"""
    return switched.platform_acceleration(switched_model(setup), t)


def cop_at(setup: RunSetup, t: float, x: np.ndarray, feedback: np.ndarray, active, locked,
           saturation) -> float:
    """Centre of pressure x_p at one state
    (:func:`posturelab.model.switched.centre_of_pressure_at`). [m]"""
    return switched.centre_of_pressure_at(switched_model(setup), t, x, feedback, active, locked,
                                          saturation)


def ankle_moment_and_load(setup: RunSetup, t: float, x: np.ndarray, feedback: np.ndarray,
                          active, locked, saturation) -> tuple[float, float]:
    """τ_ankle [N·m] and F_y [N] at one state
    (:func:`posturelab.model.switched.ankle_moment_and_load`)."""
    return switched.ankle_moment_and_load(switched_model(setup), t, x, feedback, active, locked,
                                          saturation)


def _fall_at_start(setup: RunSetup) -> str | None:
    """A fall criterion already violated at t = 0 (events only see crossings)."""
    n = setup.n_links
    x = setup.x0
    fall = setup.fall
    over = np.nonzero(np.abs(x[:n]) > fall.max_link_angle)[0]
    if over.size:
        return f"link {over[0] + 1} angle beyond ±{fall.max_link_angle:.3g} rad at the start"
    bos = fall.base_of_support
    if bos is None:
        return None
    xc = setup.body.gravity_coefficients @ np.sin(x[:n]) / setup.body.total_mass
    if not bos.heel <= xc <= bos.toe:
        return f"centre of gravity ({xc:.3f} m) outside the foot at the start"
    if fall.centre_of_pressure:
        feedback = setup.before if setup.feedback_delay > 0 else x
        sat = setup.saturation0 if setup.torque_limits is not None else None
        xp = cop_at(setup, 0.0, x, feedback, setup.active0, setup.locked0, sat)
        return cop_fall_at_start(xp, bos)
    return None


def cop_fall_at_start(xp: float, bos) -> str | None:
    """Why a centre of pressure x_p [m] at t = 0 is a fall (outside the foot), else None."""
    if not bos.heel <= xp <= bos.toe:
        return f"centre of pressure ({xp:.3f} m) outside the foot at the start: the foot tips"
    return None


def fall_at_start_by_posture(setup: RunSetup) -> str | None:
    """The part of :attr:`RunSetup.fall_at_start` that does not depend on the gains (the link
    angles and the centre of gravity)."""
    if setup.fall.centre_of_pressure:
        return _fall_at_start(setup.with_fall_criteria(centre_of_pressure=False))
    return setup.fall_at_start


#: The implicit integrators (of scipy's solve_ivp and the compiled engine's Radau IIA).
IMPLICIT_METHODS = ("Radau", "BDF", "LSODA")


def outcome_message(status: str, t: float, setup: RunSetup, *, fall_reason: str = "",
                    detail: str = "", method: str | None = None) -> str:
    """The words of a run's outcome.

    Parameters
    ----------
    status : str
        What happened: one of "completed", "fell", "step-too-small", "non-finite",
        "chattering", "no-memory", "step-budget", "time-budget", "failed" ("failed" takes
        its words from ``detail``).
    t : float
        When it happened (the fall, the failure). [s]
    method : str, optional
        The integrator that ran ("Radau", "RK45", "DOP853", …): a spent step budget suggests
        an implicit method only to a run that had an explicit one.
    """
    if status == "completed":
        return f"ran to {setup.duration:g} s"
    if status == "fell":
        when = "0 s" if t == 0.0 else f"{t:.4f} s"
        return f"fell at t = {when}: {fall_reason}"
    if status == "step-too-small":
        return (f"integrator failed at t = {t:.6g} s: required step size is less than "
                "spacing between numbers")
    if status == "non-finite":
        return f"state diverged (non-finite) at t = {t:.6g} s"
    if status == "chattering":
        return f"more than {setup.max_switches} switches by t = {t:.6g} s (chattering)"
    if status == "no-memory":
        return f"ran out of memory at t = {t:.6g} s"
    if status == "step-budget":
        if method in IMPLICIT_METHODS:
            advice = f"raise max_steps; the {method} method that ran is already implicit"
        else:
            advice = ("raise max_steps; for very stiff or viscous gains an implicit method "
                      "such as Radau needs far fewer steps")
        return (f"stopped at t = {t:.6g} s: the step budget of {setup.max_steps:,} integrator "
                f"steps ran out ({advice})")
    if status == "time-budget":
        return (f"stopped at t = {t:.6g} s: the time limit of {setup.time_limit:g} s "
                "(wall clock) ran out (raise time_limit)")
    return detail
