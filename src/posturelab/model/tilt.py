"""Support-surface tilt α(t): profiles, and what a tilt does to the muscle pairs.

Convention (docs/conventions.md): α [rad] is positive toes-up and turns the foot about the
ankle axis. In the link-angle sense (from the vertical, positive forward) the foot's angle
is then −α, so a pair that spans the foot (lo = 0) is stretched by θ_hi + α rather than
θ_hi. Its intrinsic part always feels that stretch relative to the foot. Its active
(neural) part feels the sensory-weighted error of the independent-channel model,
W·(θ_hi + α) + (1 − W)·θ_hi = θ_hi + W·α, with W the proprioceptive weight (1: relative to
the foot only; 0: relative to the vertical only). A muscle set without active gains reads
its pair gains as the whole (neural) feedback, so W applies to them. The axis is the
ankle's: the ankle does not move, and the tilt acts on the chain only through the pairs.

A visual-scene tilt v(t) takes the same profiles (:mod:`.visual`: the visual channel).

Profiles (each gives α(t) and α̇(t) for any t; before t = 0 the surface is held at α(0)):

- :class:`SineTilt`: α = A sin(2π f t + φ);
- :class:`RaisedCosineTilt`: a smooth ramp to A over a duration, then held;
- :class:`PRTSTilt`: a pseudorandom ternary sequence (PRTS) of surface velocities from a
  shift register, integrated, repeated cycle after cycle; the named sequences
  (:data:`PRTS_SEQUENCES`, :meth:`PRTSTilt.named`) are posturelab's own 80-state one (the
  default), the Eurobench COMTEST protocol's 80-state one and Peterka 2002's 242-state one,
  each with its source;
- :class:`MeasuredTilt`: sampled α, interpolated by a cubic spline whose derivative gives a
  smooth rate for the viscous terms.

Every profile is a sum of :class:`TiltTerm` (a sine, a raised-cosine ramp, or a piecewise
cubic, possibly periodic), the form both engines evaluate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from .._validation import finite_array, finite_float, float_in_range
from ..errors import ParameterError
from ..parameters import MAX_AXIS_DEPTH, MAX_TILT
from .disturbance import ProfileTerm
from .prts import (  # the sequences (stated in .prts)
    DEFAULT_PRTS,
    PETERKA_2002_CITATION,
    PETERKA_SEED,
    PETERKA_TAPS,
    POSTURELAB_80_SEED,
    POSTURELAB_80_TAPS,
    PRTS_SEQUENCES,
    PRTSSequence,
    get_prts_sequence,
    peterka_register,
    prts_sequence,
)

__all__ = [
    "Tilt",
    "TiltTerm",
    "SineTilt",
    "RaisedCosineTilt",
    "PRTSTilt",
    "MeasuredTilt",
    "prts_sequence",
    "tilt_pair_gains",
    "read_tilt_csv",
    "axis_translation",
    "MAX_AXIS_DEPTH",
    "MAX_TILT",
    "PETERKA_2002_CITATION",
    "PRTSSequence",
    "PRTS_SEQUENCES",
    "DEFAULT_PRTS",
    "get_prts_sequence",
    "PETERKA_TAPS",
    "PETERKA_SEED",
    "peterka_register",
]

# MAX_TILT [rad], the largest |α| a profile may reach: the parameter table's
# MAX_AXIS_DEPTH [m], the deepest tilt axis below the ankle: the parameter table's.



def sine_tilt_formula(t, amplitude, frequency, phase, xp=np):
    """(α, α̇, α̈) of a sine term: α = amplitude · sin(2π · frequency · t + phase) for t >= 0,
    held at its t = 0 value before; over a math namespace ``xp`` (numpy, or sympy when the C
    is generated). [rad], [rad/s], [rad/s²]"""
    w = 2 * math.pi * frequency
    arg = w * xp.maximum(t, 0.0) + phase
    after = t >= 0
    return (amplitude * xp.sin(arg), xp.where(after, amplitude * w * xp.cos(arg), 0.0),
            xp.where(after, -amplitude * w * w * xp.sin(arg), 0.0))


def raised_cosine_tilt_formula(t, amplitude, start, duration, xp=np):
    """(α, α̇, α̈) of a raised-cosine ramp: α = amplitude · (1 − cos(π s))/2 for s = (t −
    start)/duration in [0, 1], 0 before, amplitude after. [rad], [rad/s], [rad/s²]"""
    s = xp.minimum(xp.maximum((t - start) / duration, 0.0), 1.0)
    inside = (t > start) & (t < start + duration)
    k = math.pi / duration
    return (amplitude * 0.5 * (1.0 - xp.cos(math.pi * s)),
            xp.where(inside, amplitude * 0.5 * k * xp.sin(math.pi * s), 0.0),
            xp.where(inside, amplitude * 0.5 * k * k * xp.cos(math.pi * s), 0.0))


def cubic_formula(c0, c1, c2, c3, u):
    """c0 + c1 u + c2 u² + c3 u³ by Horner's rule, with its first and second derivatives in
    u (a piecewise cubic's value on one interval, u = t − knot)."""
    return (c0 + u * (c1 + u * (c2 + u * c3)), c1 + u * (2 * c2 + u * 3 * c3),
            2 * c2 + 6 * u * c3)


@dataclass(frozen=True)
class TiltTerm(ProfileTerm):
    """One term of a tilt profile (the fields of
    :class:`~posturelab.model.platform.ProfileTerm`, amplitude in [rad], and these).

    Attributes
    ----------
    kind : {"sine", "raised-cosine", "ppoly"}
        ``sine``: α = amplitude · sin(2π · frequency · t + phase) for t >= 0 (held at its
        t = 0 value before); ``raised-cosine``: α = amplitude · (1 − cos(π s))/2 for
        s = (t − start)/duration in [0, 1], 0 before, amplitude after; ``ppoly``: a
        piecewise cubic on ``knots`` with ``coefficients`` (c0, c1, c2, c3) per interval in
        powers of (t − knot), held at its end values outside, repeated with ``period``
        when that is > 0.
    knots : numpy.ndarray, shape (K + 1,), optional
        [s]
    coefficients : numpy.ndarray, shape (K, 4), optional
        [rad], [rad/s], [rad/s²], [rad/s³]
    period : float
        0 for a profile that is not repeated. [s]
    """

    knots: np.ndarray | None = None
    coefficients: np.ndarray | None = None
    period: float = 0.0

    def evaluate(self, t) -> tuple[np.ndarray, np.ndarray]:
        """(α, α̇) at ``t`` (any shape). [rad], [rad/s]"""
        return self.kinematics(t)[:2]

    def kinematics(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(α, α̇, α̈) at ``t`` (any shape). [rad], [rad/s], [rad/s²]"""
        t = np.asarray(t, dtype=float)
        if self.kind == "sine":
            return sine_tilt_formula(t, self.amplitude, self.frequency, self.phase)
        if self.kind == "raised-cosine":
            return raised_cosine_tilt_formula(t, self.amplitude, self.start, self.duration)
        # piecewise cubic
        x, c = self.knots, self.coefficients
        tt = t
        if self.period > 0:
            tt = np.where(t >= x[0], x[0] + np.mod(t - x[0], self.period), t)
        inside = (tt >= x[0]) & (tt <= x[-1])
        tc = np.clip(tt, x[0], x[-1])
        k = np.clip(np.searchsorted(x, tc, side="right") - 1, 0, len(c) - 1)
        u = tc - x[k]
        ck = c[k]
        angle, rate, accel = cubic_formula(ck[..., 0], ck[..., 1], ck[..., 2], ck[..., 3], u)
        return angle, np.where(inside, rate, 0.0), np.where(inside, accel, 0.0)


def _check(obj, *fields: tuple[str, str, float, float, str]) -> None:
    """Set each (field, label, low, high, unit) of a frozen profile to its checked float."""
    for field_name, label, low, high, unit in fields:
        object.__setattr__(obj, field_name, float_in_range(
            f"{label} [{unit}]", getattr(obj, field_name), low, high, unit=unit))


class Tilt:
    """A support-surface tilt profile α(t) (base class; see the module notes)."""

    def terms(self) -> tuple[TiltTerm, ...]:
        """The profile as a sum of :class:`TiltTerm`."""
        raise NotImplementedError(type(self).__name__)

    def angle_and_rate(self, t) -> tuple[np.ndarray, np.ndarray]:
        """(α, α̇) at ``t``, the shape of ``t``. [rad], [rad/s]"""
        return self.kinematics(t)[:2]

    def kinematics(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(α, α̇, α̈) at ``t``, the shape of ``t``. [rad], [rad/s], [rad/s²]"""
        t = np.asarray(t, dtype=float)
        out = [np.zeros(t.shape), np.zeros(t.shape), np.zeros(t.shape)]
        for term in self.terms():
            for k, v in enumerate(term.kinematics(t)):
                out[k] = out[k] + v
        return out[0], out[1], out[2]

    @property
    def rate_is_continuous(self) -> bool:
        """α̇ has no jumps after t = 0 (needed to turn about an axis off the ankle)."""
        return True

    def angle(self, t) -> np.ndarray:
        """α(t). [rad]"""
        return self.angle_and_rate(t)[0]

    def rate(self, t) -> np.ndarray:
        """α̇(t). [rad/s]"""
        return self.angle_and_rate(t)[1]

    def breakpoints(self, duration: float) -> tuple[float, ...]:
        """Times in (0, duration) where the rate has a corner or a jump. [s]"""
        return ()

    @property
    def max_step(self) -> float:
        """Largest integrator step that resolves the profile. [s]"""
        return math.inf

    def describe(self) -> str:
        """One line with units."""
        raise NotImplementedError(type(self).__name__)


@dataclass(frozen=True)
class SineTilt(Tilt):
    """α(t) = amplitude · sin(2π · frequency · t + phase).

    Parameters
    ----------
    amplitude : float
        [rad], |amplitude| <= :data:`MAX_TILT`.
    frequency : float
        (0, 1000]. [Hz]
    phase : float
        [rad]
    """

    amplitude: float
    frequency: float
    phase: float = 0.0

    def __post_init__(self) -> None:
        _check(self, ("amplitude", "tilt amplitude", -MAX_TILT, MAX_TILT, "rad"),
               ("frequency", "tilt frequency", 1e-6, 1000.0, "Hz"))
        object.__setattr__(self, "phase", finite_float("tilt phase [rad]", self.phase))

    def terms(self) -> tuple[TiltTerm, ...]:
        return (TiltTerm("sine", amplitude=self.amplitude, frequency=self.frequency,
                         phase=self.phase),)

    @property
    def max_step(self) -> float:
        return 0.05 / self.frequency

    def describe(self) -> str:
        return (f"sine tilt {self.amplitude:g} rad at {self.frequency:g} Hz"
                + (f", phase {self.phase:g} rad" if self.phase else ""))


@dataclass(frozen=True)
class RaisedCosineTilt(Tilt):
    """A smooth tilt to ``amplitude`` over ``duration`` from ``start``, then held:
    α = amplitude · (1 − cos(π (t − start)/duration))/2 on the ramp.

    Parameters
    ----------
    amplitude : float
        [rad], |amplitude| <= :data:`MAX_TILT`.
    duration : float
        Ramp time, > 0. [s]
    start : float
        Ramp start, >= 0. [s]
    """

    amplitude: float
    duration: float
    start: float = 0.0

    def __post_init__(self) -> None:
        _check(self, ("amplitude", "tilt amplitude", -MAX_TILT, MAX_TILT, "rad"),
               ("duration", "tilt duration", 1e-4, 1e4, "s"),
               ("start", "tilt start", 0.0, 1e4, "s"))

    def terms(self) -> tuple[TiltTerm, ...]:
        return (TiltTerm("raised-cosine", amplitude=self.amplitude, start=self.start,
                         duration=self.duration),)

    def breakpoints(self, duration: float) -> tuple[float, ...]:
        return tuple(b for b in (self.start, self.start + self.duration) if 0 < b < duration)

    @property
    def max_step(self) -> float:
        return self.duration / 20

    def describe(self) -> str:
        return (f"raised-cosine tilt to {self.amplitude:g} rad over {self.duration:g} s"
                + (f" from {self.start:g} s" if self.start else ""))


@dataclass(frozen=True)
class PRTSTilt(Tilt):
    """A pseudorandom ternary tilt: the surface velocity takes the sequence's values
    {+v, 0, −v} for ``state_duration`` each, and α is its integral (piecewise linear),
    scaled to the peak-to-peak ``amplitude`` and repeated every cycle.

    Parameters
    ----------
    amplitude : float
        Peak-to-peak tilt (Peterka's convention), (0, 2·MAX_TILT]. [rad]
    state_duration : float
        Time per state, > 0. [s]
    registers, taps, seed
        The shift register (:func:`prts_sequence`). [-]
    """

    amplitude: float
    state_duration: float = 0.25
    registers: int = 4
    taps: tuple[int, ...] = POSTURELAB_80_TAPS
    seed: tuple[int, ...] = POSTURELAB_80_SEED
    _term: TiltTerm = field(init=False, repr=False, compare=False, default=None)

    def __post_init__(self) -> None:
        _check(self, ("amplitude", "PRTS amplitude (peak to peak)", 1e-9, 2 * MAX_TILT, "rad"),
               ("state_duration", "PRTS state duration", 1e-3, 100.0, "s"))
        object.__setattr__(self, "taps", tuple(int(t) for t in self.taps))
        object.__setattr__(self, "seed", tuple(int(s) for s in self.seed))
        velocity = prts_sequence(self.registers, self.taps, self.seed)
        if abs(velocity.sum()) > 0.5:
            raise ParameterError("PRTS taps do not give a zero-mean sequence (the tilt would "
                                 "drift): use a primitive feedback polynomial")
        dt = self.state_duration
        angle = np.concatenate([[0.0], np.cumsum(velocity) * dt])
        span = angle.max() - angle.min()
        scale = self.amplitude / span
        offset = -0.5 * (angle.max() + angle.min()) * scale  # centred on 0 (mean level)
        knots = np.arange(angle.size) * dt
        coefficients = np.zeros((velocity.size, 4))
        coefficients[:, 0] = angle[:-1] * scale + offset
        coefficients[:, 1] = velocity * scale
        object.__setattr__(self, "_term", TiltTerm(
            "ppoly", knots=knots, coefficients=coefficients, period=knots[-1]))

    @property
    def rate_is_continuous(self) -> bool:
        return False

    @classmethod
    def named(cls, name: str = DEFAULT_PRTS, amplitude: float = 0.035) -> PRTSTilt:
        """The named sequence ``name`` (:data:`PRTS_SEQUENCES`, each with its source) at its
        own state duration, peak-to-peak ``amplitude`` [rad]."""
        seq = get_prts_sequence(name)
        return cls(amplitude, seq.state_duration, seq.registers, seq.taps, seq.seed)

    @classmethod
    def peterka_2002(cls, amplitude: float) -> PRTSTilt:
        """Refused: this former name gave posturelab's own 80-state, 20 s sequence, which is
        not Peterka 2002's. Raises ParameterError naming ``named("posturelab-80", A)`` (the
        sequence it gave) and ``named("peterka-2002-242", A)`` (Peterka 2002's)."""
        raise ParameterError(
            "PRTSTilt.peterka_2002 gave posturelab's own 80-state, 20 s sequence, which is not "
            "Peterka 2002's: use PRTSTilt.named('posturelab-80', amplitude) for the same "
            "sequence, or PRTSTilt.named('peterka-2002-242', amplitude) for Peterka 2002's "
            "242-state, 60.5 s one")

    @property
    def sequence_name(self) -> str | None:
        """The name of this register in :data:`PRTS_SEQUENCES` (whatever the state duration),
        None for another register."""
        for seq in PRTS_SEQUENCES.values():
            if (seq.registers, seq.taps, seq.seed) == (self.registers, self.taps, self.seed):
                return seq.name
        return None

    @cached_property
    def velocity_sequence(self) -> np.ndarray:
        """The sequence's values {−1, 0, 1}, one cycle. [-]"""
        return prts_sequence(self.registers, self.taps, self.seed)

    @property
    def cycle(self) -> float:
        """Cycle length. [s]"""
        return float(self._term.period)

    def terms(self) -> tuple[TiltTerm, ...]:
        return (self._term,)

    def breakpoints(self, duration: float) -> tuple[float, ...]:
        dt = self.state_duration
        count = int(math.floor(duration / dt))
        return tuple(k * dt for k in range(1, count + 1) if k * dt < duration)

    @property
    def max_step(self) -> float:
        return self.state_duration

    def describe(self) -> str:
        name = self.sequence_name
        return (f"PRTS tilt {self.amplitude:g} rad peak to peak"
                + (f" ({name})" if name else "") + f", {self.velocity_sequence.size} "
                f"states of {self.state_duration:g} s ({self.cycle:g} s cycle)")


@dataclass(frozen=True)
class MeasuredTilt(Tilt):
    """A sampled tilt, interpolated by a not-a-knot cubic spline (its derivative is the
    rate), held at the end values outside the samples.

    Parameters
    ----------
    time : array_like, shape (S,)
        Strictly increasing, from t >= 0 (a run starts at 0), S >= 4. [s]
    angle : array_like, shape (S,)
        α at those times, |α| <= :data:`MAX_TILT`. [rad]
    source : str
        Where it came from.
    """

    time: np.ndarray
    angle_samples: np.ndarray
    source: str = ""
    _term: TiltTerm = field(init=False, repr=False, compare=False, default=None)

    def __post_init__(self) -> None:
        from scipy.interpolate import CubicSpline

        t = finite_array("tilt time [s]", self.time, (None,))
        if t.size < 4:
            raise ParameterError(f"tilt time [s] must have at least 4 samples, got {t.size}")
        if np.any(np.diff(t) <= 0):
            raise ParameterError("tilt time [s] must be strictly increasing")
        if t[0] < 0:
            raise ParameterError(f"tilt time [s] must start at t >= 0 (a run starts at 0), "
                                 f"got {t[0]:g}")
        a = finite_array("tilt [rad]", self.angle_samples, (t.size,))
        if np.abs(a).max() > MAX_TILT:
            raise ParameterError(f"tilt [rad] must be within ±{MAX_TILT:g} rad, got "
                                 f"{a[np.argmax(np.abs(a))]:g}")
        spline = CubicSpline(t, a)
        coefficients = np.ascontiguousarray(spline.c[::-1].T)  # (K, 4), ascending powers
        for name, arr in (("time", t), ("angle_samples", a)):
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        object.__setattr__(self, "_term", TiltTerm("ppoly", knots=t.copy(),
                                                   coefficients=coefficients))

    def terms(self) -> tuple[TiltTerm, ...]:
        return (self._term,)

    def breakpoints(self, duration: float) -> tuple[float, ...]:
        return tuple(b for b in (float(self.time[0]), float(self.time[-1])) if 0 < b < duration)

    @property
    def max_step(self) -> float:
        return float(np.diff(self.time).min()) * 4

    def describe(self) -> str:
        src = f" from {self.source}" if self.source else ""
        return (f"measured tilt{src}: {self.time.size} samples, "
                f"{self.time[0]:g}–{self.time[-1]:g} s")


def read_tilt_csv(path) -> MeasuredTilt:
    """A measured tilt from a CSV (or Parquet) file with a header row and the columns
    ``time`` [s] and ``tilt`` [rad] (by name; a ``[unit]`` suffix must be that one, or
    ``[deg]``, converted; a column
    named twice is refused; other columns are ignored, so a
    measured platform profile may carry its tilt). The first time is >= 0 (a run starts at
    0; a negative time is refused, not dropped).

    Raises
    ------
    DataFileError
        With the file, line and column of the first problem.
    """
    from pathlib import Path

    from .._files import check_column_unit, csv_rows, read_text
    from .._parquet import is_parquet, parquet_rows
    from ..errors import DataFileError
    from .platform import refuse_named_twice, refuse_time_in_ms

    path = Path(path)
    what = f"tilt profile {str(path)!r}"
    numbered = list(parquet_rows(path, what) if is_parquet(path)
                    else csv_rows(read_text(path, "tilt profile"), what))
    rows = [r for _, r in numbered]
    if len(rows) < 5:
        raise DataFileError(f"tilt profile {str(path)!r} needs a header row and at least 4 "
                            "samples")
    header = [h.split("[")[0].strip().lower() for h in rows[0]]
    header = ["time" if h == "t" else h for h in header]
    for name in ("time", "tilt"):
        if name not in header:
            raise DataFileError(f"tilt profile {str(path)!r} lacks column {name!r}; needs "
                                "time [s] and tilt [rad]")
    refuse_named_twice(what, header, ["time", "tilt"])
    it, ia = header.index("time"), header.index("tilt")
    tilt_scale = 1.0
    for j, unit in ((it, "s"), (ia, "rad")):
        if j == ia and rows[0][j].partition("[")[2].rstrip("] ").strip().lower() == "deg":
            tilt_scale = math.pi / 180.0  # a declared unit is honoured
            continue
        check_column_unit(f"tilt profile {str(path)!r}", rows[0][j], (unit,),
                          "a tilt in rad (or deg, converted) and time in s")
    values = np.empty((len(rows) - 1, 2))
    for row_index, (lineno, r) in enumerate(numbered[1:]):
        for col, j, name in ((0, it, "time"), (1, ia, "tilt")):
            try:
                v = float(r[j])
            except (IndexError, ValueError):
                raise DataFileError(f"tilt profile {str(path)!r} line {lineno}: column "
                                    f"{name!r} is not a number") from None
            if not math.isfinite(v):
                raise DataFileError(f"tilt profile {str(path)!r} line {lineno}: column "
                                    f"{name!r} is not finite")
            values[row_index, col] = v
    refuse_time_in_ms(what, values[:, 0], rows[0][it])
    values[:, 1] *= tilt_scale
    if values[0, 0] < 0:
        raise DataFileError(f"tilt profile {str(path)!r} line {numbered[1][0]}: time "
                            f"{values[0, 0]:g} s is before 0; a profile starts at t >= 0 "
                            "(the run starts at 0)")
    try:
        return MeasuredTilt(values[:, 0], values[:, 1], source=path.name)
    except ParameterError as exc:
        raise DataFileError(f"tilt profile {str(path)!r}: {exc}") from None


def tilt_pair_gains(split_gains: np.ndarray, spans_foot: np.ndarray, delay,
                    proprioceptive_weight) -> np.ndarray:
    """Pair gains on the tilt, (…, 4, P): on α(t), α̇(t), α(t − τ), α̇(t − τ).

    A pair that spans the foot feels α in its intrinsic part and W·α in its active part
    (module notes); other pairs feel no tilt.

    Parameters
    ----------
    split_gains : numpy.ndarray, shape (..., 4, P)
        The gains split as with a delay (:func:`posturelab.model.muscles.feedback_gains`
        for any τ > 0): intrinsic k, l, active k, l. [N·m/rad], [N·m·s/rad]
    spans_foot : numpy.ndarray of bool, shape (P,)
    delay : float or array_like, shape (...)
        τ. [s]
    proprioceptive_weight : float or array_like, shape (...)
        W in [0, 1]. [-]

    Returns
    -------
    numpy.ndarray, shape (..., 4, P)
        [N·m/rad], [N·m·s/rad], [N·m/rad], [N·m·s/rad]
    """
    from .gains import (  # (loaded here: a tilt's profile alone does not need them)
        DELAYED_STIFFNESS,
        DELAYED_VISCOSITY,
        IMMEDIATE_STIFFNESS,
        IMMEDIATE_VISCOSITY,
    )

    g = np.asarray(split_gains, dtype=float) * np.asarray(spans_foot, dtype=float)
    w = np.asarray(proprioceptive_weight, dtype=float)[..., None]
    delayed = (np.asarray(delay, dtype=float) > 0)[..., None]
    intrinsic_k, intrinsic_l = g[..., IMMEDIATE_STIFFNESS, :], g[..., IMMEDIATE_VISCOSITY, :]
    active_k, active_l = w * g[..., DELAYED_STIFFNESS, :], w * g[..., DELAYED_VISCOSITY, :]
    zero = np.zeros_like(intrinsic_k)
    return np.stack([
        intrinsic_k + np.where(delayed, zero, active_k),
        intrinsic_l + np.where(delayed, zero, active_l),
        np.where(delayed, active_k, zero),
        np.where(delayed, active_l, zero),
    ], axis=-2)


def axis_acceleration_formula(depth, angle, rate, accel, xp=np):
    """The ankle's acceleration (ẍ, ÿ) when the surface turns about an axis ``depth`` [m]
    below it: ẍ = −h (α̈ cos α − α̇² sin α), ÿ = −h (α̈ sin α + α̇² cos α). [m/s²]"""
    c, s = xp.cos(angle), xp.sin(angle)
    return -depth * (accel * c - rate * rate * s), -depth * (accel * s + rate * rate * c)


def axis_translation(tilt: Tilt, depth: float, t) -> tuple[np.ndarray, np.ndarray]:
    """The ankle's acceleration and velocity when the surface turns about an axis ``depth``
    [m] below the ankle: the ankle sits at (−h sin α, h (cos α − 1)) from its level place, so

        ẍ = −h (α̈ cos α − α̇² sin α),   ÿ = −h (α̈ sin α + α̇² cos α)
        ẋ = −h α̇ cos α,                 ẏ = −h α̇ sin α.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray), shapes t.shape + (2,)
        Acceleration [m/s²] and velocity [m/s], (x, y).
    """
    a, ad, add = tilt.kinematics(t)
    acc = np.stack(axis_acceleration_formula(depth, a, ad, add), axis=-1)
    vel = np.stack([-depth * ad * np.cos(a), -depth * ad * np.sin(a)], axis=-1)
    return acc, vel


def check_proprioceptive_weight(value) -> float:
    """W in [0, 1] (the parameter table's bounds), a finite number. [-]"""
    from ..parameters import check_value

    return check_value("proprioceptive_weight", value)

