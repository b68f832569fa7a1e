"""What a run's outcome was, in one of five words, stated once for runs and sweep rows.

A run's perturbation is either *transient* (a velocity step, a pulse, a ramp-and-hold, a
measured profile, a raised-cosine or measured tilt: it ends, at :attr:`StimulusTiming.end`)
or *sustained* (a periodic tilt or platform motion, a PRTS, motor noise: it lasts the whole
run). :func:`stimulus_timing` says which; :func:`check_starts_within` refuses a transient
one that starts only after the run ends.

* ``recovered``: a transient run completed, and at its last sample every |θ_i| is within
  :data:`UPRIGHT_BAND` of upright and every |θ̇_i| within :data:`REST_RATE`; the settling
  time is counted from the end of the perturbation (the end of the platform's acceleration:
  a ramp-and-hold's stop, a pulse's end, a measured profile's last sample; the end of a
  tilt's ramp; 0 for a velocity step at t = 0) to the last sample after it at which some
  |θ_i| was outside the band (0 if none was). A run with no perturbation at all that starts
  at rest upright and stays in the band says so ("no perturbation: …").
* ``not recovered``: a transient run completed but ended outside that band of upright, or
  still moving, or ended before its perturbation did (recovery is measured only within the
  run); the final lean max |θ_i| [rad] and rate max |θ̇_i| [rad/s] say how far.
* ``steady sway``: a sustained run completed. It has no settling time; its sway is the RMS
  (about upright, 0) and the peak |·| of each link angle θ_i [rad] and of the centre of
  pressure [m] over the steady part (:meth:`StimulusTiming.steady_start`: after the first
  stimulus cycle, or the second half of a run shorter than two cycles or of a stimulus
  without a cycle).
* ``fell``: a fall criterion fired; its reason and time.
* ``failed``: the integration failed; its message.

:func:`classify` is the rule; :class:`Outcome` the frozen record of one run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["UPRIGHT_BAND", "REST_RATE", "OUTCOMES", "Outcome", "SteadySway", "StimulusTiming",
           "stimulus_timing", "check_starts_within", "steady_sway", "classify",
           "classify_rows", "profile_motion_end"]

#: Half-width of the band about upright a recovered run ends in (and of the settling time). [rad]
UPRIGHT_BAND = 0.01
#: Largest |θ̇_i| at the end of a recovered run. [rad/s]
REST_RATE = 0.05
#: The five outcomes.
OUTCOMES = ("recovered", "not recovered", "steady sway", "fell", "failed")


@dataclass(frozen=True)
class StimulusTiming:
    """When a run's perturbation acts (module notes).

    Attributes
    ----------
    sustained : bool
        The stimulus lasts the whole run (periodic, PRTS, motor noise).
    end : float
        End of a transient perturbation (settling is counted from it); ``inf`` when
        sustained. [s]
    period : float or None
        Cycle of a sustained periodic stimulus (a PRTS's cycle, a sine's period, a sum of
        sines' longest period); None without one. [s]
    what : str
        The sustained stimulus in a few words ("" for a transient one).
    perturbed : bool
        The run has a perturbation at all (False: no platform motion, tilt or noise).
    """

    sustained: bool = False
    end: float = 0.0
    period: float | None = None
    what: str = ""
    perturbed: bool = True

    def steady_start(self, duration: float) -> float:
        """Start of the steady part of a sustained run of ``duration`` [s]: one stimulus
        cycle, or half the run if that is shorter than two cycles or the stimulus has no
        cycle (then also after a transient part's end, when one ends before it). [s]"""
        duration = float(duration)
        if self.period is not None and duration >= 2.0 * self.period:
            start = float(self.period)
        else:
            start = 0.5 * duration
        if math.isfinite(self.end) and self.end < duration:
            start = max(start, self.end)
        return start


def stimulus_timing(disturbance=None, tilt=None, motor_noise=None,
                    visual_tilt=None) -> StimulusTiming:
    """The :class:`StimulusTiming` of a run's platform ``disturbance``
    (:mod:`posturelab.model.platform`), ``tilt`` and ``visual_tilt``
    (:mod:`posturelab.model.tilt`) and ``motor_noise`` (any not None is sustained)."""
    from ..model import platform as pf
    from ..model import tilt as tl

    ends, periods, what, parts = [0.0], [], [], []

    def add(part) -> None:
        if part is None or isinstance(part, pf.NoDisturbance):
            return
        parts.append(part)
        if isinstance(part, pf.VelocityStep):
            return
        if isinstance(part, pf.CombinedDisturbance):
            for q in part.parts:
                add(q)
        elif isinstance(part, pf.SumOfSines):
            periods.append(1.0 / min(part.frequencies))
            what.append("sum of sines")
        elif isinstance(part, pf.MeasuredProfile):
            ends.append(profile_motion_end(part))
        elif isinstance(part, tl.SineTilt):
            periods.append(1.0 / part.frequency)
            what.append("sine tilt")
        elif isinstance(part, tl.PRTSTilt):
            periods.append(part.cycle)
            what.append("PRTS tilt")
        elif isinstance(part, tl.MeasuredTilt):
            ends.append(float(part.time[-1]))
        elif hasattr(part, "start") and hasattr(part, "duration"):  # pulses, ramps
            ends.append(float(part.start) + float(part.duration))
        else:  # an unknown kind: treated as lasting the whole run
            what.append(type(part).__name__)

    add(disturbance)
    add(tilt)
    surface = len(what)
    add(visual_tilt)
    what[surface:] = [f"visual-scene {w}" for w in what[surface:]]
    if motor_noise is not None:
        what.append("motor noise")
    if what:
        return StimulusTiming(True, math.inf, max(periods) if periods else None,
                              ", ".join(what))
    return StimulusTiming(False, max(ends), perturbed=bool(parts) or motor_noise is not None)


def profile_motion_end(profile) -> float:
    """When a measured platform profile's motion ends: the sample after its last sample of
    non-zero acceleration (x or y), where the linearly interpolated acceleration has come
    back to zero for good; the last sample if that one is non-zero, the first if none is
    (trailing zeros, a recording's quiet tail, are not part of the perturbation). [s]"""
    import numpy as np

    moving = np.asarray(profile.acceleration_x) != 0
    if profile.acceleration_y is not None:
        moving |= np.asarray(profile.acceleration_y) != 0
    t = np.asarray(profile.time, dtype=float)
    if not moving.any():
        return float(t[0])
    last = int(np.flatnonzero(moving)[-1])
    return float(t[min(last + 1, t.size - 1)])


def _start(part) -> tuple[str, float] | None:
    """A transient part's name and start [s]; None for a part that acts from t = 0."""
    from ..model import platform as pf
    from ..model import tilt as tl

    source = f" ({part.source})" if getattr(part, "source", "") else ""
    if isinstance(part, pf.MeasuredProfile):
        return f"the platform profile{source}", float(part.time[0])
    if isinstance(part, tl.MeasuredTilt):
        return f"the tilt profile{source}", float(part.time[0])
    if isinstance(part, tl.RaisedCosineTilt):
        return "the raised-cosine tilt", float(part.start)
    if isinstance(part, pf.HalfSinePulse):
        return "the half-sine pulse", float(part.start)
    if isinstance(part, pf.RampAndHold):
        return "the ramp-and-hold", float(part.start)
    return None


def check_starts_within(disturbance, tilt, duration: float) -> None:
    """Refuse a platform ``disturbance`` or ``tilt`` part that starts at or after the end of
    a run of ``duration`` [s] (nothing of it would act), in one line naming its start.

    Raises
    ------
    ParameterError
    """
    from ..errors import ParameterError
    from ..model import platform as pf

    parts = list(disturbance.parts) if isinstance(disturbance, pf.CombinedDisturbance) \
        else [disturbance]
    for part in [*parts, tilt]:
        found = _start(part) if part is not None else None
        if found is not None and found[1] >= duration:
            name, start = found
            when = "after" if start > duration else "just as"
            raise ParameterError(f"{name} starts at {start:g} s, {when} the run ends at "
                                 f"{duration:g} s (lengthen the run or start it earlier)")


@dataclass(frozen=True)
class SteadySway:
    """The sway of a sustained run over its steady part.

    Attributes
    ----------
    start : float
        Start of the steady part (:meth:`StimulusTiming.steady_start`). [s]
    end : float
        Its end, the last sample. [s]
    rms_theta, peak_theta : tuple of float
        sqrt(mean θ_i²) and max |θ_i| over the steady samples, per link. [rad]
    rms_cop, peak_cop : float or None
        The same of the centre of pressure (relative to the ankle); None without one. [m]
    """

    start: float
    end: float
    rms_theta: tuple[float, ...]
    peak_theta: tuple[float, ...]
    rms_cop: float | None = None
    peak_cop: float | None = None

    def to_dict(self) -> dict:
        """Plain-Python form (times [s], angles [rad], centre of pressure [m]); a value that
        is not finite (a centre of pressure undefined where the foot is unloaded) is None."""
        def finite(v):
            return v if v is not None and math.isfinite(v) else None

        return {"steady_from": self.start,
                "steady_rms_theta": [finite(v) for v in self.rms_theta],
                "steady_peak_theta": [finite(v) for v in self.peak_theta],
                "steady_rms_cop": finite(self.rms_cop), "steady_peak_cop": finite(self.peak_cop)}

    @property
    def text(self) -> str:
        """The sway in words, with units."""
        def pairs(rms, peak):
            return ", ".join(f"θ{i + 1} {r:.4g}/{p:.4g}" for i, (r, p) in
                             enumerate(zip(rms, peak, strict=True)))
        cop = ("" if self.rms_cop is None else
               f"; centre of pressure {self.rms_cop:.4g}/{self.peak_cop:.4g} m")
        return (f"RMS/peak over {self.start:.4g}–{self.end:.4g} s: "
                f"{pairs(self.rms_theta, self.peak_theta)} rad{cop}")


def steady_sway(time, theta, centre_of_pressure=None, start: float = 0.0) -> SteadySway:
    """RMS and peak of ``theta`` [rad] (T, N) and ``centre_of_pressure`` [m] (T,) over the
    samples at ``time`` [s] (T,) >= ``start`` [s] (all samples if none is)."""
    time = np.asarray(time, dtype=float)
    theta = np.asarray(theta, dtype=float).reshape(time.size, -1)
    keep = time >= start - 1e-12
    if not keep.any():
        keep[:] = True
    th = theta[keep]
    rms = tuple(float(v) for v in np.sqrt(np.mean(th ** 2, axis=0)))
    peak = tuple(float(v) for v in np.abs(th).max(axis=0))
    rms_cop = peak_cop = None
    if centre_of_pressure is not None:
        cop = np.asarray(centre_of_pressure, dtype=float)[keep]
        rms_cop, peak_cop = float(np.sqrt(np.mean(cop ** 2))), float(np.abs(cop).max())
    return SteadySway(float(time[keep][0]), float(time[keep][-1]), rms, peak, rms_cop, peak_cop)


@dataclass(frozen=True)
class Outcome:
    """The outcome of one run (module notes).

    Attributes
    ----------
    kind : {"recovered", "not recovered", "steady sway", "fell", "failed"}
    settling_time : float or None
        From the end of the perturbation to the last sample after it outside the upright
        band; None unless recovered. [s]
    fall_time : float or None
        [s]
    fall_reason : str or None
    final_lean : float
        max |θ_i| at the last sample. [rad]
    final_rate : float
        max |θ̇_i| at the last sample. [rad/s]
    message : str
        The outcome in words.
    perturbation_end : float
        End of a transient perturbation (a measured platform profile's: the sample after
        its last non-zero acceleration, :func:`profile_motion_end`); ``inf`` for a
        sustained one. [s]
    steady : SteadySway or None
        The steady sway of a sustained run that completed; None otherwise.
    """

    kind: str
    settling_time: float | None
    fall_time: float | None
    fall_reason: str | None
    final_lean: float
    final_rate: float
    message: str
    perturbation_end: float = 0.0
    steady: SteadySway | None = None

    def to_dict(self) -> dict:
        """Plain-Python form (times [s], lean [rad], rate [rad/s], centre of pressure [m];
        ``perturbation_end`` None for a sustained stimulus; the ``steady_*`` keys None
        unless the outcome is a steady sway)."""
        steady = (self.steady.to_dict() if self.steady is not None else
                  dict.fromkeys(("steady_from", "steady_rms_theta", "steady_peak_theta",
                                 "steady_rms_cop", "steady_peak_cop")))
        return {"outcome": self.kind, "settling_time": self.settling_time,
                "fall_time": self.fall_time, "fall_reason": self.fall_reason,
                "final_lean": self.final_lean, "final_rate": self.final_rate,
                "outcome_message": self.message,
                "perturbation_end": (self.perturbation_end if math.isfinite(self.perturbation_end)
                                     else None), **steady}


def classify_rows(status: np.ndarray, settling_time: np.ndarray, final_state: np.ndarray,
                  sustained=False) -> np.ndarray:
    """The outcome word of many runs: ``status`` ("completed", "fell", "failed") (M,),
    ``settling_time`` [s] (M,) (NaN: never settled), ``final_state`` [rad, rad/s] (M, 2N),
    ``sustained`` (bool, or (M,)): the stimulus lasts the whole run (a completed run is then
    a steady sway). Returns an array of str, (M,)."""
    status = np.asarray(status)
    final_state = np.asarray(final_state, dtype=float)
    n = final_state.shape[-1] // 2
    lean = np.abs(final_state[..., :n]).max(axis=-1)
    rate = np.abs(final_state[..., n:]).max(axis=-1)
    at_rest = (lean <= UPRIGHT_BAND) & (rate <= REST_RATE) & np.isfinite(
        np.asarray(settling_time, dtype=float))
    completed = np.where(np.asarray(sustained, dtype=bool), "steady sway",
                         np.where(at_rest, "recovered", "not recovered"))
    return np.where(status == "failed", "failed", np.where(status == "fell", "fell", completed))


def classify(status: str, settling_time: float | None, final_state, *, fall_time=None,
             fall_reason=None, message: str = "", timing: StimulusTiming | None = None,
             steady: SteadySway | None = None, run_end: float | None = None,
             started_at_rest: bool = False) -> Outcome:
    """The :class:`Outcome` of one run (arguments as for :func:`classify_rows`, one run;
    ``message``: the run's own words, kept for a failure; ``timing``: the stimulus's
    (a transient one ending at 0 if None); ``steady``: the sway over the steady part of a
    sustained run; ``run_end``: the run's last time [s] (a run that ends before its
    transient perturbation does is not recovered: recovery is measured within the run);
    ``started_at_rest``: the run started upright at rest)."""
    timing = StimulusTiming() if timing is None else timing
    final_state = np.asarray(final_state, dtype=float)
    n = final_state.size // 2
    lean = float(np.abs(final_state[:n]).max())
    rate = float(np.abs(final_state[n:]).max())
    cut_short = (run_end is not None and not timing.sustained
                 and timing.end > float(run_end) + 1e-9)
    if cut_short:
        settling_time = None
    kind = str(classify_rows(np.array([status]), np.array(
        [np.nan if settling_time is None else settling_time]), final_state[None],
        timing.sustained)[0])
    if kind == "recovered" and not timing.perturbed and started_at_rest \
            and settling_time == 0:
        words = (f"recovered (no perturbation: started at rest upright and stayed within "
                 f"±{UPRIGHT_BAND:g} rad)")
    elif kind == "not recovered" and cut_short:
        words = (f"not recovered: the run ended at {float(run_end):.4g} s, before the "
                 f"perturbation did (at {timing.end:.4g} s): {lean:.4g} rad from upright, moving "
                 f"at up to {rate:.4g} rad/s (run past {timing.end:.4g} s to measure recovery)")
    elif kind == "recovered" and timing.end > 0:
        words = (f"recovered: within ±{UPRIGHT_BAND:g} rad of upright {settling_time:.3f} s "
                 f"after the perturbation ended at {timing.end:.4g} s")
    elif kind == "recovered":
        words = f"recovered: within ±{UPRIGHT_BAND:g} rad of upright from {settling_time:.3f} s"
    elif kind == "not recovered":
        words = (f"not recovered: ended {lean:.4g} rad from upright, moving at up to "
                 f"{rate:.4g} rad/s (recovered means within ±{UPRIGHT_BAND:g} rad and "
                 f"{REST_RATE:g} rad/s)")
    elif kind == "steady sway":
        sway = f": {steady.text}" if steady is not None else ""
        words = (f"steady sway under a sustained stimulus ({timing.what}; no settling time)"
                 f"{sway}")
    elif kind == "fell":
        words = message or f"fell at t = {fall_time} s: {fall_reason}"
    else:
        words = f"failed: {message}" if message else "failed"
    return Outcome(kind, settling_time if kind == "recovered" else None,
                   fall_time if kind == "fell" else None,
                   fall_reason if kind == "fell" else None, lean, rate, words,
                   timing.end, steady if kind == "steady sway" else None)
