"""Hostile output arguments, as a real subprocess: every output is checked before anything
is written, a device or FIFO is never replaced, and SIGTERM leaves nothing behind."""

from __future__ import annotations

import os
import signal
import stat
import subprocess
import sys
import time

import pytest

from _cli import cli, one_line_exit_2


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs mkfifo")
def test_a_fifo_as_output_is_refused_and_left_a_fifo(tmp_path):
    fifo = tmp_path / "run.csv"
    os.mkfifo(fifo)
    one_line_exit_2(cli("simulate", "--case", "1", "--duration", "0.2", "--out", str(fifo)),
                    "it exists and is not a regular file")
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)


def test_a_bad_plot_suffix_is_found_before_out_is_written(tmp_path):
    out = tmp_path / "run.csv"
    out.write_text("precious\n")
    one_line_exit_2(cli("simulate", "--case", "1", "--duration", "0.2", "--out", str(out),
                        "--plot", str(tmp_path / "run.xyz")),
                    "an output must end in .png, .svg or .pdf")
    assert out.read_text() == "precious\n"
    one_line_exit_2(cli("simulate", "--case", "1", "--duration", "0.2", "--out",
                        str(tmp_path / "run.txt")), "an output must end in .csv")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.csv"]


def test_sigterm_during_reproduce_leaves_nothing(tmp_path):
    out = tmp_path / "report"
    proc = subprocess.Popen([sys.executable, "-m", "posturelab", "reproduce", "--out",
                             str(out)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True)
    time.sleep(3.0)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143, err
    assert err.strip().splitlines()[-1] == "posturelab: terminated"
    assert not out.exists() and list(tmp_path.iterdir()) == []
