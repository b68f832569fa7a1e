"""Platform disturbances: velocity steps and acceleration profiles.

Every disturbance is an immutable object with

* ``velocity_change`` — an instantaneous change of platform velocity at
  t = 0, (Δẋ_d, Δẏ_d) [m/s] (only :class:`VelocityStep` has one; it sets the
  initial link rates through ΔΘ̇ = −J⁻¹H Δẋ_d);
* ``acceleration(t)`` — (ẍ_d, ÿ_d) at times ``t`` [m/s²], shape (..., 2);
* ``breakpoints`` — the times where the acceleration or its slope jumps; the
  simulator stops and restarts its integrator exactly there so it never
  steps blindly over a corner;
* ``primitives()`` — the acceleration as a sum of a few kinds of terms
  (:class:`Primitive`: a windowed sine, a sine, a sampled profile), which the
  compiled engine evaluates. A new kind of disturbance that is such a sum needs
  ``acceleration``, ``breakpoints``, ``scaled`` and ``primitives`` and nothing else.

Sign conventions: x forward, y up. A *backward* platform motion has
ẋ_d < 0 and makes the body sway forward.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Literal

import numpy as np

from .._validation import (
    finite_array,
    finite_float,
    float_in_range,
    nonnegative_float,
    positive_float,
)
from ..errors import DataFileError, ParameterError
from ..parameters import MAX_PLATFORM_SPEED
from .disturbance import (  # the base class and the terms (stated in .disturbance)
    MAX_PLATFORM_ACCELERATION,
    MIN_PROFILE_SPACING,
    Disturbance,
    NoDisturbance,
    Primitive,
    ProfileTerm,
    _axis,
    _check_acceleration,
    sine_formula,
    windowed_sine_formula,
)

__all__ = [
    "Primitive",
    "ProfileTerm",
    "Disturbance",
    "NoDisturbance",
    "VelocityStep",
    "HalfSinePulse",
    "RampAndHold",
    "SumOfSines",
    "MeasuredProfile",
    "CombinedDisturbance",
    "read_profile_csv",
    "combine",
    "MAX_PLATFORM_ACCELERATION",
    "MIN_PROFILE_SPACING",
    "sine_formula",
    "windowed_sine_formula",
]

Axis = Literal["x", "y"]

@dataclass(frozen=True)
class VelocityStep(Disturbance):
    """A sudden platform velocity change at t = 0 (the paper's "unit impulse").

    Parameters
    ----------
    velocity : float
        Δẋ_d (axis x) or Δẏ_d (axis y): the platform's new velocity. A
        backward step is negative. [m/s]
    axis : {"x", "y"}
        Direction of the step.
    """

    velocity: float
    axis: Axis = "x"

    def __post_init__(self) -> None:
        object.__setattr__(self, "velocity", float_in_range(
            "velocity [m/s]", self.velocity, -MAX_PLATFORM_SPEED, MAX_PLATFORM_SPEED, unit="m/s"))
        _axis(self.axis)

    @property
    def velocity_change(self) -> tuple[float, float]:  # type: ignore[override]
        return (self.velocity, 0.0) if self.axis == "x" else (0.0, self.velocity)

    @classmethod
    def backward(cls, speed: float = 1.0) -> VelocityStep:
        """Platform jerked backward at ``speed`` [m/s] (> 0): the body sways forward."""
        return cls(-positive_float("speed [m/s]", speed))

    @classmethod
    def forward(cls, speed: float = 1.0) -> VelocityStep:
        """Platform jerked forward at ``speed`` [m/s] (> 0): the body sways backward."""
        return cls(positive_float("speed [m/s]", speed))

    def scaled(self, factor: float) -> VelocityStep:
        return replace(self, velocity=self.velocity * finite_float("factor [-]", factor))

    def primitives(self) -> tuple[Primitive, ...]:
        return ()  # no acceleration: the step only sets the initial rates

    def describe(self) -> str:
        word = {"x": ("forward", "backward"), "y": ("up", "down")}[self.axis]
        return (f"platform velocity step of {abs(self.velocity):g} m/s "
                f"{word[0] if self.velocity >= 0 else word[1]} at t = 0")


class _SinePulse(Disturbance):
    """A sine-shaped acceleration on [start, start + duration], zero elsewhere (shared code)."""

    #: Cycles of the sine within the pulse: ½ for a half-sine, 1 for ramp-and-hold. [-]
    _cycles: float = 0.5
    #: The field that sets the pulse's size (what :meth:`scaled` scales), with its unit.
    _size: tuple[str, str] = ("peak_acceleration", "peak_acceleration [m/s²]")
    #: The peak acceleration's words in a message.
    _peak_words = "peak_acceleration [m/s²]"
    start: float
    duration: float
    axis: str
    #: Amplitude of the sine (a field, or a property of the size). [m/s²]
    peak_acceleration: float

    def __post_init__(self) -> None:
        name, words = self._size
        object.__setattr__(self, name, finite_float(words, getattr(self, name)))
        object.__setattr__(self, "duration", positive_float("duration [s]", self.duration))
        object.__setattr__(self, "start", nonnegative_float("start [s]", self.start))
        _axis(self.axis)
        _check_acceleration(self._peak_words, self.peak_acceleration)

    def scaled(self, factor: float) -> _SinePulse:
        name = self._size[0]
        return replace(self, **{name: getattr(self, name) * finite_float("factor [-]", factor)})

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return (self.start, self.start + self.duration)

    def primitives(self) -> tuple[Primitive, ...]:
        return (Primitive("windowed-sine", self.peak_acceleration, start=self.start,
                          duration=self.duration, axis=_axis(self.axis), cycles=self._cycles),)

    def acceleration(self, t):
        t = np.asarray(t, dtype=float)
        a = windowed_sine_formula(t, self.peak_acceleration, self.duration, self.start,
                                  self._cycles)
        out = np.zeros(t.shape + (2,))
        out[..., _axis(self.axis)] = a
        return out


@dataclass(frozen=True)
class HalfSinePulse(_SinePulse):
    """Acceleration a(t) = peak · sin(π (t − start)/duration) for start <= t <= start + duration.

    Parameters
    ----------
    peak_acceleration : float
        Peak acceleration, signed (negative is backward / down). [m/s²]
    duration : float
        Pulse length. [s]
    start : float
        Onset time. [s]
    axis : {"x", "y"}
    """

    peak_acceleration: float
    duration: float
    start: float = 0.0
    axis: Axis = "x"

    @property
    def velocity_gain(self) -> float:
        """Velocity reached at the end of the pulse, 2·peak·duration/π. [m/s]"""
        return 2.0 * self.peak_acceleration * self.duration / np.pi

    def describe(self) -> str:
        return (f"half-sine acceleration pulse, peak {self.peak_acceleration:g} m/s² along "
                f"{self.axis}, {self.duration:g} s from t = {self.start:g} s")


@dataclass(frozen=True)
class RampAndHold(_SinePulse):
    """The usual lab platform: move by ``displacement`` over ``duration``, then hold.

    The acceleration is one full sine cycle, a(t) = (2π D / T²) sin(2π (t − t0)/T),
    so acceleration, velocity and displacement all start and end smoothly at
    zero velocity; the peak velocity 2D/T is reached at mid-move.

    Parameters
    ----------
    displacement : float
        D, signed (negative is backward / down). [m]
    duration : float
        T, time of the move. [s]
    start : float
        t0, onset. [s]
    axis : {"x", "y"}
    """

    displacement: float
    duration: float
    start: float = 0.0
    axis: Axis = "x"
    _cycles = 1.0
    _size = ("displacement", "displacement [m]")
    _peak_words = "peak acceleration 2πD/T² [m/s²]"

    @property
    def peak_acceleration(self) -> float:
        """2πD/T². [m/s²]"""
        return 2.0 * np.pi * self.displacement / self.duration**2

    def describe(self) -> str:
        return (f"ramp-and-hold: {self.displacement:g} m along {self.axis} over "
                f"{self.duration:g} s from t = {self.start:g} s")


@dataclass(frozen=True)
class SumOfSines(Disturbance):
    """Acceleration Σ_i A_i sin(2π f_i t + φ_i), for system-identification runs.

    Parameters
    ----------
    amplitudes : sequence of float
        A_i. [m/s²]
    frequencies : sequence of float
        f_i, positive. [Hz]
    phases : sequence of float, optional
        φ_i; zeros by default. [rad]
    axis : {"x", "y"}
    """

    amplitudes: tuple[float, ...]
    frequencies: tuple[float, ...]
    phases: tuple[float, ...] | None = None
    axis: Axis = "x"

    def __post_init__(self) -> None:
        amp = finite_array("amplitudes [m/s²]", self.amplitudes, (None,))
        freq = finite_array("frequencies [Hz]", self.frequencies, (None,))
        if amp.size == 0 or amp.size != freq.size:
            raise ParameterError(
                f"amplitudes and frequencies must be non-empty and of equal length, got "
                f"{amp.size} and {freq.size}"
            )
        if np.any(freq <= 0):
            raise ParameterError(f"frequencies [Hz] must be > 0, got {freq[freq <= 0][0]:g}")
        ph = (np.zeros_like(amp) if self.phases is None
              else finite_array("phases [rad]", self.phases, (amp.size,)))
        _check_acceleration("sum of |amplitudes| [m/s²]", float(np.abs(amp).sum()))
        object.__setattr__(self, "amplitudes", tuple(amp.tolist()))
        object.__setattr__(self, "frequencies", tuple(freq.tolist()))
        object.__setattr__(self, "phases", tuple(ph.tolist()))
        _axis(self.axis)

    @property
    def max_step(self) -> float:
        return 0.05 / max(self.frequencies)

    def scaled(self, factor: float) -> SumOfSines:
        f = finite_float("factor [-]", factor)
        return replace(self, amplitudes=tuple(a * f for a in self.amplitudes))

    def primitives(self) -> tuple[Primitive, ...]:
        return tuple(Primitive("sine", a, f, ph, axis=_axis(self.axis))
                     for a, f, ph in zip(self.amplitudes, self.frequencies, self.phases,
                                         strict=True))

    def acceleration(self, t):
        t = np.asarray(t, dtype=float)
        a = np.zeros(t.shape)
        for amp, f, ph in zip(self.amplitudes, self.frequencies, self.phases, strict=True):
            a = a + sine_formula(t, amp, f, ph)
        out = np.zeros(t.shape + (2,))
        out[..., _axis(self.axis)] = a
        return out

    def describe(self) -> str:
        return (f"sum of {len(self.amplitudes)} sines along {self.axis}, "
                f"{min(self.frequencies):g}–{max(self.frequencies):g} Hz")


@dataclass(frozen=True)
class MeasuredProfile(Disturbance):
    """A measured platform acceleration, linearly interpolated between samples.

    Zero before the first and after the last sample: the platform keeps the velocity it has
    at the last sample (and stays where it is only if that velocity is zero). Every sample
    within ±:data:`MAX_PLATFORM_ACCELERATION` [m/s²]. A run starts at t = 0, so the first
    sample is at t >= 0 (a run refuses a profile that starts after it ends).

    Parameters
    ----------
    time : array_like, shape (S,)
        Sample times, strictly increasing, from t >= 0. [s]
    acceleration_x : array_like, shape (S,)
        ẍ_d. [m/s²]
    acceleration_y : array_like, shape (S,), optional
        ÿ_d; zeros by default. [m/s²]
    source : str
        Where the profile came from (file name).
    """

    time: np.ndarray
    acceleration_x: np.ndarray
    acceleration_y: np.ndarray | None = None
    source: str = ""
    _max_step: float = field(default=math.inf, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        t = finite_array("time [s]", self.time, (None,))
        if t.size < 2:
            raise ParameterError(f"time [s] must have at least 2 samples, got {t.size}")
        if t[0] < 0:
            raise ParameterError(f"time [s] must start at t >= 0 (a run starts at 0), got "
                                 f"{t[0]:g}")
        dt = np.diff(t)
        if np.any(dt <= 0):
            i = int(np.argmax(dt <= 0))
            raise ParameterError(
                f"time [s] must be strictly increasing; sample {i + 2} ({t[i + 1]:g}) "
                f"follows {t[i]:g}"
            )
        if np.any(dt < MIN_PROFILE_SPACING):
            i = int(np.argmax(dt < MIN_PROFILE_SPACING))
            raise ParameterError(
                f"time [s]: samples {i + 1} and {i + 2} are {dt[i]:g} s apart; at least "
                f"{MIN_PROFILE_SPACING:g} s")
        ax = finite_array("acceleration_x [m/s²]", self.acceleration_x, (t.size,))
        ay = (np.zeros_like(t) if self.acceleration_y is None
              else finite_array("acceleration_y [m/s²]", self.acceleration_y, (t.size,)))
        for name, arr in (("acceleration_x", ax), ("acceleration_y", ay)):
            i = int(np.argmax(np.abs(arr)))
            _check_acceleration(f"{name} [m/s²] (sample {i + 1})", float(arr[i]))
        for name, arr in (("time", t), ("acceleration_x", ax), ("acceleration_y", ay)):
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        object.__setattr__(self, "_max_step", float(dt.min()))

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return tuple(self.time.tolist())

    def scaled(self, factor: float) -> MeasuredProfile:
        f = finite_float("factor [-]", factor)
        if f == 1.0:
            return self
        return MeasuredProfile(self.time, self.acceleration_x * f, self.acceleration_y * f,
                               source=f"{self.source} × {f:g}" if self.source else "")

    @property
    def max_step(self) -> float:
        return self._max_step

    def primitives(self) -> tuple[Primitive, ...]:
        return (Primitive("samples", samples=(self.time, self.acceleration_x,
                                              self.acceleration_y)),)

    def acceleration(self, t):
        t = np.asarray(t, dtype=float)
        out = np.zeros(t.shape + (2,))
        out[..., 0] = np.interp(t, self.time, self.acceleration_x, left=0.0, right=0.0)
        out[..., 1] = np.interp(t, self.time, self.acceleration_y, left=0.0, right=0.0)
        return out

    def describe(self) -> str:
        src = f" from {self.source}" if self.source else ""
        return (f"measured acceleration profile{src}: {self.time.size} samples, "
                f"{self.time[0]:g}–{self.time[-1]:g} s")


@dataclass(frozen=True)
class CombinedDisturbance(Disturbance):
    """The sum of several disturbances (e.g. a horizontal and a vertical one)."""

    parts: tuple[Disturbance, ...]

    @property
    def velocity_change(self) -> tuple[float, float]:  # type: ignore[override]
        v = np.sum([p.velocity_change for p in self.parts], axis=0)
        return (float(v[0]), float(v[1]))

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return tuple(sorted({b for p in self.parts for b in p.breakpoints}))

    @property
    def max_step(self) -> float:
        return min((p.max_step for p in self.parts), default=math.inf)

    def acceleration(self, t):
        return sum(p.acceleration(t) for p in self.parts)

    def scaled(self, factor: float) -> CombinedDisturbance:
        f = finite_float("factor [-]", factor)
        return CombinedDisturbance(tuple(p.scaled(f) for p in self.parts))

    def primitives(self) -> tuple[Primitive, ...]:
        return tuple(q for p in self.parts for q in p.primitives())

    def describe(self) -> str:
        return " + ".join(p.describe() for p in self.parts)


def combine(*parts: Disturbance) -> Disturbance:
    """One disturbance from several (a single part is returned as it is)."""
    if len(parts) == 1:
        return parts[0]
    return CombinedDisturbance(tuple(parts))


REQUIRED_COLUMNS = ("time", "x_acceleration")


def refuse_named_twice(what: str, header: list[str], names: list[str]) -> None:
    """Refuse a header naming one of ``names`` more than once (which is meant is not
    guessed)."""
    for name in names:
        if header.count(name) > 1:
            where = [str(j + 1) for j, h in enumerate(header) if h == name]
            raise DataFileError(f"{what}: the header names {name!r} {len(where)} times "
                                f"(columns {', '.join(where)}); which one is meant is not "
                                "guessed")


def refuse_time_in_ms(what: str, t: np.ndarray, header: str) -> None:
    """Refuse a time column that declares no unit and steps by whole numbers of at least
    1 s over 20 or more samples: milliseconds read as seconds (``time [s]`` in the header
    reads it as it stands)."""
    dt = np.diff(t)
    if "[" in header or t.size < 20 or not dt.size:
        return
    step = float(np.median(dt))
    if step >= 1.0 and np.all(np.abs(dt - np.round(dt)) <= 1e-9 * np.maximum(1.0, dt)):
        raise DataFileError(f"{what}: the time column steps by {step:g} (a {1 / step:.3g} Hz "
                            "recording if in s): is it in ms? a profile's time is in s: "
                            f"divide it by 1000 (or declare '{header.strip()} [s]' in the "
                            "header to read it in s)")


def read_profile_csv(path: str | Path) -> MeasuredProfile:
    """Read a measured platform profile from CSV or Parquet (a column's unit in its name,
    as a CSV header gives it, or in its field's metadata).

    The file has a header row. Columns, by header name: ``time`` [s],
    ``x_acceleration`` [m/s²] and optionally ``y_acceleration`` [m/s²]
    (the aliases ``t``, ``ax``/``xdd`` and ``ay``/``ydd`` are accepted; a
    ``[unit]`` suffix must be that unit: ``time [ms]`` is refused). Time must be strictly
    increasing, no value may be NaN or missing, and every acceleration lies within
    ±:data:`MAX_PLATFORM_ACCELERATION` (1000 m/s²); a column named twice is refused, and so
    is a time column without a unit stepping by whole seconds (ms read as s). The first
    time is >= 0 (a run starts
    at 0; a negative time is refused, not dropped). The acceleration is zero after the last
    sample (and before the first): the platform goes on at the velocity it has reached.

    Raises
    ------
    DataFileError
        With the file name, row and column of the first problem.
    """
    from .._files import check_column_unit, csv_rows, header_words, read_text
    from .._parquet import is_parquet, parquet_rows

    path = Path(path)
    what = f"platform profile {str(path)!r}"
    numbered = list(parquet_rows(path, what) if is_parquet(path)
                    else csv_rows(read_text(path, "platform profile"), what))
    rows = [r for _, r in numbered]
    lines = [n for n, _ in numbered]
    if len(rows) < 3:
        raise DataFileError(
            f"platform profile {str(path)!r} needs a header row and at least 2 samples"
        )
    aliases = {
        "time": "time", "t": "time",
        "x_acceleration": "x_acceleration", "ax": "x_acceleration", "xdd": "x_acceleration",
        "y_acceleration": "y_acceleration", "ay": "y_acceleration", "ydd": "y_acceleration",
    }
    header = [aliases.get(h.split("[")[0].strip().lower(), h.strip()) for h in rows[0]]
    missing = [c for c in REQUIRED_COLUMNS if c not in header]
    if missing:
        raise DataFileError(
            f"platform profile {str(path)!r} lacks column {missing[0]!r}; needs columns "
            f"time [s], x_acceleration [m/s²] and optionally y_acceleration [m/s²]; "
            f"{header_words(rows[0])}"
        )
    idx = {name: header.index(name) for name in ("time", "x_acceleration", "y_acceleration")
           if name in header}
    refuse_named_twice(what, header, list(idx))
    for name, j in idx.items():
        accepted = ("s",) if name == "time" else ("m/s²", "m/s^2", "m/s2")
        check_column_unit(what, rows[0][j], accepted, "accelerations in m/s² and time in s")
    data = {name: [] for name in idx}
    for lineno, r in zip(lines[1:], rows[1:], strict=True):
        for name, j in idx.items():
            try:
                v = float(r[j])
            except (IndexError, ValueError):
                raise DataFileError(
                    f"platform profile {str(path)!r} line {lineno}: column {name!r} is "
                    f"{'not a number' if j < len(r) else 'missing'}"
                ) from None
            if not math.isfinite(v):
                raise DataFileError(
                    f"platform profile {str(path)!r} line {lineno}: column {name!r} is {v}; "
                    "NaN and inf are not allowed"
                )
            if name != "time" and not abs(v) <= MAX_PLATFORM_ACCELERATION:
                raise DataFileError(
                    f"platform profile {str(path)!r} line {lineno}: column {name!r} is {v:g} "
                    f"m/s²; it must be within ±{MAX_PLATFORM_ACCELERATION:g} m/s²"
                )
            data[name].append(v)
    t = np.array(data["time"])
    refuse_time_in_ms(what, t, rows[0][idx["time"]])
    if t[0] < 0:
        raise DataFileError(
            f"platform profile {str(path)!r} line {lines[1]}: time {t[0]:g} s is before 0; "
            "a profile starts at t >= 0 (the run starts at 0)"
        )
    bad = np.nonzero(np.diff(t) <= 0)[0]
    if bad.size:
        i = int(bad[0])
        raise DataFileError(
            f"platform profile {str(path)!r} line {lines[i + 2]}: time {t[i + 1]:g} s does not "
            f"increase (previous {t[i]:g} s); time must be strictly increasing"
        )
    close = np.nonzero(np.diff(t) < MIN_PROFILE_SPACING)[0]
    if close.size:
        i = int(close[0])
        raise DataFileError(
            f"platform profile {str(path)!r} line {lines[i + 2]}: time {t[i + 1]:g} s is "
            f"{t[i + 1] - t[i]:g} s after the previous sample; at least "
            f"{MIN_PROFILE_SPACING:g} s (a 1 MHz recording)"
        )
    return MeasuredProfile(
        t, np.array(data["x_acceleration"]),
        np.array(data["y_acceleration"]) if "y_acceleration" in data else None,
        source=path.name,
    )


def sample_profile(disturbance: Disturbance, time: Sequence[float]) -> np.ndarray:
    """Acceleration of ``disturbance`` sampled at ``time`` [s], shape (T, 2). [m/s²]"""
    return disturbance.acceleration(np.asarray(time, dtype=float))
