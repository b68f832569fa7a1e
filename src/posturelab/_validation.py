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


def finite_float(name: str, value: Any) -> float:
    """Return ``value`` as a finite float or raise :class:`ParameterError` naming ``name``."""
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a finite number, got {value!r}") from None
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
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be numeric, got {value!r}") from None
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
