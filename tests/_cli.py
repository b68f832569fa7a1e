"""Shared test helpers: the command line as a real subprocess, and its one-line refusal."""

import subprocess
import sys


def cli(*args: str, cwd=None, timeout: float = 300) -> subprocess.CompletedProcess:
    """``posturelab ARGS`` in a fresh interpreter (``cwd``: where it runs)."""
    return subprocess.run([sys.executable, "-m", "posturelab", *args], capture_output=True,
                          text=True, timeout=timeout, cwd=cwd)


def one_line_exit_2(p: subprocess.CompletedProcess, *words: str) -> None:
    """A refusal: exit code 2, one line on standard error, no traceback, naming ``words``."""
    err = p.stderr.strip()
    assert p.returncode == 2, p.stderr
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    for w in words:
        assert w in err, err
