"""The one reader of recordings: named columns in SI on a uniform grid, and what was done.

Every command that takes a recording (``frf``, ``fit-frf``, ``cohort``, ``fit``,
``likeness``, ``compare-frf``, ``likeness-reference``) reads it by :func:`read_recording`:
it finds the time column and the named columns
(:func:`~posturelab.recordings.columns.read_table`, also importable from here), converts
the units a header declares (``tilt [deg]``) and, for columns that declare none, the units
the user declared (angles ``deg`` → rad, lengths ``mm`` → m, time ``ms`` → s; never
guessed), refuses a time column that repeats or goes backwards, either checks that
the time column is uniform or, with ``resample``, puts the recording on a uniform grid
(:func:`posturelab.recordings.resample.resample_uniform`), cuts it to the stimulus's whole
cycles, and with ``sway`` computes ``com_angle`` as ``posturelab convert`` does. It prints
nothing: the returned :class:`Recording` says what was resampled
(:class:`~posturelab.recordings.resample.ResampleReport`) and cut (:class:`TrimReport`);
the command line says it (stderr, or ``"resampling"``/``"trimming"`` in ``--json``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .._files import check_column_unit
from ..errors import DataFileError, ParameterError
from .columns import (
    ANGLE_UNITS,
    LENGTH_UNITS,
    MAX_ROWS,
    SCALE,
    SI_UNITS,
    TIME_UNITS,
    _listing,
    check_time,
    read_table,
)
from .resample import ResampleReport, resample_uniform, uniform_step

if TYPE_CHECKING:
    from .sway import SwaySpec

__all__ = ["Recording", "TrimReport", "read_recording", "read_series", "read_table",
           "SI_UNITS", "ANGLE_UNITS", "LENGTH_UNITS", "TIME_UNITS", "MAX_ROWS", "SCALE"]


@dataclass(frozen=True)
class TrimReport:
    """What :func:`read_recording` cut from a recording.

    Attributes
    ----------
    start : float or None
        The time before which samples were dropped (``start``), or None. [s]
    dropped_before : int
        Samples dropped before ``start``. [-]
    dropped_after : int
        Samples dropped after the last whole cycle (``drop_partial``). [-]
    dropped_after_duration : float
        Their duration. [s]
    cycle_length : float or None
        The cycle the recording was cut to. [s]
    samples : int
        Samples kept. [-]
    """

    start: float | None
    dropped_before: int
    dropped_after: int
    dropped_after_duration: float
    cycle_length: float | None
    samples: int

    def text(self, start: bool = True) -> str:
        """One line saying what was cut (``start=False``: leaving out the samples dropped
        before ``start``, said on their own line)."""
        parts = []
        if start and self.start is not None:
            parts.append(f"dropped {self.dropped_before} sample(s) before {self.start:g} s")
        if self.dropped_after:
            parts.append(f"dropped the last {self.dropped_after} sample(s) "
                         f"({self.dropped_after_duration:.4g} s), a partial cycle of "
                         f"{self.cycle_length:g} s")
        if not parts and not start and self.start is not None:
            return f"{self.samples} sample(s) kept"
        return "; ".join(parts or ["nothing cut"]) + f"; {self.samples} sample(s) kept"

    def to_dict(self) -> dict:
        """The report as JSON-ready values."""
        return {"start_s": self.start, "dropped_before": self.dropped_before,
                "dropped_after": self.dropped_after,
                "dropped_after_s": self.dropped_after_duration,
                "cycle_length_s": self.cycle_length, "samples": self.samples}


@dataclass(frozen=True)
class Recording:
    """The named columns of a recording in SI on a uniform grid, and what was done to them
    (:func:`read_recording`).

    Attributes
    ----------
    rate : float
        Sample rate. [Hz]
    columns : dict of str -> numpy.ndarray
        Each column. [SI]
    resampling : ResampleReport or None
        What the resampling did (None: the time column was uniform).
    trimming : TrimReport or None
        What was cut (None: nothing asked).
    notes : tuple of str
        Other things done (units scaled, the sway method).
    """

    rate: float
    columns: dict[str, np.ndarray]
    resampling: ResampleReport | None = None
    trimming: TrimReport | None = None
    notes: tuple[str, ...] = field(default=())

    def report_lines(self) -> list[str]:
        """One line per thing done, in the order it was done (for standard error): reading
        (units), samples dropped before --start, resampling, com_angle, the partial cycle
        dropped (or nothing cut) and the samples kept."""
        later = [n for n in self.notes if n.startswith("com_angle by")]
        lines = [n for n in self.notes if n not in later]
        trim = self.trimming
        split = trim is not None and trim.start is not None and self.resampling is not None
        if split:  # --start cut before the resampling
            lines.append(f"dropped {trim.dropped_before} sample(s) before {trim.start:g} s")
        if self.resampling is not None:
            lines.append(self.resampling.text())
        lines += later
        if trim is not None:
            lines.append(trim.text(start=not split))
        return lines

    def report_dict(self) -> dict:
        """``resampling`` and ``trimming`` (when done) and ``notes``, JSON-ready."""
        out: dict = {}
        if self.resampling is not None:
            out["resampling"] = self.resampling.to_dict()
        if self.trimming is not None:
            out["trimming"] = self.trimming.to_dict()
        if self.notes:
            out["reading_notes"] = list(self.notes)
        return out


def read_recording(path: str | Path, columns: list[str],
                   units: dict[str, tuple[str, ...]] | None = None, *,
                   kinds: dict[str, str] | None = None, angle_unit: str = "rad",
                   length_unit: str = "m", time_unit: str = "s",
                   resample: float | None = None, max_gap: float | None = None,
                   start: float | None = None, drop_partial: bool = False,
                   cycle_length: float | None = None, sway: SwaySpec | None = None
                   ) -> Recording:
    """The named columns of a recording, in SI, on a uniform grid, and what was done.

    Parameters
    ----------
    path : str or Path
        A CSV (header row, a ``time`` or ``t`` column) or a ``.c3d``.
    columns : list of str
        Columns to read (lower case).
    units : dict of str -> tuple of str, optional
        The SI units each column may declare in its header (default :data:`SI_UNITS`).
    kinds : dict of str -> str, optional
        ``"angle"`` or ``"length"`` per column: which declared unit applies to it.
    angle_unit, length_unit : str
        The unit of the angle (``rad``, ``deg``) and length (``m``, ``mm``) columns whose
        header declares no unit, as the user declares it; converted to rad and m. A unit a
        header declares is honoured (deg and mm converted; one ``units`` does not accept
        and cannot convert refused).
    time_unit : str
        The unit of a CSV's time column (``s``, ``ms``); converted to s.
    resample : float, optional
        Put the recording on a uniform grid at this rate [Hz] by a cubic spline (see
        :func:`~posturelab.recordings.resample.resample_uniform`); without it a non-uniform
        time column or a missing sample is refused.
    max_gap : float, optional
        Longest gap the resampling accepts. [s]
    start : float, optional
        Drop the samples before this time (where the stimulus's first cycle starts). [s]
    drop_partial : bool
        Drop the samples after the last whole cycle of ``cycle_length`` (a recording that
        runs on past the stimulus); said in :attr:`Recording.trimming`.
    cycle_length : float, optional
        [s]
    sway : SwaySpec, optional
        Compute ``com_angle`` [rad] from markers or a force plate
        (:func:`posturelab.recordings.convert.convert_recording`, the same computation as
        ``posturelab convert --sway``); ``columns`` may then name ``com_angle``.

    Returns
    -------
    Recording

    Raises
    ------
    DataFileError, ParameterError
    """
    from .columns import check_start

    start = check_start(start)
    if angle_unit not in ANGLE_UNITS:
        raise ParameterError(f"angle unit must be one of {', '.join(ANGLE_UNITS)}, got "
                             f"{angle_unit!r}")
    if length_unit not in LENGTH_UNITS:
        raise ParameterError(f"length unit must be one of {', '.join(LENGTH_UNITS)}, got "
                             f"{length_unit!r}")
    path = Path(path)
    what = repr(str(path))
    twice = next((c for k, c in enumerate(columns) if c in columns[:k]), None)
    if twice is not None:
        raise ParameterError(f"the column {twice!r} is asked for twice (a stimulus and a "
                             "response must be different columns)")
    notes: list[str] = []
    resampling = None
    if sway is not None:
        from .convert import convert_recording

        conv = convert_recording(path, resample=resample, max_gap=max_gap,
                                 length_unit=None if length_unit == "m" else length_unit,
                                 time_unit=time_unit, refuse_unknown_units=False,
                                 start=start, **sway.options())
        missing = [c for c in columns if c not in conv.columns]
        if missing:
            raise DataFileError(f"{what} has no column {missing[0]!r}; columns: "
                                + _listing(list(conv.columns)))
        time, declared = conv.time, {c: conv.units.get(c, "") for c in columns}
        cols = {c: np.asarray(conv.columns[c], dtype=float) for c in columns}
        declared["com_angle"] = ""  # computed in rad
        resampling = conv.resampling
        said = {resampling.text() if resampling else "", f"{conv.dropped_before} sample(s) "
                f"before {start:g} s dropped" if start is not None else ""}
        notes = [n for n in conv.notes if n not in said]
        dropped_before = 0 if start is None else conv.dropped_before
    else:
        time, cols, declared = read_table(path, columns, time_unit=time_unit, notes=notes)
    kinds = kinds or {}
    for c in columns:
        if sway is not None and c == "com_angle":
            continue
        cols[c] = _to_si(what, c, cols[c], declared[c], kinds.get(c), angle_unit,
                         length_unit, (units or {}).get(c, SI_UNITS), notes)
    if sway is None:
        check_time(time, what)
        dropped_before = 0
        if start is not None:
            keep = time >= float(start) - 1e-9
            if not keep.any():
                raise DataFileError(f"{what} ends at {time[-1]:g} s, before --start "
                                    f"{start:g} s")
            dropped_before = int((~keep).sum())
            time, cols = time[keep], {c: v[keep] for c, v in cols.items()}
        if time.size < 8:
            raise DataFileError(f"{what} needs at least 8 samples, has {time.size}")
        if resample is not None:
            _, cols, resampling = resample_uniform(time, cols, resample, max_gap=max_gap,
                                                   what=what)
            step = 1.0 / resampling.rate
        else:
            step = _uniform_or_refuse(time, cols, columns, what)
    else:
        step = 1.0 / conv.rate
    n = next(iter(cols.values())).size if cols else time.size
    dropped_after = 0
    if drop_partial:
        if cycle_length is None:
            raise ParameterError("--drop-partial needs --cycle-length")
        per = int(round(float(cycle_length) / step))
        whole = (n // per) * per if per > 0 else n
        if whole == 0:
            raise DataFileError(f"{what} holds {n * step:g} s, less than one cycle of "
                                f"{cycle_length:g} s")
        dropped_after, n = n - whole, whole
        cols = {c: v[:whole] for c, v in cols.items()}
    trimming = None
    if start is not None or drop_partial:
        trimming = TrimReport(start=None if start is None else float(start),
                              dropped_before=dropped_before, dropped_after=dropped_after,
                              dropped_after_duration=dropped_after * step,
                              cycle_length=None if cycle_length is None
                              else float(cycle_length), samples=n)
    return Recording(rate=1.0 / step, columns=cols, resampling=resampling,
                     trimming=trimming, notes=tuple(notes))


def read_series(path: str | Path, columns: list[str],
                units: dict[str, tuple[str, ...]] | None = None, **options
                ) -> tuple[float, dict[str, np.ndarray], ResampleReport | None]:
    """The sample rate [Hz], the named columns [SI] and what the resampling did (None when
    the time column was uniform): :func:`read_recording` with the same options, as a tuple.
    Nothing is printed; :func:`read_recording` also says what was cut."""
    rec = read_recording(path, columns, units, **options)
    return rec.rate, rec.columns, rec.resampling


#: Units a header may declare that are converted to SI: unit -> (SI unit, factor). [-]
CONVERTIBLE = {"deg": ("rad", SCALE["deg"]), "mm": ("m", SCALE["mm"])}


def _to_si(what: str, c: str, values: np.ndarray, header: str, kind: str | None,
           angle_unit: str, length_unit: str, accepted: tuple[str, ...],
           notes: list[str] | None = None) -> np.ndarray:
    """One column in SI. A unit its header declares is honoured: kept when in ``accepted``,
    converted when it is deg or mm and rad or m is accepted, else refused. A column that
    declares none is in the unit the user declared for its kind (``angle_unit``,
    ``length_unit``: these apply only to columns without a declared unit)."""
    if header:
        unit = header.lower()
        if unit in {a.lower() for a in accepted}:
            return values
        si, factor = CONVERTIBLE.get(unit, ("", 1.0))
        if si in accepted and si == {"angle": "rad", "length": "m"}.get(kind or "", si):
            if notes is not None:
                notes.append(f"{c} from {unit} (its header) to {si}")
            return values * factor
        check_column_unit(what, f"{c} [{header}]", accepted)
        return values
    given = {"angle": angle_unit, "length": length_unit}.get(kind or "")
    if given is not None and given not in ("rad", "m"):
        if notes is not None:
            notes.append(f"{c} from {given} (--{kind}-unit) to {CONVERTIBLE[given][0]}")
        return values * SCALE[given]
    return values


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
