"""C3D motion-capture files, read (and written, for examples and tests) with ezc3d.

:func:`read_c3d` reads a C3D file with `ezc3d <https://github.com/pyomeca/ezc3d>`_ (Michaud &
Begon 2021, J Open Source Softw 6(58):2911, doi:10.21105/joss.02911) and returns one table
on one uniform time grid: every marker as ``LABEL_x``, ``LABEL_y``, ``LABEL_z`` in metres
(scaled from the file's ``POINT:UNITS``, mm or m), every analog channel by its label (in
the unit of ``ANALOG:UNITS``), and each force plate ``k`` as ``fpk_fx``, ``fpk_fy``,
``fpk_fz`` [N] and its centre of pressure ``fpk_copx``, ``fpk_copy``, ``fpk_copz`` [m]
(ezc3d's force-platform extraction, in the lab frame). Labels are lower-cased; characters
other than letters, digits and ``_`` become ``_``.

Rates: the table is at the marker rate unless another ``rate`` is asked for. Analog
channels (and plates) are brought to it by scipy's ``resample_poly`` (a zero-phase FIR
low-pass, Kaiser window, the ends extended by a line) when the analog rate is an integer
multiple of it, else by a cubic spline; markers, when the rate differs from theirs, by a
cubic spline. A marker missing in some frames (NaN in ezc3d) is filled by the same spline
when the gap is at most :data:`posturelab.recordings.resample.MAX_GAP_STEPS` frames, else
left out of the table (its reason kept in :attr:`C3DRecording.unusable`, said when the
marker is asked for), as is a marker occluded throughout and an analog channel with
missing (NaN) samples that cannot be filled. Labels are made unique (an
empty label becomes ``analogN``/``markerN``, a repeated one gets ``_2``, ``_3``). Time
starts at 0 at the first frame, and the table covers the whole record: ``F`` frames at
``f`` Hz are ``F / f`` seconds, ``round(F / f × rate)`` samples. A file with fewer than 2
frames is refused, and so is a ``rate`` above the file's highest (marker or analog) rate,
a table of more than :data:`MAX_TABLE_SAMPLES` samples per column or
:data:`MAX_TABLE_CELLS` values.

A truncated file is refused: ezc3d reads as many frames as a cut file holds, so the data
size the header announces is checked against the file's size first.
"""

from __future__ import annotations

import re
import struct
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import DataFileError, PostureLabError
from .resample import MAX_GAP_STEPS, RATE_RANGE, resample_uniform, samples_over

__all__ = ["C3DRecording", "read_c3d", "write_c3d", "EZC3D_CITATION"]

EZC3D_CITATION = ("Michaud B, Begon M (2021) ezc3d: An easy C3D file I/O cross-platform "
                  "solution for C++, Python and MATLAB. J Open Source Softw 6(58):2911, "
                  "doi:10.21105/joss.02911")
#: Length units of POINT:UNITS and their factor to metres. [m per unit]
LENGTH_FACTORS = {"mm": 1e-3, "cm": 1e-2, "m": 1.0}
#: Largest C3D file read. [bytes]
MAX_C3D_BYTES = 512 * 2**20
#: Most samples per column of the table (bounds memory when --rate raises the rate). [-]
MAX_TABLE_SAMPLES = 2_000_000
#: Most values (samples × columns) of the table: 400 MB of float64. [-]
MAX_TABLE_CELLS = 50_000_000


@dataclass(frozen=True)
class C3DRecording:
    """The contents of a C3D file as one table.

    Attributes
    ----------
    time : numpy.ndarray, shape (S,)
        Uniform, from 0. [s]
    columns : dict of str -> numpy.ndarray, shape (S,)
        Markers [m], analog channels [their ANALOG:UNITS], plate forces [N] and centres of
        pressure [m].
    units : dict of str -> str
        Each column's unit.
    rate : float
        The table's sample rate. [Hz]
    point_rate, analog_rate : float
        The file's marker and analog rates. [Hz]
    markers, analogs : tuple of str
        The (cleaned) marker and analog labels.
    plates : int
        Force plates read. [-]
    notes : tuple of str
        What was done (units scaled, rates changed, samples filled, labels renamed).
    unusable : dict of str -> str
        Columns left out (markers occluded for longer than the accepted gap, analog
        channels with unfillable missing samples) and why.
    """

    time: np.ndarray
    columns: dict[str, np.ndarray]
    units: dict[str, str]
    rate: float
    point_rate: float
    analog_rate: float
    markers: tuple[str, ...]
    analogs: tuple[str, ...]
    plates: int
    notes: tuple[str, ...] = field(default=())
    unusable: dict[str, str] = field(default_factory=dict)


def _ezc3d():
    try:
        import ezc3d
    except ImportError:
        raise PostureLabError("reading C3D files needs ezc3d: pip install ezc3d (or "
                              "'posturelab[c3d]')") from None
    return ezc3d


def _clean(label: str) -> str:
    return re.sub(r"[^0-9a-z_]", "_", str(label).strip().lower())


def _unique(labels: list[str], empty: str, taken: set[str], notes: list[str]) -> tuple:
    """Cleaned labels, each unique (and not in ``taken``): an empty one becomes
    ``{empty}{k}`` (k from 1), a repeated one gets ``_2``, ``_3``; renames said in
    ``notes``."""
    out: list[str] = []
    for k, raw in enumerate(labels, start=1):
        name = _clean(raw) or f"{empty}{k}"
        base, n = name, 1
        while name in taken:
            n += 1
            name = f"{base}_{n}"
        if name != _clean(raw):
            notes.append(f"{empty} {k} labelled {str(raw).strip()!r} read as {name!r}")
        taken.add(name)
        out.append(name)
    return tuple(out)


def _check_size(path: Path, what: str) -> None:
    """Refuse a file shorter than the data its header announces (ezc3d would read the
    frames it holds and say nothing)."""
    size = path.stat().st_size
    if size > MAX_C3D_BYTES:
        raise DataFileError(f"{what} is {size} bytes, more than the {MAX_C3D_BYTES} read")
    with open(path, "rb") as f:
        head = f.read(512)
    if len(head) < 512 or head[1] != 0x50:
        raise DataFileError(f"{what} is not a C3D file (no C3D header)")
    n_points, n_analog, first, last = struct.unpack("<HHHH", head[2:10])
    scale = struct.unpack("<f", head[12:16])[0]
    data_start = struct.unpack("<H", head[16:18])[0]
    if last == 0xFFFF or last < first or data_start == 0:
        return  # a long file counts its frames elsewhere (TRIAL): leave it to ezc3d
    word = 4 if scale < 0 else 2
    need = (data_start - 1) * 512 + (last - first + 1) * (4 * n_points + n_analog) * word
    if size < need:
        raise DataFileError(f"{what} is truncated: its header announces {last - first + 1} "
                            f"frames ({need} bytes) but the file has {size} bytes")


def _to_rate(t_in: np.ndarray, values: np.ndarray, grid: np.ndarray, ratio: float,
             what: str, name: str) -> np.ndarray:
    """Values sampled at ``t_in`` brought to ``grid``: decimation when ``ratio`` (input
    rate / output rate) is an integer > 1 and the grids line up, else a cubic spline."""
    from scipy.signal import resample_poly

    r = int(round(ratio))
    if r > 1 and abs(ratio - r) < 1e-9 and np.all(np.isfinite(values)):
        # a zero-phase FIR low-pass (Kaiser window), the record extended by a line at each
        # end so that its edges make no transient; output k is input k·r
        out = resample_poly(values, 1, r, padtype="line")
        return out[:grid.size]
    if r == 1 and abs(ratio - 1) < 1e-9 and np.all(np.isfinite(values)):
        return values[:grid.size]
    _, cols, _ = resample_uniform(t_in, {name: values}, 1.0 / (grid[1] - grid[0]),
                                  what=what)
    return cols[name][:grid.size]


def read_c3d(path: str | Path, rate: float | None = None) -> C3DRecording:
    """Read a C3D file into one table of SI columns on a uniform time grid.

    Parameters
    ----------
    path : str or Path
    rate : float, optional
        The table's sample rate [Hz] (default: the marker rate).

    Returns
    -------
    C3DRecording

    Raises
    ------
    DataFileError
        Not a C3D file, a truncated one, an unknown POINT:UNITS, a marker missing for
        longer than the accepted gap.
    """
    from .._files import refuse_non_regular
    from .._validation import float_in_range

    path = Path(path)
    what = repr(str(path))
    if not path.exists():
        raise DataFileError(f"{what} does not exist")
    refuse_non_regular(path, DataFileError)
    _check_size(path, what)
    ezc3d = _ezc3d()
    try:
        c = ezc3d.c3d(str(path), extract_forceplat_data=True)
    except Exception as e:  # ezc3d raises OSError, ValueError, RuntimeError
        raise DataFileError(f"{what} could not be read as C3D: "
                            f"{str(e).splitlines()[0] if str(e) else type(e).__name__}"
                            ) from None
    params = c["parameters"]
    point_rate = float(c["header"]["points"]["frame_rate"])
    analog_rate = float(c["header"]["analogs"]["frame_rate"] or 0.0)
    points = np.asarray(c["data"]["points"], dtype=float)
    n_frames = points.shape[2]
    if n_frames < 2 or not point_rate > 0:
        raise DataFileError(f"{what} has {n_frames} frame(s) at {point_rate:g} Hz; needs at "
                            "least 2")
    highest = max(point_rate, analog_rate)
    kind = "analog" if analog_rate > point_rate else "marker"
    out_rate = point_rate if rate is None else float_in_range(
        f"--rate [Hz] for {what} (at most its highest rate, {kind} {highest:g} Hz: a rate "
        "above it adds no information)", rate, RATE_RANGE[0], min(highest, RATE_RANGE[1]),
        unit="Hz")
    t_points = np.arange(n_frames) / point_rate
    duration = n_frames / point_rate  # each frame stands for 1 / point_rate
    n_out = samples_over(duration, out_rate)
    if n_out > MAX_TABLE_SAMPLES:
        raise DataFileError(f"{what}: {duration:g} s at --rate {out_rate:g} Hz is {n_out:,} "
                            f"samples per column; at most {MAX_TABLE_SAMPLES:,} are made "
                            f"(--rate at most {MAX_TABLE_SAMPLES / duration:.6g} Hz for this "
                            "file)")
    n_analog = int(np.asarray(c["data"]["analogs"]).shape[1]) if np.asarray(
        c["data"]["analogs"]).ndim == 3 else 0
    cells = n_out * (3 * points.shape[1] + n_analog + 6 * len(c["data"].get("platform", [])
                                                             or []))
    if cells > MAX_TABLE_CELLS:
        raise DataFileError(f"{what}: {duration:g} s at {out_rate:g} Hz is {n_out:,} samples "
                            f"× {cells // n_out} columns = {cells:,} values; at most "
                            f"{MAX_TABLE_CELLS:,} are made (bounds memory; a lower --rate)")
    grid = np.arange(n_out) / out_rate
    columns: dict[str, np.ndarray] = {}
    units: dict[str, str] = {}
    notes: list[str] = []
    unusable: dict[str, str] = {}
    unit_words = [str(u).strip().lower() for u in params["POINT"].get("UNITS", {}).get(
        "value", [])] or ["mm"]
    markers = _unique(list(params["POINT"]["LABELS"]["value"])[:points.shape[1]], "marker",
                      set(), notes)
    if markers:
        if unit_words[0] not in LENGTH_FACTORS:
            raise DataFileError(f"{what}: POINT:UNITS is {unit_words[0]!r}; posturelab reads "
                                f"{', '.join(LENGTH_FACTORS)}")
        factor = LENGTH_FACTORS[unit_words[0]]
        notes.append(f"markers scaled from {unit_words[0]} (POINT:UNITS) to m"
                     + (f", from {point_rate:g} Hz to {out_rate:g} Hz by a cubic spline"
                        if out_rate != point_rate else ""))
        gap = MAX_GAP_STEPS / point_rate
        for j, label in enumerate(markers):
            for a, axis in enumerate("xyz"):
                v = points[a, j] * factor
                name = f"{label}_{axis}"
                if np.isfinite(v).all() and out_rate == point_rate:
                    columns[name] = v
                elif not np.isfinite(v).any():
                    unusable[name] = "the marker is missing (occluded) in every frame"
                    continue
                else:
                    try:
                        _, filled, report = resample_uniform(
                            t_points, {name: v}, out_rate, max_gap=gap, what=what,
                            gap_words=f"{MAX_GAP_STEPS:g} frames")
                    except DataFileError as e:
                        unusable[name] = str(e).removeprefix(f"{what}: ")
                        continue
                    columns[name] = filled[name][:n_out]
                    if report.filled:
                        notes.append(f"{name}: {report.filled} missing frame(s) filled by a "
                                     "cubic spline")
                units[name] = "m"
    analogs = np.asarray(c["data"]["analogs"], dtype=float)
    n_channels = analogs.shape[1] if analogs.ndim == 3 else 0
    raw = list(params["ANALOG"].get("LABELS", {}).get("value", []))[:n_channels]
    raw += [""] * (n_channels - len(raw))  # a channel without a label
    labels = _unique(raw, "analog", {f"{m}_{a}" for m in markers for a in "xyz"}, notes)
    analog_units = list(params["ANALOG"].get("UNITS", {}).get("value", []))
    if analogs.size and labels and analog_rate > 0:
        t_an = np.arange(analogs.shape[2]) / analog_rate
        for j, label in enumerate(labels):
            try:
                columns[label] = _to_rate(t_an, analogs[0, j], grid, analog_rate / out_rate,
                                          what, label)
            except DataFileError as e:  # a channel with missing samples: left out
                unusable[label] = str(e).removeprefix(f"{what}: ")
                continue
            units[label] = str(analog_units[j]).strip() if j < len(analog_units) else ""
        if analog_rate != out_rate:
            notes.append(f"analog channels from {analog_rate:g} Hz to {out_rate:g} Hz")
    plates = c["data"].get("platform", []) or []
    for k, plate in enumerate(plates, start=1):
        pos = LENGTH_FACTORS.get(str(plate.get("unit_position", "mm")).strip().lower(), 1e-3)
        force = np.asarray(plate["force"], dtype=float)
        cop = np.asarray(plate["center_of_pressure"], dtype=float) * pos
        t_pl = np.arange(force.shape[1]) / (analog_rate or point_rate)
        ratio = (analog_rate or point_rate) / out_rate
        for a, axis in enumerate("xyz"):
            columns[f"fp{k}_f{axis}"] = _to_rate(t_pl, force[a], grid, ratio, what,
                                                 f"fp{k}_f{axis}")
            units[f"fp{k}_f{axis}"] = "N"
            columns[f"fp{k}_cop{axis}"] = _to_rate(t_pl, np.nan_to_num(cop[a]), grid, ratio,
                                                   what, f"fp{k}_cop{axis}")
            units[f"fp{k}_cop{axis}"] = "m"
    n = min([n_out, *(v.size for v in columns.values())])
    return C3DRecording(time=grid[:n], columns={k: v[:n] for k, v in columns.items()},
                        units=units, rate=out_rate, point_rate=point_rate,
                        analog_rate=analog_rate, markers=markers,
                        analogs=labels, plates=len(plates), notes=tuple(notes),
                        unusable=unusable)


def write_c3d(path: str | Path, markers: dict[str, np.ndarray], point_rate: float, *,
              analogs: dict[str, np.ndarray] | None = None, analog_rate: float | None = None,
              analog_units: dict[str, str] | None = None, point_units: str = "mm") -> None:
    """Write a small C3D file (for examples and tests), atomically.

    Parameters
    ----------
    markers : dict of str -> numpy.ndarray, shape (F, 3)
        Marker positions per frame. [m] (stored in ``point_units``)
    point_rate : float
        [Hz]
    analogs : dict of str -> numpy.ndarray, shape (F * r,), optional
        Analog channels at ``analog_rate`` = r × ``point_rate``. [their units]
    analog_rate : float, optional
        [Hz] (default ``point_rate``)
    analog_units : dict of str -> str, optional
    point_units : str
        ``mm`` (default) or ``m``.
    """
    ezc3d = _ezc3d()
    c = ezc3d.c3d()
    names = list(markers)
    frames = len(next(iter(markers.values())))
    pts = np.ones((4, len(names), frames))
    for j, n in enumerate(names):
        pts[:3, j, :] = np.asarray(markers[n], dtype=float).T / LENGTH_FACTORS[point_units]
    c["parameters"]["POINT"]["RATE"]["value"] = [float(point_rate)]
    c["parameters"]["POINT"]["LABELS"]["value"] = tuple(names)
    c["parameters"]["POINT"]["UNITS"]["value"] = [point_units]
    c["data"]["points"] = pts
    analogs = analogs or {}
    rate = float(analog_rate or point_rate)
    if analogs:
        labels = list(analogs)
        c["parameters"]["ANALOG"]["RATE"]["value"] = [rate]
        c["parameters"]["ANALOG"]["LABELS"]["value"] = tuple(labels)
        c["parameters"]["ANALOG"]["UNITS"]["value"] = [(analog_units or {}).get(n, "")
                                                       for n in labels]
        c["data"]["analogs"] = np.array([[np.asarray(analogs[n], dtype=float)
                                          for n in labels]])
    from .._files import atomic_outputs

    with atomic_outputs([path], suffix=".c3d") as (tmp,):
        c.write(str(tmp))  # ezc3d appends .c3d to a name without it
