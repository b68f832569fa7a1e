"""Reading a Parquet table as posturelab's CSV readers read a CSV: one header, one reader.

:func:`read_parquet` returns the header cells and the columns of a Parquet table; a field
whose metadata declares a ``unit`` (as ``simulate``, ``convert`` and ``sweep`` write it) and
whose name declares none gets it in brackets (``tilt`` → ``tilt [rad]``), so that a header
is parsed the same way from either format (a name such as ``tilt [deg]`` keeps its unit).
:func:`parquet_rows` gives the same table as :func:`posturelab._files.csv_rows` gives a
CSV's rows, for the readers that parse rows of cells (platform profiles, runs,
trajectories). Every reader of a table dispatches on the suffix ``.parquet`` to here.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np

from .errors import DataFileError

__all__ = ["read_parquet", "parquet_rows", "is_parquet"]


def is_parquet(path: str | Path) -> bool:
    """Whether ``path`` names a Parquet table (by its suffix)."""
    return Path(path).suffix.lower() == ".parquet"


def read_parquet(path: str | Path, what: str
                 ) -> tuple[list[str], list[np.ndarray], list[str]]:
    """The header cells, the columns (float, nulls as NaN; a column that is not numeric as
    an object array of its values as text) and each column's type name, of a Parquet
    table (its size and rows bounded as a CSV's).

    Raises
    ------
    DataFileError
        pyarrow missing, the file too large or not Parquet, a unit in a field's metadata
        contradicting the one in its name.
    """
    from ._files import MAX_DATA_ROWS, MAX_INPUT_BYTES, column_unit

    path = Path(path)
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        raise DataFileError(f"reading {what} (Parquet) needs pyarrow: pip install pyarrow, "
                            "or give a CSV") from None
    try:
        size = path.stat().st_size
        if size > MAX_INPUT_BYTES:
            raise DataFileError(f"{what} is {size:,} bytes; at most {MAX_INPUT_BYTES:,}")
        meta = pq.read_metadata(path)
        if meta.num_rows > MAX_DATA_ROWS:
            raise DataFileError(f"{what} has {meta.num_rows:,} rows; at most "
                                f"{MAX_DATA_ROWS:,}")
        table = pq.ParquetFile(path).read()  # (read_table refuses a name given twice)
    except (OSError, pa.ArrowException) as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise DataFileError(f"cannot read {what} as Parquet: {first}") from None
    header, columns, types = [], [], []
    for k, f in enumerate(table.schema):
        meta_unit = (f.metadata or {}).get(b"unit", b"").decode("utf-8", "replace").strip()
        named = column_unit(f.name)
        if meta_unit and named and meta_unit != named:
            raise DataFileError(f"{what}: column {f.name!r} declares {named} in its name and "
                                f"{meta_unit} in its metadata; which one holds is not guessed")
        header.append(f"{f.name} [{meta_unit}]" if meta_unit and not named else f.name)
        numeric = pa.types.is_floating(f.type) or pa.types.is_integer(f.type)
        col = table.column(k)
        columns.append(col.to_numpy(zero_copy_only=False).astype(float) if numeric else
                       np.array(["" if v is None else str(v) for v in col.to_pylist()],
                                dtype=object))
        types.append(str(f.type))
    return header, columns, types


def parquet_rows(path: str | Path, what: str) -> Iterator[tuple[int, list[str]]]:
    """(row number, cells) of a Parquet table as :func:`posturelab._files.csv_rows` gives a
    CSV's: the header first (units in brackets), then each row's numbers as text (exact:
    ``repr``), a null as an empty cell, other values as their text (a reader refuses them
    as it refuses such a CSV cell)."""
    header, columns, _ = read_parquet(path, what)
    yield 1, header
    if not columns:
        return

    def cell(c: np.ndarray, i: int) -> str:
        if c.dtype == object:
            return c[i]
        return "" if np.isnan(c[i]) else repr(float(c[i]))

    for i in range(columns[0].size):
        yield i + 2, [cell(c, i) for c in columns]
