"""Two-parameter grids of pair gains and the stability maps over them.

:func:`parameter_grid` sweeps two named parameters (:data:`GRID_PARAMETERS`: the
paper's five pair stiffnesses [N·m/rad] and the viscosity ratio [s]; or, for any body,
the pairs of a base muscle set) over ranges, every other parameter taken from a Table I
case (or from the base muscle set); :func:`posturelab.linear.batch.stability_map`
evaluates the largest real part of the poles [1/s] and the stable flag at every point,
and :meth:`StabilityMap.write_csv` writes it as CSV. The public names are those of
:mod:`posturelab.linear.batch`. This module imports no numba and nothing of
:mod:`posturelab.linear.batch`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import IO

import numpy as np

from .._validation import nonnegative_float
from ..errors import ParameterError, UnknownNameError
from ..model.muscles import (
    DEFAULT_VISCOSITY_RATIO,
    PAPER_PAIR_NAMES,
    STIFFNESS_CASES,
    MuscleSet,
    get_stiffness_case,
)
from ..parameters import check_value, names_for, resolve, unit

__all__ = [
    "GRID_PARAMETERS",
    "GRID_PARAMETER_UNITS",
    "ParameterRange",
    "ParameterGrid",
    "StabilityMap",
    "parameter_grid",
]

#: The parameter table's quantities a grid can sweep (:mod:`posturelab.parameters`).
GRID_QUANTITIES: tuple[str, ...] = ("stiffness", "viscosity_ratio")
#: Parameters a grid can sweep, by the parameter table's names: the paper's five pair
#: stiffnesses ``stiffness:PAIR`` [N·m/rad] and the viscosity ratio [s].
GRID_PARAMETERS: tuple[str, ...] = names_for(PAPER_PAIR_NAMES, (), GRID_QUANTITIES)

#: Unit of each grid parameter.
GRID_PARAMETER_UNITS: dict[str, str] = {name: unit(name) for name in GRID_PARAMETERS}


def _check_parameter_name(name: str, pairs: tuple[str, ...] = PAPER_PAIR_NAMES) -> str:
    """The table's one spelling of a grid parameter for a body with these pairs (a former
    one is refused naming the new one)."""
    return resolve(name, pairs, (), accepts=GRID_QUANTITIES, what="grid parameter")


def _check_name_form(name) -> str:
    """``"viscosity_ratio"`` or ``"stiffness:PAIR"`` with PAIR an identifier (checked against
    the muscle set by :func:`parameter_grid`); a former spelling is refused naming the new
    one, an unknown name listing the known ones."""
    if not isinstance(name, str):
        raise UnknownNameError(
            f"unknown parameter {name!r}; known parameters: {', '.join(GRID_PARAMETERS)} "
            "(or stiffness:PAIR for the pairs of the muscle set)")
    text = name.strip().lower()
    quantity, _, pair = text.partition(":")
    if text == "viscosity_ratio" or (quantity == "stiffness" and pair.isidentifier()):
        return text
    return _check_parameter_name(text)


@dataclass(frozen=True)
class ParameterRange:
    """A named parameter swept over [low, high].

    Parameters
    ----------
    name : str
        ``"stiffness:PAIR"`` [N·m/rad] (PAIR one of the paper's pairs, :data:`GRID_PARAMETERS`,
        or of the base muscle set's pairs) or ``"viscosity_ratio"`` [s].
    low, high : float
        Range ends, 0 <= low < high. [N·m/rad] or [s]
    """

    name: str
    low: float
    high: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "name", _check_name_form(self.name))
        unit = self.unit
        low = nonnegative_float(f"{self.name} low [{unit}]", self.low)
        high = nonnegative_float(f"{self.name} high [{unit}]", self.high)
        if not low < high:
            raise ParameterError(
                f"{self.name} range must satisfy low < high [{unit}], got {low:g} .. {high:g}"
            )
        check_value(self.name, high, f"{self.name} high")  # the parameter table's bound
        object.__setattr__(self, "low", low)
        object.__setattr__(self, "high", high)

    @property
    def unit(self) -> str:
        """Unit of the parameter: "N·m/rad" or "s"."""
        return "s" if self.name == "viscosity_ratio" else "N·m/rad"

    @property
    def label(self) -> str:
        """Axis label with unit, e.g. ``"ankle pair stiffness [N·m/rad]"``."""
        if self.name == "viscosity_ratio":
            return "viscosity ratio (viscosity / stiffness) [s]"
        return f"{self.name.partition(':')[2]} pair stiffness [N·m/rad]"

    def values(self, count: int) -> np.ndarray:
        """``count`` evenly spaced values from low to high inclusive. [unit]"""
        return np.linspace(self.low, self.high, count)


def _as_range(value: ParameterRange | tuple) -> ParameterRange:
    if isinstance(value, ParameterRange):
        return value
    try:
        name, low, high = value
    except (TypeError, ValueError):
        raise ParameterError(
            f"a parameter range must be ParameterRange or (name, low, high), got {value!r}"
        ) from None
    return ParameterRange(str(name), low, high)


@dataclass(frozen=True)
class ParameterGrid:
    """A two-parameter grid of pair gains around a Table I case or a base muscle set.

    Set index ``iy * nx + ix`` has ``x = x_values[ix]`` and ``y = y_values[iy]``
    (row-major, y along rows as an image).

    Attributes
    ----------
    x, y : ParameterRange
        The swept parameters.
    x_values : numpy.ndarray, shape (nx,)
        Values along x. [N·m/rad] or [s]
    y_values : numpy.ndarray, shape (ny,)
        Values along y. [N·m/rad] or [s]
    base_case : str or None
        Table I case giving every parameter not swept; None for a base muscle set.
    base_stiffness : numpy.ndarray, shape (P,)
        The pair stiffness of the parameters not swept, in the order of ``pair_names``.
        [N·m/rad]
    base_viscosity_ratio : float
        Viscosity ratio when not swept. [s]
    pair_names : tuple of str
        The pairs, in column order (the paper's five by default).
    """

    x: ParameterRange
    y: ParameterRange
    x_values: np.ndarray
    y_values: np.ndarray
    base_case: str | None
    base_stiffness: np.ndarray
    base_viscosity_ratio: float
    pair_names: tuple[str, ...] = PAPER_PAIR_NAMES

    @property
    def shape(self) -> tuple[int, int]:
        """(ny, nx). [-]"""
        return (self.y_values.size, self.x_values.size)

    @property
    def size(self) -> int:
        """Number of parameter sets nx·ny. [-]"""
        return self.x_values.size * self.y_values.size

    def rows(self, start: int = 0, stop: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Gains of grid rows ``start:stop`` (y indices), flattened row-major.

        Returns
        -------
        pair_stiffness : numpy.ndarray, shape (rows·nx, P)
            [N·m/rad]
        viscosity_ratio : numpy.ndarray, shape (rows·nx,)
            [s]
        """
        ys = self.y_values[start:stop]
        xs = self.x_values
        count = ys.size * xs.size
        stiffness = np.empty((count, len(self.pair_names)))
        stiffness[:] = self.base_stiffness
        ratio = np.full(count, self.base_viscosity_ratio)
        for rng, vals in ((self.x, np.tile(xs, ys.size)), (self.y, np.repeat(ys, xs.size))):
            if rng.name == "viscosity_ratio":
                ratio[:] = vals
            else:
                stiffness[:, self.pair_names.index(rng.name.partition(":")[2])] = vals
        return stiffness, ratio

    @property
    def pair_stiffness(self) -> np.ndarray:
        """All sets' pair stiffness, shape (nx·ny, P). [N·m/rad]"""
        return self.rows()[0]

    @property
    def viscosity_ratio(self) -> np.ndarray:
        """All sets' viscosity ratio, shape (nx·ny,). [s]"""
        return self.rows()[1]

    def table_i_points(self) -> list[tuple[str, float, float]]:
        """Table I cases that lie in this plane: (case, x, y).

        A case lies in the plane when every parameter not swept equals the
        grid's base (a Table I case's viscosity ratio is the paper's 0.25 [s])
        and its two swept values fall within the ranges.
        """
        points = []
        if self.base_case is None or tuple(self.pair_names) != PAPER_PAIR_NAMES:
            return points  # Table I is of the paper's five pairs
        names = [f"stiffness:{p}" for p in PAPER_PAIR_NAMES]
        for case, stiffness in STIFFNESS_CASES.items():
            params = dict(zip(names, stiffness, strict=True))
            params["viscosity_ratio"] = DEFAULT_VISCOSITY_RATIO
            base = dict(zip(names, self.base_stiffness, strict=True))
            base["viscosity_ratio"] = self.base_viscosity_ratio
            if any(params[n] != base[n] for n in GRID_PARAMETERS
                   if n not in (self.x.name, self.y.name)):
                continue
            px, py = params[self.x.name], params[self.y.name]
            if self.x.low <= px <= self.x.high and self.y.low <= py <= self.y.high:
                points.append((case, float(px), float(py)))
        return points


def parameter_grid(
    x: ParameterRange | tuple[str, float, float],
    y: ParameterRange | tuple[str, float, float],
    resolution: int | tuple[int, int] = 200,
    *,
    case: str = "1",
    viscosity_ratio: float | None = None,
    muscles: MuscleSet | None = None,
) -> ParameterGrid:
    """Grid over two named parameters, every other one from a Table I case (or from
    ``muscles``).

    Parameters
    ----------
    x, y : ParameterRange or (name, low, high)
        Parameters to sweep, names from :data:`GRID_PARAMETERS` (or ``muscles``' pairs
        and ``"viscosity_ratio"``); different names. [N·m/rad] for a pair stiffness, [s]
        for ``"viscosity_ratio"``.
    resolution : int or (nx, ny)
        Points per axis, each in [2, 5000]. [-]
    case : str, optional
        Table I case for the parameters not swept ("1" … "7", "6a", "6b").
    viscosity_ratio : float, optional
        Viscosity ratio when it is not swept; the paper's 0.25 by default. [s]
    muscles : MuscleSet, optional
        A base muscle set of any body instead of a Table I case: its pairs name the
        parameters and its stiffness gives those not swept ([N·m/rad]; viscosity = ratio
        × stiffness; active gains are not part of this map: see
        :func:`posturelab.linear.delay_batch.delay_stability_map`).

    Returns
    -------
    ParameterGrid
    """
    x, y = _as_range(x), _as_range(y)
    if muscles is not None:
        if not isinstance(muscles, MuscleSet):
            raise ParameterError(f"muscles must be a MuscleSet, got {type(muscles).__name__}")
        if muscles.has_active_feedback:
            raise ParameterError("a pair-stiffness map is of the pair gains only; this muscle "
                                 "set has active (delayed) gains: map them with "
                                 "delay_stability_map")
        pair_names = tuple(muscles.names)
    else:
        pair_names = PAPER_PAIR_NAMES
    for rng in (x, y):
        _check_parameter_name(rng.name, pair_names)
    if x.name == y.name:
        raise ParameterError(f"x and y must be different parameters, both are {x.name!r}")
    if isinstance(resolution, int | np.integer):
        nx = ny = int(resolution)
    else:
        try:
            nx, ny = (int(v) for v in resolution)
        except (TypeError, ValueError):
            raise ParameterError(
                f"resolution must be an integer or (nx, ny), got {resolution!r}"
            ) from None
    for label, count in (("nx", nx), ("ny", ny)):
        if not 2 <= count <= 5000:
            raise ParameterError(f"resolution {label} must be in [2, 5000], got {count}")
    if muscles is not None:
        base = np.array(muscles.stiffnesses, dtype=float)
        case_key = None
    else:
        base = np.array(get_stiffness_case(case), dtype=float)
        case_key = str(case).strip().lower().replace("case", "").replace(" ", "")
    if viscosity_ratio is None:
        ratio = DEFAULT_VISCOSITY_RATIO
    else:
        if "viscosity_ratio" in (x.name, y.name):
            raise ParameterError(
                "viscosity_ratio is swept along an axis; do not also give it as a fixed value"
            )
        ratio = check_value("viscosity_ratio", viscosity_ratio)
    base.setflags(write=False)
    xv, yv = x.values(nx), y.values(ny)
    xv.setflags(write=False)
    yv.setflags(write=False)
    return ParameterGrid(x, y, xv, yv, case_key, base, ratio, pair_names)


@dataclass(frozen=True)
class StabilityMap:
    """Largest real part and stability over a :class:`ParameterGrid`.

    Attributes
    ----------
    grid : ParameterGrid
        The parameter sets.
    max_real_part : numpy.ndarray, shape (ny, nx)
        Largest real part of the poles at each grid point. [1/s]
    stable : numpy.ndarray of bool, shape (ny, nx)
        True where every pole has real part < −δ (:mod:`posturelab.linear.batch`,
        *Stability margin*).
    body_name : str
        The name of the body the map is of.
    """

    grid: ParameterGrid
    max_real_part: np.ndarray
    stable: np.ndarray
    body_name: str = "paper"

    @property
    def stable_fraction(self) -> float:
        """Fraction of grid points that are stable. [-]"""
        return float(self.stable.mean())

    def write_csv(self, stream: IO[str], *, rows_per_block: int = 100_000,
                  progress: Callable[[int, int], None] | None = None) -> None:
        """Write ``x name, y name, max_real_part, stable`` rows (stable as 1/0).

        One row per grid point, row-major (x fastest); x, y in their units,
        max_real_part in [1/s], numbers with 12 significant digits.

        Parameters
        ----------
        stream : text stream
            Where to write (opened with ``newline=""``).
        rows_per_block : int, optional
            Rows formatted at a time. [-]
        progress : callable(done, total), optional
            Called after each block with the rows written and the total. [-]
        """
        from . import _format_kernels as fmt  # imports numba

        g = self.grid
        stream.write(f"{g.x.name},{g.y.name},max_real_part,stable\n")
        values = np.ascontiguousarray(self.max_real_part, dtype=float).ravel()
        stable = np.ascontiguousarray(self.stable, dtype=bool).ravel()
        x_text, x_len = fmt.text_table(g.x_values)
        y_text, y_len = fmt.text_table(g.y_values)
        special = fmt.special_values(values)  # 0, NaN, ±inf, tiny or huge: Python's text
        special_text, special_len = fmt.text_table(values[special])
        row_bytes = int(x_len.max() + y_len.max()) + fmt.WIDTH + 4
        rows_per_block = max(1, int(rows_per_block))
        buffer = np.empty(min(g.size, rows_per_block) * row_bytes, dtype=np.uint8)
        raw = _ascii_buffer(stream)  # the bytes beneath a UTF-8/ASCII file, if any
        for start in range(0, g.size, rows_per_block):
            stop = min(g.size, start + rows_per_block)
            # the text of "%.12g,%.12g,%.12g,%d\n" % row for each row, compiled
            end = fmt.csv_rows(start, stop, g.x_values.size, x_text, x_len, y_text, y_len,
                               values, stable, special, special_text, special_len, buffer)
            if raw is not None:
                raw.write(memoryview(buffer)[:end])
            else:
                stream.write(buffer[:end].tobytes().decode("ascii"))
            if progress is not None:
                progress(stop, g.size)


def _ascii_buffer(stream):
    """The binary buffer beneath ``stream`` when ASCII bytes can go there directly (a
    file opened in text mode with UTF-8 or ASCII encoding, flushed first), else None."""
    import codecs
    import io

    if not isinstance(stream, io.TextIOWrapper):
        return None
    try:
        name = codecs.lookup(stream.encoding).name
    except LookupError:
        return None
    if name not in ("utf-8", "ascii"):
        return None
    stream.flush()
    return stream.buffer
