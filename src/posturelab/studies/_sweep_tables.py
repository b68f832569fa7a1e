"""The table of a sweep: :class:`SweepResult` and its CSV / Parquet writers. Public through
:mod:`posturelab.studies.sweep`.
"""

from __future__ import annotations

import io
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import ParameterError, PostureLabError
from ..parameters import unit as parameter_unit
from ..simulation.results import atomic_write_bytes, atomic_write_text
from ._sweep_grid import OUTCOME_UNITS, SweepGrid, _steady_unit

if TYPE_CHECKING:  # (the engine loads when a sweep runs: posturelab --help stays light)
    from ..simulation.compiled import BatchResult




# ---------------------------------------------------------------------------
# Results
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class SweepResult:
    """One row per run: the varied values, then the outcomes.

    Attributes
    ----------
    grid : SweepGrid
        The runs.
    outcomes : BatchResult
        Their outcomes (row r is run r).
    """

    grid: SweepGrid
    outcomes: BatchResult

    def columns(self) -> list[tuple[str, np.ndarray]]:
        """(name, values) of every column, in table order (units: :data:`PARAMETER_UNITS`,
        :data:`OUTCOME_UNITS`)."""
        cols = [(name, self.grid.values[:, k]) for k, name in enumerate(self.grid.names)]
        o = self.outcomes
        n = o.final_state.shape[1] // 2
        cols.append(("outcome", o.outcome))
        cols.append(("failure", o.failure))
        cols.append(("fell", o.fell))
        cols.append(("fall_time", o.fall_time))
        for i in range(o.peak_theta.shape[1]):
            cols.append((f"peak_theta{i + 1}", o.peak_theta[:, i]))
        cols.append(("settling_time", o.settling_time))
        cols.append(("final_lean", np.abs(o.final_state[:, :n]).max(axis=1)))
        cols.append(("final_rate", np.abs(o.final_state[:, n:]).max(axis=1)))
        if o.steady_rms_theta is not None:  # a sustained stimulus: the steady sway
            for i in range(n):
                cols.append((f"steady_rms_theta{i + 1}", o.steady_rms_theta[:, i]))
                cols.append((f"steady_peak_theta{i + 1}", o.steady_peak_theta[:, i]))
            if o.steady_rms_cop is not None:
                cols.append(("steady_rms_cop", o.steady_rms_cop))
                cols.append(("steady_peak_cop", o.steady_peak_cop))
        return cols

    def units(self) -> dict[str, str]:
        """The unit of each column that has one."""
        varied = set(self.grid.names)
        return {name: parameter_unit(name) if name in varied
                else OUTCOME_UNITS.get(name, _steady_unit(name))
                for name, _ in self.columns()}

    def to_csv_text(self) -> str:
        """CSV: a header row, then one row per run; ``fell`` is true/false, a missing fall or
        settling time is an empty cell, numbers have 17 significant digits (exact)."""
        return table_csv_text(self.columns())

    def to_parquet_bytes(self) -> bytes:
        """The table as Parquet (pyarrow): float64 columns (NaN as null), ``fell`` boolean;
        each field's unit in its metadata."""
        return table_parquet_bytes(self.columns(), self.units())

    def write(self, path: str | Path) -> None:
        """Write the table to ``path`` (.csv or .parquet by its suffix), atomically."""
        write_table(path, self.columns(), self.units())


def table_csv_text(columns: Sequence[tuple[str, np.ndarray]]) -> str:
    """A table as CSV: a header row, then one row per entry; boolean columns are true/false,
    NaN an empty cell, numbers with 17 significant digits (exact)."""
    buf = io.StringIO()
    buf.write(",".join(name for name, _ in columns) + "\n")
    text_cols = []
    for _, values in columns:
        values = np.asarray(values)
        if values.dtype == bool:
            text_cols.append(np.where(values, "true", "false"))
        elif values.dtype.kind in "US":
            text_cols.append(values.astype(str))
        else:
            text_cols.append(np.array([_number(v) for v in values.tolist()], dtype=object))
    for row in zip(*text_cols, strict=True):
        buf.write(",".join(row) + "\n")
    return buf.getvalue()


def table_parquet_bytes(columns: Sequence[tuple[str, np.ndarray]], units: dict[str, str]
                        ) -> bytes:
    """A table as Parquet (pyarrow): float64 columns (NaN as null), boolean columns boolean;
    each field's unit (``units``) in its metadata."""
    pa, pq = _pyarrow()
    fields, arrays = [], []
    for name, values in columns:
        unit = units.get(name, "")
        if np.asarray(values).dtype == bool:
            arr = pa.array(np.asarray(values, dtype=bool))
            typ = pa.bool_()
        elif np.asarray(values).dtype.kind in "US":
            arr = pa.array(np.asarray(values).astype(str).tolist(), type=pa.string())
            typ = pa.string()
        else:
            values = np.asarray(values, dtype=float)
            arr = pa.array(values, mask=np.isnan(values), type=pa.float64())
            typ = pa.float64()
        fields.append(pa.field(name, typ, metadata={"unit": unit} if unit else None))
        arrays.append(arr)
    table = pa.Table.from_arrays(arrays, schema=pa.schema(fields))
    sink = io.BytesIO()
    pq.write_table(table, sink)
    return sink.getvalue()


def write_table(path: str | Path, columns: Sequence[tuple[str, np.ndarray]],
                units: dict[str, str]) -> None:
    """Write a table to ``path``, .csv or .parquet by its suffix, atomically (a temporary
    file renamed: nothing half-written is left)."""
    kind = table_format(path)
    if kind == "csv":
        atomic_write_text(path, table_csv_text(columns))
    else:
        atomic_write_bytes(path, table_parquet_bytes(columns, units))


def _number(v: float) -> str:
    return "" if math.isnan(v) else repr(float(v))


def _pyarrow():
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        raise PostureLabError("writing Parquet needs pyarrow: pip install pyarrow (or "
                              "'posturelab[parquet]'); or write .csv") from None
    return pa, pq


def table_format(path: str | Path) -> str:
    """'csv' or 'parquet' from the file suffix; anything else is a ParameterError."""
    suffix = Path(path).suffix.lower()
    if suffix == ".csv":
        return "csv"
    if suffix in (".parquet", ".pq"):
        return "parquet"
    raise ParameterError(f"the output file must end in .csv or .parquet, got {str(path)!r}")


