"""Reading the named columns of a recording (a CSV table or a C3D file) in SI units.

One reader for every command that takes a recording (``frf``, ``fit-frf``, ``fit``,
``convert``): :func:`read_series` finds the time column and the named columns, converts the
units the user declared (angles ``deg`` → rad, lengths ``mm`` → m; never guessed), and
either checks that the time column is uniform or, with ``resample``, puts the recording on
a uniform grid (:func:`posturelab.recordings.resample.resample_uniform`).

A CSV header may declare a column's unit in brackets (``tilt [deg]``). Without a declared
unit (``angle_unit``/``length_unit``) only SI is read: a column declaring deg or mm is
refused with a message naming the option that reads it. A ``.c3d`` file is read by
:func:`posturelab.recordings.c3d.read_c3d` (markers in m, analog channels, force plates).
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np

from .._files import check_column_unit, column_unit
from ..errors import DataFileError, ParameterError
from .resample import ResampleReport, resample_uniform, uniform_step

__all__ = ["read_series", "read_table", "SI_UNITS", "ANGLE_UNITS", "LENGTH_UNITS",
           "MAX_ROWS", "SCALE"]

#: Most data rows a series file may have. [-]
MAX_ROWS = 2_000_000  # posturelab._files.MAX_DATA_ROWS
#: Units a data column may declare in its header when no other unit is declared. [-]
SI_UNITS = ("rad", "m", "N", "N·m", "N m", "rad/s", "m/s")
#: Angle units a user may declare (``--angle-unit``). [-]
ANGLE_UNITS = ("rad", "deg")
#: Length units a user may declare (``--length-unit``). [-]
LENGTH_UNITS = ("m", "mm")
#: Factor to SI of each declarable unit. [SI unit per unit]
SCALE = {"rad": 1.0, "deg": math.pi / 180.0, "m": 1.0, "mm": 1e-3}


def _name(header: str) -> str:
    name = header.split("[")[0].strip().lower()
    return "time" if name == "t" else name


def read_table(path: str | Path, columns: list[str] | None = None, *,
               skipped: list[str] | None = None
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
    if path.suffix.lower() == ".c3d":
        from .c3d import read_c3d

        rec = read_c3d(path)
        names = list(rec.columns)
        for c in columns or []:
            if c not in rec.columns:
                raise DataFileError(f"{str(path)!r} has no column {c!r}; it has "
                                    f"{_listing(names)}")
        wanted = names if columns is None else list(columns)
        return rec.time, {c: rec.columns[c] for c in wanted}, {c: rec.units[c] for c in wanted}
    return _read_csv(path, columns, skipped)


def _listing(names: list[str], most: int = 12) -> str:
    shown = ", ".join(names[:most])
    return shown + (f", … ({len(names)} columns)" if len(names) > most else "")


def _read_csv(path: Path, columns: list[str] | None, skipped: list[str] | None = None):
    from .._files import csv_rows, header_words, read_text

    what = repr(str(path))
    rows_in = csv_rows(read_text(path, "data file"), what, max_rows=MAX_ROWS)
    first = next(rows_in, None)
    if first is None:
        raise DataFileError(f"{what} is empty")
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
    for c in wanted_cols:
        if c not in names:
            raise DataFileError(f"{what} has no column {c!r}; {header_words(first[1])}")
    wanted = ["time", *wanted_cols]
    index = [names.index(c) for c in wanted]
    check_column_unit(what, first[1][index[0]], ("s",))
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
                raise DataFileError(f"{what} line {lineno}: column {c!r} is not a "
                                    "number") from None
            if not math.isfinite(v):
                raise DataFileError(f"{what} line {lineno}: column {c!r} is {v}; NaN and "
                                    "inf are not allowed")
            values.append(v)
        rows.append(values)
    data = np.array(rows, dtype=float).reshape(len(rows), len(wanted))
    units = {c: column_unit(first[1][j]) for c, j in zip(wanted, index, strict=True)}
    units.pop("time")
    return data[:, 0], {c: data[:, k + 1] for k, c in enumerate(wanted_cols)}, units


def read_series(path: str | Path, columns: list[str],
                units: dict[str, tuple[str, ...]] | None = None, *,
                kinds: dict[str, str] | None = None, angle_unit: str = "rad",
                length_unit: str = "m", resample: float | None = None,
                max_gap: float | None = None, start: float | None = None,
                drop_partial: bool = False, cycle_length: float | None = None
                ) -> tuple[float, dict[str, np.ndarray], ResampleReport | None]:
    """The sample rate and the named columns of a recording, in SI, on a uniform grid.

    Parameters
    ----------
    path : str or Path
        A CSV (header row, a ``time`` or ``t`` column [s]) or a ``.c3d``.
    columns : list of str
        Columns to read (lower case).
    units : dict of str -> tuple of str, optional
        The SI units each column may declare in its header (default :data:`SI_UNITS`).
    kinds : dict of str -> str, optional
        ``"angle"`` or ``"length"`` per column: which declared unit applies to it.
    angle_unit, length_unit : str
        The unit of the angle (``rad``, ``deg``) and length (``m``, ``mm``) columns, as the
        user declares it; converted to rad and m. A header that declares another unit is
        refused.
    resample : float, optional
        Put the recording on a uniform grid at this rate [Hz] by a cubic spline (see
        :func:`~posturelab.recordings.resample.resample_uniform`); without it a non-uniform
        time column or a missing sample is refused.
    max_gap : float, optional
        Longest gap the resampling accepts. [s]
    start : float, optional
        Drop the samples before this time (where the stimulus's first cycle starts). [s]
    drop_partial : bool
        Drop the samples after the last whole cycle of ``cycle_length`` [s] (a recording
        that runs on past the stimulus); the cut is said on standard error.
    cycle_length : float, optional
        [s]

    Returns
    -------
    (float, dict of str -> numpy.ndarray, ResampleReport or None)
        Sample rate [Hz], each column [SI], and what the resampling did.

    Raises
    ------
    DataFileError, ParameterError
    """
    if angle_unit not in ANGLE_UNITS:
        raise ParameterError(f"angle unit must be one of {', '.join(ANGLE_UNITS)}, got "
                             f"{angle_unit!r}")
    if length_unit not in LENGTH_UNITS:
        raise ParameterError(f"length unit must be one of {', '.join(LENGTH_UNITS)}, got "
                             f"{length_unit!r}")
    path = Path(path)
    what = repr(str(path))
    time, cols, declared = read_table(path, columns)
    kinds = kinds or {}
    for c in columns:
        kind = kinds.get(c)
        given = {"angle": angle_unit, "length": length_unit}.get(kind or "")
        header = declared[c]
        if given is not None and given not in ("rad", "m") and header in ("", given):
            cols[c] = cols[c] * SCALE[given]  # declared by the user (the header agrees)
            continue
        accepted = (units or {}).get(c, SI_UNITS)
        hint = {("deg", "angle"): "; give --angle-unit deg to read degrees",
                ("mm", "length"): "; give --length-unit mm to read millimetres"}.get(
                    (header.lower(), kind or {"deg": "angle", "mm": "length"}.get(
                        header.lower(), "")), "")
        if header and header.lower() not in {a.lower() for a in accepted} and hint:
            raise DataFileError(f"{what}: column {f'{c} [{header}]'!r} is in {header}; "
                                f"posturelab reads {' or '.join(accepted)}{hint}")
        check_column_unit(what, f"{c} [{header}]" if header else c, accepted)
    if start is not None:
        keep = time >= float(start) - 1e-9
        if not keep.any():
            raise DataFileError(f"{what} ends at {time[-1]:g} s, before --start {start:g} s")
        time, cols = time[keep], {c: v[keep] for c, v in cols.items()}
    if time.size < 8:
        raise DataFileError(f"{what} needs at least 8 samples, has {time.size}")
    report = None
    if resample is not None:
        _, cols, report = resample_uniform(time, cols, resample, max_gap=max_gap, what=what)
        step = 1.0 / report.rate
    else:
        step = _uniform_or_refuse(time, cols, columns, what)
    if drop_partial:
        if cycle_length is None:
            raise ParameterError("--drop-partial needs --cycle-length")
        per = int(round(float(cycle_length) / step))
        n = next(iter(cols.values())).size
        whole = (n // per) * per if per > 0 else n
        if whole == 0:
            raise DataFileError(f"{what} holds {n * step:g} s, less than one cycle of "
                                f"{cycle_length:g} s")
        if whole < n:
            import sys

            print(f"note: {what}: dropped the last {n - whole} sample(s) "
                  f"({(n - whole) * step:.4g} s), a partial cycle", file=sys.stderr)
            cols = {c: v[:whole] for c, v in cols.items()}
    return 1.0 / step, cols, report


def _uniform_or_refuse(time: np.ndarray, cols: dict[str, np.ndarray], columns: list[str],
                       what: str) -> float:
    """The step of a uniform time column with no missing sample [s]; else refused."""
    step = uniform_step(time)
    if step is None:
        dt = np.diff(time)
        med = float(np.median(dt))
        i = int(np.argmax(np.abs(dt - med)))
        raise DataFileError(f"{what}: the time column is not uniform (step {med:g} s, but "
                            f"{dt[i]:g} s at t = {time[i]:g} s); give --resample HZ to "
                            "interpolate it onto a uniform grid")
    for c in columns:
        bad = np.flatnonzero(~np.isfinite(cols[c]))
        if bad.size:
            raise DataFileError(f"{what}: column {c!r} is missing at t = {time[bad[0]]:g} s "
                                f"({bad.size} sample(s)); give --resample HZ to fill short "
                                "gaps")
    return step
