"""Reading the series of an identification experiment from a CSV file."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .._files import check_column_unit, column_unit
from ..errors import DataFileError

__all__ = ["read_series_csv", "column_unit", "check_column_unit", "SI_UNITS", "MAX_ROWS"]

#: Most data rows a series file may have. [-]
MAX_ROWS = 2_000_000  # posturelab._files.MAX_DATA_ROWS


#: Units a data column may declare in its header (``name [unit]``): those posturelab reads,
#: SI. A column that declares another (deg, mm, ms, ...) is refused, never rescaled. [-]
SI_UNITS = ("rad", "m", "N", "N·m", "N m", "rad/s", "m/s")


def _name(header: str) -> str:
    name = header.split("[")[0].strip().lower()
    return "time" if name == "t" else name


def read_series_csv(path: str | Path, columns: list[str],
                    units: dict[str, tuple[str, ...]] | None = None
                    ) -> tuple[float, dict[str, np.ndarray]]:
    """The sample rate and the named columns of a CSV file with a header row and a uniform
    ``time`` (or ``t``) column [s].

    A header may declare a column's unit in brackets (``com [rad]``); the time column must
    then be in s and each named column in one of ``units[name]`` (default :data:`SI_UNITS`);
    any other unit (deg, ms, mm, ...) is refused, never silently read as SI.

    Returns
    -------
    (float, dict of str -> numpy.ndarray)
        Sample rate [Hz] and each column's values.

    Raises
    ------
    DataFileError
        Unreadable file, a missing or unknown column (the known ones are listed), a column
        in another unit, a cell that is not a finite number (line and column named), a
        non-uniform time column.
    """
    from .._files import csv_rows, header_words, read_text

    path = Path(path)
    what = repr(str(path))
    rows_in = csv_rows(read_text(path, "data file"), what, max_rows=MAX_ROWS)
    first = next(rows_in, None)
    if first is None:
        raise DataFileError(f"{what} is empty")
    names = [_name(h) for h in first[1]]
    if "time" not in names:
        raise DataFileError(f"{what} has no time column (named t or time, in s); "
                            f"{header_words(first[1])}")
    for c in columns:
        if c not in names:
            raise DataFileError(f"{what} has no column {c!r}; {header_words(first[1])}")
    wanted = ["time", *columns]
    index = [names.index(c) for c in wanted]
    for c, j in zip(wanted, index, strict=True):
        accepted = ("s",) if c == "time" else (units or {}).get(c, SI_UNITS)
        check_column_unit(what, first[1][j], accepted)
    rows = []
    for lineno, row in rows_in:
        values = []
        for c, j in zip(wanted, index, strict=True):
            try:
                v = float(row[j])
            except (IndexError, ValueError):
                raise DataFileError(f"{what} line {lineno}: column {c!r} is not a "
                                    "number") from None
            if not math.isfinite(v):
                raise DataFileError(f"{what} line {lineno}: column {c!r} is {v}; NaN and "
                                    "inf are not allowed")
            values.append(v)
        rows.append(values)
    if len(rows) < 8:
        raise DataFileError(f"{str(path)!r} needs at least 8 samples, has {len(rows)}")
    data = np.array(rows)
    t = data[:, 0]
    dt = np.diff(t)
    step = float(np.median(dt))
    if not step > 0 or np.max(np.abs(dt - step)) > 1e-6 * step + 1e-12 * abs(t).max():
        i = int(np.argmax(np.abs(dt - step))) if step > 0 else 0
        raise DataFileError(f"{str(path)!r}: the time column is not uniform (step {step:g} s, "
                            f"but {dt[i]:g} s after line {i + 2})")
    return 1.0 / step, {c: data[:, k + 1] for k, c in enumerate(columns)}
