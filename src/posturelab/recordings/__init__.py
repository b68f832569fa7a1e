"""Lab recordings: uneven time columns, C3D files, and body sway from markers or plates.

* :mod:`~posturelab.recordings.resample` — a uniform grid by a cubic spline, gaps refused.
* :mod:`~posturelab.recordings.columns` — a recording's columns (CSV or C3D) as stored.
* :mod:`~posturelab.recordings.table` — the one reader of recordings: SI, a uniform grid,
  whole cycles, sway; it says what it did (:class:`Recording`).
* :mod:`~posturelab.recordings.c3d` — C3D files through ezc3d.
* :mod:`~posturelab.recordings.sway` — ``com_angle`` from markers (Winter's segments, the
  hip–shoulder approximation) or from a force plate's centre of pressure.
* :mod:`~posturelab.recordings.convert` — a recording to a posturelab CSV/Parquet table.
"""

from .resample import ResampleReport, resample_uniform
from .sway import com_angle_cop, com_angle_segments, com_angle_two_markers
from .table import Recording, TrimReport, read_recording, read_series, read_table

__all__ = ["ResampleReport", "resample_uniform", "read_series", "read_table", "read_recording",
           "Recording", "TrimReport",
           "com_angle_segments", "com_angle_two_markers", "com_angle_cop"]
