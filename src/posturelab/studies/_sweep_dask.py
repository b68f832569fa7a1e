"""A sweep's chunks on Dask (:func:`posturelab.studies.sweep.run_chunks` with ``workers``,
``scheduler`` or ``client``): the scheduler address checked before any connection, the
connection bounded in time and checked to be a Dask scheduler, Ctrl-C held back while a
local cluster starts, and the chunks that finished kept after an interrupt."""

from __future__ import annotations

import contextlib

from ..errors import ParameterError, PostureLabError

#: Seconds to wait for a Dask scheduler to answer before giving up. [s]
SCHEDULER_TIMEOUT = 10


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


class _RowsKept:
    """Rows of the leading finished chunks: what an interrupt keeps, and so what progress
    counts (chunks finish out of order; one finished after a running one is not kept)."""

    def __init__(self, parts: list, bounds: list) -> None:
        self.parts, self.bounds, self.leading = parts, bounds, 0

    def __call__(self) -> int:
        """The rows kept now. [-]"""
        while self.leading < len(self.parts) and self.parts[self.leading] is not None:
            self.leading += 1
        return self.bounds[self.leading - 1][1] if self.leading else 0


def _run_chunk(task, grid, lo: int, hi: int):
    """A chunk on a Dask worker: one thread per task (the worker's threads run tasks)."""
    return task.run(grid, lo, hi, parallel=False)


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


#: Seconds a scheduler has to connect and send its handshake (it sends it at once): the
#: probe then leaves time within SCHEDULER_TIMEOUT for an answer. [s]
HANDSHAKE_TIMEOUT = 5.0
#: Most bytes a Dask scheduler's first message (its handshake, a small dict) may claim. [B]
MAX_HANDSHAKE_BYTES = 1 << 20


def probe_scheduler(address: str, timeout: float = HANDSHAKE_TIMEOUT) -> None:
    """Refuse in one line, within ``timeout`` [s], a ``tcp://`` address where no Dask
    scheduler answers: nothing listening, no answer (an HTTP server waiting for a
    request), or an answer that is not a Dask handshake (a scheduler writes its handshake
    first on every connection: an 8-byte little-endian length, then that many bytes;
    distributed itself waits for it without a time limit, and reads a web server's
    "HTTP/1.0 426" as a length of 3 EiB). Other protocols are left to distributed."""
    import socket
    import struct
    import time

    protocol, sep, rest = address.partition("://")
    if sep and protocol != "tcp":
        return
    host, _, port = (rest if sep else address).rpartition(":")
    host = host.strip("[]")
    where = f"--scheduler {address!r}"
    deadline = time.monotonic() + timeout
    try:
        with socket.create_connection((host, int(port)), timeout=timeout) as sock:
            header = b""
            while len(header) < 8:
                sock.settimeout(max(deadline - time.monotonic(), 1e-3))
                got = sock.recv(8 - len(header))
                if not got:
                    raise PostureLabError(f"{where}: the peer closed the connection without "
                                          "a Dask handshake (is it a Dask scheduler?)")
                header += got
    except TimeoutError:
        raise PostureLabError(f"{where}: no Dask scheduler answered within {timeout:g} s "
                              "(nothing listening, or a server that is not Dask's)") from None
    except OSError as exc:
        raise PostureLabError(f"cannot reach the Dask scheduler at {address!r}: "
                              f"{exc.strerror or exc}") from None
    (size,) = struct.unpack("<Q", header)
    if not 0 < size <= MAX_HANDSHAKE_BYTES:
        shown = header.decode("ascii", "replace").split("\r")[0].split("\n")[0]
        raise PostureLabError(f"{where} is not a Dask scheduler: it answered {shown!r} "
                              "instead of a Dask handshake")


def _run_on_dask(task, grid, bounds, workers, scheduler, client, progress,
                 parts: list) -> list:
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
                probe_scheduler(scheduler)
                try:
                    with _quiet_dask():
                        own_client = client = distributed.Client(
                            scheduler, timeout=SCHEDULER_TIMEOUT)
                except Exception as exc:  # (OSError, a timeout, or what a peer that is not
                    # Dask makes distributed raise: MemoryError, EOFError, struct.error, …)
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
        kept = _RowsKept(parts, bounds)
        try:
            for fut in distributed.as_completed(futures):
                parts[index[fut.key]] = fut.result()
                if progress is not None:
                    progress(kept(), grid.n_runs)
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

