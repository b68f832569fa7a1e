"""Parameter sweeps of the nonlinear simulation over the paper's pair gains.

A sweep takes a base experiment (a :class:`~posturelab.scenarios.Scenario`
with the paper's five muscle pairs) and a list of parameters to vary, each
over N evenly spaced values from LO to HI inclusive
(:class:`VaryRange`, written ``NAME=LO:HI:N`` on the command line). It
simulates the full grid (the cartesian product, the first parameter varying
slowest) with the compiled simulator (:func:`posturelab.simulation.compiled.simulate_batch`)
and returns one row per run: the varied values, then the outcomes (fell,
fall time, peak |θ_i|, settling time).

Parameters that can vary (:data:`SWEEP_PARAMETERS`; names, units and bounds from the
parameter table, :mod:`posturelab.parameters`): a pair's ``stiffness:PAIR``,
``viscosity:PAIR``, ``active_stiffness:PAIR`` and ``active_viscosity:PAIR`` (the paper's
pairs ankle, knee, hip, quadriceps, gastrocnemius), ``viscosity_ratio`` [s],
``disturbance_scale`` [-], which multiplies the base experiment's platform motion (the
velocity step's speed, a pulse's peak, a ramp's displacement, the sines' amplitudes, a
measured profile's accelerations; see :meth:`posturelab.model.platform.Disturbance.scaled`),
so that a sweep over it finds how large a perturbation each gain set absorbs,
``feedback_delay`` [s], the neural delay of the muscle feedback,
``proprioceptive_weight`` [-], ``visual_weight`` [-] (W_v, with the base experiment's
visual-scene tilt; each run's W + W_v <= 1), and ``torque_limit:JOINT`` [N·m] (ankle,
knee, hip), the largest net muscle moment at each joint (the others keep the base experiment's
limits; none by default). Every feature of the base experiment (torque limits, a
delay, centre-of-pressure falls) carries into the sweep. The viscosity of a pair is
the varied ``viscosity:PAIR``, else the ratio times its stiffness: the varied ratio, else
the one given, else the base experiment's own ratio for that pair (0.25, the paper's,
where its stiffness is 0). The table's columns are named by the parameters verbatim.

Work can go to a Dask distributed cluster (:func:`run_sweep` with
``workers``/``scheduler``/``client``) in chunks; the results are identical to
the single-process path (each run is the same deterministic computation).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import IO, TYPE_CHECKING, Any

import numpy as np

from ..errors import ParameterError
from ..scenarios import Scenario
from ..simulation.options import RunOptions
from ..simulation.tolerances import DEFAULT_ATOL, DEFAULT_RTOL
from ._sweep_grid import (
    MAX_RUNS,
    OUTCOME_COLUMNS,
    OUTCOME_UNITS,
    PARAMETER_UNITS,
    SETTLE_TOLERANCE,
    STEADY_COLUMN_PREFIXES,
    SWEEP_PARAMETERS,
    SWEEP_QUANTITIES,
    TORQUE_LIMIT_PARAMETERS,
    SweepGrid,
    SweepResult,
    VaryRange,
    check_base,
    joints_of,
    parse_vary,
    sweep_grid,
    sweep_parameters,
    table_csv_text,
    table_format,
    table_parquet_bytes,
    write_table,
)

if TYPE_CHECKING:  # (the engine loads when a sweep runs: posturelab --help stays light)
    from ..simulation.compiled import BatchResult
    from ._sweep_dask import (  # (given by __getattr__ below)
        SCHEDULER_PROTOCOLS,
        SCHEDULER_TIMEOUT,
        check_scheduler_address,
    )

__all__ = [
    "SWEEP_PARAMETERS",
    "PARAMETER_UNITS",
    "OUTCOME_COLUMNS",
    "OUTCOME_UNITS",
    "VaryRange",
    "parse_vary",
    "SweepGrid",
    "sweep_grid",
    "SweepResult",
    "run_sweep",
    "ProgressBar",
    "SweepInterrupted",
    "MAX_RUNS",
    "SWEEP_QUANTITIES",
    "TORQUE_LIMIT_PARAMETERS",
    "STEADY_COLUMN_PREFIXES",
    "SETTLE_TOLERANCE",
    "SCHEDULER_PROTOCOLS",
    "SCHEDULER_TIMEOUT",
    "WORKERS_PER_CPU",
    "check_base",
    "check_scheduler_address",
    "joints_of",
    "max_workers",
    "run_chunks",
    "sweep_parameters",
    "table_csv_text",
    "table_format",
    "table_parquet_bytes",
    "write_table",
]

# ---------------------------------------------------------------------------
# Running
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class _Task:
    """What every chunk of a sweep shares (sent once to each Dask worker)."""

    scenario: Scenario
    options: RunOptions  # (the scenario's, on the compiled engine at the sweep's tolerances)
    strategy: bool = False  # each row's hip fraction too (run again alone)

    def run(self, grid: SweepGrid, lo: int, hi: int, parallel: bool) -> BatchResult:
        result = self._batch(grid, lo, hi, parallel)
        if result.stimulus is not None and result.stimulus.sustained:
            result = self._with_steady_sway(result, grid, lo, hi)
        if self.strategy:
            from dataclasses import replace

            from ..model.kinematics import hip_fraction

            runs = (self._row_run(grid, r) for r in range(lo, hi))
            # a run that fell has no strategy to speak of: NaN (null), as in the maps
            share = [float("nan") if run.fell else hip_fraction(run.theta) for run in runs]
            result = replace(result, hip_fraction=np.array(share, dtype=float))
        return result

    def _steady_row(self, grid: SweepGrid, r: int):
        """Row ``r`` run alone on the compiled engine: its steady sway (or None)."""
        return self._row_run(grid, r).steady_sway(centre_of_pressure=False)

    def _row_run(self, grid: SweepGrid, r: int):
        """Row ``r`` run alone on the compiled engine (its trajectory)."""
        from dataclasses import replace

        from ..simulation.engines import simulate

        sc = self.scenario
        pairs = []
        for j, pair in enumerate(sc.muscles.pairs):
            extra = {} if grid.active_stiffness is None else {
                "active_stiffness": float(grid.active_stiffness[r, j]),
                "active_viscosity": float(grid.active_viscosity[r, j])}
            pairs.append(replace(pair, stiffness=float(grid.stiffness[r, j]),
                                 viscosity=float(grid.viscosity[r, j]), **extra))
        muscles = type(sc.muscles)(tuple(pairs), sc.muscles.n_links)
        disturbance = sc.disturbance
        if grid.disturbance_scale is not None:
            disturbance = disturbance.scaled(float(grid.disturbance_scale[r]))
        limits = None if grid.torque_limits is None else tuple(grid.torque_limits[r])
        weight = (self.options.proprioceptive_weight if grid.proprioceptive_weight is None
                  else float(grid.proprioceptive_weight[r]))
        visual = (self.options.visual_weight if grid.visual_weight is None
                  else float(grid.visual_weight[r]))
        return simulate(sc.body, muscles, disturbance, options=self._options(grid, r).replace(
            torque_limits=limits, feedback_delay=float(grid.feedback_delay[r]),
            proprioceptive_weight=weight, visual_weight=visual))

    def _with_steady_sway(self, result: BatchResult, grid: SweepGrid, lo: int,
                          hi: int) -> BatchResult:
        """The batch's rows with their steady sway: under a sustained stimulus each row that
        completed is run again, alone on the compiled engine, for its trajectory (the batch
        keeps none), and the RMS and peak of its angles over the steady part are computed as
        for one run (:meth:`SimulationResult.steady_sway`; the centre of pressure's would
        cost ten times the run, so a sweep leaves it to single runs)."""
        from dataclasses import replace

        n = self.scenario.body.n_links
        m = hi - lo
        rms, peak = np.full((m, n), np.nan), np.full((m, n), np.nan)
        rows = [int(k) for k in np.nonzero(result.status == "completed")[0]]
        # (one at a time: the rerun is mostly Python, which threads would not speed up)
        sways = [self._steady_row(grid, lo + k) for k in rows]
        for k, sway in zip(rows, sways, strict=True):
            if sway is None:
                continue
            rms[k], peak[k] = sway.rms_theta, sway.peak_theta
        return replace(result, steady_rms_theta=rms, steady_peak_theta=peak)

    def _options(self, grid: SweepGrid, r: int) -> RunOptions:
        """The options of row ``r``: the task's, with its joint controller's factor."""
        if grid.joint_feedback_scale is None:
            return self.options
        return self.options.replace(joint_feedback=self.options.joint_feedback.scaled(
            float(grid.joint_feedback_scale[r])))

    def _batch(self, grid: SweepGrid, lo: int, hi: int, parallel: bool) -> BatchResult:
        scale = grid.joint_feedback_scale
        if scale is None or np.all(scale[lo:hi] == scale[lo]):
            return self._batch_of(grid, lo, hi, parallel, self._options(grid, lo))
        # one batch per stretch of rows that share the controller's factor, in row order
        cuts = [lo, *(lo + 1 + np.flatnonzero(np.diff(scale[lo:hi]) != 0)).tolist(), hi]
        return _concatenate([self._batch_of(grid, a, b, parallel, self._options(grid, a))
                             for a, b in zip(cuts[:-1], cuts[1:], strict=True)])

    def _batch_of(self, grid: SweepGrid, lo: int, hi: int, parallel: bool,
                  options: RunOptions) -> BatchResult:
        from ..simulation.compiled import simulate_batch

        sc = self.scenario
        return simulate_batch(
            sc.body, grid.stiffness[lo:hi], grid.viscosity[lo:hi], sc.disturbance,
            muscles=sc.muscles, options=options,
            torque_limits=_rows(grid.torque_limits, lo, hi),
            feedback_delay=grid.feedback_delay[lo:hi],
            proprioceptive_weight=(self.options.proprioceptive_weight
                                   if grid.proprioceptive_weight is None
                                   else grid.proprioceptive_weight[lo:hi]),
            visual_weight=(self.options.visual_weight if grid.visual_weight is None
                           else grid.visual_weight[lo:hi]),
            active_stiffness=_rows(grid.active_stiffness, lo, hi),
            active_viscosity=_rows(grid.active_viscosity, lo, hi),
            disturbance_scale=_rows(grid.disturbance_scale, lo, hi),
            settle_tolerance=SETTLE_TOLERANCE, parallel=parallel)


def _rows(values: np.ndarray | None, lo: int, hi: int) -> np.ndarray | None:
    return None if values is None else values[lo:hi]


def _concatenate(parts: list[BatchResult]) -> BatchResult:
    from ..simulation.compiled import BatchResult

    if len(parts) == 1:
        return parts[0]
    fields = ("fell", "fall_time", "peak_theta", "settling_time", "final_state", "status_code",
              "n_steps", "n_switches")
    steady = ("steady_rms_theta", "steady_peak_theta", "steady_rms_cop", "steady_peak_cop",
              "hip_fraction")
    return BatchResult(**{f: np.concatenate([getattr(p, f) for p in parts]) for f in fields},
                       settle_tolerance=parts[0].settle_tolerance,
                       stimulus=parts[0].stimulus,
                       **{f: (None if getattr(parts[0], f) is None else
                              np.concatenate([getattr(p, f) for p in parts])) for f in steady})


def ProgressBar(total: int, stream: IO[str] | None = None, width: int = 30,
                unit: str = "runs"):
    """A one-line progress bar of ``total`` runs on ``stream`` (standard error by default):
    :class:`posturelab._progress.Progress`, the bar every command draws; ``update(done)``
    sets the finished count, ``close()`` ends the line."""
    from .._progress import Progress

    return Progress(total, unit=unit, stream=stream, width=width)


def run_sweep(
    scenario: Scenario,
    varies: Sequence[VaryRange],
    *,
    viscosity_ratio: float | None = None,
    rtol: float = DEFAULT_RTOL,
    atol: float = DEFAULT_ATOL,
    workers: int | None = None,
    scheduler: str | None = None,
    client: Any = None,
    chunk_size: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    strategy: bool = False,
) -> SweepResult:
    """Simulate every run of the grid and collect the outcomes.

    Parameters
    ----------
    scenario : Scenario
        The base experiment (the paper's five pairs, 3 links).
    varies : sequence of VaryRange
        The parameters to vary.
    viscosity_ratio : float, optional
        See :func:`sweep_grid`. [s]
    rtol : float
        Relative tolerance of the fast simulator. [-]
    atol : float
        Absolute tolerance. [rad, rad/s]
    workers : int, optional
        Run on a Dask LocalCluster of this many single-threaded worker
        processes (unless ``scheduler`` or ``client`` is given), 1 …
        :func:`max_workers` (4 × the CPUs). [-]
    scheduler : str, optional
        Address of a running Dask scheduler (``[tcp://]host:port``, checked before
        connecting; one that does not answer within :data:`SCHEDULER_TIMEOUT` s is
        refused); its workers need posturelab installed.
    client : distributed.Client, optional
        An existing Dask client to use.
    chunk_size : int, optional
        Runs per chunk (a progress step, a Dask task). [-]
    progress : callable, optional
        ``progress(done, total)`` after each finished chunk.
    strategy : bool
        Also each run's hip fraction (a ``hip_fraction`` column; every row run again alone,
        for its trajectory, which the batch does not keep).

    Returns
    -------
    SweepResult
        The same numbers whichever way the runs were spread.
    """
    # (a solver.method the compiled engine lacks: one line)
    options = scenario.run_options("compiled").replace(rtol=rtol, atol=atol)
    grid = sweep_grid(scenario, varies, viscosity_ratio)
    try:
        parts = run_chunks(_Task(scenario, options, bool(strategy)), grid, workers=workers,
                           scheduler=scheduler, client=client, chunk_size=chunk_size,
                           progress=progress)
    except SweepInterrupted as exc:
        if exc.parts:
            exc.result = SweepResult(grid.head(exc.rows), _concatenate(exc.parts))
        raise
    return SweepResult(grid, _concatenate(parts))


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C (or SIGTERM) stopped a sweep: the chunks not started were dropped, those
    running abandoned. ``parts`` are the finished chunks' results, a prefix of the grid's
    rows (``rows`` of ``total``); ``terminated`` tells SIGTERM from Ctrl-C; the sweep
    function sets ``result`` to the table of the finished rows."""

    def __init__(self, parts: list, rows: int, total: int, terminated: bool) -> None:
        super().__init__(f"interrupted after {rows} of {total} runs")
        self.parts, self.rows, self.total, self.terminated = parts, rows, total, terminated
        self.result: Any = None


def _interrupted(exc: BaseException, parts: list, bounds: list, total: int
                 ) -> SweepInterrupted:
    """The SweepInterrupted of ``exc`` with the leading finished ``parts``."""
    done = []
    for part in parts:
        if part is None:
            break
        done.append(part)
    rows = bounds[len(done) - 1][1] if done else 0
    return SweepInterrupted(done, rows, total, type(exc).__name__ == "Terminated")


#: Dask worker processes a local sweep may start, per CPU. [-]
WORKERS_PER_CPU = 4
def max_workers() -> int:
    """The most Dask worker processes a local sweep starts: 4 per CPU. [-]"""
    return WORKERS_PER_CPU * (os.cpu_count() or 1)


def run_chunks(task, grid: SweepGrid, *, workers: int | None = None, scheduler: str | None = None,
               client: Any = None, chunk_size: int | None = None,
               progress: Callable[[int, int], None] | None = None, largest_chunk: int = 2048,
               threads: int = 1) -> list:
    """Run the rows of ``grid`` in chunks: ``task.run(grid, lo, hi, parallel)`` for each, here
    (``parallel=True``; ``threads`` chunks at a time) or on Dask (``parallel=False``, one
    chunk per single-threaded worker task); the parts in row order.

    ``progress(done, total)`` after each finished chunk. The same parts whichever way.
    Ctrl-C or SIGTERM drops the chunks not started and raises :class:`SweepInterrupted`
    with the leading finished ones at once (here a running chunk is abandoned, on Dask
    cancelled).
    """
    m = grid.n_runs
    distributed_run = client is not None or scheduler is not None or workers is not None
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or not 1 <= workers <= max_workers()):
        raise ParameterError(f"--workers must be an integer in 1 … {max_workers()} (4 × the "
                             f"{os.cpu_count() or 1} CPUs), got {workers!r}")
    from ._sweep_dask import _run_on_dask, check_scheduler_address

    if scheduler is not None:
        check_scheduler_address(scheduler)
    if chunk_size is None:
        chunk_size = largest_chunk if not distributed_run else max(
            min(64, largest_chunk), min(largest_chunk, -(-m // (8 * (workers or 4)))))
    if chunk_size < 1:
        raise ParameterError(f"chunk size must be >= 1, got {chunk_size}")
    bounds = [(lo, min(m, lo + chunk_size)) for lo in range(0, m, chunk_size)]
    parts: list = [None] * len(bounds)
    if distributed_run:
        try:
            return _run_on_dask(task, grid, bounds, workers, scheduler, client, progress,
                                parts)
        except SweepInterrupted:
            raise
        except KeyboardInterrupt as exc:
            raise _interrupted(exc, parts, bounds, m) from None
    return _run_here(task, grid, bounds, parts, progress, max(1, int(threads)))


def _run_here(task, grid, bounds: list, parts: list, progress, threads: int) -> list:
    """The chunks on ``threads`` daemon threads of this process, this thread waiting.

    Ctrl-C (or SIGTERM) takes effect at once: no chunk starts after it, and a chunk still
    running is abandoned, not awaited (a daemon thread does not hold the interpreter's exit;
    one PRTS chunk may run for tens of seconds). Only the leading finished chunks are kept.
    """
    import queue
    import threading

    from ._sweep_dask import _RowsKept

    m = grid.n_runs
    todo: queue.SimpleQueue = queue.SimpleQueue()
    for k, (lo, hi) in enumerate(bounds):
        todo.put((k, lo, hi))
    finished: queue.SimpleQueue = queue.SimpleQueue()
    stop = threading.Event()

    def work() -> None:
        while not stop.is_set():
            try:
                k, lo, hi = todo.get_nowait()
            except queue.Empty:
                return
            try:
                finished.put((k, task.run(grid, lo, hi, True), None))
            except BaseException as exc:  # (re-raised in the waiting thread)
                finished.put((k, None, exc))
                return

    for _ in range(min(threads, len(bounds))):
        threading.Thread(target=work, name="posturelab-sweep", daemon=True).start()
    kept = _RowsKept(parts, bounds)
    try:
        for _ in bounds:
            k, part, error = finished.get()  # (a lock wait: Ctrl-C interrupts it)
            if error is not None:
                raise error
            parts[k] = part
            if progress is not None:
                progress(kept(), m)
    except KeyboardInterrupt as exc:
        stop.set()
        while True:  # chunks that finished meanwhile are kept; running ones abandoned
            try:
                k, part, error = finished.get_nowait()
            except queue.Empty:
                break
            if error is None:
                parts[k] = part
        raise _interrupted(exc, parts, bounds, m) from None
    except BaseException:
        stop.set()
        raise
    return parts


#: What this module gives of :mod:`posturelab.studies._sweep_dask`, imported on first use
#: (``posturelab sweep --help`` stays light).
_FROM_DASK_PART = ("SCHEDULER_PROTOCOLS", "SCHEDULER_TIMEOUT", "check_scheduler_address")


def __getattr__(name: str):
    if name in _FROM_DASK_PART:
        from . import _sweep_dask

        return getattr(_sweep_dask, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
