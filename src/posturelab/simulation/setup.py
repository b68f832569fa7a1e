"""The set-up of a run, shared by both engines: the initial state, the knee at its stop,
which pairs act and which joints saturate at the start, a fall at the start, the output grid
and the breakpoints.

:func:`prepare_run` turns a body, muscles, a disturbance and the run's
:class:`~posturelab.simulation.options.RunOptions` (checked when they were made) into a frozen
:class:`RunSetup`; the reference and the compiled engines take that object and differ only in
how they integrate. :func:`model_response` evaluates the model (numpy,
:mod:`posturelab.model.dynamics`) with the switches of a run applied; the reference engine's
right-hand side is this function. The words of each outcome are in
:mod:`posturelab.simulation.messages`.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np

from .._validation import initial_state_array
from ..errors import ParameterError
from ..model import switched
from ..model.body import Body
from ..model.checks import check_model
from ..model.dynamics import (
    constrained_velocity,
    gravity_vector,
    knee_constraint_row,
    mass_matrix,
    platform_vector,
)
from ..model.joint_feedback import joint_feedback_moments, joint_gain_rows
from ..model.limits import body_torque_limits
from ..model.muscles import MuscleSet, muscle_set_gains
from ..model.noise import MotorNoise, TorqueSeries, motor_noise_series, torque_at
from ..model.options import FallCriteria, KneeModel
from ..model.platform import Disturbance, NoDisturbance
from ..model.tilt import Tilt, axis_translation, tilt_pair_gains
from ..model.visual import visual_pair_gains
from ..parameters import MAX_DURATION, MAX_FEEDBACK_DELAY, MAX_STEP_BUDGET, MAX_TIME_LIMIT
from .messages import outcome_message
from .options import MAX_OUTPUT_SAMPLES, OPTION_NAMES, RunOptions, default_step_budget
from .outcome import check_starts_within

__all__ = ["RunSetup", "RunOptions", "RUN_OPTIONS", "prepare_run", "initial_state_for",
           "model_response", "output_grid", "outcome_message", "DELAY_BREAKPOINT_MULTIPLES",
           "MAX_FEEDBACK_DELAY", "MAX_DURATION", "MAX_OUTPUT_SAMPLES", "MAX_STEP_BUDGET",
           "MAX_TIME_LIMIT", "default_step_budget"]

#: With a feedback delay τ the motion is not smooth at t = kτ (the step at t = 0 reaches
#: the muscles at τ, its derivative at 2τ, …); every engine ends a step exactly at kτ for
#: k = 1 … this many (the order of the default integrators), and at t_i + kτ after each knee
#: impact t_i (the impact changes the rates at once). [-]
DELAY_BREAKPOINT_MULTIPLES = 5

#: The options of a run and their defaults, read from :class:`RunOptions` (its fields are
#: the one declaration; this mapping is for reading).
RUN_OPTIONS: dict[str, object] = {name: RunOptions.__dataclass_fields__[name].default
                                  for name in OPTION_NAMES}

Status = Literal["completed", "fell", "failed"]


@dataclass(frozen=True, eq=False)
class RunSetup:
    """Everything both engines share about one run (built by :func:`prepare_run`).

    The run's options are :attr:`options` (a :class:`RunOptions`); the properties
    ``duration``, ``feedback_delay``, ``tilt``, ``knee``, ``fall``, ``rtol``, ``atol``, … read
    them (the tolerances, step budget and time limit resolved to numbers).

    Attributes
    ----------
    body : Body
    muscles : MuscleSet
    disturbance : Disturbance
    options : RunOptions
        The run's options as given (checked).
    torque_limits : numpy.ndarray, shape (2, N), or None
        Each joint's largest negative (its magnitude, row 0) and positive net muscle moment
        (:mod:`posturelab.model.limits`), ``inf`` where none; None if none limit. [N·m]
    gains : numpy.ndarray, shape (4, P)
        The pair gains by when they act (:func:`posturelab.model.muscles.feedback_gains`):
        immediate stiffness and viscosity, delayed stiffness and viscosity.
        [N·m/rad], [N·m·s/rad], [N·m/rad], [N·m·s/rad]
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
    tilt_gains : numpy.ndarray, shape (4, P), or None
        Pair gains on α(t), α̇(t), α(t − τ), α̇(t − τ)
        (:func:`posturelab.model.tilt.tilt_pair_gains`); None without a tilt.
        [N·m/rad], [N·m·s/rad], [N·m/rad], [N·m·s/rad]
    visual_gains : numpy.ndarray, shape (4, P), or None
        Gains on the visual-scene tilt v(t), v̇(t), v(t − τ), v̇(t − τ), as tilt_gains
        (:func:`posturelab.model.visual.visual_pair_gains`); None without one.
    velocity_jump : (float, float)
        The ankle's velocity change at t = 0: the disturbance's step and the start of a
        tilt about an axis below the ankle. [m/s]
    motor_torque : TorqueSeries or None
        The motor noise's realisation over the run: added to each joint's moment before the
        limits. [N·m]
    joint_gains : numpy.ndarray, shape (4, N, N)
        The joint-space controller's moment gains by when they act
        (:func:`posturelab.model.joint_feedback.joint_gain_rows`; zeros for none).
        [N·m/rad], [N·m·s/rad]
    """

    body: Body
    muscles: MuscleSet
    disturbance: Disturbance
    options: RunOptions
    torque_limits: np.ndarray | None
    gains: np.ndarray
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
    tilt_gains: np.ndarray | None = None
    velocity_jump: tuple[float, float] = (0.0, 0.0)
    motor_torque: TorqueSeries | None = None
    joint_gains: np.ndarray | None = None
    visual_gains: np.ndarray | None = None

    @property
    def n_links(self) -> int:
        """N. [-]"""
        return self.body.n_links

    @property
    def duration(self) -> float:
        """Simulated time. [s]"""
        return self.options.duration

    @property
    def feedback_delay(self) -> float:
        """Neural delay τ of the muscle feedback; 0 for none. [s]"""
        return self.options.feedback_delay

    @property
    def tilt(self) -> Tilt | None:
        """The support-surface tilt α(t), None for none."""
        return self.options.tilt

    @property
    def visual_tilt(self) -> Tilt | None:
        """The visual-scene tilt v(t), None for none."""
        return self.options.visual_tilt

    @property
    def visual_weight(self) -> float:
        """W_v of the active part's error for pairs that span the foot. [-]"""
        return self.options.visual_weight

    @property
    def proprioceptive_weight(self) -> float:
        """W of the active part's error for pairs that span the foot. [-]"""
        return self.options.proprioceptive_weight

    @property
    def tilt_axis_depth(self) -> float:
        """Distance of the tilt axis below the ankle (0: the ankle's own axis). [m]"""
        return self.options.tilt_axis_depth

    @property
    def knee(self) -> KneeModel:
        """The knee model."""
        return self.options.knee

    @property
    def fall(self) -> FallCriteria:
        """The fall criteria."""
        return self.options.fall

    @property
    def rates_from(self) -> str:
        """Where J⁻¹H was evaluated for a velocity step."""
        return self.options.rates_from

    @property
    def motor_noise(self) -> MotorNoise | None:
        """The motor noise of the run, None for none."""
        return self.options.motor_noise

    @property
    def rtol(self) -> float:
        """Relative tolerance (the engine's default unless given). [-]"""
        return self.options.tolerances[0]

    @property
    def atol(self) -> float:
        """Absolute tolerance (the engine's default unless given). [rad, rad/s]"""
        return self.options.tolerances[1]

    @property
    def sample_rate(self) -> float:
        """Output samples per second. [Hz]"""
        return self.options.sample_rate

    @property
    def max_switches(self) -> int:
        """More switches than this fail the run (chattering). [-]"""
        return self.options.max_switches

    @property
    def max_steps(self) -> int:
        """The step budget: more accepted integrator steps end the run as failed. [-]"""
        return self.options.step_budget

    @property
    def time_limit(self) -> float:
        """The wall-clock budget of the integration; ``inf`` for none. [s]"""
        return self.options.wall_clock_limit

    @property
    def description(self) -> str:
        """The run in words (the disturbance's own unless the options give some)."""
        return self.options.description or self.disturbance.describe()

    def with_fall_criteria(self, **changes) -> RunSetup:
        """The same set-up with some fall criteria changed (fall_at_start recomputed)."""
        options = self.options.replace(fall=replace(self.fall, **changes))
        new = replace(self, options=options, fall_at_start=None)
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
          else initial_state_array(initial_state, 2 * n))
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


def prepare_run(body: Body, muscles: MuscleSet, disturbance: Disturbance | None = None,
                options: RunOptions | float | None = None, **keywords) -> RunSetup:
    """Check a run against its body and muscles and work out everything both engines share.

    Parameters
    ----------
    body : Body
    muscles : MuscleSet
    disturbance : Disturbance, optional
        Platform motion; none by default.
    options : RunOptions, optional
        The run's options (default ``RunOptions()``). A number here is the duration [s] and
        ``keywords`` the other options (the former call, ``prepare_run(body, muscles, d,
        5.0, feedback_delay=0.1)``).

    A set-up is immutable, so the same arguments (when every one is hashable: a measured
    profile is not) return the same object, computed once.

    Raises
    ------
    ParameterError
        An unknown option, an argument of the wrong type or outside its range, the knee
        beyond its stop, a muscle set for another number of links.
    """
    if not isinstance(options, RunOptions):
        if options is not None:
            keywords = {"duration": options, **keywords}
        options = RunOptions.from_keywords("a run", **keywords)
    elif keywords:
        options = options.replace(**keywords)
    disturbance = NoDisturbance() if disturbance is None else disturbance
    if _hashable((body, muscles, disturbance, options)):
        return _prepare_memo(body, muscles, disturbance, options)
    return _prepare(body, muscles, disturbance, options)


def _hashable(value) -> bool:
    """Whether ``value`` can key the memo (a measured profile, holding arrays, cannot)."""
    try:
        hash(value)
    except TypeError:
        return False
    return True


def _prepare(body: Body, muscles: MuscleSet, disturbance: Disturbance,
             options: RunOptions) -> RunSetup:
    """:func:`prepare_run` without the memo: the checks that need the model, then the start."""
    check_model(body, muscles)
    if not isinstance(disturbance, Disturbance):
        raise ParameterError(f"disturbance must be a Disturbance, got "
                             f"{type(disturbance).__name__} {disturbance!r:.60}")
    tilt, depth, delay = options.tilt, options.tilt_axis_depth, options.feedback_delay
    duration, knee, visual = options.duration, options.knee, options.visual_tilt
    for what, profile in (("platform", tilt), ("visual-scene", visual)):
        if profile is not None and muscles.one_sided_mask.any():
            raise ParameterError(f"a {what} tilt cannot be combined with one-sided pairs "
                                 "(make them two-sided)")
    check_starts_within(disturbance, tilt, duration)
    check_starts_within(NoDisturbance(), visual, duration)
    noise = options.motor_noise
    motor_torque = None if noise is None else motor_noise_series(noise, duration, body.n_links)
    n = body.n_links
    if knee.mode != "free" and n < 2:
        raise ParameterError("knee mode 'locked' or 'stop' needs a body with at least 2 links")
    limits = body_torque_limits(options.torque_limits, body, options.fall.base_of_support)
    initial_state = options.initial_state
    before = (np.zeros(2 * n) if initial_state is None
              else initial_state_array(initial_state, 2 * n))
    jump = (0.0, 0.0)
    if tilt is not None and depth > 0:  # the ankle starts moving with the surface's rate
        jump = tuple(float(v) for v in axis_translation(tilt, depth, 0.0)[1])
    x0 = initial_state_for(body, disturbance, before, options.rates_from, jump)
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
                                     options.proprioceptive_weight)
        tilt_gains.setflags(write=False)
    joint_gains = joint_gain_rows(options.joint_feedback, n, delay)
    visual_gains = None
    if visual is not None:
        visual_gains = visual_pair_gains(muscle_set_gains(muscles, 1.0), muscles.spans_foot,
                                         delay, options.visual_weight)
        visual_gains.setflags(write=False)
    moments0 = moments_at_start(muscles, x0, before, active0, gains, delay, tilt, tilt_gains,
                                motor_torque, visual, visual_gains) \
        + joint_feedback_moments(joint_gains, x0, before)
    saturation0 = start_saturation(moments0, limits)
    corners = set(disturbance.breakpoints)
    for profile in (tilt, visual):  # the tilts' corners, and where the delayed part feels them
        if profile is not None:
            tilt_corners = profile.breakpoints(duration)
            corners |= set(tilt_corners) | {b + delay for b in tilt_corners if delay > 0}
    breakpoints = np.array(sorted({b for b in corners if 0.0 < b < duration}), dtype=float)
    delay_bps = np.array([k * delay for k in range(1, DELAY_BREAKPOINT_MULTIPLES + 1)
                          if delay > 0 and k * delay < duration])
    max_step = min(disturbance.max_step, duration, delay if delay > 0 else math.inf,
                   tilt.max_step if tilt is not None else math.inf,
                   visual.max_step if visual is not None else math.inf,
                   noise.max_step if noise is not None else math.inf)
    for arr in (before, x0, active0, saturation0, breakpoints, delay_bps, gains, joint_gains):
        arr.setflags(write=False)
    setup = RunSetup(
        body=body, muscles=muscles, disturbance=disturbance, options=options,
        torque_limits=limits, gains=gains, before=before, x0=x0, locked0=bool(locked0),
        active0=active0, saturation0=saturation0,
        grid=output_grid(duration, options.sample_rate), breakpoints=breakpoints,
        delay_breakpoints=delay_bps, max_step=max_step, fall_at_start=None, knee_row=knee_row,
        tilt_gains=tilt_gains, velocity_jump=tuple(
            float(a + b) for a, b in zip(disturbance.velocity_change, jump, strict=True)),
        motor_torque=motor_torque, joint_gains=joint_gains, visual_gains=visual_gains,
    )
    object.__setattr__(setup, "fall_at_start", _fall_at_start(setup))
    return setup


_prepare_memo = functools.lru_cache(maxsize=128)(_prepare)


def moments_at_start(muscles: MuscleSet, state: np.ndarray, before: np.ndarray,
                     active: np.ndarray, gains: np.ndarray, delay: float,
                     tilt: Tilt | None = None, tilt_gains: np.ndarray | None = None,
                     motor_torque: TorqueSeries | None = None, visual_tilt: Tilt | None = None,
                     visual_gains: np.ndarray | None = None) -> np.ndarray:
    """Unsaturated joint moments at t = 0 of one run, or of runs that share a delay (a batch):
    the pairs' feedback (:func:`start_moments`, ``state``, ``before`` (..., 2N), ``active``
    (..., P), ``gains`` (..., 4, P)), the tilt's part with ``tilt_gains`` (..., 4, P), the
    visual-scene tilt's with ``visual_gains`` (..., 4, P) and the motor noise. Returns
    (..., N). [N·m]

    ``delay`` is the runs' feedback delay τ. [s]
    """
    moments = start_moments(muscles, state, before, active, gains)
    if tilt is not None:
        moments = moments + tilt_torques(tilt, tilt_gains, delay, 0.0) @ muscles.crossing_matrix
    if visual_tilt is not None:
        moments = moments + (tilt_torques(visual_tilt, visual_gains, delay, 0.0)
                             @ muscles.crossing_matrix)
    if motor_torque is not None:
        moments = moments + torque_at(motor_torque, 0.0)
    return moments


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
            knee_row=setup.knee_row, knee=setup.knee, fall=setup.fall,
            torque_feedback_gain=setup.options.torque_feedback_gain,
            torque_feedback_time_constant=setup.options.torque_feedback_time_constant,
            joint_gains=setup.joint_gains if setup.options.joint_feedback is not None else None,
            visual_tilt=setup.visual_tilt, visual_gains=setup.visual_gains)
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
    stiffness, _ = switched.pair_gains(switched_model(setup), j)
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
