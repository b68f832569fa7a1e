"""The compiled engine: the model of :mod:`posturelab.model` in C.

:func:`integrate_compiled` runs a :class:`~posturelab.simulation.setup.RunSetup` and
returns the same :class:`~posturelab.simulation.results.SimulationResult` as the
reference engine (``posturelab.simulate(..., engine="compiled")``);
:func:`simulate_batch` runs many parameter sets (gains, torque limits, feedback
delays, perturbation sizes) and keeps only their outcomes (:class:`BatchResult`),
spread over the CPU cores. Everything the reference engine does, this one does:
one-sided pairs, the knee free, locked or against its stop, joint torque
saturation, falls by link angle, centre of gravity and centre of pressure, and
neural feedback delay as a delay differential equation (``docs/simulators.md``).

The C sources (``csrc/``, built by ``setup.py`` when the package is installed):
``pl_rhs.c`` (the equation of motion, general N) and ``pl_rhs_small.c`` (generated for
N = 1, 2, 3 by :mod:`._codegen`); ``pl_explicit.c`` (one step routine for every explicit
pair, whose tableau comes from :mod:`._tableaux` as data); ``pl_radau.c`` (Radau IIA of
order 5, the default: the model is stiff); ``pl_history.c`` (the past of a delayed run);
``pl_events.c`` (event functions and roots); ``pl_driver.c`` (the integration loop,
written once); ``pl_module.c`` (the entry points). In Python: :mod:`._encode` (set-up →
arrays), :mod:`._binding` (the structs and the library), :mod:`._layout` (shared codes).

Nothing is compiled at run time: the extension is built at install (a C compiler, a few
seconds). A batch runs in chunks on Python threads; each C call releases the GIL.
"""

from __future__ import annotations

import ctypes
import functools
import math
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..._validation import finite_array, positive_float
from ...errors import ParameterError
from ...model.body import Body
from ...model.events import fall_message
from ...model.muscles import MuscleSet, feedback_gains, muscle_set_gains, paper_muscles
from ...model.noise import MotorNoise, torque_at
from ...model.options import FallCriteria, KneeModel
from ...model.platform import Disturbance
from ...model.tilt import Tilt, check_proprioceptive_weight, tilt_pair_gains
from ..derived import derived_series
from ..engines import simulate
from ..outcome import StimulusTiming, stimulus_timing
from ..results import SimulationResult
from ..setup import (
    RunSetup,
    cop_fall_at_start,
    fall_at_start_by_posture,
    outcome_message,
    prepare_run,
    start_activity,
    start_centre_of_pressure,
    start_moments,
    start_saturation,
)
from ..tolerances import DEFAULT_ATOL, DEFAULT_RTOL
from . import _encode as enc
from ._binding import Batch, Out, Run, library, pointer
from ._layout import (
    METHOD_EXPLICIT,
    METHOD_RADAU,
    N_RESULT,
    R_ANY_OUTSIDE,
    R_FALL_INDEX,
    R_FALL_KIND,
    R_FALL_SAMPLE,
    R_FALL_TIME,
    R_FINAL_OUTSIDE,
    R_LAST_OUTSIDE,
    R_N_SAMPLES,
    R_N_STEPS,
    R_N_SWITCHES,
    R_STATUS,
    R_T_REACHED,
    STATUS_FAILURES,
    STATUS_FELL,
    STATUS_NAMES,
    STATUS_OUTCOMES,
)
from ._tableaux import BOGACKI_SHAMPINE_32, DORMAND_PRINCE_54

ctypes_int64 = ctypes.POINTER(ctypes.c_int64)
ctypes_uint8 = ctypes.POINTER(ctypes.c_uint8)

__all__ = [
    "DEFAULT_RTOL",
    "DEFAULT_ATOL",
    "METHODS",
    "BatchResult",
    "integrate_compiled",
    "simulate_fast",
    "simulate_batch",
    "default_method",
    "warm_up",
]

#: The compiled integrators: Radau IIA of order 5, or an explicit pair given by its tableau.
METHODS = {"Radau": None, "RK45": DORMAND_PRINCE_54, "RK23": BOGACKI_SHAMPINE_32}


def default_method(feedback_delay: float) -> str:
    """The integrator the compiled engine chooses when none is asked for.

    Radau IIA when the muscles act without delay: their viscosity on light links makes
    the model stiff (case 1 has a pole at −554 1/s), and an implicit method's steps then
    follow the motion instead of that mode. Dormand–Prince 5(4) when every pair's
    feedback is delayed: the undelayed equations are then the passive chain, not stiff,
    and an explicit pair is both accurate and cheaper (case 1 with a 10 ms delay: 1,858
    RK45 steps against 6,875 for Radau at rtol 1e-6).

    Parameters
    ----------
    feedback_delay : float
        The run's neural delay. [s]
    """
    return "Radau" if feedback_delay == 0.0 else "RK45"


def _check_method(method: str) -> None:
    if method not in METHODS:
        raise ParameterError(f"method must be one of {', '.join(map(repr, METHODS))} for the "
                             f"compiled engine, got {method!r}")


@functools.lru_cache(maxsize=64)
def _packed(setup: RunSetup) -> dict:
    """The gain-independent arrays of a run (memoised per set-up object)."""
    from ...model import events as ev

    n = setup.n_links
    fpar, ipar = enc.options(setup)
    muscles = setup.muscles
    limited = (np.isfinite(setup.torque_limits) if setup.torque_limits is not None
               else np.zeros(n, bool))
    slots = ev.event_slots(n, setup.fall.base_of_support is not None,
                           setup.fall.centre_of_pressure, limited, muscles.one_sided_mask,
                           setup.knee.mode == "stop", muscles.pull_only_mask)
    return {
        "x0": enc.readonly(setup.x0), "before": enc.readonly(setup.before),
        "grid": enc.readonly(setup.grid), "bp": enc.body_array(setup.body),
        "E": enc.readonly(muscles.selection_matrix), "C": enc.readonly(muscles.crossing_matrix),
        "one_sided": enc.readonly(muscles.one_sided_mask.astype(np.int64)),
        "dp": enc.encode_disturbance(setup.disturbance), "tp": enc.encode_tilt(setup.tilt),
        "tilt_gain": enc.readonly(np.ascontiguousarray(
            setup.tilt_gains @ muscles.crossing_matrix if setup.tilt_gains is not None
            else np.zeros((4, n)))),
        "tilt_depth": float(setup.tilt_axis_depth),
        "mp": enc.encode_motor_noise(setup.motor_torque),
        "bps": enc.readonly(setup.breakpoints.astype(float)), "fpar": fpar, "ipar": ipar,
        "active0": enc.readonly(setup.active0), "slots": slots,
        "ev_offset": ev.EVENT_OFFSET, "ev_direction": ev.EVENT_DIRECTION,
        "ev_ends": ev.EVENT_ENDS_RUN, "n": n,
    }


def _run_struct(a: dict, method: str, gains, lim, delay: float, sat0) -> Run:
    """The C inputs of one run (the arrays in ``a`` must outlive it): a copy of the run's
    gain-independent inputs (built once per set-up and method) with these filled in."""
    base = a.get(("run", method))
    if base is None:
        base = a[("run", method)] = _base_run_struct(a, method)
    run = Run.from_buffer_copy(base)
    run.gains, run.lim, run.sat0 = pointer(gains), pointer(lim), pointer(sat0)
    run.delay = float(delay)
    return run


def _base_run_struct(a: dict, method: str) -> Run:
    """The gain-independent C inputs of a run."""
    from ..setup import DELAY_BREAKPOINT_MULTIPLES

    tab = METHODS[method]
    n = a["n"]
    run = Run(n=n, p=a["E"].shape[0], n_grid=a["grid"].size, n_bps=a["bps"].size,
              n_slots=len(a["slots"]), method=METHOD_RADAU if tab is None else METHOD_EXPLICIT,
              delay_multiples=DELAY_BREAKPOINT_MULTIPLES, tilt_depth=a["tilt_depth"])
    for name in ("x0", "before", "grid", "bp", "E", "C", "dp", "bps", "fpar", "active0",
                 "ev_offset", "tp", "tilt_gain", "mp"):
        setattr(run, name, pointer(a[name]))
    for name in ("one_sided", "ipar", "ev_direction", "ev_ends"):
        setattr(run, name, pointer(a[name], ctypes_int64))
    slots = a["slots"]
    run.slot_kind = pointer(slots.kind, ctypes_int64)
    run.slot_index = pointer(slots.index, ctypes_int64)
    run.slot_cond = pointer(slots.condition, ctypes_int64)
    run.slot_side = pointer(slots.side)
    if tab is not None:
        run.n_stages = tab.nodes.size
        run.tab_A, run.tab_c = pointer(tab.A), pointer(tab.nodes)
        run.tab_e, run.tab_P = pointer(tab.error), pointer(tab.dense)
        run.tab_error_order = tab.error_order
    return run


def integrate_compiled(setup: RunSetup, method: str | None = None) -> SimulationResult:
    """Integrate one run on the compiled engine.

    Parameters
    ----------
    setup : RunSetup
        The run (:func:`posturelab.simulation.setup.prepare_run`).
    method : {"Radau", "RK45", "RK23"}, optional
        Radau IIA of order 5 (implicit, for the model's stiff viscous modes),
        Dormand–Prince 5(4) or Bogacki–Shampine 3(2) (explicit); by default
        :func:`default_method`.

    Returns
    -------
    SimulationResult
        Its derived series are computed when first read.
    """
    method = default_method(setup.feedback_delay) if method is None else method
    _check_method(method)
    a = _packed(setup)
    n = a["n"]
    m = 2 * n
    muscles = setup.muscles
    delayed = setup.feedback_delay > 0
    switches = np.zeros(0)
    feedback = None
    T = a["grid"].size
    if setup.fall_at_start is not None:
        status, t_reached = STATUS_FELL, 0.0
        time = np.zeros(1)
        samples = np.array(setup.x0[:, None])
        locked = np.array([setup.locked0])
        count = 1
        fall_time, fall_reason = 0.0, setup.fall_at_start
        message = outcome_message("fell", 0.0, setup, fall_reason=fall_reason)
        if delayed:
            feedback = np.array(setup.before[None, :])
    else:
        g = enc.readonly(np.ascontiguousarray(setup.gains))
        lim = enc.readonly(enc.limits(setup.torque_limits, n))
        sat0 = enc.readonly(setup.saturation0)
        run = _run_struct(a, method, g, lim, setup.feedback_delay, sat0)
        samples = np.empty((m, T + 1))
        fb = np.empty((m, T + 1)) if delayed else None
        locked_u8 = np.zeros(T + 1, np.uint8)
        switches = np.empty(setup.max_switches + 1)
        peak, final, res = np.empty(n), np.empty(m), np.empty(N_RESULT)
        out = Out(samples=pointer(samples), fb=pointer(fb),
                  locked=pointer(locked_u8, ctypes_uint8), switches=pointer(switches),
                  switch_cap=switches.size, peak=pointer(peak), final=pointer(final),
                  res=pointer(res))
        library().pl_run_one(run, out)
        locked = locked_u8.astype(bool)
        status = int(res[R_STATUS])
        t_reached = float(res[R_T_REACHED])
        n_grid = int(res[R_N_SAMPLES])
        count = n_grid + int(res[R_FALL_SAMPLE])
        time = setup.grid[:n_grid]
        if count > n_grid:
            time = np.append(time, t_reached)
        if count == 0:  # the run ended before its first sample: the series is its initial state
            time, count = np.zeros(1), 1
            samples[:, 0] = setup.x0
            locked[0] = setup.locked0
            if delayed:
                fb[:, 0] = setup.before
        switches = switches[:min(int(res[R_N_SWITCHES]), switches.size)]
        if delayed:
            feedback = fb[:, :count].T
        if status == STATUS_FELL:
            fall_time = float(res[R_FALL_TIME])
            fall_reason = _fall_reason(int(res[R_FALL_KIND]), int(res[R_FALL_INDEX]), setup)
            message = outcome_message("fell", fall_time, setup, fall_reason=fall_reason)
        else:
            fall_time, fall_reason = None, None
            message = outcome_message(STATUS_OUTCOMES[status], t_reached, setup,
                                      method=method)
    # the engine keeps time last; the result holds time-first views of the same memory
    theta = samples[:n, :count].T
    omega = samples[n:, :count].T
    locked = locked[:count]
    for arr in (time, theta, omega):
        arr.setflags(write=False)
    state = samples[:m, :count].T
    derive = functools.partial(derived_series, setup, time, state, feedback, locked)
    return SimulationResult(
        time=time, theta=theta, omega=omega, pair_names=tuple(muscles.names),
        status=STATUS_NAMES[status], message=message, fell=status == STATUS_FELL,
        fall_time=fall_time, fall_reason=fall_reason,
        switch_times=tuple(float(v) for v in switches), description=setup.description,
        derived=derive,
        stimulus=stimulus_timing(setup.disturbance, setup.tilt, setup.motor_noise),
    )


def _fall_reason(kind: int, index: int, setup: RunSetup) -> str:
    bos = setup.fall.base_of_support
    return fall_message(kind, index, max_link_angle=setup.fall.max_link_angle,
                        toe=bos.toe if bos is not None else 0.0,
                        heel=bos.heel if bos is not None else 0.0)


def simulate_fast(body: Body, muscles: MuscleSet, disturbance: Disturbance | None = None,
                  duration: float = 5.0, **options) -> SimulationResult:
    """``posturelab.simulate(..., engine="compiled")``, under its former name.

    Parameters (keywords ``initial_state``, ``rates_from``, ``knee``, ``fall``,
    ``torque_limits``, ``feedback_delay``, ``rtol``, ``atol``, ``sample_rate``,
    ``max_switches``, ``description``, ``method``) and result as
    :func:`posturelab.simulate`; the tolerances default to the compiled engine's
    (rtol 1e-6, atol 1e-9 [rad, rad/s]) and the method to :func:`default_method`.
    """
    if "engine" in options:
        raise ParameterError("simulate_fast always runs the compiled engine; use "
                             "posturelab.simulate(..., engine=...) to choose")
    return simulate(body, muscles, disturbance, duration, engine="compiled", **options)


# ---------------------------------------------------------------------------
# Many simulations, outcomes only
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class BatchResult:
    """Outcomes of many runs (no trajectories); row r is run r.

    Every quantity is computed on the output samples, exactly as
    :class:`~posturelab.simulation.results.SimulationResult` computes it for one run
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
        From the end of the perturbation (``stimulus.end``) to the last sample time at
        which some |θ_i| exceeded ``settle_tolerance``; 0 if none did after it; NaN if the
        run fell, had not settled by its last sample, or the stimulus is sustained
        (``SimulationResult.settling_time``). [s]
    final_state : numpy.ndarray, shape (M, 2N)
        ``[Θ, Θ̇]`` at the last sample. [rad], [rad/s]
    status_code : numpy.ndarray of int8, shape (M,)
        0 completed, 1 fell, 2 step size underflow, 3 non-finite state,
        4 too many switches, 5 out of memory, 6 step budget spent, 7 time limit
        reached (2–7 are "failed"). [-]
    n_steps : numpy.ndarray of int64, shape (M,)
        Accepted integrator steps. [-]
    n_switches : numpy.ndarray of int64, shape (M,)
        Switches: one-sided pairs, the knee stop, torque saturation. [-]
    settle_tolerance : float
        Angle threshold of the settling time. [rad]
    fall_kind : numpy.ndarray of int64, shape (M,), optional
        Event code of the fall (:mod:`posturelab.model.events`), −1 if none. [-]
    stimulus : StimulusTiming, optional
        When the perturbation acts (:mod:`posturelab.simulation.outcome`); None: a
        transient one that ends at t = 0.
    steady_rms_theta, steady_peak_theta : numpy.ndarray, shape (M, N), optional
        Under a sustained stimulus, the RMS and peak |θ_i| over each run's steady part
        (``SimulationResult.steady_sway``), NaN for a run that did not complete; None when
        not computed (the batch keeps no trajectories: a sweep computes them). [rad]
    steady_rms_cop, steady_peak_cop : numpy.ndarray, shape (M,), optional
        The same of the centre of pressure. [m]
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
    fall_kind: np.ndarray | None = None
    stimulus: StimulusTiming | None = None
    steady_rms_theta: np.ndarray | None = None
    steady_peak_theta: np.ndarray | None = None
    steady_rms_cop: np.ndarray | None = None
    steady_peak_cop: np.ndarray | None = None

    @property
    def n_runs(self) -> int:
        """Number of runs M. [-]"""
        return int(self.fell.size)

    @property
    def status(self) -> np.ndarray:
        """"completed", "fell" or "failed" per run (as ``SimulationResult.status``)."""
        return np.array(STATUS_NAMES)[self.status_code]

    @property
    def failure(self) -> np.ndarray:
        """Why each failed run failed, in a few words ("step budget spent", "non-finite
        state", …); "" for a run that completed or fell."""
        return np.array(STATUS_FAILURES)[self.status_code]

    @property
    def outcome(self) -> np.ndarray:
        """"recovered", "not recovered", "steady sway", "fell" or "failed" per run
        (:mod:`posturelab.simulation.outcome`, as ``SimulationResult.outcome``)."""
        from ..outcome import classify_rows

        sustained = self.stimulus is not None and self.stimulus.sustained
        return classify_rows(self.status, self.settling_time, self.final_state, sustained)


def _per_run(name: str, value, m: int, width: int | None) -> np.ndarray:
    """A scalar/row broadcast to every run, or one value/row per run."""
    arr = np.asarray(value, dtype=float)
    want = (m,) if width is None else (m, width)
    if arr.shape == want:
        return np.ascontiguousarray(arr)
    single = () if width is None else (width,)
    if arr.shape == single:
        return np.ascontiguousarray(np.broadcast_to(arr, want))
    raise ParameterError(f"{name} must have shape {single or '()'} (every run) or {want} (one "
                         f"per run), got shape {arr.shape}")


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
    torque_limits: np.ndarray | None = None,
    feedback_delay: float | np.ndarray = 0.0,
    active_stiffness: np.ndarray | None = None,
    active_viscosity: np.ndarray | None = None,
    tilt: Tilt | None = None,
    proprioceptive_weight: float | np.ndarray = 1.0,
    tilt_axis_depth: float = 0.0,
    motor_noise: MotorNoise | None = None,
    rtol: float = DEFAULT_RTOL,
    atol: float = DEFAULT_ATOL,
    sample_rate: float = 1000.0,
    settle_tolerance: float = 0.01,
    max_switches: int = 10_000,
    parallel: bool = True,
    chunk: int = 64,
    method: str | None = None,
    disturbance_scale: np.ndarray | None = None,
    max_steps: int | None = None,
    time_limit: float | None = None,
) -> BatchResult:
    """Simulate M parameter sets on one body and disturbance; keep only the outcomes.

    Run r is ``posturelab.simulate(body, muscles with stiffness[r] and viscosity[r], …,
    torque_limits=torque_limits[r], feedback_delay=feedback_delay[r],
    engine="compiled")``: the same integration, bit for bit, without storing its
    trajectory.

    Parameters
    ----------
    body : Body
        The chain (N links).
    stiffness : array_like, shape (M, P)
        Pair stiffness per run. [N·m/rad]
    viscosity : array_like, shape (M, P)
        Pair viscosity per run. [N·m·s/rad]
    disturbance, duration, initial_state
        As for :func:`posturelab.simulate` (platform motion; [s]; [rad], [rad/s]).
    muscles : MuscleSet, optional
        The pair layout (spans and one-sidedness, in column order); its own
        gains are ignored. Default: the paper's five pairs, two-sided (N = 3).
    rates_from, knee, fall
        As for :func:`posturelab.simulate`.
    torque_limits : array_like, shape (N,) or (M, N), optional
        Largest net muscle moment per joint, for every run or per run; ``inf`` for
        none. [N·m]
    feedback_delay : float or array_like, shape (M,)
        Neural delay of the muscle feedback, for every run or per run. [s]
    active_stiffness, active_viscosity : array_like, shape (M, P), optional
        Active (neural, delayed) pair gains per run; with either given, ``stiffness`` and
        ``viscosity`` are the intrinsic (undelayed) part and the delay applies to these
        only; with neither, the delay applies to the whole pair feedback
        (:func:`posturelab.model.muscles.feedback_gains`). [N·m/rad], [N·m·s/rad]
    tilt : Tilt, optional
        The support-surface tilt of every run (:mod:`posturelab.model.tilt`).
    proprioceptive_weight : float or array_like, shape (M,)
        W of the active part's error for pairs that span the foot, in [0, 1], for every
        run or per run. [-]
    tilt_axis_depth : float
        Distance of the tilt axis below the ankle (0: the ankle's own). [m]
    motor_noise : MotorNoise, optional
        The motor noise of every run: the same realisation in each
        (:mod:`posturelab.model.noise`). [N·m]
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
        Spread the runs over threads, one per CPU available (:func:`batch_threads`);
        False runs them one after another in the calling thread, without the GIL
        (for callers that bring their own threads, such as Dask workers).
    chunk : int
        Runs per call of the engine (a work item of the threads). [-]
    method : {"Radau", "RK45", "RK23"}, optional
        The compiled integrator of every run; by default each run's
        :func:`default_method` (as its single run would choose).
    disturbance_scale : array_like, shape (M,), optional
        Run r's disturbance is ``disturbance.scaled(disturbance_scale[r])``
        (:meth:`posturelab.model.platform.Disturbance.scaled`: the step speed, pulse
        peak, ramp displacement, sine amplitudes or measured accelerations times
        the factor); by default every run has ``disturbance`` as it is. [-]
    max_steps : int, optional
        The step budget of each run (:func:`posturelab.simulate`); a run that spends it
        is ``failed`` (status code 6). [-]
    time_limit : float, optional
        The wall-clock budget of each run (status code 7 when spent); none by
        default. [s]

    Returns
    -------
    BatchResult
    """
    from ...model.checks import check_model

    check_model(body, muscles)
    if method is not None:
        _check_method(method)
    if muscles is None:
        if body.n_links != 3:
            raise ParameterError(
                f"the default pair layout is the paper's five pairs on 3 links; this body has "
                f"{body.n_links}: pass muscles=MuscleSet(...) for the layout"
            )
        muscles = paper_muscles("1")
    P = len(muscles.pairs)
    n = body.n_links
    kd_all = _gain_array("stiffness [N·m/rad]", stiffness, P)
    ld_all = _gain_array("viscosity [N·m·s/rad]", viscosity, P)
    if kd_all.shape != ld_all.shape:
        raise ParameterError(f"stiffness and viscosity must have the same shape, got "
                             f"{kd_all.shape} and {ld_all.shape}")
    settle_tolerance = positive_float("settle_tolerance [rad]", settle_tolerance)
    if isinstance(chunk, bool) or not isinstance(chunk, int | np.integer) or chunk < 1:
        raise ParameterError(f"chunk must be an integer >= 1, got {chunk!r}")
    M = kd_all.shape[0]
    ka_all = la_all = None
    if active_stiffness is not None or active_viscosity is not None:
        if muscles.one_sided_mask.any():
            raise ParameterError("one-sided pairs cannot be combined with active (delayed) "
                                 "gains (make them two-sided, or give no active gains)")
        zeros = np.zeros_like(kd_all)
        ka_all = (zeros if active_stiffness is None
                  else _gain_array("active_stiffness [N·m/rad]", active_stiffness, P))
        la_all = (zeros if active_viscosity is None
                  else _gain_array("active_viscosity [N·m·s/rad]", active_viscosity, P))
        for label, arr in (("active_stiffness", ka_all), ("active_viscosity", la_all)):
            if arr.shape != kd_all.shape:
                raise ParameterError(f"{label} must have the shape of stiffness, "
                                     f"{kd_all.shape}, got {arr.shape}")
    delays = _per_run("feedback_delay [s]", feedback_delay, M, None)
    weights = _per_run("proprioceptive_weight [-]", proprioceptive_weight, M, None)
    lims = (np.full((M, n), math.inf) if torque_limits is None
            else _per_run("torque_limits [N·m]", torque_limits, M, n))
    scale = (np.ones(M) if disturbance_scale is None
             else finite_array("disturbance_scale [-]", disturbance_scale, (M,)))

    def level_setup(factor: float, delay: float, limits) -> RunSetup:
        d = disturbance if disturbance is None or factor == 1.0 else disturbance.scaled(factor)
        return prepare_run(body, muscles, d, duration, initial_state=initial_state,
                           rates_from=rates_from, knee=knee, fall=fall,
                           torque_limits=limits, feedback_delay=delay, rtol=rtol, atol=atol,
                           sample_rate=sample_rate, max_switches=max_switches, tilt=tilt,
                           proprioceptive_weight=weight, tilt_axis_depth=tilt_axis_depth,
                           motor_noise=motor_noise, max_steps=max_steps,
                           time_limit=time_limit)

    weight = float(weights[0]) if M else 1.0
    for w in np.unique(weights):  # each checked as a single run's would be
        check_proprioceptive_weight(float(w))

    # every run's delay and limits are checked as a single run's would be
    for d in np.unique(delays):
        level_setup(1.0, float(d), None)
    any_limit = bool(np.isfinite(lims).any())
    for row in (np.unique(lims, axis=0) if M and any_limit else []):
        level_setup(1.0, 0.0, None if np.all(np.isinf(row)) else row)
    # one level per distinct (scale, delayed or not, pairs acting at the start): start
    # state, disturbance, knee, pairs (a pull-only pair's start depends on the run's gains)
    delayed = delays > 0
    slot_limits = np.where(np.isfinite(lims).any(axis=0), 1.0, math.inf) if any_limit else None
    # (a level's limits only decide which event slots exist: the finite ones of any run)
    gains_all = enc.readonly(np.ascontiguousarray(
        feedback_gains(kd_all, ld_all, ka_all, la_all, delays)))
    keys = np.stack([scale, delayed.astype(float)], axis=1)
    if M and muscles.one_sided_mask.any():
        first, where = np.unique(keys, axis=0, return_inverse=True)
        starts = [level_setup(float(f), 1.0 if dl else 0.0, slot_limits) for f, dl in first]
        state = np.stack([lv.before if dl else lv.x0
                          for lv, (_, dl) in zip(starts, first, strict=True)])
        acting = start_activity(muscles, state[np.asarray(where).ravel()], gains_all)
        keys = np.concatenate([keys, acting], axis=1)
    values, which = np.unique(keys, axis=0, return_inverse=True) if M else (keys, [])
    which = np.ascontiguousarray(np.asarray(which).ravel(), dtype=np.int64)
    levels = [level_setup(float(row[0]), 1.0 if row[1] else 0.0, slot_limits) for row in values]
    base = levels[0] if levels else level_setup(1.0, 0.0, slot_limits)
    packed = [_packed(lv) for lv in levels] or [_packed(base)]
    stack = lambda key: enc.readonly(np.stack([p[key] for p in packed]))  # noqa: E731
    x0_all, before_all, ipar_all = stack("x0"), stack("before"), stack("ipar")
    dp_len = max(p["dp"].size for p in packed)
    dp_all = enc.readonly(np.stack([np.pad(p["dp"], (0, dp_len - p["dp"].size))
                                    for p in packed]))
    active_all = enc.readonly(np.stack(
        [row[2:] if row.size > 2 else start_activity(muscles, lv.before if row[1] else lv.x0)
         for lv, row in zip(levels, values, strict=True)] or [packed[0]["active0"]]))
    # per run: the saturation at the start
    moments0 = start_moments(muscles, x0_all[which], before_all[which], active_all[which],
                             gains_all)
    tilt_gain_all = enc.readonly(np.zeros((M, 4, n)))
    if base.tilt is not None:  # the tilt's gains follow each run's gains and delay
        split = feedback_gains(kd_all, ld_all, ka_all, la_all, np.ones(M))
        pair_gains = tilt_pair_gains(split, muscles.spans_foot, delays, weights)
        a0, ad0 = base.tilt.angle_and_rate(0.0)
        ab, adb = base.tilt.angle_and_rate(-delays)  # what the delayed part feels at t = 0
        at_start = (pair_gains[:, 0] * a0 + pair_gains[:, 1] * ad0
                    + pair_gains[:, 2] * ab[:, None] + pair_gains[:, 3] * adb[:, None])
        moments0 = moments0 + at_start @ muscles.crossing_matrix
        tilt_gain_all = enc.readonly(np.ascontiguousarray(pair_gains @ muscles.crossing_matrix))
    if base.motor_torque is not None:
        moments0 = moments0 + torque_at(base.motor_torque, 0.0)
    sat0_all = enc.readonly(start_saturation(moments0, lims))
    lim_all = enc.readonly(lims)
    delay_all = enc.readonly(delays)
    a = {key: v for key, v in packed[0].items() if isinstance(key, str)}  # no cached run
    a["fpar"] = enc.options(base, settle_tolerance)[0]
    results = np.zeros((M, N_RESULT))
    peaks = np.zeros((M, n))
    finals = np.zeros((M, 2 * n))
    # runs that fall at t = 0 whatever their gains (posture), or by their centre of pressure
    at_start = np.zeros(M, dtype=bool)
    for k, lv in enumerate(levels):
        if fall_at_start_by_posture(lv) is not None:
            at_start |= which == k
    if M and base.fall.centre_of_pressure:
        for k, lv in enumerate(levels):
            rows = (which == k) & ~at_start
            if rows.any():
                xp = start_centre_of_pressure(lv, moments0[rows], lims[rows], sat0_all[rows])
                bos = lv.fall.base_of_support
                out = np.array([cop_fall_at_start(float(v), bos) is not None for v in xp])
                at_start[np.nonzero(rows)[0][out]] = True
    names = ([method] * M if method is not None
             else [default_method(float(d)) for d in delays])
    # (the runs that choose their own method choose RK45 or Radau: one tableau at most)
    method_all = enc.readonly(np.array([METHOD_RADAU if METHODS[nm] is None
                                        else METHOD_EXPLICIT for nm in names], np.int64))
    shared = next((nm for nm in names if METHODS[nm] is not None), "Radau")
    todo = np.nonzero(~at_start)[0]
    if todo.size:
        batch = Batch(base=_run_struct(a, shared, gains_all[0], lim_all[0], 0.0, sat0_all[0]),
                      which=pointer(which, ctypes_int64), x0_all=pointer(x0_all),
                      before_all=pointer(before_all), dp_all=pointer(dp_all),
                      dp_stride=dp_len, ipar_all=pointer(ipar_all, ctypes_int64),
                      active0_all=pointer(active_all), gains_all=pointer(gains_all),
                      lim_all=pointer(lim_all), delay_all=pointer(delay_all),
                      sat0_all=pointer(sat0_all), method_all=pointer(method_all, ctypes_int64),
                      results=pointer(results),
                      peaks=pointer(peaks), finals=pointer(finals),
                      tilt_gain_all=pointer(tilt_gain_all))
        _run_rows(batch, todo, parallel, int(chunk))
    if at_start.any():
        results[at_start] = 0.0
        results[at_start, R_STATUS] = STATUS_FELL
        results[at_start, R_FALL_TIME] = 0.0
        results[at_start, R_FALL_KIND] = -1
        peaks[at_start] = np.abs(x0_all[which[at_start], :n])
        finals[at_start] = x0_all[which[at_start]]
    status = results[:, R_STATUS].astype(np.int8)
    fell = status == STATUS_FELL
    fall_time = np.where(fell, results[:, R_FALL_TIME], np.nan)
    final_outside = results[:, R_FINAL_OUTSIDE] > 0
    any_outside = results[:, R_ANY_OUTSIDE] > 0
    timing = stimulus_timing(base.disturbance, base.tilt, base.motor_noise)
    # counted from the end of the perturbation (the C engine gives the last time outside)
    # (none when the run ends before its perturbation does: recovery is measured within it)
    cut_short = not timing.sustained and timing.end > base.duration + 1e-9
    settling = np.where(fell | final_outside | timing.sustained | cut_short, np.nan, np.where(
        any_outside, np.maximum(results[:, R_LAST_OUTSIDE] - timing.end, 0.0), 0.0))
    return BatchResult(
        fell=fell, fall_time=fall_time, peak_theta=peaks, settling_time=settling,
        final_state=finals, status_code=status,
        n_steps=results[:, R_N_STEPS].astype(np.int64),
        n_switches=results[:, R_N_SWITCHES].astype(np.int64),
        settle_tolerance=settle_tolerance,
        fall_kind=results[:, R_FALL_KIND].astype(np.int64), stimulus=timing,
    )


#: Threads a parallel batch uses by default (the CPUs this process may run on). [-]
def batch_threads() -> int:
    """Number of threads of a parallel batch: the CPUs available to this process. [-]"""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not on Linux
        return max(1, os.cpu_count() or 1)


def _run_rows(batch: Batch, rows: np.ndarray, parallel: bool, chunk: int) -> None:
    """Run the given rows of a batch: contiguous ranges, over threads when parallel."""
    lib = library()
    # contiguous ranges of the rows to run (the rows that fall at the start are skipped)
    breaks = np.nonzero(np.diff(rows) != 1)[0] + 1
    ranges = []
    for part in np.split(rows, breaks):
        for lo in range(int(part[0]), int(part[-1]) + 1, chunk):
            ranges.append((lo, min(lo + chunk, int(part[-1]) + 1)))
    threads = batch_threads() if parallel else 1
    if threads == 1 or len(ranges) == 1:
        for lo, hi in ranges:
            lib.pl_run_batch(batch, lo, hi)
        return
    with ThreadPoolExecutor(max_workers=threads) as pool:
        list(pool.map(lambda r: lib.pl_run_batch(batch, r[0], r[1]), ranges))


def state_derivative(body: Body, muscles: MuscleSet, state, *, active=None, locked=False,
                     platform_acceleration=(0.0, 0.0), delayed_moments=None,
                     saturation=None, torque_limits=None, general=False) -> np.ndarray:
    """[Θ̇, Θ̈] of the C right-hand side at one state (for tests and checks).

    Parameters
    ----------
    state : array_like, shape (2N,)
        [rad], [rad/s]
    active : array_like, shape (P,), optional
        Which pairs act (1) or are slack (0); all by default. [-]
    locked : bool
        The knee constraint holds.
    platform_acceleration : (float, float)
        (ẍ_d, ÿ_d). [m/s²]
    delayed_moments : array_like, shape (N,), optional
        τ_delayed added to the joint moments. [N·m]
    saturation, torque_limits : array_like, shape (N,), optional
        ±1 where a joint saturates at its limit [N·m].
    general : bool
        Use the general-N code even where generated straight-line code exists.

    Returns
    -------
    numpy.ndarray, shape (2N,)
        [rad/s], [rad/s²]
    """
    n = body.n_links
    P = len(muscles.pairs)
    x = np.ascontiguousarray(state, dtype=float)
    act = np.ones(P) if active is None else np.ascontiguousarray(active, dtype=float)
    g = np.ascontiguousarray(muscle_set_gains(muscles, 0.0))
    lim = np.ascontiguousarray(enc.limits(torque_limits, n))
    sat = np.zeros(n) if saturation is None else np.ascontiguousarray(saturation, dtype=float)
    inp = np.zeros(2 + n)
    inp[:2] = platform_acceleration
    if delayed_moments is not None:
        inp[2:] = delayed_moments
    out = np.empty(2 * n)
    tau = np.empty(n)
    bp = enc.body_array(body)
    E = np.ascontiguousarray(muscles.selection_matrix)
    C = np.ascontiguousarray(muscles.crossing_matrix)
    library().pl_state_derivative(n, P, pointer(bp), pointer(E), pointer(C), pointer(g),
                                  pointer(act), pointer(lim), pointer(sat), pointer(x),
                                  pointer(inp), int(bool(locked)), int(bool(general)),
                                  pointer(out), pointer(tau))
    return out


def rotated_sine_cosine(theta: float, theta_b: float) -> tuple[float, float]:
    """(sin θ, cos θ) as the C right-hand side computes them from those of θ_b (tests)."""
    s, c = ctypes.c_double(), ctypes.c_double()
    library().pl_rotate_value(theta, theta_b, math.sin(theta_b), math.cos(theta_b),
                              ctypes.byref(s), ctypes.byref(c))
    return s.value, c.value


def warm_up(methods: tuple[str, ...] = ("Radau",),
            entries: tuple[str, ...] = ("one", "parallel", "serial")) -> None:
    """Load the engine and check that it runs (nothing is compiled at run time; the
    arguments, which once chose what numba compiled, are kept for compatibility)."""
    for method in methods:
        _check_method(method)
    library()

from ..._lazy import submodule_getattr  # noqa: E402

__getattr__ = submodule_getattr(__name__, __path__)
