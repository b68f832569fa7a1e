"""Cohorts: the same model fitted to every subject's FRF, in parallel, one row per subject and
parameter, and a summary.

:func:`fit_cohort` takes one FRF per subject (an :class:`~posturelab.frequency.FRFEstimate`,
an :class:`~posturelab.frequency.table.FRFTable`, or a file :func:`read_frf_file` reads: a
trial CSV, the JSON ``posturelab frf --json`` writes, or a table of gain and phase with or
without standard errors) and fits each with :func:`posturelab.frequency.fit.fit_frf` from the
same starting body, gains and options, in worker processes (by default one per CPU this
process may use, at most four per CPU; each subject is one task, so the table does not
depend on how many ran at once). A subject whose file
cannot be read or whose fit fails gets rows saying why (``failed``, ``reason``) and never
stops the others; a fit that is no success (:attr:`posturelab.frequency.fit.FRFFit.success`:
its optimiser did not converge, its fitted loop is unstable, or its model does not describe
the data) keeps its values, marked failed with the fit's reason.

The table (:meth:`CohortFit.columns`) has one row per subject and parameter: ``subject``,
``parameter``, ``unit``, ``value``, ``standard_error``, ``ci95_low``, ``ci95_high`` (the
parameter's unit), ``determined``, ``fit_error`` [-], ``variance_accounted_for`` [-],
``converged``, ``stable``, ``describes_data`` ("true", "false", or empty when there is no
fit), ``weighting``, ``failed``, ``reason``. The summary (:meth:`CohortFit.summary`) gives
per parameter the number of subjects fitted, the median and the quartiles of their
estimates (``determined`` counts those the data determined); failed and flagged fits are
left out of it, and ``left_out`` says how many and why (no fit, not converged, unstable
loop, model not describing the data; one subject may have several).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ParameterError, PostureLabError
from .fit import check_fit_request

__all__ = ["CohortFit", "SubjectFit", "fit_cohort", "read_frf_file", "read_trial_frf",
           "max_cohort_workers",
           "usable_cpus", "csv_text", "MAX_SUBJECTS"]

#: Most subjects one cohort may have. [-]
MAX_SUBJECTS = 100_000


def usable_cpus() -> int:
    """The CPUs this process may run on (its affinity where the system says). [-]"""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return max(1, os.cpu_count() or 1)


def max_cohort_workers() -> int:
    """The most worker processes a cohort fit starts: four per usable CPU (as a sweep's
    ``--workers``); the default is one per CPU. [-]"""
    return 4 * usable_cpus()


def read_frf_file(path, *, stimulus: str | None = None, response: str | None = None,
                  cycle_length: float | None = None, discard_cycles: int = 0,
                  response_sign: int = -1, input: str = "tilt", what: str = "FRF JSON",
                  **recording):
    """One condition's FRF from a file: ``.json`` an FRF table
    (:func:`posturelab.frequency.table.read_frf_json`: what ``posturelab frf --json`` writes,
    or gain and phase with optional standard errors), anything else a trial CSV whose
    ``stimulus`` and ``response`` columns are estimated over cycles of ``cycle_length`` [s]
    (:func:`posturelab.frequency.estimate_frf`), the response multiplied by
    ``response_sign`` (−1: posturelab's tilt convention). ``what`` names a JSON file in
    messages.

    Raises
    ------
    ParameterError, DataFileError
        An unreadable file, a trial CSV without its columns or cycle length.
    """
    if str(path).lower().endswith(".json"):
        from .table import read_frf_json

        return read_frf_json(path, what)
    return read_trial_frf(path, stimulus=stimulus, response=response,
                          cycle_length=cycle_length, discard_cycles=discard_cycles,
                          response_sign=response_sign, input=input, **recording)[0]


def read_trial_frf(path, *, stimulus: str | None = None, response: str | None = None,
                   cycle_length: float | None = None, discard_cycles: int = 0,
                   response_sign: int = -1, input: str = "tilt", **recording):
    """A trial recording's FRF (as :func:`read_frf_file` estimates it) and what reading it
    did: (:class:`~posturelab.frequency.estimate.FRFEstimate`,
    :class:`~posturelab.recordings.table.Recording`); ``recording`` are
    :func:`~posturelab.recordings.table.read_recording`'s options.

    Raises
    ------
    ParameterError, DataFileError
    """
    from .._validation import float_in_range
    from ..recordings.table import read_recording
    from .estimate import estimate_frf, whole_cycles

    if stimulus is None or response is None or cycle_length is None:
        raise ParameterError("a trial CSV needs --stimulus, --response and --cycle-length")
    float_in_range("--cycle-length [s]", cycle_length, 1e-3, 1e5, unit="s")
    stim, resp = stimulus.strip().lower(), response.strip().lower()
    rec = read_recording(
        path, [stim, resp], {stim: ("rad",) if input == "tilt" else ("m",)},
        kinds={stim: "angle" if input == "tilt" else "length", resp: "angle"},
        cycle_length=cycle_length, **recording)
    fs, cols = rec.rate, rec.columns
    x, y, _ = whole_cycles(cols[stim], cols[resp], fs, cycle_length)
    return estimate_frf(x, y, fs, cycle_length, discard_cycles=discard_cycles,
                        response_sign=response_sign), rec


@dataclass(frozen=True)
class SubjectFit:
    """One subject's fit in a cohort.

    Attributes
    ----------
    subject : str
    estimates, standard_errors : numpy.ndarray, shape (K,)
        NaN when the fit failed. [each parameter's unit]
    confidence_intervals : numpy.ndarray, shape (K, 2)
        95 %. [each parameter's unit]
    determined : numpy.ndarray of bool, shape (K,)
    fit_error : float
        As :attr:`posturelab.frequency.fit.FRFFit.fit_error` (NaN when failed). [-]
    weighting : str
    failed : bool
    reason : str
        Why it failed (empty when it did not).
    reading : tuple of str
        What reading the subject's trial recording did (resampled, cut; one line each;
        empty for an FRF file or a recording read as it was).
    converged, stable, describes_data : bool or None
        As :class:`posturelab.frequency.fit.FRFFit`'s (None: no fit, or not checked).
    variance_accounted_for : float
        As :attr:`posturelab.frequency.fit.FRFFit.variance_accounted_for` (NaN: no fit). [-]
    """

    subject: str
    estimates: np.ndarray
    standard_errors: np.ndarray
    confidence_intervals: np.ndarray
    determined: np.ndarray
    fit_error: float
    weighting: str = ""
    failed: bool = False
    reason: str = ""
    reading: tuple[str, ...] = ()
    converged: bool | None = None
    stable: bool | None = None
    describes_data: bool | None = None
    variance_accounted_for: float = math.nan

    def left_out_because(self) -> tuple[str, ...]:
        """Why the summary leaves this subject out (empty: it does not)."""
        if not self.failed:
            return ()
        if self.converged is None:
            return ("no fit",)
        why = tuple(w for bad, w in ((not self.converged, "not converged"),
                                     (self.stable is False, "unstable loop"),
                                     (self.describes_data is False,
                                      "model does not describe the data")) if bad)
        return why or ("failed",)


@dataclass(frozen=True)
class CohortFit:
    """The result of :func:`fit_cohort` (module notes).

    Attributes
    ----------
    parameters : tuple of str
        The fitted parameters (the parameter table's spelling).
    units : tuple of str
    subjects : tuple of SubjectFit
        In the order given.
    """

    parameters: tuple
    units: tuple
    subjects: tuple = field(default=())

    @property
    def failed(self) -> tuple:
        """The subjects whose fit failed."""
        return tuple(s.subject for s in self.subjects if s.failed)

    def values(self, parameter: str) -> np.ndarray:
        """Every subject's estimate of ``parameter`` (NaN when its fit failed). [its unit]"""
        if parameter not in self.parameters:
            raise ParameterError(f"{parameter!r} was not fitted; fitted: "
                                 f"{', '.join(self.parameters)}")
        k = self.parameters.index(parameter)
        return np.array([np.nan if s.failed else s.estimates[k] for s in self.subjects])

    def columns(self) -> list[tuple[str, np.ndarray]]:
        """The table, one row per subject and parameter (module notes)."""
        rows = [(s, k) for s in self.subjects for k in range(len(self.parameters))]

        def col(values, dtype=float):
            return np.array(list(values), dtype=dtype)

        def flag(v):
            return "" if v is None else ("true" if v else "false")

        return [
            ("subject", col((s.subject for s, _ in rows), str)),
            ("parameter", col((self.parameters[k] for _, k in rows), str)),
            ("unit", col((self.units[k] for _, k in rows), str)),
            ("value", col(s.estimates[k] for s, k in rows)),
            ("standard_error", col(s.standard_errors[k] for s, k in rows)),
            ("ci95_low", col(s.confidence_intervals[k, 0] for s, k in rows)),
            ("ci95_high", col(s.confidence_intervals[k, 1] for s, k in rows)),
            ("determined", col((bool(s.determined[k]) for s, k in rows), bool)),
            ("fit_error", col(s.fit_error for s, _ in rows)),
            ("variance_accounted_for", col(s.variance_accounted_for for s, _ in rows)),
            ("converged", col((flag(s.converged) for s, _ in rows), str)),
            ("stable", col((flag(s.stable) for s, _ in rows), str)),
            ("describes_data", col((flag(s.describes_data) for s, _ in rows), str)),
            ("weighting", col((s.weighting for s, _ in rows), str)),
            ("failed", col((s.failed for s, _ in rows), bool)),
            ("reason", col((s.reason for s, _ in rows), str))]

    def column_units(self) -> dict[str, str]:
        """Units of the table's numeric columns (a parameter's are in its ``unit`` column)."""
        return {"fit_error": "-", "variance_accounted_for": "-"}

    def write(self, path) -> None:
        """Write the table to ``path`` (.csv or .parquet by its suffix), atomically: an
        interrupted write leaves nothing. CSV: text cells quoted where they need it (a
        reason may hold commas), NaN an empty cell, numbers exact (17 digits)."""
        from .._files import atomic_write_text
        from ..studies.sweep import table_format, write_table

        if table_format(path) == "csv":
            atomic_write_text(path, csv_text(self.columns()))
        else:
            write_table(path, self.columns(), self.column_units())

    def summary(self) -> dict:
        """Per parameter: ``unit``, ``subjects`` (fitted, failed and flagged fits left out),
        ``determined``, ``median``, ``q1``, ``q3`` (quartiles) and ``min``, ``max`` of the
        estimates; and the cohort's ``subjects``, ``failed`` (with their reasons) and
        ``left_out``: ``count`` and ``by_reason`` (subjects per reason: "no fit", "not
        converged", "unstable loop", "model does not describe the data"). JSON-safe."""
        def num(v):
            return float(v) if math.isfinite(v) else None

        out = {}
        for k, name in enumerate(self.parameters):
            ok = [s for s in self.subjects if not s.failed and math.isfinite(s.estimates[k])]
            v = np.array([s.estimates[k] for s in ok])
            q = np.percentile(v, [0, 25, 50, 75, 100]) if v.size else [math.nan] * 5
            out[name] = {"unit": self.units[k], "subjects": len(ok),
                         "determined": sum(bool(s.determined[k]) for s in ok),
                         "median": num(q[2]), "q1": num(q[1]), "q3": num(q[3]),
                         "min": num(q[0]), "max": num(q[4])}
        by_reason: dict[str, int] = {}
        for s in self.subjects:
            for why in s.left_out_because():
                by_reason[why] = by_reason.get(why, 0) + 1
        return {"subjects": len(self.subjects), "parameters": out,
                "failed": [{"subject": s.subject, "reason": s.reason}
                           for s in self.subjects if s.failed],
                "left_out": {"count": sum(s.failed for s in self.subjects),
                             "by_reason": by_reason}}


def csv_text(columns) -> str:
    """A table as CSV (the csv module's quoting): booleans true/false, NaN an empty cell,
    numbers with 17 significant digits, text as it is."""
    import csv
    import io

    cells = []
    for _, values in columns:
        values = np.asarray(values)
        if values.dtype == bool:
            cells.append(["true" if v else "false" for v in values])
        elif values.dtype.kind in "US":
            cells.append([str(v) for v in values])
        else:
            cells.append(["" if math.isnan(v) else repr(float(v)) for v in values.tolist()])
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow([name for name, _ in columns])
    writer.writerows(zip(*cells, strict=True))
    return buf.getvalue()


@dataclass(frozen=True)
class _CohortTask:
    """What every subject's fit shares (sent to each worker process)."""

    body: object
    muscles: object
    free: tuple
    options: tuple  # fit_frf's keyword options, as items
    reader: tuple   # read_frf_file's keyword options, as items
    parameters: tuple

    def __call__(self, item: tuple) -> SubjectFit:
        subject, data = item
        return _fit_one(self, subject, data)


def _failed(task: _CohortTask, subject: str, reason: str) -> SubjectFit:
    K = len(task.parameters)
    nan = np.full(K, np.nan)
    return SubjectFit(subject, nan, nan.copy(), np.full((K, 2), np.nan), np.zeros(K, bool),
                      math.nan, "", True, reason)


def _fit_one(task: _CohortTask, subject: str, data) -> SubjectFit:
    from .fit import fit_frf

    reading: tuple[str, ...] = ()
    try:
        if isinstance(data, str | Path) and not str(data).lower().endswith(".json"):
            data, rec = read_trial_frf(data, **dict(task.reader))
            reading = tuple(rec.report_lines())
        elif isinstance(data, str | Path):
            data = read_frf_file(data, **dict(task.reader))
        fit = fit_frf(task.body, task.muscles, data, list(task.free), **dict(task.options))
    except PostureLabError as exc:
        return _failed(task, subject, str(exc))
    except Exception as exc:  # (any other failure of one subject's fit: said, not raised)
        return _failed(task, subject, f"{type(exc).__name__}: {exc}"[:300])
    return SubjectFit(subject, fit.estimates, fit.standard_errors, fit.confidence_intervals,
                      fit.determined, fit.fit_error, fit.weighting, not fit.success, fit.reason,
                      reading, fit.converged, fit.stable, fit.describes_data,
                      fit.variance_accounted_for)


def _refuse_repeated_files(subjects) -> None:
    """One file given twice would be fitted as two subjects: refused."""
    seen: dict[Path, str] = {}
    for s in subjects:
        if isinstance(s, str | Path):
            key = Path(s).resolve()
            if key in seen:
                raise ParameterError(f"--data names the same file twice ({seen[key]!r} and "
                                     f"{str(s)!r}); each subject is one file, given once")
            seen[key] = str(s)


def _subject_names(subjects, names) -> list[str]:
    _refuse_repeated_files(subjects)
    if names is not None:
        names = [str(n) for n in names]
        if len(names) != len(subjects):
            raise ParameterError(f"names must name each of the {len(subjects)} subjects, got "
                                 f"{len(names)}")
        return names
    out = []
    for k, s in enumerate(subjects):
        out.append(Path(s).stem if isinstance(s, str | Path) else f"subject {k + 1}")
    if len(set(out)) < len(out):  # the same file name in two folders: the paths
        out = [str(s) if isinstance(s, str | Path) else n for s, n in zip(subjects, out,
                                                                            strict=True)]
    return out


def fit_cohort(body, muscles, subjects: Sequence, free, *, names=None,
               workers: int | None = None, progress: Callable[[int, int], None] | None = None,
               reader: dict | None = None, **fit_options) -> CohortFit:
    """Fit the same model to every subject's FRF (module notes).

    Parameters
    ----------
    body, muscles
        The body and the starting gains, as for :func:`posturelab.frequency.fit.fit_frf`.
    subjects : sequence of FRFEstimate, FRFTable or path
        One per subject; a path is read in the worker by :func:`read_frf_file`.
    free : sequence of str
        The parameters fitted (the parameter table's names).
    names : sequence of str, optional
        The subjects' names (default: a file's stem, else ``subject k``).
    workers : int, optional
        Worker processes, 1 … :func:`max_cohort_workers` (default: one per usable CPU, at
        most one per subject); 1 fits here, in turn. [-]
    progress : callable(done, total), optional
        Called after each subject.
    reader : dict, optional
        :func:`read_frf_file`'s options for trial CSVs (``stimulus``, ``response``,
        ``cycle_length``, ``discard_cycles``, ``response_sign``, ``input``).
    **fit_options
        ``input``, ``output``, ``feedback_delay``, ``proprioceptive_weight``, ``bounds`` of
        :func:`~posturelab.frequency.fit.fit_frf`.

    Returns
    -------
    CohortFit

    Raises
    ------
    ParameterError
        No subjects, a bad name or bound (checked before any fit), a bad worker count.
    """
    from ..parameters import unit as parameter_unit

    if isinstance(subjects, str | Path) or not isinstance(subjects, Sequence):
        raise ParameterError("subjects must be a sequence of FRFs or paths, one per subject")
    subjects = list(subjects)
    if not 1 <= len(subjects) <= MAX_SUBJECTS:
        raise ParameterError(f"a cohort needs 1 … {MAX_SUBJECTS:,} subjects, got "
                             f"{len(subjects)}")
    if "per_condition" in fit_options:
        raise ParameterError("a cohort fits one FRF per subject: no per-condition parameters")
    free_c, _, _, _, bounds = check_fit_request(muscles, free, (),
                                                fit_options.get("bounds"))
    limit = max_cohort_workers()
    if workers is None:
        workers = min(usable_cpus(), len(subjects))
    if isinstance(workers, bool) or not isinstance(workers, int | np.integer) \
            or not 1 <= workers <= limit:
        raise ParameterError(f"--workers must be an integer in 1 … {limit} (4 × the CPUs), got "
                             f"{workers!r}")
    labels = _subject_names(subjects, names)
    options = {**fit_options, "bounds": bounds or None}
    task = _CohortTask(body, muscles, tuple(free_c), tuple(options.items()),
                       tuple((reader or {}).items()), tuple(free_c))
    items = list(zip(labels, subjects, strict=True))
    results: list[SubjectFit | None] = [None] * len(items)
    total = len(items)
    if workers == 1 or total == 1:
        for k, item in enumerate(items):
            results[k] = task(item)
            if progress is not None:
                progress(k + 1, total)
    else:
        results = _in_processes(task, items, min(workers, total), progress)
    units = tuple(parameter_unit(n) for n in free_c)
    return CohortFit(tuple(free_c), units, tuple(results))


#: The task of the worker processes of the running cohort (set by each worker's initialiser).
_TASK: _CohortTask | None = None


def _set_task(task: _CohortTask) -> None:
    """A worker's start: its task, and Ctrl-C left to the parent (which cancels the rest),
    so that a worker never dies halfway with a traceback of its own."""
    import signal

    global _TASK
    _TASK = task
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _fit_chunk(items: list) -> list:
    return [_TASK(item) for item in items]


def _in_processes(task: _CohortTask, items: list, workers: int, progress) -> list:
    """The subjects' fits in a pool of ``workers`` processes (fork on Linux), in chunks of
    subjects (about four per worker, so that a slow subject does not hold the others up);
    Ctrl-C cancels the chunks not started and stops the pool before it propagates."""
    import multiprocessing
    import sys
    from concurrent.futures import ProcessPoolExecutor, as_completed

    import scipy.linalg  # noqa: F401  (loaded once here: forked workers inherit them)
    import scipy.optimize  # noqa: F401
    import scipy.stats  # noqa: F401

    context = multiprocessing.get_context("fork" if sys.platform.startswith("linux")
                                          else None)
    size = max(1, -(-len(items) // (4 * workers)))
    chunks = [list(range(k, min(k + size, len(items)))) for k in range(0, len(items), size)]
    results: list = [None] * len(items)
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=context, initializer=_set_task,
                               initargs=(task,))
    try:
        futures = {pool.submit(_fit_chunk, [items[k] for k in chunk]): chunk
                   for chunk in chunks}
        done = 0
        for future in as_completed(futures):
            chunk = futures[future]
            try:
                fits = future.result()
            except Exception as exc:  # (a worker that died: its subjects fail, not the rest)
                fits = [_failed(task, items[k][0], f"{type(exc).__name__}: {exc}"[:300])
                        for k in chunk]
            for k, fit in zip(chunk, fits, strict=True):
                results[k] = fit
            done += len(chunk)
            if progress is not None:
                progress(done, len(items))
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown(wait=True)
    return results
