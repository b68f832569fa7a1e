"""Reading the series of an identification experiment from a CSV (or C3D) recording.

The reading itself is :func:`posturelab.recordings.table.read_series` (declared units,
resampling of an uneven time column, C3D files); this module keeps the frequency package's
entry point.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._files import check_column_unit, column_unit
from ..recordings.table import MAX_ROWS, SI_UNITS, read_series

__all__ = ["read_series_csv", "column_unit", "check_column_unit", "SI_UNITS", "MAX_ROWS"]


def read_series_csv(path: str | Path, columns: list[str],
                    units: dict[str, tuple[str, ...]] | None = None, *,
                    kinds: dict[str, str] | None = None, angle_unit: str = "rad",
                    length_unit: str = "m", resample: float | None = None,
                    max_gap: float | None = None, start: float | None = None,
                    drop_partial: bool = False, cycle_length: float | None = None,
                    **options) -> tuple[float, dict[str, np.ndarray]]:
    """The sample rate and the named columns of a recording with a header row and a
    ``time`` (or ``t``) column [s] (a CSV, or a ``.c3d``).

    A header may declare a column's unit in brackets (``com [rad]``); the time column must
    then be in s and each named column in one of ``units[name]`` (default :data:`SI_UNITS`),
    unless the user declared the angles in deg or the lengths in mm (``angle_unit``,
    ``length_unit``, applying to the columns ``kinds`` names ``"angle"`` or ``"length"``).
    A non-uniform time column is refused unless ``resample`` [Hz] is given
    (:func:`posturelab.recordings.resample.resample_uniform`). ``start`` [s],
    ``drop_partial`` and ``cycle_length`` [s] cut the recording to the stimulus's whole
    cycles; ``options`` are :func:`posturelab.recordings.table.read_recording`'s others
    (``time_unit``, ``sway``). Nothing is printed: :func:`~posturelab.recordings.table.
    read_recording` returns what was resampled and cut.

    Returns
    -------
    (float, dict of str -> numpy.ndarray)
        Sample rate [Hz] and each column's values [SI].

    Raises
    ------
    DataFileError
        Unreadable file, a missing or unknown column (the known ones are listed), a column
        in another unit, a cell that is not a finite number (line and column named), a
        non-uniform time column (without ``resample``), a gap (with it).
    """
    fs, cols, _ = read_series(path, columns, units, kinds=kinds, angle_unit=angle_unit,
                              length_unit=length_unit, resample=resample, max_gap=max_gap,
                              start=start, drop_partial=drop_partial,
                              cycle_length=cycle_length, **options)
    return fs, cols
