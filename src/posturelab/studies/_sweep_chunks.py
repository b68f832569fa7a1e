"""Running a sweep's rows in chunks, here or on a Dask cluster (:func:`run_chunks`), and
what an interruption keeps (:class:`SweepInterrupted`). Public through
:mod:`posturelab.studies.sweep`.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from ..errors import ParameterError, PostureLabError
from ._sweep_grid import SweepGrid

if TYPE_CHECKING:  # (the engine loads when a sweep runs: posturelab --help stays light)
    from ..simulation.compiled import BatchResult


def _run_chunk(task, grid: SweepGrid, lo: int, hi: int) -> BatchResult:
    """A chunk on a Dask worker: one thread per task (the worker's threads run tasks)."""
    return task.run(grid, lo, hi, parallel=False)


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C (or SIGTERM) stopped a sweep: the chunks not started were dropped, those
    running finished. ``parts`` are the finished chunks' results, a prefix of the grid's
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
#: Seconds to wait for a Dask scheduler to answer before giving up. [s]
SCHEDULER_TIMEOUT = 10


def max_workers() -> int:
    """The most Dask worker processes a local sweep starts: 4 per CPU. [-]"""
    return WORKERS_PER_CPU * (os.cpu_count() or 1)


#: Protocols a Dask scheduler address may name.
SCHEDULER_PROTOCOLS = ("tcp", "tls", "ucx", "ws", "wss", "inproc")


def check_scheduler_address(address: str) -> None:
    """Refuse a Dask scheduler address that is not ``[PROTOCOL://]HOST:PORT`` (one line
    naming it), before any connection is tried."""
    form = "[tcp://]HOST:PORT, e.g. tcp://127.0.0.1:8786"
    protocol, sep, rest = address.partition("://")
    if not sep:
        protocol, rest = "tcp", address
    host, colon, port = rest.rpartition(":")
    if protocol not in SCHEDULER_PROTOCOLS:
        raise ParameterError(f"--scheduler {address!r}: unknown protocol {protocol!r} (one of "
                             f"{', '.join(SCHEDULER_PROTOCOLS)}); the form is {form}")
    if protocol == "inproc":
        return
    if not colon or not host or not port.isdigit() or not 1 <= int(port) <= 65535:
        raise ParameterError(f"--scheduler {address!r} is not an address of the form {form} "
                             "(PORT 1 … 65535)")


def run_chunks(task, grid: SweepGrid, *, workers: int | None = None, scheduler: str | None = None,
               client: Any = None, chunk_size: int | None = None,
               progress: Callable[[int, int], None] | None = None, largest_chunk: int = 2048,
               threads: int = 1) -> list:
    """Run the rows of ``grid`` in chunks: ``task.run(grid, lo, hi, parallel)`` for each, here
    (``parallel=True``; ``threads`` chunks at a time) or on Dask (``parallel=False``, one
    chunk per single-threaded worker task); the parts in row order.

    ``progress(done, total)`` after each finished chunk. The same parts whichever way.
    Ctrl-C or SIGTERM drops the chunks not started, waits for those running and raises
    :class:`SweepInterrupted` with the finished ones.
    """
    m = grid.n_runs
    distributed_run = client is not None or scheduler is not None or workers is not None
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or not 1 <= workers <= max_workers()):
        raise ParameterError(f"--workers must be an integer in 1 … {max_workers()} (4 × the "
                             f"{os.cpu_count() or 1} CPUs), got {workers!r}")
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
    done = 0
    if threads <= 1:
        try:
            for k, (lo, hi) in enumerate(bounds):
                parts[k] = task.run(grid, lo, hi, parallel=True)
                done += hi - lo
                if progress is not None:
                    progress(done, m)
        except KeyboardInterrupt as exc:
            raise _interrupted(exc, parts, bounds, m) from None
        return parts
    from concurrent.futures import ThreadPoolExecutor, as_completed

    pool = ThreadPoolExecutor(threads)
    futures: dict = {}
    try:
        futures = {pool.submit(task.run, grid, lo, hi, True): k
                   for k, (lo, hi) in enumerate(bounds)}
        for fut in as_completed(futures):
            k = futures[fut]
            parts[k] = fut.result()
            done += bounds[k][1] - bounds[k][0]
            if progress is not None:
                progress(done, m)
    except KeyboardInterrupt as exc:
        pool.shutdown(wait=True, cancel_futures=True)  # the running chunks finish
        for fut, k in futures.items():
            if parts[k] is None and fut.done() and not fut.cancelled() \
                    and fut.exception() is None:
                parts[k] = fut.result()
        raise _interrupted(exc, parts, bounds, m) from None
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
    return parts


@contextlib.contextmanager
def _quiet_dask():
    """Every logger silent for the block (distributed's, tornado's and asyncio's report the
    connections a shutdown after Ctrl-C cuts, as errors with tracebacks)."""
    import logging

    previous = logging.root.manager.disable
    logging.disable(logging.CRITICAL)
    try:
        yield
    finally:
        logging.disable(previous)


@contextlib.contextmanager
def _sigint_held():
    """Ctrl-C held back for the block and delivered after it (at once if it came meanwhile),
    so that a cluster is not left half-started; the worker processes started in the block
    ignore SIGINT (a terminal's Ctrl-C, or ``timeout -s INT``, reaches the whole process
    group: only this process is to handle it, and then close the cluster)."""
    import signal
    import threading

    hold = hasattr(signal, "pthread_sigmask") and \
        threading.current_thread() is threading.main_thread()
    if not hold:
        yield
        return
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)  # (inherited by the workers; on
    try:  # Linux a blocked signal stays pending though ignored)
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


def _close_dask(client, cluster, quiet: bool) -> None:
    """Close the client, then the cluster (each at most a few seconds); after Ctrl-C with
    every logger silent."""
    with _quiet_dask() if quiet else contextlib.nullcontext():
        for closing in (client, cluster):
            if closing is None:
                continue
            try:
                closing.close(timeout=5) if closing is client else closing.close()
            except Exception:  # (a shutdown after Ctrl-C: the connections may be gone)
                if not quiet:
                    raise


def _run_on_dask(task, grid, bounds, workers, scheduler, client, progress,
                 parts: list) -> list[BatchResult]:
    try:
        import distributed
    except ImportError:
        raise PostureLabError("--workers/--scheduler need Dask: pip install 'dask[distributed]' "
                              "(or 'posturelab[dask]')") from None
    own_client = own_cluster = None
    interrupted = False
    try:
        if client is None:
            if scheduler is not None:
                try:
                    with _quiet_dask():
                        own_client = client = distributed.Client(
                            scheduler, timeout=SCHEDULER_TIMEOUT)
                except (OSError, TimeoutError, ValueError) as exc:
                    reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
                    raise PostureLabError(
                        f"cannot reach the Dask scheduler at {scheduler!r} within "
                        f"{SCHEDULER_TIMEOUT} s: {reason}") from None
            else:
                import logging

                with _sigint_held():
                    own_cluster = distributed.LocalCluster(
                        n_workers=workers, threads_per_worker=1, processes=True,
                        dashboard_address=None, silence_logs=logging.CRITICAL)
                    own_client = client = distributed.Client(own_cluster)
        shared = client.scatter(task, broadcast=True)
        shared_grid = client.scatter(grid, broadcast=True)
        futures = [client.submit(_run_chunk, shared, shared_grid, lo, hi, pure=False)
                   for lo, hi in bounds]
        index = {f.key: k for k, f in enumerate(futures)}
        done = 0
        try:
            for fut in distributed.as_completed(futures):
                k = index[fut.key]
                parts[k] = fut.result()
                lo, hi = bounds[k]
                done += hi - lo
                if progress is not None:
                    progress(done, grid.n_runs)
        except KeyboardInterrupt:
            interrupted = True
            with _quiet_dask():  # keep the chunks that finished, drop the rest
                for k, fut in enumerate(futures):
                    try:
                        if parts[k] is None and fut.status == "finished":
                            parts[k] = fut.result(timeout=5)
                    except Exception:
                        pass
                with contextlib.suppress(Exception):
                    client.cancel(futures)
            raise
        return parts  # type: ignore[return-value]
    except KeyboardInterrupt:
        interrupted = True
        raise
    finally:
        _close_dask(own_client, own_cluster, quiet=interrupted)

