"""Input checks used at the edge of the public API (private helpers)."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from .errors import ParameterError


def _fmt(value: Any) -> str:
    if isinstance(value, float):
        return repr(value)
    return str(value)


def as_number(name: str, value: Any, want: str = "a number") -> float:
    """``value`` as a float, refusing what is not a number: a string ("5", which ``float``
    would read), bytes, a bool (True is not 1 s) or anything ``float`` cannot take, with
    :class:`ParameterError` "NAME must be WANT, got '5' (str)". The one check of "is it a
    number" at the public API's edge (:func:`finite_float`, the parameter table's
    ``check_value`` and the run settings use it)."""
    if isinstance(value, str | bytes | bool | np.bool_):
        raise ParameterError(f"{name} must be {want}, got {value!r:.60} "
                             f"({type(value).__name__})")
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be {want}, got {value!r:.60}") from None


def finite_float(name: str, value: Any) -> float:
    """Return ``value`` as a finite float or raise :class:`ParameterError` naming ``name``
    (a string or bool is refused: :func:`as_number`)."""
    out = as_number(name, value, "a finite number")
    if not math.isfinite(out):
        raise ParameterError(f"{name} must be a finite number, got {_fmt(out)}")
    return out


def positive_float(name: str, value: Any, unit: str = "") -> float:
    """A finite number > 0."""
    out = finite_float(name, value)
    if out <= 0.0:
        raise ParameterError(f"{name} must be > 0{(' ' + unit) if unit else ''}, got {_fmt(out)}")
    return out


def nonnegative_float(name: str, value: Any, unit: str = "") -> float:
    """A finite number >= 0."""
    out = finite_float(name, value)
    if out < 0.0:
        raise ParameterError(f"{name} must be >= 0{(' ' + unit) if unit else ''}, got {_fmt(out)}")
    return out


def float_in_range(
    name: str, value: Any, low: float, high: float, *, include_low: bool = True,
    include_high: bool = True, unit: str = "",
) -> float:
    """A finite number within [low, high] (bounds open or closed as asked)."""
    out = finite_float(name, value)
    ok_low = out >= low if include_low else out > low
    ok_high = out <= high if include_high else out < high
    if not (ok_low and ok_high):
        lb = "[" if include_low else "("
        hb = "]" if include_high else ")"
        u = f" {unit}" if unit else ""
        raise ParameterError(f"{name} must be in {lb}{low:g}, {high:g}{hb}{u}, got {_fmt(out)}")
    return out


def finite_array(name: str, value: Any, shape: tuple[int | None, ...] | None = None) -> np.ndarray:
    """Return a float array with every entry finite, optionally of a given shape.

    ``None`` in ``shape`` accepts any length along that axis.
    """
    if _holds_non_numbers(value):
        raise ParameterError(f"{name} must be numeric, got {value!r:.80}")
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be numeric, got {value!r:.80}") from None
    if shape is not None:
        ok = arr.ndim == len(shape) and all(
            s is None or s == d for s, d in zip(shape, arr.shape, strict=False)
        )
        if not ok:
            want = "(" + ", ".join("any" if s is None else str(s) for s in shape) + ")"
            raise ParameterError(f"{name} must have shape {want}, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        bad = arr[~np.isfinite(arr)].ravel()[0]
        raise ParameterError(f"{name} must contain only finite numbers, got {bad}")
    return arr


def _holds_non_numbers(value: Any) -> bool:
    """An array of strings or bools, or a (nested) list holding one: not numbers, though
    numpy would convert them ("0.1" → 0.1, True → 1)."""
    if isinstance(value, np.ndarray):
        return value.dtype.kind in "USb" or (value.dtype.kind == "O" and any(
            isinstance(v, str | bytes | bool | np.bool_) for v in value.ravel().tolist()))
    if isinstance(value, str | bytes | bool | np.bool_):
        return True
    if isinstance(value, list | tuple):
        return any(_holds_non_numbers(v) for v in value)
    return False


def reject_unknown_keys(
    where: str, given: Mapping[str, Any] | Iterable[str], allowed: Iterable[str]
) -> None:
    """Raise if ``given`` has a key that is not in ``allowed``."""
    allowed = list(allowed)
    unknown = [k for k in given if k not in allowed]
    if unknown:
        raise ParameterError(
            f"unknown key {unknown[0]!r} in {where}; allowed keys: {', '.join(sorted(allowed))}"
        )


def expect_type(name: str, value: Any, kind: type | tuple[type, ...]) -> None:
    """Raise :class:`ParameterError` naming the argument unless ``value`` is a ``kind``."""
    if not isinstance(value, kind):
        want = kind.__name__ if isinstance(kind, type) else " or ".join(k.__name__ for k in kind)
        raise ParameterError(f"{name} must be a {want}, got {type(value).__name__} "
                             f"{value!r:.60}")


#: Largest |initial angle| accepted: a link angle beyond ±π [rad] names the same posture as
#: one within it, and a run started there only "falls at t = 0". [rad]
MAX_INITIAL_ANGLE = math.pi


def initial_state_array(value: Any, size: int | None = None) -> np.ndarray:
    """An initial state [Θ, Θ̇] checked at the edge: numeric (:func:`finite_array`), of
    ``size`` entries when given (else an even count), its angles (the first half) within
    ±:data:`MAX_INITIAL_ANGLE` [rad]; "initial_state [rad, rad/s] angle 1 must be in
    [−3.14159, 3.14159] rad, got 100.0". [rad], [rad/s]"""
    name = "initial_state [rad, rad/s]"
    state = finite_array(name, value, (size,)).copy()
    if size is None and state.size % 2:
        raise ParameterError(f"{name} must hold N angles then N rates (an even count), got "
                             f"{state.size} values")
    angles = state[:state.size // 2]
    bad = np.flatnonzero(np.abs(angles) > MAX_INITIAL_ANGLE)
    if bad.size:
        k = int(bad[0])
        raise ParameterError(f"{name} angle {k + 1} must be in [−{MAX_INITIAL_ANGLE:.6g}, "
                             f"{MAX_INITIAL_ANGLE:.6g}] rad, got {_fmt(float(angles[k]))}")
    return state
