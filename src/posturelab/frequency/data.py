"""Reading the series of an identification experiment from a CSV file."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from ..errors import DataFileError

__all__ = ["read_series_csv", "MAX_ROWS"]

#: Most data rows a series file may have. [-]
MAX_ROWS = 20_000_000


def _name(header: str) -> str:
    name = header.split("[")[0].strip().lower()
    return "time" if name == "t" else name


def read_series_csv(path: str | Path, columns: list[str]) -> tuple[float, dict[str, np.ndarray]]:
    """The sample rate and the named columns of a CSV file with a header row and a uniform
    ``time`` column [s] (a ``[unit]`` suffix in a header is ignored).

    Returns
    -------
    (float, dict of str -> numpy.ndarray)
        Sample rate [Hz] and each column's values.

    Raises
    ------
    DataFileError
        Unreadable file, a missing or unknown column (the known ones are listed), a cell that
        is not a finite number (line and column named), a non-uniform time column.
    """
    path = Path(path)
    if not path.is_file():
        raise DataFileError(f"cannot read {str(path)!r}: not a regular file")
    try:
        with path.open(newline="", encoding="utf-8-sig") as fh:
            reader = csv.reader(fh)
            header = next(reader, None)
            if header is None:
                raise DataFileError(f"{str(path)!r} is empty")
            names = [_name(h) for h in header]
            if "time" not in names:
                raise DataFileError(f"{str(path)!r} has no time column; columns: "
                                    f"{', '.join(names)}")
            for c in columns:
                if c not in names:
                    raise DataFileError(f"{str(path)!r} has no column {c!r}; columns: "
                                        f"{', '.join(names)}")
            wanted = ["time", *columns]
            index = [names.index(c) for c in wanted]
            rows = []
            for lineno, row in enumerate(reader, start=2):
                if not row or not any(cell.strip() for cell in row):
                    continue
                if len(rows) >= MAX_ROWS:
                    raise DataFileError(f"{str(path)!r} has more than {MAX_ROWS:,} rows")
                values = []
                for c, j in zip(wanted, index, strict=True):
                    try:
                        v = float(row[j])
                    except (IndexError, ValueError):
                        raise DataFileError(f"{str(path)!r} line {lineno}: column {c!r} is not "
                                            "a number") from None
                    if not math.isfinite(v):
                        raise DataFileError(f"{str(path)!r} line {lineno}: column {c!r} is "
                                            f"{v}; NaN and inf are not allowed")
                    values.append(v)
                rows.append(values)
    except UnicodeDecodeError:
        raise DataFileError(f"{str(path)!r} is not a UTF-8 CSV file") from None
    except OSError as exc:
        raise DataFileError(f"cannot read {str(path)!r}: {exc.strerror or exc}") from None
    except csv.Error as exc:
        raise DataFileError(f"{str(path)!r} is not a readable CSV file: {exc}") from None
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
