"""One run on the compiled engine: :func:`integrate_compiled`, its integrators
(:data:`METHODS`) and the C inputs of a set-up (:func:`packed`, :func:`run_struct`)."""

from __future__ import annotations

import ctypes
import functools

import numpy as np

from ...errors import ParameterError
from ...model.events import fall_message
from ...model.gains import GAIN_ROWS
from ..derived import derived_series
from ..messages import outcome_message
from ..outcome import stimulus_timing
from ..results import SimulationResult
from ..setup import DELAY_BREAKPOINT_MULTIPLES, RunSetup, switched_model
from . import _encode as enc
from ._binding import Out, Run, library, pointer
from ._layout import (
    METHOD_EXPLICIT,
    METHOD_RADAU,
    N_RESULT,
    R_FALL_INDEX,
    R_FALL_KIND,
    R_FALL_SAMPLE,
    R_FALL_TIME,
    R_N_SAMPLES,
    R_N_SWITCHES,
    R_STATUS,
    R_T_REACHED,
    STATUS_FELL,
    STATUS_NAMES,
    STATUS_OUTCOMES,
)
from ._tableaux import BOGACKI_SHAMPINE_32, DORMAND_PRINCE_54

ctypes_int64 = ctypes.POINTER(ctypes.c_int64)
ctypes_uint8 = ctypes.POINTER(ctypes.c_uint8)

__all__ = ["METHODS", "default_method", "check_method", "integrate_compiled", "packed",
           "run_struct"]

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


def check_method(method: str) -> None:
    if method not in METHODS:
        raise ParameterError(f"method must be one of {', '.join(map(repr, METHODS))} for the "
                             f"compiled engine, got {method!r}")


def _stimulus_gains(name: str, pair_gains: np.ndarray | None, muscles, n: int) -> dict:
    """A stimulus's gains as the engine reads them: ``NAME_gain`` (4, n) on the joint
    moments and ``NAME_pair_gain`` (4, p) on the pair torques (what the torque feedback
    filters take), zeros without the stimulus."""
    if pair_gains is None:
        pair_gains = np.zeros((len(GAIN_ROWS), len(muscles.pairs)))
    return {f"{name}_gain": enc.readonly(np.ascontiguousarray(
                pair_gains @ muscles.crossing_matrix)),
            f"{name}_pair_gain": enc.readonly(np.ascontiguousarray(pair_gains))}


@functools.lru_cache(maxsize=64)
def packed(setup: RunSetup) -> dict:
    """The gain-independent arrays of a run (memoised per set-up object)."""
    from ...model import events as ev

    n = setup.n_links
    fpar, ipar = enc.options(setup)
    muscles = setup.muscles
    limited = (np.isfinite(setup.torque_limits).any(axis=0) if setup.torque_limits is not None
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
        **_stimulus_gains("tilt", setup.tilt_gains, muscles, n),
        "tilt_depth": float(setup.tilt_axis_depth),
        "n_filters": switched_model(setup).n_filter_states,
        "filter_gain": float(setup.options.torque_feedback_gain),
        "filter_time": float(setup.options.torque_feedback_time_constant),
        "mp": enc.encode_motor_noise(setup.motor_torque),
        "joint_gain": enc.readonly(np.ascontiguousarray(setup.joint_gains)),
        "vp": enc.encode_tilt(setup.visual_tilt),
        **_stimulus_gains("visual", setup.visual_gains, muscles, n),
        "bps": enc.readonly(setup.breakpoints.astype(float)), "fpar": fpar, "ipar": ipar,
        "active0": enc.readonly(setup.active0), "slots": slots,
        "ev_offset": ev.EVENT_OFFSET, "ev_direction": ev.EVENT_DIRECTION,
        "ev_ends": ev.EVENT_ENDS_RUN, "n": n,
    }


def run_struct(a: dict, method: str, gains, lim, delay: float, sat0) -> Run:
    """The C inputs of one run (the arrays in ``a`` must outlive it): a copy of the run's
    gain-independent inputs (built once per set-up and method) with these filled in."""
    base = a.get(("run", method))
    if base is None:
        base = a[("run", method)] = base_run_struct(a, method)
    run = Run.from_buffer_copy(base)
    run.gains, run.lim, run.sat0 = pointer(gains), pointer(lim), pointer(sat0)
    run.delay = float(delay)
    return run


def base_run_struct(a: dict, method: str) -> Run:
    """The gain-independent C inputs of a run."""
    tab = METHODS[method]
    n = a["n"]
    run = Run(n=n, p=a["E"].shape[0], n_grid=a["grid"].size, n_bps=a["bps"].size,
              n_slots=len(a["slots"]), method=METHOD_RADAU if tab is None else METHOD_EXPLICIT,
              delay_multiples=DELAY_BREAKPOINT_MULTIPLES, tilt_depth=a["tilt_depth"],
              n_filters=a["n_filters"], filter_gain=a["filter_gain"],
              filter_time=a["filter_time"])
    for name in ("x0", "before", "grid", "bp", "E", "C", "dp", "bps", "fpar", "active0",
                 "ev_offset", "tp", "tilt_gain", "tilt_pair_gain", "mp", "joint_gain", "vp",
                 "visual_gain", "visual_pair_gain"):
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
    check_method(method)
    a = packed(setup)
    n = a["n"]
    m = 2 * n + a["n_filters"]  # [Θ, Θ̇] and the torque feedback filters' Y
    muscles = setup.muscles
    delayed = setup.feedback_delay > 0
    switches = np.zeros(0)
    feedback = None
    T = a["grid"].size
    if setup.fall_at_start is not None:
        status, t_reached = STATUS_FELL, 0.0
        time = np.zeros(1)
        samples = np.concatenate([setup.x0, np.zeros(m - 2 * n)])[:, None]
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
        run = run_struct(a, method, g, lim, setup.feedback_delay, sat0)
        samples = np.empty((m, T + 1))
        fb = np.empty((2 * n, T + 1)) if delayed else None
        locked_u8 = np.zeros(T + 1, np.uint8)
        switches = np.empty(setup.max_switches + 1)
        peak, final, res = np.empty(n), np.empty(2 * n), np.empty(N_RESULT)
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
            samples[:, 0] = 0.0  # (the filters start at rest)
            samples[:2 * n, 0] = setup.x0
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
    omega = samples[n:2 * n, :count].T
    locked = locked[:count]
    for arr in (time, theta, omega):
        arr.setflags(write=False)
    state = samples[:2 * n, :count].T
    filters = samples[2 * n:, :count].T if m > 2 * n else None
    derive = functools.partial(derived_series, setup, time, state, feedback, locked, filters)
    return SimulationResult(
        time=time, theta=theta, omega=omega, pair_names=tuple(muscles.names),
        status=STATUS_NAMES[status], message=message, fell=status == STATUS_FELL,
        fall_time=fall_time, fall_reason=fall_reason,
        switch_times=tuple(float(v) for v in switches), description=setup.description,
        derived=derive,
        stimulus=stimulus_timing(setup.disturbance, setup.tilt, setup.motor_noise,
                                 setup.visual_tilt),
    )


def _fall_reason(kind: int, index: int, setup: RunSetup) -> str:
    bos = setup.fall.base_of_support
    return fall_message(kind, index, max_link_angle=setup.fall.max_link_angle,
                        toe=bos.toe if bos is not None else 0.0,
                        heel=bos.heel if bos is not None else 0.0)

