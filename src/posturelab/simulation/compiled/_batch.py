"""Many runs on the compiled engine, outcomes only: :func:`simulate_batch`, :class:`BatchResult`.

Each run is set up as a single run is (:func:`posturelab.simulation.setup.prepare_run` with
the batch's :class:`~posturelab.simulation.options.RunOptions`, once per distinct start), and
its start moments come from the same function
(:func:`posturelab.simulation.setup.moments_at_start`) with that run's gains and delay, so a
row equals its single run bit for bit.
"""

from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..._validation import finite_array, positive_float
from ...errors import ParameterError
from ...model.body import Body
from ...model.checks import check_model
from ...model.gains import GAIN_ROWS
from ...model.joint_feedback import joint_feedback_moments, joint_gain_rows
from ...model.limits import body_torque_limits, limits_as_entries
from ...model.muscles import MuscleSet, feedback_gains, paper_muscles
from ...model.platform import Disturbance
from ...model.tilt import tilt_pair_gains
from ...model.visual import visual_pair_gains
from ..options import OPTION_NAMES, RunOptions
from ..outcome import StimulusTiming, stimulus_timing
from ..setup import (
    RunSetup,
    cop_fall_at_start,
    fall_at_start_by_posture,
    moments_at_start,
    prepare_run,
    start_activity,
    start_centre_of_pressure,
    start_saturation,
)
from . import _encode as enc
from ._binding import Batch, library, pointer
from ._layout import (
    METHOD_EXPLICIT,
    METHOD_RADAU,
    N_RESULT,
    R_ANY_OUTSIDE,
    R_FALL_KIND,
    R_FALL_TIME,
    R_FINAL_OUTSIDE,
    R_LAST_OUTSIDE,
    R_N_STEPS,
    R_N_SWITCHES,
    R_STATUS,
    STATUS_FAILURES,
    STATUS_FELL,
    STATUS_NAMES,
)
from ._run import METHODS, check_method, ctypes_int64, default_method, packed, run_struct

__all__ = ["BatchResult", "simulate_batch", "batch_threads", "PER_RUN_OPTIONS"]

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
    hip_fraction : numpy.ndarray, shape (M,), optional
        Each run's hip fraction (:func:`posturelab.model.kinematics.hip_fraction`); None when
        not computed (a sweep asked for its strategy computes it). [-]
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
    hip_fraction: np.ndarray | None = None

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


def _batch_limits(value, m: int, n: int, common: RunOptions, body: Body) -> np.ndarray:
    """Per-run limits as bounds (M, 2, N) (:mod:`posturelab.model.limits`) from numbers (N,)
    or (M, N) (both ways), pairs (M, N, 2) (lower, upper), or one run's ``torque_limits``
    entries (pairs, "foot") for every run; each row is checked later as a single run's."""
    if value is None:
        return np.full((m, 2, n), math.inf)
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        arr = None
    if arr is not None and arr.ndim == 3:
        if arr.shape != (m, n, 2):
            raise ParameterError(f"torque_limits [N·m] as pairs must have shape ({m}, {n}, 2) "
                                 f"(lower, upper per run and joint), got shape {arr.shape}")
        return np.ascontiguousarray(np.stack([-arr[..., 0], arr[..., 1]], axis=1))
    if arr is not None and arr.ndim in (1, 2) and (arr.ndim == 2 or arr.size == n):
        sym = _per_run("torque_limits [N·m]", arr, m, n)
        return np.ascontiguousarray(np.stack([sym, sym], axis=1))
    one = body_torque_limits(value, body, common.fall.base_of_support)
    one = np.full((2, n), math.inf) if one is None else one
    return np.ascontiguousarray(np.broadcast_to(one, (m, 2, n)))


def _shared_options(options: RunOptions | None, duration, initial_state,
                    keywords: dict[str, Any]) -> RunOptions:
    """The options every run of a batch shares, on the compiled engine (the sensory weights
    are per run: checked there, and each level is set up with W_v = 0, the batch computing
    each run's gains on the visual-scene tilt itself)."""
    unknown = [k for k in keywords if k not in OPTION_NAMES or k in PER_RUN_OPTIONS]
    if unknown:
        shared_names = ", ".join(k for k in OPTION_NAMES if k not in PER_RUN_OPTIONS)
        raise ParameterError(f"unknown option {unknown[0]!r} of simulate_batch(); known: "
                             f"{shared_names} and the per-run {', '.join(PER_RUN_OPTIONS)}")
    changes = dict(keywords)
    if duration is not None:
        changes["duration"] = duration
    if initial_state is not None:
        changes["initial_state"] = initial_state
    shared = (options or RunOptions()).replace(**changes)
    if shared.engine != "compiled":
        raise ParameterError("simulate_batch runs the compiled engine; got engine "
                             f"{shared.engine!r}")
    return shared


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


#: The options each run of a batch may have its own value of (an array, one per run); the
#: others are shared by every run.
PER_RUN_OPTIONS = ("feedback_delay", "proprioceptive_weight", "visual_weight",
                   "torque_limits")


def simulate_batch(
    body: Body,
    stiffness: np.ndarray,
    viscosity: np.ndarray,
    disturbance: Disturbance | None = None,
    duration: float | None = None,
    initial_state: np.ndarray | None = None,
    *,
    muscles: MuscleSet | None = None,
    options: RunOptions | None = None,
    feedback_delay: float | np.ndarray | None = None,
    proprioceptive_weight: float | np.ndarray | None = None,
    visual_weight: float | np.ndarray | None = None,
    torque_limits: np.ndarray | tuple[float, ...] | None = None,
    active_stiffness: np.ndarray | None = None,
    active_viscosity: np.ndarray | None = None,
    disturbance_scale: np.ndarray | None = None,
    settle_tolerance: float = 0.01,
    parallel: bool = True,
    chunk: int = 64,
    **keywords: Any,
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
        As for :func:`posturelab.simulate` (platform motion; [s]; [rad], [rad/s]); they
        replace those of ``options``.
    muscles : MuscleSet, optional
        The pair layout (spans and one-sidedness, in column order); its own
        gains are ignored. Default: the paper's five pairs, two-sided (N = 3).
    options : RunOptions, optional
        The options every run shares (:class:`~posturelab.simulation.options.RunOptions`:
        knee, fall criteria, tilt, motor noise, tolerances, method, output rate, budgets),
        on the compiled engine. The integrator of every run is its ``method``, by default
        each run's :func:`default_method` (as its single run would choose).
    feedback_delay : float or array_like, shape (M,), optional
        Neural delay of the muscle feedback, for every run or per run (default
        ``options.feedback_delay``). [s]
    proprioceptive_weight : float or array_like, shape (M,), optional
        W of the active part's error for pairs that span the foot, in [0, 1], for every
        run or per run (default ``options.proprioceptive_weight``). [-]
    visual_weight : float or array_like, shape (M,), optional
        W_v of the visual-scene tilt (``options.visual_tilt``), in [0, 1] with each run's
        W + W_v <= 1, for every run or per run (default ``options.visual_weight``). [-]
    torque_limits : array_like, shape (N,), (M, N) or (M, N, 2), or a run's entries, optional
        Largest net muscle moment per joint, both ways, for every run or per run (``inf``
        for none); per run and joint a pair (lower < 0, upper > 0); or a single run's
        ``torque_limits`` (numbers, pairs, "foot") for every run (default
        ``options.torque_limits``; :mod:`posturelab.model.limits`). [N·m]
    active_stiffness, active_viscosity : array_like, shape (M, P), optional
        Active (neural, delayed) pair gains per run; with either given, ``stiffness`` and
        ``viscosity`` are the intrinsic (undelayed) part and the delay applies to these
        only; with neither, the delay applies to the whole pair feedback
        (:func:`posturelab.model.muscles.feedback_gains`). [N·m/rad], [N·m·s/rad]
    disturbance_scale : array_like, shape (M,), optional
        Run r's disturbance is ``disturbance.scaled(disturbance_scale[r])``
        (:meth:`posturelab.model.platform.Disturbance.scaled`: the step speed, pulse
        peak, ramp displacement, sine amplitudes or measured accelerations times
        the factor); by default every run has ``disturbance`` as it is. [-]
    settle_tolerance : float
        Angle threshold of the settling time. [rad]
    parallel : bool
        Spread the runs over threads, one per CPU available (:func:`batch_threads`);
        False runs them one after another in the calling thread, without the GIL
        (for callers that bring their own threads, such as Dask workers).
    chunk : int
        Runs per call of the engine (a work item of the threads). [-]
    **keywords
        Fields of :class:`~posturelab.simulation.options.RunOptions` by name (``rtol``,
        ``method``, ``tilt``, ``knee``, ``max_steps``, ``time_limit``, …), replacing those
        of ``options``.

    Returns
    -------
    BatchResult
    """
    check_model(body, muscles)
    common = _shared_options(options, duration, initial_state, keywords)
    method = common.method
    if method is not None:
        check_method(method)
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
    if feedback_delay is None:
        feedback_delay = common.feedback_delay
    if proprioceptive_weight is None:
        proprioceptive_weight = common.proprioceptive_weight
    if visual_weight is None:
        visual_weight = common.visual_weight
    if torque_limits is None:
        torque_limits = common.torque_limits
    delays = _per_run("feedback_delay [s]", feedback_delay, M, None)
    weights = _per_run("proprioceptive_weight [-]", proprioceptive_weight, M, None)
    visual_weights = _per_run("visual_weight [-]", visual_weight, M, None)
    common = common.replace(visual_weight=0.0)  # (each run's W_v: visual_weights)
    lims = _batch_limits(torque_limits, M, n, common, body)  # (M, 2, N)
    scale = (np.ones(M) if disturbance_scale is None
             else finite_array("disturbance_scale [-]", disturbance_scale, (M,)))

    def level_setup(factor: float, delay: float, limits) -> RunSetup:
        """A single run's set-up: the batch's options with this delay and these limits."""
        d = disturbance if disturbance is None or factor == 1.0 else disturbance.scaled(factor)
        return prepare_run(body, muscles, d, common.replace(
            feedback_delay=delay, torque_limits=limits, proprioceptive_weight=weight))

    # each (W, W_v) checked as a single run's would be (naming both when W + W_v > 1)
    for w, wv in (np.unique(np.stack([weights, visual_weights], axis=1), axis=0) if M else []):
        common.replace(proprioceptive_weight=float(w), visual_weight=float(wv))
    weight = float(weights[0]) if M else common.proprioceptive_weight

    # every run's delay and limits are checked as a single run's would be
    for d in np.unique(delays):
        level_setup(1.0, float(d), None)
    any_limit = bool(np.isfinite(lims).any())
    some_delay = 1.0 if common.torque_feedback_gain > 0 else 0.0  # (it needs one)
    for row in (np.unique(lims, axis=0) if M and any_limit else []):
        level_setup(1.0, some_delay, None if np.all(np.isinf(row)) else limits_as_entries(row))
    # one level per distinct (scale, delayed or not, pairs acting at the start): start
    # state, disturbance, knee, pairs (a pull-only pair's start depends on the run's gains)
    delayed = delays > 0
    slot_limits = (tuple(np.where(np.isfinite(lims).any(axis=(0, 1)), 1.0, math.inf))
                   if any_limit else None)
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
    base = levels[0] if levels else level_setup(1.0, some_delay, slot_limits)
    packs = [packed(lv) for lv in levels] or [packed(base)]
    stack = lambda key: enc.readonly(np.stack([p[key] for p in packs]))  # noqa: E731
    x0_all, before_all, ipar_all = stack("x0"), stack("before"), stack("ipar")
    dp_len = max(p["dp"].size for p in packs)
    dp_all = enc.readonly(np.stack([np.pad(p["dp"], (0, dp_len - p["dp"].size))
                                    for p in packs]))
    active_all = enc.readonly(np.stack(
        [row[2:] if row.size > 2 else start_activity(muscles, lv.before if row[1] else lv.x0)
         for lv, row in zip(levels, values, strict=True)] or [packs[0]["active0"]]))
    # per run: the saturation at the start, from the moments a single run computes (the
    # tilt's gains follow each run's gains and delay)
    tilt_gain_all = enc.readonly(np.zeros((M, len(GAIN_ROWS), n)))
    tilt_pair_gain_all = enc.readonly(np.zeros((M, len(GAIN_ROWS), P)))
    pair_gains = None
    if base.tilt is not None:
        split = feedback_gains(kd_all, ld_all, ka_all, la_all, np.ones(M))
        pair_gains = tilt_pair_gains(split, muscles.spans_foot, delays, weights)
        tilt_gain_all = enc.readonly(np.ascontiguousarray(pair_gains @ muscles.crossing_matrix))
        tilt_pair_gain_all = enc.readonly(np.ascontiguousarray(pair_gains))
    if common.joint_feedback is not None and len({bool(d > 0) for d in delays}) > 1:
        raise ParameterError("a batch with a joint_feedback controller needs every run's "
                             "feedback_delay > 0, or every one 0 (not a mix)")
    visual_gain_all = enc.readonly(np.zeros((M, len(GAIN_ROWS), n)))
    visual_pair_gain_all = enc.readonly(np.zeros((M, len(GAIN_ROWS), len(muscles.pairs))))
    visual_gains = None
    if base.visual_tilt is not None:  # (each run's visual weight, gains and delay)
        split = feedback_gains(kd_all, ld_all, ka_all, la_all, np.ones(M))
        visual_gains = visual_pair_gains(split, muscles.spans_foot, delays, visual_weights)
        visual_gain_all = enc.readonly(np.ascontiguousarray(
            visual_gains @ muscles.crossing_matrix))
        visual_pair_gain_all = enc.readonly(np.ascontiguousarray(visual_gains))
    moments0 = np.empty((M, n))
    for d in np.unique(delays):
        rows = delays == d
        moments0[rows] = moments_at_start(
            muscles, x0_all[which[rows]], before_all[which[rows]], active_all[which[rows]],
            gains_all[rows], float(d), base.tilt,
            None if pair_gains is None else pair_gains[rows], base.motor_torque,
            base.visual_tilt, None if visual_gains is None else visual_gains[rows])
        if common.joint_feedback is not None:  # the controller's moment at the start
            moments0[rows] += joint_feedback_moments(
                joint_gain_rows(common.joint_feedback, n, float(d)), x0_all[which[rows]],
                before_all[which[rows]])
    sat0_all = enc.readonly(start_saturation(moments0, lims))
    lim_all = enc.readonly(lims)
    delay_all = enc.readonly(delays)
    a = {key: v for key, v in packs[0].items() if isinstance(key, str)}  # no cached run
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
        batch = Batch(base=run_struct(a, shared, gains_all[0], lim_all[0], 0.0, sat0_all[0]),
                      which=pointer(which, ctypes_int64), x0_all=pointer(x0_all),
                      before_all=pointer(before_all), dp_all=pointer(dp_all),
                      dp_stride=dp_len, ipar_all=pointer(ipar_all, ctypes_int64),
                      active0_all=pointer(active_all), gains_all=pointer(gains_all),
                      lim_all=pointer(lim_all), delay_all=pointer(delay_all),
                      sat0_all=pointer(sat0_all), method_all=pointer(method_all, ctypes_int64),
                      results=pointer(results),
                      peaks=pointer(peaks), finals=pointer(finals),
                      tilt_gain_all=pointer(tilt_gain_all),
                      tilt_pair_gain_all=pointer(tilt_pair_gain_all),
                      visual_gain_all=pointer(visual_gain_all),
                      visual_pair_gain_all=pointer(visual_pair_gain_all))
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
    timing = stimulus_timing(base.disturbance, base.tilt, base.motor_noise, base.visual_tilt)
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

