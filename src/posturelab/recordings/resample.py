"""Putting a recording with an uneven (or gappy) time column onto a uniform grid.

Motion-capture systems and lab acquisition software often log a time column whose step
jitters (e.g. 0.0107–0.0117 s at a nominal 90 Hz) or drop samples; the FRF estimate
(:mod:`posturelab.frequency.estimate`) needs a uniform sample rate. :func:`resample_uniform`
interpolates each column onto ``t0 + k / rate`` by a **cubic spline** (scipy's
``CubicSpline``, not-a-knot ends) through the samples it has, and refuses a **gap** — a
step of the time column, or a run of missing (NaN) samples in one column — longer than
``max_gap`` [s] (default :data:`MAX_GAP_STEPS` median steps), naming where it is. It says
what it did (:class:`ResampleReport`).

The grid covers the **whole record**: each sample stands for the interval
``[t_k, t_k + step)`` (``step`` the median step of the time column), so a record of S samples
spans ``t_0 … t_last + step``, a duration ``D = t_last − t_0 + step``, and is resampled to
``round(D · rate)`` samples ``t_0 + k / rate`` — a 60 s recording at 50 Hz gives 6,000
samples at 100 Hz (three whole 20 s cycles), not 5,999. The grid points past ``t_last``
(fewer than one input step, e.g. one point going from 50 Hz to 100 Hz) are the cubic
spline's end polynomial continued (its extrapolation over less than one step), counted in
:attr:`ResampleReport.extrapolated`.

Accuracy (tests/test_recordings.py): a sinusoid of frequency f sampled at f_s with a
jittered clock is reproduced by the spline with an error of order (2πf/f_s)⁴ of its
amplitude — at f = 2.2 Hz (the highest band of the 80-state PRTS protocol) and f_s ≈ 90 Hz
about 1e-5 — far below the scatter of a measured FRF.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import float_in_range
from ..errors import DataFileError

__all__ = ["ResampleReport", "resample_uniform", "MAX_GAP_STEPS", "MAX_SAMPLES_OUT",
           "INTERPOLATION", "RATE_RANGE", "uniform_step", "record_duration",
           "samples_over"]

#: Longest gap accepted by default, in median steps of the time column. [-]
MAX_GAP_STEPS = 3.0
#: The interpolation, as said in reports.
INTERPOLATION = "cubic spline (not-a-knot), scipy.interpolate.CubicSpline"
#: Sample rates a recording may be resampled to. [Hz]
RATE_RANGE = (1.0, 100_000.0)
#: Most samples a resampled column may have (bounds memory: a long file at a high rate). [-]
MAX_SAMPLES_OUT = 2_000_000
#: Relative step variation under which a time column counts as uniform. [-]
UNIFORM_TOLERANCE = 1e-6


@dataclass(frozen=True)
class ResampleReport:
    """What :func:`resample_uniform` did.

    Attributes
    ----------
    rate : float
        The new, uniform sample rate. [Hz]
    interpolation : str
        How values between samples were found.
    samples_in, samples_out : int
        Samples before and after. [-]
    step_min, step_median, step_max : float
        The input time column's steps. [s]
    max_gap : float
        The longest gap accepted. [s]
    filled : int
        Missing (NaN) samples filled by the interpolation, over all columns. [-]
    extrapolated : int
        Output samples past the last input time (within its interval; fewer than one input
        step), continued by the spline's end polynomial. [-]
    """

    rate: float
    interpolation: str
    samples_in: int
    samples_out: int
    step_min: float
    step_median: float
    step_max: float
    max_gap: float
    filled: int
    extrapolated: int = 0

    def text(self) -> str:
        """One line saying what was done."""
        filled = f"; {self.filled} missing sample(s) filled" if self.filled else ""
        if self.extrapolated:
            filled += (f"; the last {self.extrapolated} sample(s), within the last input "
                       "sample's interval, continue the spline's end")
        return (f"resampled {self.samples_in} samples (steps {self.step_min:.6g} … "
                f"{self.step_max:.6g} s, median {self.step_median:.6g} s) to "
                f"{self.samples_out} at {self.rate:g} Hz by {self.interpolation}; gaps up to "
                f"{self.max_gap:.4g} s accepted{filled}")

    def to_dict(self) -> dict:
        """The report as JSON-ready values."""
        return {"rate_hz": self.rate, "interpolation": self.interpolation,
                "samples_in": self.samples_in, "samples_out": self.samples_out,
                "step_min_s": self.step_min, "step_median_s": self.step_median,
                "step_max_s": self.step_max, "max_gap_s": self.max_gap,
                "filled": self.filled, "extrapolated": self.extrapolated}


def uniform_step(time: np.ndarray) -> float | None:
    """The step of a uniform time column [s], or None when it is not uniform."""
    t = np.asarray(time, dtype=float)
    dt = np.diff(t)
    step = float(np.median(dt)) if dt.size else 0.0
    if not step > 0:
        return None
    tol = UNIFORM_TOLERANCE * step + 1e-12 * float(np.abs(t).max())
    return step if float(np.max(np.abs(dt - step))) <= tol else None


def resample_uniform(time: np.ndarray, columns: dict[str, np.ndarray], rate: float, *,
                     max_gap: float | None = None, what: str = "the recording",
                     gap_words: str | None = None
                     ) -> tuple[np.ndarray, dict[str, np.ndarray], ResampleReport]:
    """Columns sampled at (uneven) ``time`` interpolated onto a uniform grid.

    Parameters
    ----------
    time : numpy.ndarray, shape (S,)
        Strictly increasing sample times. [s]
    columns : dict of str -> numpy.ndarray, shape (S,)
        Values at those times; NaN marks a missing sample (filled when its gap is short).
        [any unit; kept]
    rate : float
        The new sample rate. [Hz]
    max_gap : float, optional
        Longest gap accepted: a step of ``time``, or the span between the valid samples
        around a run of NaN. [s] (default :data:`MAX_GAP_STEPS` × the median step)
    what : str
        Names the data in messages.
    gap_words : str, optional
        What the limit is, in messages (default: "3 median steps" or "the given maximum
        gap").

    Returns
    -------
    (numpy.ndarray, dict, ResampleReport)
        The new times ``time[0] + k / rate``, ``k < round(D · rate)`` with
        ``D = time[-1] − time[0] + median step`` (the whole record, the last sample's
        interval included) [s], each column on them, and what was done.

    Raises
    ------
    DataFileError
        Times not strictly increasing, a gap longer than ``max_gap`` (its time named), a
        column with fewer than 4 valid samples, more than :data:`MAX_SAMPLES_OUT` samples
        out.
    """
    from scipy.interpolate import CubicSpline

    rate = float_in_range("resample rate [Hz]", rate, *RATE_RANGE, unit="Hz")
    t = np.asarray(time, dtype=float)
    if t.ndim != 1 or t.size < 4:
        raise DataFileError(f"{what}: needs at least 4 samples to resample, has {t.size}")
    if not np.all(np.isfinite(t)):
        raise DataFileError(f"{what}: the time column has a missing or non-finite value")
    dt = np.diff(t)
    bad = np.flatnonzero(dt <= 0)
    if bad.size:
        i = int(bad[0])
        raise DataFileError(f"{what}: the time column does not increase at t = {t[i + 1]:g} s "
                            f"(after {t[i]:g} s); sort it or drop repeated samples")
    median = float(np.median(dt))
    limit = MAX_GAP_STEPS * median if max_gap is None else float_in_range(
        "max gap [s]", max_gap, 0.0, 1e6, unit="s")
    worst = int(np.argmax(dt))
    if dt[worst] > limit:
        raise DataFileError(f"{what}: a gap of {dt[worst]:.4g} s in the time column at "
                            f"t = {t[worst]:g} … {t[worst + 1]:g} s, longer than the "
                            f"{limit:.4g} s accepted ({gap_words or _limit_words(max_gap)})")
    duration = record_duration(t)
    n_out = samples_over(duration, rate)
    if n_out > MAX_SAMPLES_OUT:
        raise DataFileError(f"{what}: {duration:g} s at {rate:g} Hz is {n_out:,} samples; "
                            f"at most {MAX_SAMPLES_OUT:,} are made (a lower --resample rate)")
    grid = t[0] + np.arange(n_out) / rate
    extrapolated = int(np.count_nonzero(grid > t[-1] + 1e-9 * median))
    out, filled = {}, 0
    for name, values in columns.items():
        v = np.asarray(values, dtype=float)
        ok = np.isfinite(v)
        if ok.sum() < 4:
            raise DataFileError(f"{what}: column {name!r} has fewer than 4 valid samples")
        tv = t[ok]
        spans = np.concatenate(([tv[0] - t[0]], np.diff(tv), [t[-1] - tv[-1]]))
        k = int(np.argmax(spans))
        if spans[k] > limit:
            start = t[0] if k == 0 else tv[k - 1]
            end = t[-1] if k == tv.size else tv[k]
            raise DataFileError(f"{what}: column {name!r} is missing for {spans[k]:.4g} s at "
                                f"t = {start:g} … {end:g} s, longer than the {limit:.4g} s "
                                f"accepted ({gap_words or _limit_words(max_gap)})")
        filled += int((~ok).sum())
        out[name] = CubicSpline(tv, v[ok])(grid)
    report = ResampleReport(rate=rate, interpolation=INTERPOLATION, samples_in=int(t.size),
                            samples_out=int(n_out), step_min=float(dt.min()),
                            step_median=median, step_max=float(dt.max()), max_gap=limit,
                            filled=filled, extrapolated=extrapolated)
    return grid, out, report


def record_duration(time: np.ndarray) -> float:
    """The duration a record of samples at ``time`` covers [s]: from the first sample to
    the end of the last one's interval, ``time[-1] − time[0] + median step``."""
    t = np.asarray(time, dtype=float)
    return float(t[-1] - t[0] + np.median(np.diff(t)))


def samples_over(duration: float, rate: float) -> int:
    """Samples at ``rate`` [Hz] that cover ``duration`` [s]: ``round(duration · rate)``,
    at least 1. [-]"""
    return max(int(round(float(duration) * float(rate))), 1)


def _limit_words(max_gap: float | None) -> str:
    if max_gap is None:
        return f"{MAX_GAP_STEPS:g} median steps"
    return "the given maximum gap"
