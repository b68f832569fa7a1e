"""Running the explorer in-process and driving it in a headless browser: what its tests,
its benchmark and its screenshots share.

The browser is the system's Chromium (Debian's ``chromium`` package), driven by
Playwright's Python package with that executable, so nothing is downloaded at run time.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import threading
from collections.abc import Iterator

__all__ = ["running_server", "chromium_path", "launch_chromium", "CHROMIUM_ARGS"]

#: Chromium's options for a headless run on a machine without a network beyond loopback:
#: no sandbox (it runs as root in CI), no GPU, and none of its background connections.
CHROMIUM_ARGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                 "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync")


@contextlib.contextmanager
def running_server() -> Iterator[str]:
    """Serve the explorer on a free loopback port in a thread; yields its URL and stops
    the server on exit."""
    import io

    from .app import HOST, serve

    ready = threading.Event()
    servers = []

    def listening(server) -> None:
        servers.append(server)
        ready.set()

    thread = threading.Thread(target=serve, args=(0,), daemon=True,
                              kwargs={"open_browser": False, "stream": io.StringIO(),
                                      "on_ready": listening})
    thread.start()
    if not ready.wait(30):
        raise RuntimeError("the explorer's server did not start within 30 s")
    try:
        yield f"http://{HOST}:{servers[0].server_port}/"
    finally:
        servers[0].shutdown()
        thread.join(10)


def chromium_path() -> str | None:
    """The system Chromium's executable (``$CHROMIUM``, else ``chromium`` on the PATH),
    or None."""
    return os.environ.get("CHROMIUM") or shutil.which("chromium") or shutil.which(
        "chromium-browser")


def launch_chromium(playwright):
    """A headless system Chromium under Playwright (``playwright.sync_api``)."""
    path = chromium_path()
    if path is None:
        raise RuntimeError("no Chromium found: install Debian's chromium package or set "
                           "$CHROMIUM")
    return playwright.chromium.launch(executable_path=path, args=list(CHROMIUM_ARGS))
