"""The columns of a recording (a CSV table or a C3D file) as stored.

:func:`read_table` finds the time column [s] and the named columns of a CSV or C3D file,
refusing what cannot be read unambiguously (other separators, decimal commas, a column
named twice, a time unit not declared); :func:`posturelab.recordings.table.read_recording`
(the one reader every command uses) builds on it: declared units, resampling, the cut to
whole cycles, sway.

A CSV header may declare a column's unit in brackets (``tilt [deg]``). Without a declared
unit (``angle_unit``/``length_unit``) only SI is read: a column declaring deg or mm is
refused with a message naming the option that reads it. A ``.c3d`` file is read by
:func:`posturelab.recordings.c3d.read_c3d` (markers in m, analog channels, force plates).
"""

from __future__ import annotations

import io
import itertools
import math
import re
from pathlib import Path

import numpy as np

from .._files import check_column_unit, column_unit
from ..errors import DataFileError, ParameterError

__all__ = ["read_table", "check_time", "check_start", "check_time_steps", "SI_UNITS",
           "ANGLE_UNITS", "LENGTH_UNITS",
           "TIME_UNITS", "MAX_ROWS", "SCALE", "TO_SI", "KNOWN_SI"]

#: Most data rows a series file may have. [-]
MAX_ROWS = 2_000_000  # posturelab._files.MAX_DATA_ROWS
#: Units a data column may declare in its header when no other unit is declared. [-]
SI_UNITS = ("rad", "m", "N", "N·m", "N m", "rad/s", "m/s")
#: Angle units a user may declare (``--angle-unit``). [-]
ANGLE_UNITS = ("rad", "deg")
#: Length units a user may declare (``--length-unit``). [-]
LENGTH_UNITS = ("m", "mm")
#: Time units a user may declare for a CSV's time column (``--time-unit``). [-]
TIME_UNITS = ("s", "ms")
#: Factor to SI of each declarable unit. [SI unit per unit]
SCALE = {"rad": 1.0, "deg": math.pi / 180.0, "m": 1.0, "mm": 1e-3, "s": 1.0, "ms": 1e-3}
#: Units a column may declare that ``convert`` turns into SI: unit -> (SI unit, factor). [-]
TO_SI = {"deg": ("rad", SCALE["deg"]), "mm": ("m", SCALE["mm"]),
         "deg/s": ("rad/s", SCALE["deg"]), "mm/s": ("m/s", SCALE["mm"])}
#: SI (and dimensionless) units a column may declare as they stand. [-]
KNOWN_SI = SI_UNITS + ("s", "m/s²", "m/s^2", "m/s2", "rad/s²", "rad/s^2", "kg", "V", "-",
                       "1", "%")


def _name(header: str) -> str:
    name = header.split("[")[0].strip().lower()
    return "time" if name == "t" else name


def read_table(path: str | Path, columns: list[str] | None = None, *,
               skipped: list[str] | None = None, time_unit: str = "s",
               notes: list[str] | None = None
               ) -> tuple[np.ndarray, dict[str, np.ndarray], dict[str, str]]:
    """The time column and the named columns of a CSV or C3D recording, as stored.

    Parameters
    ----------
    path : str or Path
        A CSV with a header row and a ``time`` (or ``t``) column [s], or a ``.c3d``.
    columns : list of str, optional
        The columns wanted (default all numeric ones; names are case-insensitive).
    skipped : list, optional
        With ``columns`` None, receives the names of the CSV columns left out because their
        first value is not a number (labels, comments).
    time_unit : str
        The unit of a CSV's time column, ``s`` or ``ms`` (converted to s); a header that
        declares another is refused. A C3D file's time comes from its rate.
    notes : list, optional
        Receives what reading a C3D file did (units scaled, rates changed, samples filled).

    Returns
    -------
    (numpy.ndarray, dict of str -> numpy.ndarray, dict of str -> str)
        Time [s]; each column's values (NaN where a CSV cell is empty); each column's
        declared unit ("" when none).

    Raises
    ------
    DataFileError
        Unreadable file, no time column, a missing column (the known ones listed), a cell
        that is not a number (line and column named).
    """
    path = Path(path)
    if time_unit not in TIME_UNITS:
        raise ParameterError(f"time unit must be one of {', '.join(TIME_UNITS)}, got "
                             f"{time_unit!r}")
    if path.suffix.lower() == ".c3d":
        from .c3d import read_c3d

        if time_unit != "s":
            raise ParameterError("--time-unit is for a CSV's time column; a C3D file's time "
                                 "comes from its frame rate")
        rec = read_c3d(path)
        if notes is not None:
            notes.extend(rec.notes)
        names = list(rec.columns)
        for c in columns or []:
            if c in rec.unusable:
                raise DataFileError(f"{str(path)!r}: column {c!r} cannot be used: "
                                    f"{rec.unusable[c]}")
            if c not in rec.columns:
                raise DataFileError(f"{str(path)!r} has no column {c!r}; it has "
                                    f"{_listing(names)}")
        wanted = names if columns is None else list(columns)
        return rec.time, {c: rec.columns[c] for c in wanted}, {c: rec.units[c] for c in wanted}
    if path.suffix.lower() == ".parquet":
        return _read_parquet(path, columns, skipped, time_unit)
    return _read_csv(path, columns, skipped, time_unit)


def _refuse_other_separators(header: list[str], what: str) -> None:
    """Refuse a header separated by semicolons or tabs (a spreadsheet's export in a locale
    with decimal commas): posturelab reads comma-separated values with decimal points."""
    for sep, name in ((";", "semicolons"), ("\t", "tabs")):
        if len(header) == 1 and sep in header[0] or (
                sum(sep in h for h in header) >= max(1, len(header) // 2) and sep in
                "".join(header)):
            raise DataFileError(f"{what} is separated by {name}; posturelab reads "
                                "comma-separated values with decimal points: export it as "
                                "CSV with ',' between columns and '.' in numbers")


def _refuse_decimal_commas(text: str, what: str) -> None:
    """Refuse a file whose first data line has more fields than its header and a number with
    a decimal comma (``0,5``): its columns cannot be told apart."""
    import csv

    lines = [ln for ln in itertools.islice(io.StringIO(text), 50) if ln.strip()][:2]
    if len(lines) < 2 or ";" in lines[0] or not re.search(r"\d,\d", lines[1]):
        return
    try:
        head, row = list(csv.reader(lines))[:2]
    except (csv.Error, ValueError):
        return  # (csv_rows says what is wrong)
    if len(row) > len(head):
        raise DataFileError(f"{what}: its first data line has more fields than its header: "
                            "decimal commas? posturelab reads comma-separated values with "
                            "decimal points")


def _listing(names: list[str], most: int = 12) -> str:
    shown = ", ".join(names[:most])
    return shown + (f", … ({len(names)} columns)" if len(names) > most else "")


def _read_csv(path: Path, columns: list[str] | None, skipped: list[str] | None = None,
              time_unit: str = "s"):
    from .._files import csv_rows, header_words, read_text

    what = repr(str(path))
    text = read_text(path, "data file")
    _refuse_decimal_commas(text, what)
    rows_in = csv_rows(text, what, max_rows=MAX_ROWS)
    first = next(rows_in, None)
    if first is None:
        raise DataFileError(f"{what} is empty")
    _refuse_other_separators(first[1], what)
    names = [_name(h) for h in first[1]]
    if "time" not in names:
        raise DataFileError(f"{what} has no time column (named t or time, in s); "
                            f"{header_words(first[1])}")
    first_row = next(rows_in, None)
    if columns is None:  # every column whose first value is a number
        wanted_cols = []
        for j, n in enumerate(names):
            if n == "time" or n in wanted_cols:
                continue
            cell = first_row[1][j].strip() if first_row and j < len(first_row[1]) else ""
            try:
                float(cell) if cell else None
                wanted_cols.append(n)
            except ValueError:
                if skipped is not None:
                    skipped.append(n)
    else:
        wanted_cols = list(columns)
    if first_row is not None:
        rows_in = itertools.chain([first_row], rows_in)
    wanted = ["time", *wanted_cols]
    index = _indices(what, first[1], names, wanted, header_words(first[1]))
    _check_time_header(what, first[1][index[0]], time_unit)
    rows = []
    for lineno, row in rows_in:
        values = []
        for c, j in zip(wanted, index, strict=True):
            cell = row[j].strip() if j < len(row) else None
            if cell == "" and c != "time":
                values.append(math.nan)  # a missing sample: resampling may fill it
                continue
            try:
                v = float(cell)  # type: ignore[arg-type]
            except (TypeError, ValueError):
                comma = (" (a decimal comma? posturelab reads decimal points)"
                         if cell and re.fullmatch(r"[-+]?\d+,\d+", cell) else "")
                raise DataFileError(f"{what} line {lineno}: column {c!r} is not a "
                                    f"number{comma}") from None
            if not math.isfinite(v):
                raise DataFileError(f"{what} line {lineno}: column {c!r} is {v}; NaN and "
                                    "inf are not allowed")
            values.append(v)
        rows.append(values)
    data = np.array(rows, dtype=float).reshape(len(rows), len(wanted))
    units = {c: column_unit(first[1][j]) for c, j in zip(wanted, index, strict=True)}
    units.pop("time")
    check_time_steps(what, data[:, 0], first[1][index[0]], time_unit)
    return (data[:, 0] * SCALE[time_unit],
            {c: data[:, k + 1] for k, c in enumerate(wanted_cols)}, units)


def _indices(what: str, header: list[str], names: list[str], wanted: list[str],
             listing: str) -> list[int]:
    """The header index of each wanted column; a missing one or one named twice refused
    (CSV and Parquet alike)."""
    for c in wanted:
        if c not in names:
            raise DataFileError(f"{what} has no column {c!r}; {listing}")
        if names.count(c) > 1:
            where = [j + 1 for j, n in enumerate(names) if n == c]
            raise DataFileError(f"{what}: the header names {c!r} {len(where)} times (columns "
                                f"{', '.join(map(str, where))}); which one is meant is not "
                                "guessed")
    return [names.index(c) for c in wanted]


def _check_time_header(what: str, header: str, time_unit: str) -> None:
    """The time column's declared unit agrees with ``time_unit`` (ms needs --time-unit ms)."""
    if column_unit(header) == "ms" and time_unit != "ms":
        raise DataFileError(f"{what}: column {header.strip()!r} is in ms; posturelab reads "
                            "time in s: give --time-unit ms to read it (converted to s)")
    check_column_unit(what, header, (time_unit,))


#: Fewest samples before a time column's steps are judged (:func:`check_time_steps`). [-]
MIN_SAMPLES_JUDGED = 20


def check_time_steps(what: str, time: np.ndarray, header: str, time_unit: str = "s") -> None:
    """Refuse a time column that declares no unit, is read in s, and steps by whole numbers
    of at least 1 s (a recording at 1 Hz or slower): a lab recording's time in ms read as s.
    Declaring the unit in the header (``time [s]``) reads it as it stands."""
    if column_unit(header) or time_unit != "s" or time.size < MIN_SAMPLES_JUDGED:
        return
    dt = np.diff(time)
    step = float(np.median(dt))
    if step >= 1.0 and np.all(np.abs(dt - np.round(dt)) <= 1e-9 * np.maximum(1.0, dt)):
        raise DataFileError(f"{what}: the time column steps by {step:g} (a {1 / step:.3g} Hz "
                            "recording if in s): is it in ms? give --time-unit ms (or "
                            f"declare '{header.strip()} [s]' in the header to read it in s)")


def _read_parquet(path: Path, columns: list[str] | None, skipped: list[str] | None = None,
                  time_unit: str = "s"):
    """A Parquet table (as ``convert``, ``simulate`` and ``sweep`` write it: each field's
    unit in its metadata ``unit``, or in its name as a CSV header declares it), read like a
    CSV (:mod:`posturelab._parquet` gives its header): a ``time`` or ``t`` column, nulls as
    NaN (missing samples), NaN or inf values refused, a column named twice refused."""
    from .._parquet import read_parquet

    what = repr(str(path))
    header, data, types = read_parquet(path, what)
    names = [_name(h) for h in header]
    listing = f"columns: {_listing(names)}"
    if "time" not in names:
        raise DataFileError(f"{what} has no time column (named t or time, in s); {listing}")
    if columns is None:
        wanted_cols = []
        for n, d in zip(names, data, strict=True):
            if n == "time" or n in wanted_cols:
                continue
            if d.dtype != object:
                wanted_cols.append(n)
            elif skipped is not None:
                skipped.append(n)
    else:
        wanted_cols = list(columns)
    wanted = ["time", *wanted_cols]
    index = _indices(what, header, names, wanted, listing)
    _check_time_header(what, header[index[0]], time_unit)
    units, out = {}, {}
    for c, j in zip(wanted, index, strict=True):
        values = data[j]
        if values.dtype == object:
            raise DataFileError(f"{what}: column {c!r} is {types[j]}, not a number")
        bad = np.flatnonzero(np.isinf(values) | (np.isnan(values) & (c == "time")))
        if bad.size:
            raise DataFileError(f"{what} row {int(bad[0]) + 1}: column {c!r} is "
                                f"{values[bad[0]]}; NaN and inf are not allowed")
        units[c], out[c] = column_unit(header[j]), values
    units.pop("time")
    time = out.pop("time")
    check_time_steps(what, time, header[index[0]], time_unit)
    return time * SCALE[time_unit], out, units


def check_time(time: np.ndarray, what: str) -> None:
    """Refuse a time column that repeats a time stamp or goes backwards (naming where)."""
    dt = np.diff(time)
    bad = np.flatnonzero(dt <= 0)
    if bad.size:
        i = int(bad[0])
        if dt[i] == 0:
            raise DataFileError(f"{what}: the time stamp {time[i]:g} s is repeated (samples "
                                f"{i + 1} and {i + 2}); drop the duplicated rows")
        raise DataFileError(f"{what}: the time column goes backwards at sample {i + 2} "
                            f"({time[i]:g} s, then {time[i + 1]:g} s); sort it or split "
                            "the recording")


#: Latest --start accepted. [s]
MAX_START = 1e7


def check_start(start: float | None) -> float | None:
    """``--start`` [s] checked: None, or a finite time in [0, :data:`MAX_START`] s."""
    if start is None:
        return None
    from .._validation import float_in_range

    return float_in_range("--start [s]", start, 0.0, MAX_START, unit="s")
