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


def run_main(capsys, *argv) -> tuple[int, str, str]:
    """``posturelab ARGV`` in this process (``cli.main``): exit code, stdout, stderr."""
    from posturelab.cli import main

    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def refused_in_one_line(capsys, *argv) -> str:
    """``posturelab ARGV`` in this process refused: exit 2, nothing on stdout, one line on
    stderr without a traceback; returns that line."""
    code, out, err = run_main(capsys, *argv)
    assert code == 2 and out == "", (out, err)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]
