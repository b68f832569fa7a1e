"""A lab recording (C3D or CSV) turned into a posturelab table: uniform time, SI columns,
and ``com_angle`` from markers or a force plate (:mod:`posturelab.recordings.sway`)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import DataFileError, ParameterError
from .columns import (
    ANGLE_UNITS,
    KNOWN_SI,
    LENGTH_UNITS,
    SCALE,
    TO_SI,
    check_start,
    check_time,
)
from .resample import ResampleReport
from .sway import AXES, SwaySpec

__all__ = ["ConvertedRecording", "convert_recording", "AXES"]


@dataclass(frozen=True)
class ConvertedRecording:
    """A recording as a posturelab table.

    Attributes
    ----------
    time : numpy.ndarray, shape (S,)
        Uniform. [s]
    columns : dict of str -> numpy.ndarray
        [each column's unit]
    units : dict of str -> str
    rate : float
        [Hz]
    notes : tuple of str
        What was done: units scaled, rates changed, resampling, the sway method (last).
    resampling : ResampleReport or None
        What the resampling did (None: not resampled).
    dropped_before : int
        Samples dropped before ``start``. [-]
    """

    time: np.ndarray
    columns: dict[str, np.ndarray]
    units: dict[str, str]
    rate: float
    notes: tuple[str, ...]
    resampling: ResampleReport | None = None
    dropped_before: int = 0

    def write(self, path: str | Path) -> None:
        """Write the table (.csv with units in the header, or .parquet with units in the
        fields' metadata), atomically."""
        from .._files import atomic_write_csv, check_output_rows
        from ..studies._sweep_grid import table_format, table_parquet_bytes

        cols = [("time", self.time), *self.columns.items()]
        units = {"time": "s", **self.units}
        fix = "a lower --rate or --resample, or --start"
        if table_format(path) == "csv":
            named = [f"{n} [{units[n]}]" if units.get(n) else n for n, _ in cols]
            atomic_write_csv(path, named, [v for _, v in cols], fix=fix)
        else:
            from .._files import atomic_write_bytes

            check_output_rows(self.time.size, f"--out {str(path)!r}", fix)
            atomic_write_bytes(path, table_parquet_bytes(cols, units))


def _axis(table: dict, label: str, axis: str, what: str,
          unusable: dict[str, str] | None = None) -> np.ndarray:
    sign = -1.0 if axis.startswith("-") else 1.0
    name = f"{label}_{axis.lstrip('-')}"
    if name in (unusable or {}):
        raise DataFileError(f"{what}: marker {label!r} cannot be used: {unusable[name]}")
    if name not in table:
        known = sorted({k.rsplit("_", 1)[0] for k in table if k.endswith(("_x", "_y", "_z"))})
        if known:
            listing = "markers (LABEL_x, LABEL_y, LABEL_z): " + ", ".join(known)
        else:
            listing = ("no marker columns (LABEL_x, LABEL_y, LABEL_z); a column holding a "
                       "marker's forward position may be named instead: "
                       + (", ".join(k for k in table if k != "time") or "none"))
        raise DataFileError(f"{what} has no marker {label!r} (column {name!r}); "
                            + listing[:300])
    return sign * table[name]


def convert_recording(path: str | Path, *, rate: float | None = None,
                      resample: float | None = None, max_gap: float | None = None,
                      angle_unit: str | None = None, length_unit: str | None = None,
                      time_unit: str = "s", angle_columns: tuple[str, ...] = (),
                      sway: str | None = None, markers: dict[str, str] | None = None,
                      plate: int = 1, forward: str = "x", up: str = "z",
                      height: float | None = None, mass: float | None = None,
                      start: float | None = None, refuse_unknown_units: bool = True
                      ) -> ConvertedRecording:
    """Read a recording and return it as a posturelab table, with ``com_angle`` if asked.

    Parameters
    ----------
    path : str or Path
        A ``.c3d`` (markers in m from POINT:UNITS) or a CSV with a ``time`` column [s].
    rate : float, optional
        C3D only: the table's rate [Hz] (default the marker rate).
    resample : float, optional
        Put an uneven time column on a uniform grid at this rate [Hz] (cubic spline).
    max_gap : float, optional
        Longest gap the resampling accepts. [s]
    angle_unit, length_unit : str, optional
        The unit of ``angle_columns`` that declare none (rad, deg; default rad), and (CSV) of
        the marker columns that declare none (m, mm; default m); converted to rad and m.
        Given where it applies to no column (no ``angle_columns`` without a declared unit;
        a C3D's or no marker columns), it is refused: it would do nothing.
    time_unit : str
        The unit of a CSV's time column (s, ms); converted to s.
    angle_columns : tuple of str
        Columns that are angles, converted to rad from the unit they declare (a C3D
        channel's ANALOG:UNITS, a CSV header's brackets) or else ``angle_unit``.
    sway : str, optional
        ``segments``, ``two-marker`` or ``cop`` (:data:`posturelab.recordings.sway.SWAY_METHODS`).
    markers : dict of str -> str, optional
        Landmark (ankle, knee, hip, shoulder) → marker label (its ``LABEL_x`` … columns), or
        for a CSV with forward positions only, the column itself.
    plate : int
        The force plate ``cop`` uses (1-based).
    forward, up : str
        The lab axes (x, y, z, with - to flip) pointing forward and up.
    height, mass : float, optional
        The subject's height [m] and mass [kg] (``cop``; ``two-marker`` on forward positions).
    start : float, optional
        Drop the samples before this time. [s]
    refuse_unknown_units : bool
        Refuse a CSV or Parquet column declaring a unit that is neither SI
        (:data:`~.columns.KNOWN_SI`) nor converted (:data:`~.columns.TO_SI`). Every column
        declaring deg, mm, deg/s or mm/s is converted to SI (said in ``notes``).

    Returns
    -------
    ConvertedRecording
    """
    from . import sway as sw
    from .c3d import read_c3d
    from .columns import read_table
    from .resample import resample_uniform, uniform_step

    path = Path(path)
    what = repr(str(path))
    start = check_start(start)
    angle_given, length_given = angle_unit is not None, length_unit is not None
    angle_unit, length_unit = angle_unit or "rad", length_unit or "m"
    if angle_given and not angle_columns:
        raise ParameterError("--angle-unit is the unit of the --angle-columns whose header "
                             "declares none (a declared unit is always converted); give "
                             "--angle-columns COL,... or leave --angle-unit out")
    if length_given and (path.suffix.lower() == ".c3d" or not markers):
        raise ParameterError("--length-unit is the unit of a CSV's marker columns (--markers) "
                             "whose header declares none; it does nothing here (a C3D's "
                             "markers are scaled from POINT:UNITS): leave it out")
    if angle_unit not in ANGLE_UNITS or length_unit not in LENGTH_UNITS:
        raise ParameterError(f"angle unit must be one of {', '.join(ANGLE_UNITS)} and length "
                             f"unit one of {', '.join(LENGTH_UNITS)}")
    for a in (forward, up):
        if a not in AXES:
            raise ParameterError(f"an axis must be one of {', '.join(AXES)}, got {a!r}")
    markers = {k.strip().lower(): v.strip().lower() for k, v in (markers or {}).items()}
    if sway is not None:  # checked before any reading
        SwaySpec(sway, tuple(markers.items()), plate, forward, up, height, mass)
    else:
        for k in markers:
            if k not in sw.LANDMARKS:
                raise ParameterError(f"unknown landmark {k!r} in --markers; known: "
                                     + ", ".join(sw.LANDMARKS))
    notes: list[str] = []
    unusable: dict[str, str] = {}
    if path.suffix.lower() == ".c3d":
        if time_unit != "s":
            raise ParameterError("--time-unit is for a CSV's time column; a C3D file's "
                                 "time comes from its frame rate")
        rec = read_c3d(path, rate=rate)
        time, cols, units = rec.time, dict(rec.columns), dict(rec.units)
        notes += list(rec.notes)
        unusable = dict(rec.unusable)
    else:
        if rate is not None:
            raise ParameterError("--sample-rate (--rate) is for C3D files; give --resample HZ "
                                 "for a CSV")
        skipped: list[str] = []
        time, cols, units = read_table(path, skipped=skipped, time_unit=time_unit)
        if skipped:
            notes.append("left out (not numbers): " + ", ".join(skipped))
        if length_unit == "mm":
            for label in markers.values():
                for name in [label] + [f"{label}_{a}" for a in "xyz"]:
                    if name in cols and units.get(name, "") in ("", "mm"):
                        cols[name] = cols[name] * SCALE["mm"]
                        units[name] = "m"
            notes.append("marker columns from mm to m")
    if angle_given and all(units.get(c) for c in angle_columns if c in cols):
        c = next(c for c in angle_columns if c in cols) if any(
            c in cols for c in angle_columns) else None
        if c is not None:
            raise ParameterError(f"--angle-unit {angle_unit} does nothing: every "
                                 f"--angle-columns column declares its unit ({c!r} is in "
                                 f"{units[c]}, converted as declared); leave it out")
    for c in angle_columns:
        if c not in cols:
            raise DataFileError(f"{what} has no column {c!r} (--angle-columns); columns: "
                                + ", ".join(cols)[:300])
        unit = units.get(c) or angle_unit
        if unit not in ANGLE_UNITS:
            raise DataFileError(f"{what}: column {c!r} is in {unit!r}, not an angle unit "
                                f"({', '.join(ANGLE_UNITS)})")
        if unit == "deg":
            cols[c] = cols[c] * SCALE["deg"]
            notes.append(f"{c} from deg to rad")
        units[c] = "rad"
    _declared_to_si(cols, units, notes, what,
                    refuse_unknown_units and path.suffix.lower() != ".c3d")
    check_time(time, what)
    dropped = 0
    if start is not None:
        keep = time >= float(start) - 1e-9
        if keep.sum() < 8:
            raise DataFileError(f"{what} has fewer than 8 samples from --start {start:g} s "
                                f"(it ends at {time[-1]:g} s)")
        dropped = int((~keep).sum())
        time, cols = time[keep], {c: v[keep] for c, v in cols.items()}
        notes.append(f"{dropped} sample(s) before {start:g} s dropped")
    report = None
    if resample is not None:
        time, cols, report = resample_uniform(time, cols, resample, max_gap=max_gap,
                                              what=what)
        notes.append(report.text())
    elif uniform_step(time) is None:
        dt = np.diff(time)
        i = int(np.argmax(np.abs(dt - np.median(dt))))
        raise DataFileError(f"{what}: the time column is not uniform (step "
                            f"{np.median(dt):g} s, but {dt[i]:g} s at t = {time[i]:g} s); "
                            "give --resample HZ to interpolate it onto a uniform grid")
    step = float(np.median(np.diff(time)))
    if sway is not None:
        cols["com_angle"] = _sway(sway, cols, markers, plate, forward, up, height, mass,
                                  1.0 / step, what, unusable)
        units["com_angle"] = "rad"
        notes.append(f"com_angle by the {sway} method: {sw.SWAY_METHODS[sway]}")
    elif unusable:
        notes.append("left out: " + "; ".join(f"{k} ({v})" for k, v in unusable.items()))
    return ConvertedRecording(time=time, columns=cols, units=units, rate=1.0 / step,
                              notes=tuple(notes), resampling=report, dropped_before=dropped)


def _declared_to_si(cols: dict, units: dict, notes: list, what: str, strict: bool) -> None:
    """Every column declaring deg, mm, deg/s or mm/s converted to SI (a note each); with
    ``strict`` a unit neither SI nor converted is refused (a C3D's other units, e.g. an
    analog channel's V, are kept as declared)."""
    for c in list(cols):
        unit = units.get(c, "")
        if not unit:
            continue
        si, factor = TO_SI.get(unit, TO_SI.get(unit.lower(), ("", 1.0)))
        if si:
            cols[c] = cols[c] * factor
            units[c] = si
            notes.append(f"{c} from {unit} to {si}")
        elif strict and unit not in KNOWN_SI:
            raise DataFileError(f"{what}: column {f'{c} [{unit}]'!r} is in {unit}, which "
                                "posturelab neither reads nor converts (it converts deg, mm, "
                                "deg/s and mm/s; reads " + ", ".join(KNOWN_SI[:9])
                                + "): convert the column to SI")


def _sway(method, cols, markers, plate, forward, up, height, mass, rate, what, unusable):
    from . import sway as sw

    need = sw.NEEDS[method]
    if method == "cop":
        name = f"fp{plate}_cop{forward.lstrip('-')}"
        if name not in cols:
            raise DataFileError(f"{what} has no force plate {plate} (column {name!r})")
        sign = -1.0 if forward.startswith("-") else 1.0
        return sw.com_angle_cop(sign * cols[name], rate, height=height, mass=mass)

    def point(landmark):
        label = markers[landmark]
        if label in cols:  # a forward position only
            return cols[label]
        return np.stack([_axis(cols, label, forward, what, unusable),
                         _axis(cols, label, up, what, unusable)], axis=1)

    if method == "segments":
        return sw.com_angle_segments(*(point(n) for n in need))
    ankle = point("ankle") if "ankle" in markers else None
    return sw.com_angle_two_markers(point("hip"), point("shoulder"), ankle, height=height)
