"""A compiled simulator: the physics and events of :func:`posturelab.simulate.simulate`, fast.

:func:`simulate_fast` returns the same :class:`~posturelab.results.SimulationResult`
as :func:`posturelab.simulate.simulate` (the reference, scipy's DOP853);
:func:`simulate_batch` runs many gain sets and keeps only their outcomes
(:class:`BatchResult`), never the trajectories, spread over the CPU cores.

What is the same as the reference
---------------------------------
* The model: DESIGN.md's closed form for any N-link chain (a_i, J_ii, c_ij),
  muscle pairs U = −Eᵀ(K_d EΘ + L_d EΘ̇), one-sided pairs acting only while
  their stretch is >= 0, horizontal and vertical platform acceleration.
* Disturbances: a velocity step sets the initial rates through
  :func:`posturelab.simulate.initial_state_for`; half-sine pulses,
  ramp-and-hold moves, sums of sines and measured profiles (linear
  interpolation, zero outside) are compiled as a code and a parameter row
  each; combinations are summed. Every breakpoint of the profile is a step
  end: a step is clipped to land on it, never steps over it; the step is also
  capped at the disturbance's ``max_step``, as in the reference.
* Events, located on the dense-output interpolant of the step in which they
  occur (Illinois regula falsi to 4 machine epsilons, like scipy's brentq),
  with the reference's direction rules and order: a fall when any |θ_i|
  passes ``max_link_angle`` or the centre of gravity x_c = Σ a_i sin θ_i / Σm
  leaves [heel, toe]; a one-sided pair switching (the same hysteresis,
  ``posturelab.simulate._SWITCH_HYSTERESIS``); the knee reaching its
  hyper-extension stop (plastic impact, then locked) and letting go. A state
  already beyond a fall criterion at t = 0 is a fall at t = 0.
* Knee modes ``free``, ``locked`` and ``stop``, all compiled (the locked knee
  in the projection form of ``simulate._Model.acceleration``).
* Output: the same sample grid, the same rule for which samples a fall or a
  switch keeps (and the state at the fall closing the series), the same
  derived fields (torques, moments, accelerations, centre of gravity, ground
  reaction, centre of pressure, platform motion) and messages.

Not compiled (``simulate_fast`` hands these runs to the reference
:func:`posturelab.simulate.simulate` with the same arguments;
``simulate_batch`` refuses them): joint torque limits (``torque_limits``), a
neural feedback delay (``feedback_delay > 0``) and falls by the centre of
pressure (``FallCriteria(centre_of_pressure=True)``).

What differs
------------
The integrator. The paper's model is stiff: case 1 has a real pole at
−554 1/s (the viscous knee–hip mode; −1200 1/s for the stiffest gains of a
typical sweep) beside poles of a few 1/s that carry the motion. An explicit
method's step is then bounded by stability, not accuracy (RK45 takes 868
steps on case 1 at rtol 1e-6 and is accurate to 2e-9 rad, far more than
asked). The default, ``method="Radau"``, is scipy's ``Radau`` (Radau IIA of
order 5, Hairer & Wanner's RADAU5: simplified Newton iterations, its error
estimate and step-size prediction, the Jacobian re-evaluated only when
Newton converges slowly, the cubic collocation polynomial as dense output),
compiled, so its steps are set by accuracy (case 1: 166 steps, angle error
2.4e-8 rad at rtol 1e-6). Its Jacobian is [[0, I], [∂Θ̈/∂Θ, ∂Θ̈/∂Θ̇]]
(forward differences for the lower half), which reduces each Newton system
from 2N×2N to N×N: S(c) a = r₂ + (cI − ∂Θ̈/∂Θ̇) r₁, b = c a − r₁ with
S(c) = c²I − c ∂Θ̈/∂Θ̇ − ∂Θ̈/∂Θ (closed-form inverses for N = 3, LU with
pivoting otherwise). ``method="RK45"`` is the Dormand–Prince 5(4) pair of
scipy's ``RK45`` (tableau, error estimate, free 4th-order dense output) and
``method="RK23"`` the Bogacki–Shampine 3(2) pair of scipy's ``RK23``, both
with Hairer's PI step-size controller; they remain for comparison and for
non-stiff gain sets. After a switch the integration restarts with a fresh
initial step (and, for Radau, a fresh Jacobian), as the reference does; at a
profile breakpoint it lands on it and continues. All three are tested
against the reference on every built-in scenario; measured speeds are in
benchmarks/bench_simulate.py.

Compilation: every kernel is ``@njit(cache=True)``. The first call in a
fresh environment compiles them (about 70 s on 2 cores for simulate_fast and
both batch paths); later processes load the machine code from numba's cache
(``__pycache__`` beside the sources, or ``NUMBA_CACHE_DIR``) in well under a
second. :func:`warm_up` compiles or loads everything at once.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..._validation import finite_array, float_in_range, positive_float
from ...errors import ParameterError
from ...model.body import Body
from ...model.muscles import MuscleSet, paper_muscles
from ...model.options import FallCriteria, KneeModel
from ...model.platform import Disturbance, NoDisturbance
from ..engines import simulate
from ..results import DerivedSeries, SimulationResult
from ..setup import initial_state_for
from . import _kernels as kern
from ._encode import (
    EncodedDisturbance,
    control_arrays,
    crossings,
    encode_disturbance,
    model_array,
    pair_layout,
)

__all__ = [
    "DEFAULT_RTOL",
    "DEFAULT_ATOL",
    "BatchResult",
    "simulate_fast",
    "simulate_batch",
    "warm_up",
]

#: Default relative tolerance of the fast simulator. [-]
DEFAULT_RTOL = 1e-6
#: Default absolute tolerance [rad, rad/s]. With rtol = 1e-6 the angle error of the paper's
#: scenarios and of random-gain sweeps stays below 1e-6 rad against a DOP853 rtol = 1e-10
#: reference (measured by benchmarks/bench_simulate.py; tested in tests/test_fast.py).
DEFAULT_ATOL = 1e-9

_METHODS = ("RK45", "RK23", "Radau")

_STATUS_NAMES = ("completed", "fell", "failed", "failed", "failed")


# ---------------------------------------------------------------------------
# Shared set-up
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class _Setup:
    """Everything a kernel call needs that does not depend on the gains."""

    x0: np.ndarray
    grid: np.ndarray
    mp0: np.ndarray
    E: np.ndarray
    one_sided: np.ndarray
    dist: EncodedDisturbance
    bps: np.ndarray
    fpar: np.ndarray
    ipar: np.ndarray
    duration: float
    max_switches: int
    locked0: bool
    fall_at_start: str | None
    crosses: np.ndarray


@functools.lru_cache(maxsize=32)
def _output_grid(duration: float, sample_rate: float) -> np.ndarray:
    # exactly the reference's grid (posturelab.simulate.simulate); read-only, shared
    grid = np.arange(0.0, duration + 0.5 / sample_rate, 1.0 / sample_rate)
    grid = grid[grid <= duration + 1e-12]
    grid.setflags(write=False)
    return grid


def _unsupported(knee: KneeModel, fall: FallCriteria, torque_limits, feedback_delay) -> str:
    """What the compiled simulator does not cover, in words ('' if nothing)."""
    if torque_limits is not None and not np.all(np.isinf(np.asarray(torque_limits, float))):
        return "joint torque limits"
    if feedback_delay != 0.0:
        return "a feedback delay"
    if getattr(fall, "centre_of_pressure", False):
        return "falls by the centre of pressure"
    return ""


def _fall_at_start(x: np.ndarray, n: int, body: Body, fall: FallCriteria) -> str | None:
    """A fall criterion already violated at t = 0 (as simulate._outside_at_start)."""
    over = np.nonzero(np.abs(x[:n]) > fall.max_link_angle)[0]
    if over.size:
        return f"link {over[0] + 1} angle beyond ±{fall.max_link_angle:.3g} rad at the start"
    bos = fall.base_of_support
    if bos is None:
        return None
    xc = body.gravity_coefficients @ np.sin(x[:n]) / body.total_mass
    if not bos.heel <= xc <= bos.toe:
        return f"centre of gravity ({xc:.3f} m) outside the foot at the start"
    return None


def _setup(body: Body, muscles: MuscleSet, disturbance: Disturbance, duration: float,
           initial_state, rates_from: str, knee: KneeModel, fall: FallCriteria,
           rtol: float, atol: float, sample_rate: float, max_switches: int,
           settle_tolerance: float, method: str) -> _Setup:
    """The gain-independent part of a run, memoised when every input is hashable.

    Bodies, muscle sets, knee models, fall criteria and most disturbances are
    frozen dataclasses; a measured profile (arrays) is not hashable and is set
    up afresh each call. The cached arrays are never written by the kernels.
    """
    key_state = None if initial_state is None else tuple(
        np.asarray(initial_state, dtype=float).ravel().tolist())
    try:
        return _setup_cached(body, muscles, disturbance, duration, key_state, rates_from, knee,
                             fall, rtol, atol, sample_rate, max_switches, settle_tolerance,
                             method)
    except TypeError:  # something unhashable (a measured profile)
        return _setup_uncached(body, muscles, disturbance, duration, initial_state, rates_from,
                               knee, fall, rtol, atol, sample_rate, max_switches,
                               settle_tolerance, method)


@functools.lru_cache(maxsize=64)
def _setup_cached(body, muscles, disturbance, duration, initial_state, rates_from, knee, fall,
                  rtol, atol, sample_rate, max_switches, settle_tolerance, method) -> _Setup:
    return _setup_uncached(body, muscles, disturbance, duration,
                           None if initial_state is None else np.array(initial_state),
                           rates_from, knee, fall, rtol, atol, sample_rate, max_switches,
                           settle_tolerance, method)


def _setup_uncached(body: Body, muscles: MuscleSet, disturbance: Disturbance, duration: float,
                    initial_state, rates_from: str, knee: KneeModel, fall: FallCriteria,
                    rtol: float, atol: float, sample_rate: float, max_switches: int,
                    settle_tolerance: float, method: str) -> _Setup:
    if method not in _METHODS:
        raise ParameterError(f"method must be one of {', '.join(map(repr, _METHODS))}, got "
                             f"{method!r}")
    if muscles.n_links != body.n_links:
        raise ParameterError(
            f"muscle set is for {muscles.n_links} links but the body has {body.n_links}"
        )
    duration = positive_float("duration [s]", duration)
    rtol = float_in_range("rtol", rtol, 1e-14, 1e-1)
    atol = float_in_range("atol", atol, 1e-16, 1e-1)
    sample_rate = float_in_range("sample_rate [Hz]", sample_rate, 1.0, 1e6, unit="Hz")
    if not isinstance(max_switches, int | np.integer) or max_switches < 0:
        raise ParameterError(f"max_switches must be an integer >= 0, got {max_switches!r}")
    n = body.n_links
    if knee.mode != "free" and n < 2:
        raise ParameterError("knee mode 'locked' or 'stop' needs a body with at least 2 links")
    dist = encode_disturbance(disturbance)
    x = initial_state_for(body, disturbance, initial_state, rates_from)
    mp0 = model_array(body)
    locked0 = knee.mode == "locked"
    if locked0:
        x[n:] = kern.project_velocity(x[:n].copy(), x[n:].copy(), mp0)
    if knee.mode == "stop":
        kappa = x[1] - x[0]
        if kappa > knee.stop_angle + 1e-12:
            raise ParameterError(
                f"initial knee angle θ2 − θ1 = {kappa:g} rad is beyond the hyper-extension "
                f"stop ({knee.stop_angle:g} rad)"
            )
        if abs(kappa - knee.stop_angle) <= 1e-12 and (x[n + 1] - x[n]) >= 0:
            locked0 = True
            x[n:] = kern.project_velocity(x[:n].copy(), x[n:].copy(), mp0)
    max_step = min(dist.max_step, duration)
    bps = np.array(sorted({b for b in dist.breakpoints if 0.0 < b < duration}), dtype=float)
    fpar, ipar = control_arrays(body, fall, knee, rtol=rtol, atol=atol, max_step=max_step,
                                duration=duration, max_switches=int(max_switches),
                                locked0=locked0, settle_tolerance=settle_tolerance,
                                method=method)
    E, one_sided = pair_layout(muscles)
    for arr in (x, mp0, E, one_sided, bps, fpar, ipar):
        arr.setflags(write=False)  # shared by memoised calls: nothing may write them
    crosses = crossings(muscles)
    crosses.setflags(write=False)
    return _Setup(x, _output_grid(duration, sample_rate), mp0, E, one_sided, dist, bps, fpar,
                  ipar, duration, int(max_switches), locked0, _fall_at_start(x, n, body, fall),
                  crosses)


def _fall_reason(kind: int, n: int, fall: FallCriteria) -> str:
    if kind < n:
        return f"link {kind + 1} angle passed ±{fall.max_link_angle:.3g} rad"
    bos = fall.base_of_support
    if kind == n:
        return f"centre of gravity passed the toe ({bos.toe:.3f} m)"
    return f"centre of gravity passed the heel ({bos.heel:.3f} m)"


def _message(status: int, t: float, duration: float, max_switches: int) -> str:
    if status == kern.STATUS_COMPLETED:
        return f"ran to {duration:g} s"
    if status == kern.STATUS_STEP_TOO_SMALL:
        return (f"integrator failed at t = {t:.6g} s: required step size is less than "
                "spacing between numbers")
    if status == kern.STATUS_NONFINITE:
        return f"state diverged (non-finite) at t = {t:.6g} s"
    return f"more than {max_switches} switches by t = {t:.6g} s (chattering)"


# ---------------------------------------------------------------------------
# One simulation
# ---------------------------------------------------------------------------


def simulate_fast(
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
    rtol: float = DEFAULT_RTOL,
    atol: float = DEFAULT_ATOL,
    sample_rate: float = 1000.0,
    max_switches: int = 10_000,
    description: str = "",
    method: str = "Radau",
) -> SimulationResult:
    """Simulate the nonlinear chain with the compiled integrator.

    Same model, events and result as :func:`posturelab.simulate.simulate`;
    only the integrator differs (see the module docstring). Runs with joint
    torque limits, a feedback delay or centre-of-pressure falls are handed to
    :func:`posturelab.simulate.simulate` with the same arguments (and scipy's
    DOP853), since those are not compiled.

    Parameters
    ----------
    body : Body
        The chain.
    muscles : MuscleSet
        Muscle pairs (one-sided pairs switch exactly where their stretch crosses 0).
    disturbance : Disturbance, optional
        Platform motion: a velocity step, half-sine, ramp-and-hold, sum of sines,
        measured profile, or a combination; none by default.
    duration : float
        Simulated time. [s]
    initial_state : array_like, shape (2N,), optional
        ``[Θ, Θ̇]`` before any velocity step; upright at rest by default. [rad], [rad/s]
    rates_from : {"upright", "posture"}
        Where J⁻¹H is evaluated for a velocity step (see
        :func:`posturelab.simulate.initial_state_for`).
    knee : KneeModel, optional
        Free (default), locked, or with a hyper-extension stop. Needs N >= 2.
    fall : FallCriteria, optional
        Default: any |θ_i| > π/3, no foot limit (the paper's model).
    torque_limits : array_like, shape (N,), optional
        Largest net muscle moment per joint [N·m] (reference simulator).
    feedback_delay : float
        Neural delay of the muscle feedback [s] (reference simulator if > 0).
    rtol : float
        Relative tolerance. [-]
    atol : float
        Absolute tolerance. [rad, rad/s]
    sample_rate : float
        Output samples per second. [Hz]
    max_switches : int
        More switches than this fail the run (chattering guard). [-]
    description : str
        Words stored in the result.
    method : {"Radau", "RK45", "RK23"}
        The compiled integrator: Radau IIA of order 5 (default; implicit, for the
        model's stiff viscous modes), Dormand–Prince 5(4) or Bogacki–Shampine 3(2)
        (explicit; see the module docstring). Ignored by the reference fallback
        (DOP853).

    Returns
    -------
    SimulationResult
        As :func:`posturelab.simulate.simulate` returns it.
    """
    disturbance = NoDisturbance() if disturbance is None else disturbance
    knee = KneeModel() if knee is None else knee
    fall = FallCriteria() if fall is None else fall
    if _unsupported(knee, fall, torque_limits, feedback_delay):
        return simulate(body, muscles, disturbance, duration, initial_state=initial_state,
                        rates_from=rates_from, knee=knee, fall=fall,
                        torque_limits=torque_limits, feedback_delay=feedback_delay, rtol=rtol,
                        atol=atol, sample_rate=sample_rate, max_switches=max_switches,
                        description=description)
    s = _setup(body, muscles, disturbance, duration, initial_state, rates_from, knee, fall,
               rtol, atol, sample_rate, max_switches, 0.01, method)
    n = body.n_links
    kd = np.ascontiguousarray(muscles.stiffnesses, dtype=float)
    ld = np.ascontiguousarray(muscles.viscosities, dtype=float)
    switches = np.zeros(0)
    if s.fall_at_start is not None:
        status, t_reached = kern.STATUS_FELL, 0.0
        time = np.zeros(1)
        samples = np.array(s.x0[:, None])  # writable, like the kernel's
        locked = np.array([s.locked0])
        count = 1
        fall_time, fall_reason = 0.0, s.fall_at_start
        message = f"fell at t = 0 s: {fall_reason}"
    else:
        res, samples, sample_locked, switches = kern.run_one(
            s.x0, s.grid, s.mp0, s.E, kd, ld, s.one_sided, s.dist.packed, s.bps, s.fpar,
            s.ipar)
        status = int(res[kern.R_STATUS])
        t_reached = float(res[kern.R_T_REACHED])
        n_grid = int(res[kern.R_N_SAMPLES])
        count = n_grid + int(res[kern.R_FALL_SAMPLE])
        time = s.grid[:n_grid]
        if count > n_grid:
            time = np.append(time, t_reached)
        locked = sample_locked
        switches = switches[:min(int(res[kern.R_N_SWITCHES]), switches.size)]
        if status == kern.STATUS_FELL:
            fall_time = float(res[kern.R_FALL_TIME])
            fall_reason = _fall_reason(int(res[kern.R_FALL_KIND]), n, fall)
            message = f"fell at t = {fall_time:.4f} s: {fall_reason}"
        else:
            fall_time, fall_reason = None, None
            message = _message(status, t_reached, s.duration, s.max_switches)
    # the kernels keep time last; the result holds time-first views of the same memory
    theta = samples[:n, :count].T
    omega = samples[n:, :count].T
    for arr in (time, theta, omega):
        arr.setflags(write=False)
    derive = functools.partial(_derived_series, samples, count, locked, s, kd, ld,
                               body.total_mass, time)
    return SimulationResult(
        time=time, theta=theta, omega=omega,
        pair_names=tuple(muscles.names), status=_STATUS_NAMES[status], message=message,
        fell=status == kern.STATUS_FELL, fall_time=fall_time, fall_reason=fall_reason,
        switch_times=tuple(float(v) for v in switches),
        description=description or disturbance.describe(), derived=derive,
    )


def _derived_series(samples: np.ndarray, count: int, locked: np.ndarray, s: _Setup,
                    kd: np.ndarray, ld: np.ndarray, total_mass: float,
                    time: np.ndarray) -> DerivedSeries:
    """The derived series of a run (computed when the result is first asked for one)."""
    (M, U, moments, alpha, cog, cogv, ground, cop, acc, vel, pos) = kern.derived_fields(
        samples, count, locked, s.E, kd, ld, s.one_sided, s.crosses, s.mp0, total_mass,
        np.array(time, dtype=float), s.dist.packed, *s.dist.velocity_change)
    alpha = alpha.T
    alpha.setflags(write=False)
    return DerivedSeries(
        pair_torques=M.T, joint_torques=U.T, joint_moments=moments.T, cog_position=cog.T,
        cog_velocity=cogv.T, platform_acceleration=acc.T, platform_velocity=vel.T,
        platform_position=pos.T, angular_acceleration=alpha, ground_reaction=ground.T,
        centre_of_pressure=cop,
    )


# ---------------------------------------------------------------------------
# Many simulations, outcomes only
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class BatchResult:
    """Outcomes of many runs (no trajectories); row r is run r.

    Every quantity is computed on the output samples, exactly as
    :class:`~posturelab.results.SimulationResult` computes it for one run
    (including the state at a fall, which closes a fallen run's series).

    Attributes
    ----------
    fell : numpy.ndarray of bool, shape (M,)
        True when a fall criterion fired.
    fall_time : numpy.ndarray, shape (M,)
        Time of the fall; NaN if the run did not fall. [s]
    peak_theta : numpy.ndarray, shape (M, N)
        Peak |θ_i| over the samples (``SimulationResult.max_abs_theta``). [rad]
    settling_time : numpy.ndarray, shape (M,)
        Last sample time at which some |θ_i| exceeded ``settle_tolerance``; 0 if
        none did; NaN if the run fell or had not settled by its last sample
        (``SimulationResult.settling_time``). [s]
    final_state : numpy.ndarray, shape (M, 2N)
        ``[Θ, Θ̇]`` at the last sample. [rad], [rad/s]
    status_code : numpy.ndarray of int8, shape (M,)
        0 completed, 1 fell, 2 step size underflow, 3 non-finite state,
        4 too many switches (2–4 are "failed"). [-]
    n_steps : numpy.ndarray of int64, shape (M,)
        Accepted integrator steps. [-]
    n_switches : numpy.ndarray of int64, shape (M,)
        One-sided pair and knee-stop switches. [-]
    settle_tolerance : float
        Angle threshold of the settling time. [rad]
    """

    fell: np.ndarray
    fall_time: np.ndarray
    peak_theta: np.ndarray
    settling_time: np.ndarray
    final_state: np.ndarray
    status_code: np.ndarray
    n_steps: np.ndarray
    n_switches: np.ndarray
    settle_tolerance: float = 0.01

    @property
    def n_runs(self) -> int:
        """Number of runs M. [-]"""
        return int(self.fell.size)

    @property
    def status(self) -> np.ndarray:
        """"completed", "fell" or "failed" per run (as ``SimulationResult.status``)."""
        return np.array(_STATUS_NAMES)[self.status_code]


def _gain_array(name: str, value, n_pairs: int) -> np.ndarray:
    arr = finite_array(name, value)
    if arr.ndim == 1 and arr.size == n_pairs:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != n_pairs:
        raise ParameterError(f"{name} must have shape (M, {n_pairs}) (one row per run, one "
                             f"column per pair), got shape {arr.shape}")
    if np.any(arr < 0):
        raise ParameterError(f"{name} must be >= 0, got {arr[arr < 0][0]:g}")
    return np.ascontiguousarray(arr, dtype=float)


def simulate_batch(
    body: Body,
    stiffness: np.ndarray,
    viscosity: np.ndarray,
    disturbance: Disturbance | None = None,
    duration: float = 5.0,
    initial_state: np.ndarray | None = None,
    *,
    muscles: MuscleSet | None = None,
    rates_from: Literal["upright", "posture"] = "upright",
    knee: KneeModel | None = None,
    fall: FallCriteria | None = None,
    rtol: float = DEFAULT_RTOL,
    atol: float = DEFAULT_ATOL,
    sample_rate: float = 1000.0,
    settle_tolerance: float = 0.01,
    max_switches: int = 10_000,
    parallel: bool = True,
    chunk: int = 8,
    method: str = "Radau",
    disturbance_scale: np.ndarray | None = None,
) -> BatchResult:
    """Simulate M gain sets on one body and disturbance; keep only the outcomes.

    Run r is ``simulate_fast(body, muscles with stiffness[r] and viscosity[r], …)``:
    the same integration, bit for bit, without storing its trajectory.

    Parameters
    ----------
    body : Body
        The chain (N links).
    stiffness : array_like, shape (M, P)
        Pair stiffness per run. [N·m/rad]
    viscosity : array_like, shape (M, P)
        Pair viscosity per run. [N·m·s/rad]
    disturbance : Disturbance, optional
        Platform motion (as for :func:`simulate_fast`); none by default.
    duration : float
        Simulated time. [s]
    initial_state : array_like, shape (2N,), optional
        ``[Θ, Θ̇]`` before any velocity step; upright at rest by default. [rad], [rad/s]
    muscles : MuscleSet, optional
        The pair layout (spans and one-sidedness, in column order); its own
        gains are ignored. Default: the paper's five pairs, two-sided (N = 3).
    rates_from, knee, fall
        As for :func:`simulate_fast` (centre-of-pressure falls are not compiled).
    rtol : float
        Relative tolerance. [-]
    atol : float
        Absolute tolerance. [rad, rad/s]
    sample_rate : float
        Output samples per second on which the outcomes are computed. [Hz]
    settle_tolerance : float
        Angle threshold of the settling time. [rad]
    max_switches : int
        More switches than this fail a run. [-]
    parallel : bool
        Spread the runs over numba's threads (see ``numba.set_num_threads``);
        False runs them one after another in the calling thread, without the
        GIL (for callers that bring their own threads, such as Dask workers).
    chunk : int
        Runs per parallel work item. [-]
    method : {"Radau", "RK45", "RK23"}
        The compiled integrator, as for :func:`simulate_fast`.
    disturbance_scale : array_like, shape (M,), optional
        Run r's disturbance is ``disturbance.scaled(disturbance_scale[r])``
        (:meth:`posturelab.platform.Disturbance.scaled`: the step speed, pulse
        peak, ramp displacement, sine amplitudes or measured accelerations times
        the factor); by default every run has ``disturbance`` as it is. [-]

    Returns
    -------
    BatchResult
    """
    disturbance = NoDisturbance() if disturbance is None else disturbance
    knee = KneeModel() if knee is None else knee
    fall = FallCriteria() if fall is None else fall
    what = _unsupported(knee, fall, None, 0.0)
    if what:
        raise ParameterError(f"simulate_batch does not compile {what}; use "
                             "posturelab.simulate.simulate for such runs")
    if muscles is None:
        if body.n_links != 3:
            raise ParameterError(
                f"the default pair layout is the paper's five pairs on 3 links; this body has "
                f"{body.n_links}: pass muscles=MuscleSet(...) for the layout"
            )
        muscles = paper_muscles("1")
    P = len(muscles.pairs)
    kd_all = _gain_array("stiffness [N·m/rad]", stiffness, P)
    ld_all = _gain_array("viscosity [N·m·s/rad]", viscosity, P)
    if kd_all.shape != ld_all.shape:
        raise ParameterError(f"stiffness and viscosity must have the same shape, got "
                             f"{kd_all.shape} and {ld_all.shape}")
    settle_tolerance = positive_float("settle_tolerance [rad]", settle_tolerance)
    if not isinstance(chunk, int | np.integer) or chunk < 1:
        raise ParameterError(f"chunk must be an integer >= 1, got {chunk!r}")
    s = _setup(body, muscles, disturbance, duration, initial_state, rates_from, knee, fall,
               rtol, atol, sample_rate, max_switches, settle_tolerance, method)
    M = kd_all.shape[0]
    n = body.n_links
    if disturbance_scale is not None:
        scale = finite_array("disturbance_scale [-]", disturbance_scale, (M,))
    if disturbance_scale is None or M == 0:
        levels = [s]
        which = np.zeros(M, dtype=np.int64)
    else:
        values, which = np.unique(scale, return_inverse=True)
        # one set-up per distinct scale: its initial state (a scaled velocity step) and
        # its packed disturbance; the breakpoints do not depend on the scale
        levels = [_setup(body, muscles, disturbance.scaled(float(v)), duration, initial_state,
                         rates_from, knee, fall, rtol, atol, sample_rate, max_switches,
                         settle_tolerance, method) for v in values]
        which = np.ascontiguousarray(which.ravel(), dtype=np.int64)
    # read-only like the single-run arrays, so that the kernels share one compiled form
    # (whether the knee starts locked, in ipar, depends on the scaled initial state too)
    x0_all = np.stack([lv.x0 for lv in levels])
    dp_all = np.stack([lv.dist.packed for lv in levels])
    ipar_all = np.stack([lv.ipar for lv in levels])
    for arr in (x0_all, dp_all, ipar_all, which):
        arr.setflags(write=False)
    results = np.zeros((M, kern.N_RESULT))
    peaks = np.zeros((M, n))
    finals = np.zeros((M, 2 * n))
    at_start = np.array([lv.fall_at_start is not None for lv in levels])
    if M and not at_start.all():
        args = (x0_all, which, s.grid, s.mp0, s.E, kd_all, ld_all, s.one_sided, dp_all, s.bps,
                s.fpar, ipar_all, results, peaks, finals)
        if parallel:
            kern.run_batch_parallel(*args, int(chunk))
        else:
            kern.run_batch_serial(*args)
    if at_start.any():
        # these runs fall at t = 0 whatever their gains (the reference's check at the start)
        rows = at_start[which]
        results[rows] = 0.0
        results[rows, kern.R_STATUS] = kern.STATUS_FELL
        results[rows, kern.R_FALL_TIME] = 0.0
        peaks[rows] = np.abs(x0_all[which[rows], :n])
        finals[rows] = x0_all[which[rows]]
    status = results[:, kern.R_STATUS].astype(np.int8)
    fell = status == kern.STATUS_FELL
    fall_time = np.where(fell, results[:, kern.R_FALL_TIME], np.nan)
    final_outside = results[:, kern.R_FINAL_OUTSIDE] > 0
    any_outside = results[:, kern.R_ANY_OUTSIDE] > 0
    settling = np.where(fell | final_outside, np.nan,
                        np.where(any_outside, results[:, kern.R_LAST_OUTSIDE], 0.0))
    return BatchResult(
        fell=fell, fall_time=fall_time, peak_theta=peaks, settling_time=settling,
        final_state=finals, status_code=status,
        n_steps=results[:, kern.R_N_STEPS].astype(np.int64),
        n_switches=results[:, kern.R_N_SWITCHES].astype(np.int64),
        settle_tolerance=settle_tolerance,
    )


def integrate_compiled(setup, method: str = "Radau") -> SimulationResult:
    """Run a :class:`~posturelab.simulation.setup.RunSetup` on the compiled engine."""
    return simulate_fast(
        setup.body, setup.muscles, setup.disturbance, setup.duration,
        initial_state=setup.before, rates_from=setup.rates_from, knee=setup.knee,
        fall=setup.fall, torque_limits=setup.torque_limits,
        feedback_delay=setup.feedback_delay, rtol=setup.rtol, atol=setup.atol,
        sample_rate=setup.sample_rate, max_switches=setup.max_switches,
        description=setup.description, method=method)


def warm_up() -> None:
    """Compile (or load from numba's cache) the kernels with a tiny run of each entry point."""
    from ...model.body import paper_body
    from ...model.platform import VelocityStep

    body = paper_body()
    muscles = paper_muscles("1")
    simulate_fast(body, muscles, VelocityStep.backward(0.1), 0.01)
    g = np.asarray(muscles.stiffnesses)[None, :]
    simulate_batch(body, g, 0.25 * g, VelocityStep.backward(0.1), 0.01)
    simulate_batch(body, g, 0.25 * g, VelocityStep.backward(0.1), 0.01, parallel=False)
