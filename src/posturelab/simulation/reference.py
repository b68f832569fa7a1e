"""The reference engine: the model's numpy functions integrated by scipy's ``solve_ivp``.

Slow and obvious on purpose: the switched model of :mod:`posturelab.model.switched` (its
right-hand side :func:`~posturelab.model.switched.model_response`, its event values
:func:`~posturelab.model.switched.event_value` and what each switch does) evaluated with
numpy, and scipy integrates. This module keeps only the segments, the delay history and
the calls to ``solve_ivp``. It is the check on the compiled engine, whose C is generated
from the same formulas.

Switches are located as events, never as an ``if`` inside the right-hand
side that the integrator could step over: the integration runs in segments
within which the model is smooth, and a segment ends

* at every corner (breakpoint) of the platform profile, and at kτ with a
  feedback delay τ;
* where an event of :mod:`posturelab.model.events` fires: a fall ends the
  run; a one-sided pair engaging or going slack, a joint moment saturating or
  letting go, the knee reaching or leaving its stop restart it.

With a neural feedback delay τ the muscles respond to the state at t − τ. The
delay differential equation is integrated by the method of steps: segments no
longer than τ, so that the past the feedback needs is always already computed;
the history is the state before the run for t < 0, then the dense output of
the segments.
"""

from __future__ import annotations

import bisect
import math
import time

import numpy as np

from ..model import events as ev
from ..model import switched as sw
from .derived import derived_series
from .outcome import stimulus_timing
from .results import SimulationResult
from .setup import (
    DELAY_BREAKPOINT_MULTIPLES,
    RunSetup,
    outcome_message,
    switched_model,
)

__all__ = ["integrate_reference", "REFERENCE_METHODS"]

#: scipy ``solve_ivp`` methods the reference engine accepts.
REFERENCE_METHODS = ("DOP853", "RK45", "RK23", "Radau", "BDF", "LSODA")


class _Budget:
    """A run's step and time budgets, shared by the solvers of all its segments."""

    def __init__(self, max_steps: int, time_limit: float):
        self.max_steps, self.time_limit = max_steps, time_limit
        self.steps = 0
        self.started = time.monotonic()
        self.spent: str | None = None  # "step-budget" or "time-budget" once one runs out

    def solver(self, method: str):
        """scipy's ``method`` class, counting its accepted steps against the budgets."""
        import scipy.integrate

        budget = self

        class Budgeted(getattr(scipy.integrate, method)):
            def _step_impl(self):
                if budget.steps >= budget.max_steps:
                    budget.spent = "step-budget"
                elif time.monotonic() - budget.started > budget.time_limit:
                    budget.spent = "time-budget"
                if budget.spent is not None:
                    return False, budget.spent
                budget.steps += 1
                return super()._step_impl()

        return Budgeted


class _History:
    """The state at past times: ``before`` for t < 0, then the segments' dense outputs."""

    def __init__(self, before: np.ndarray):
        self.before = np.asarray(before, dtype=float).copy()
        self.starts: list[float] = []
        self.ends: list[float] = []
        self.pieces: list = []

    def add(self, t0: float, t1: float, sol) -> None:
        if t1 > t0:
            self.starts.append(t0)
            self.ends.append(t1)
            self.pieces.append(sol)

    def __call__(self, t: float) -> np.ndarray:
        if t < 0.0 or not self.pieces:
            return self.before
        k = max(bisect.bisect_right(self.starts, t) - 1, 0)
        return self.pieces[k](min(t, self.ends[k]))

    def left(self, t: float) -> np.ndarray:
        """The state just before ``t`` (where the rates jump: the start, a knee impact)."""
        k = bisect.bisect_left(self.starts, t) - 1
        if t <= 0.0 or k < 0:
            return self.before
        return self.pieces[k](min(t, self.ends[k]))


def integrate_reference(setup: RunSetup, method: str = "DOP853") -> SimulationResult:
    """Integrate one run with scipy.

    Parameters
    ----------
    setup : RunSetup
        The run (:func:`posturelab.simulation.setup.prepare_run`).
    method : str
        A scipy ``solve_ivp`` method (:data:`REFERENCE_METHODS`).

    Returns
    -------
    SimulationResult
    """
    from scipy.integrate import solve_ivp

    from ..errors import ParameterError

    if method not in REFERENCE_METHODS:
        raise ParameterError(f"method must be one of {', '.join(REFERENCE_METHODS)} for the "
                             f"reference engine, got {method!r}")
    n = setup.n_links
    muscles, fall, knee = setup.muscles, setup.fall, setup.knee
    delay = setup.feedback_delay
    history = _History(setup.before) if delay > 0 else None
    budget = _Budget(setup.max_steps, setup.time_limit)
    solver = budget.solver(method)

    m = 2 * n  # [Θ, Θ̇]; the torque feedback filters' states follow them in the state

    def feedback(t: float, x: np.ndarray) -> np.ndarray:
        return x[:m] if history is None else history(t - delay)[:m]

    model = switched_model(setup)
    filters = model.n_filter_states

    def filter_part(y: np.ndarray) -> np.ndarray | None:
        return y[m:] if filters else None

    limits = setup.torque_limits
    limited = np.isfinite(limits).astype(np.int64) if limits is not None else np.zeros(n, int)
    x = np.concatenate([setup.x0, np.zeros(filters)])  # the filters start at rest
    locked = setup.locked0
    active = setup.active0.copy()
    saturation = setup.saturation0.copy()
    bos = fall.base_of_support
    slots = ev.event_slots(n, bos is not None, fall.centre_of_pressure, limited,
                           muscles.one_sided_mask, knee.mode == "stop", muscles.pull_only_mask)

    def event_function(k: int, j: int, sd: float, _active, _locked, _sat, feedback=feedback):
        """The event function g(t, x) of event kind k (index j, side sd) in this segment
        (:func:`posturelab.model.switched.event_value`); ``feedback(t, x)`` is the state the
        muscles respond to (by default the run's)."""
        return lambda t, y: sw.event_value(model, k, j, sd, t, y[:m], feedback(t, y), _active,
                                           _locked, _sat, filter_part(y))

    if locked and knee.mode == "stop" and event_function(
            ev.KNEE_LEAVES_STOP, 1, 0.0, active, False, saturation)(0.0, x) < 0.0:
        locked = False  # at its stop, but the muscles pull the knee off it at once

    grid = setup.grid
    stops = setup.stops
    max_step = setup.max_step
    if math.isfinite(setup.disturbance.max_step) and setup.breakpoints.size > 2000:
        stops = sorted({*setup.delay_breakpoints.tolist(), setup.duration})  # a long
        # measured profile: the step is capped at its sample spacing instead
    duration = setup.duration
    times: list[np.ndarray] = []
    states: list[np.ndarray] = []
    locked_flags: list[np.ndarray] = []
    t = 0.0
    status, message = "completed", outcome_message("completed", duration, setup)
    fell, fall_time, fall_reason = False, None, None
    switch_times: list[float] = []

    if setup.fall_at_start is not None:
        times.append(np.array([0.0]))
        states.append(x[None, :])
        locked_flags.append(np.array([locked]))
        fell, fall_time, fall_reason = True, 0.0, setup.fall_at_start
        status = "fell"
        message = outcome_message("fell", 0.0, setup, fall_reason=fall_reason)
        t = duration  # nothing to integrate

    rate_jumps = [0.0]  # when the rates jump: the start (a velocity step), knee impacts
    feedback_jumps: list[float] = []  # … and when the delayed feedback feels it (+ τ, > 0)

    def jumped_event(listed, t: float, x: np.ndarray) -> int | None:
        """The first event of ``listed`` whose function jumps across zero in its direction at
        t, where the delayed feedback passes a jump of the rates (t − τ = 0, the velocity step,
        or a knee impact); None if none does.

        Such a jump is no crossing inside a segment (at τ the first segment ends seeing the
        state before the run, the next starts seeing the state after the step), so without
        this check a moment that jumps past its limit (or a pull-only pair's torque that
        jumps below 0, or a centre of pressure that jumps past the toe) is missed. The
        compiled engine sees the jump at the end of its step landing on t.
        """
        if history is None:
            return None
        tol = 1e-12 * max(1.0, t)
        rate_jumps[:] = [s for s in rate_jumps if s >= t - delay - tol]  # (the past ones go)
        source = next((s for s in rate_jumps if abs(t - delay - s) <= tol), None)
        if source is None:
            return None
        sat_now = saturation.copy() if limits is not None else None
        left = history.left(source)[:m]
        for e, (k, j, sd) in enumerate(listed):
            before_jump = event_function(k, j, sd, active, locked, sat_now,
                                         feedback=lambda tt, yy: left)(t, x)
            after_jump = event_function(k, j, sd, active, locked, sat_now)(t, x)
            if (before_jump <= 0.0 < after_jump if ev.EVENT_DIRECTION[k] > 0
                    else before_jump >= 0.0 > after_jump):
                return e
        return None

    while t < duration:
        listed = ev.segment_events(slots, saturation, active, locked)
        e = jumped_event(listed, t, x)
        if e is not None:  # an event at τ itself (x and t stay)
            kind, j, sd = listed[e]
            seg_end = t
        else:
            feedback_jumps[:] = [s for s in feedback_jumps if s > t + 1e-12]
            t_end = min(next((s for s in stops if s > t + 1e-12), duration),
                        min(feedback_jumps, default=duration))
            if delay > 0:
                t_end = min(t_end, t + delay)  # the method of steps: the past is already known
            sat = saturation.copy() if limits is not None else None

            def rhs(tt, xx, _active=active, _locked=locked, _sat=sat):
                fb = feedback(tt, xx)
                acc = sw.model_response(model, tt, xx[:m], fb, _active, _locked, _sat,
                                        filter_part(xx))[1]
                if not filters:
                    return np.concatenate([xx[n:], acc])
                return np.concatenate([xx[n:m], acc,
                                       sw.torque_feedback_rate(model, tt, fb, _active, xx[m:])])

            events = []
            for k, j, sd in listed:
                g = event_function(k, j, sd, active, locked, sat)
                g.terminal = True
                g.direction = int(ev.EVENT_DIRECTION[k])
                events.append(g)

            try:
                sol = solve_ivp(rhs, (t, t_end), x, method=solver, rtol=setup.rtol,
                                atol=setup.atol, dense_output=True, events=events,
                                max_step=max_step)
            except (ValueError, np.linalg.LinAlgError, FloatingPointError) as exc:
                status = "failed"
                message = outcome_message("failed", t, setup,
                                          detail=f"integrator error at t = {t:.6g} s: {exc}")
                break
            seg_end = float(sol.t[-1])
            if history is not None:
                history.add(t, seg_end, sol.sol)
            last_segment = sol.status == 0 and t_end >= duration
            sel = (grid >= t - 1e-12) & ((grid <= seg_end + 1e-12)
                                          if last_segment or sol.status == 1
                                          else (grid < seg_end - 1e-12))
            if sel.any():
                times.append(grid[sel])
                states.append(sol.sol(grid[sel]).T)
                locked_flags.append(np.full(int(sel.sum()), locked))
                grid = grid[~sel | (grid > seg_end + 1e-12)]
                grid = grid[grid > seg_end - 1e-12] if sol.status == 1 else grid
            if sol.status == -1:
                status = "failed"
                message = outcome_message(
                    budget.spent or "failed", seg_end, setup, method=method,
                    detail=f"integrator failed at t = {seg_end:.6g} s: {sol.message}")
                break
            x = sol.y[:, -1].copy()
            if not np.all(np.isfinite(x)):
                status = "failed"
                message = outcome_message("non-finite", seg_end, setup)
                break
            if sol.status != 1:
                t = t_end
                continue
            fired = [k for k, te in enumerate(sol.t_events) if len(te) and
                     abs(te[-1] - seg_end) <= 1e-12 * max(1.0, seg_end)]
            if not fired:
                fired = [k for k, te in enumerate(sol.t_events) if len(te)]
            e = fired[0]
            kind, j, sd = listed[e]
            x = sol.y_events[e][-1].copy()
            t = seg_end
        if ev.EVENT_ENDS_RUN[kind]:
            # the state at the fall itself closes the series (it is off the sample grid)
            if not times or times[-1][-1] < seg_end - 1e-12:
                times.append(np.array([seg_end]))
                states.append(x[None, :])
                locked_flags.append(np.array([locked]))
            fell, fall_time, status = True, seg_end, "fell"
            fall_reason = ev.fall_message(
                kind, j, max_link_angle=fall.max_link_angle,
                toe=bos.toe if bos is not None else 0.0,
                heel=bos.heel if bos is not None else 0.0)
            message = outcome_message("fell", seg_end, setup, fall_reason=fall_reason)
            break
        switch_times.append(seg_end)
        if len(switch_times) > setup.max_switches:
            status = "failed"
            message = outcome_message("chattering", seg_end, setup)
            break
        switched_state, active, saturation, locked = sw.apply_switch(
            model, kind, j, sd, x[:m], feedback(seg_end, x), active, saturation, locked)
        x = np.concatenate([switched_state, x[m:]])
        if kind == ev.KNEE_HITS_STOP and delay > 0:  # the muscles feel the impact τ later,
            rate_jumps.append(seg_end)  # its derivatives 2τ, … later
            feedback_jumps.extend(seg_end + k * delay
                                  for k in range(1, DELAY_BREAKPOINT_MULTIPLES + 1))

    if not times:  # the run ended before its first sample: the series is its initial state
        times.append(np.array([0.0]))
        states.append(np.concatenate([setup.x0, np.zeros(filters)])[None, :])
        locked_flags.append(np.array([setup.locked0]))
    time = np.concatenate(times)
    state = np.concatenate(states, axis=0)
    filter_states = state[:, m:] if filters else None
    state = state[:, :m]
    feedback_states = None
    if history is not None:
        feedback_states = np.array([history(tk - delay)[:m] for tk in time])
    lock = np.concatenate(locked_flags)
    theta, omega = state[:, :n].copy(), state[:, n:].copy()
    for arr in (time, theta, omega):
        arr.setflags(write=False)
    derived = derived_series(setup, time, state, feedback_states, lock, filter_states)
    return SimulationResult(
        time=time, theta=theta, omega=omega, pair_names=tuple(muscles.names), status=status,
        message=message, fell=fell, fall_time=fall_time, fall_reason=fall_reason,
        switch_times=tuple(switch_times), description=setup.description, derived=derived,
        stimulus=stimulus_timing(setup.disturbance, setup.tilt, setup.motor_noise,
                                 setup.visual_tilt),
    )
