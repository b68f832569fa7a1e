"""The stability maps under hostile requests, as real subprocesses: a resolution bounded by
what finishes in reasonable time, progress for the delayed map, and outputs checked before
any work and written so that a failure leaves none of them."""

from __future__ import annotations

import io
import os
import subprocess
import sys

import pytest

from _cli import cli, one_line_exit_2
from posturelab.cli._common import ExpectedTime
from posturelab.errors import PostureLabError
from posturelab.linear.delay_batch import MAX_DELAY_MAP_RESOLUTION
from posturelab.simulation.results import atomic_write_files

DELAYED = ["stability-map", "--body", "paper-1link", "--stiffness", "28", "--viscosity", "11",
           "--x", "active_stiffness:ankle:0:1700", "--y", "active_viscosity:ankle:0:680",
           "--feedback-delay", "0.15"]



def test_the_delayed_map_resolution_is_bounded():
    assert MAX_DELAY_MAP_RESOLUTION == 300
    one_line_exit_2(cli(*DELAYED, "--resolution", "301", "--out", "never.png"),
                    "--resolution must be in [2, 300] with a feedback delay, got 301")
    assert not os.path.exists("never.png")


def test_the_delayed_map_draws_progress(tmp_path):
    p = cli(*DELAYED, "--resolution", "40", "--out", str(tmp_path / "d.png"), "--progress")
    assert p.returncode == 0, p.stderr
    assert "1600/1600 sets" in p.stderr and "100%" in p.stderr
    assert sorted(f.name for f in tmp_path.iterdir()) == ["d.csv", "d.png"]


@pytest.mark.parametrize("delayed", [True, False])
def test_an_unwritable_csv_is_found_before_any_work_and_nothing_is_written(tmp_path, delayed):
    (tmp_path / "m.csv").mkdir()
    argv = (DELAYED if delayed else ["stability-map", "--x", "stiffness:ankle:0:2000",
                                     "--y", "stiffness:hip:0:1000"])
    one_line_exit_2(cli(*argv, "--resolution", "5", "--out", str(tmp_path / "m.png")),
                    "m.csv", "it is a directory")
    assert [f.name for f in tmp_path.iterdir()] == ["m.csv"]


def test_atomic_write_files_leaves_nothing_when_one_fails(tmp_path):
    first = tmp_path / "a.png"
    with pytest.raises(PostureLabError, match="missing"):
        atomic_write_files({first: b"figure", tmp_path / "missing" / "a.csv": b"rows"})
    assert list(tmp_path.iterdir()) == []
    atomic_write_files({first: b"figure", tmp_path / "a.csv": b"rows"})
    assert first.read_bytes() == b"figure" and (tmp_path / "a.csv").read_bytes() == b"rows"


def test_expected_time_is_said_once_up_front_for_long_work():
    stream = io.StringIO()
    notice = ExpectedTime("stability-map", "sets", stream=stream, notice_after=0.0)
    notice(0, 1000)
    notice(10, 1000)
    notice(20, 1000)
    lines = stream.getvalue().splitlines()
    assert len(lines) == 1 and "1,000 sets, about" in lines[0] and "--progress" in lines[0]
    quiet = io.StringIO()
    ExpectedTime("x", "sets", stream=quiet, notice_after=1e9)(10, 1000)
    assert quiet.getvalue() == ""
    small = io.StringIO()
    ExpectedTime("x", "sets", stream=small, notice_after=0.0, min_total=2000)(10, 1000)
    assert small.getvalue() == ""


def test_ctrl_c_stops_the_delayed_map_and_leaves_nothing(tmp_path):
    import re
    import signal

    proc = subprocess.Popen([sys.executable, "-m", "posturelab", "stability-map", "--x",
                             "active_stiffness:ankle:0:1700", "--y",
                             "active_viscosity:ankle:0:680",
                             "--feedback-delay", "0.15", "--case", "1", "--resolution", "120",
                             "--progress", "--out", str(tmp_path / "m.png")],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    seen = ""
    while not re.search(r"\] +\d+% [1-9][\d,]*/", seen):
        char = proc.stderr.read(1)
        assert char, f"the map ended before any progress: {seen}"
        seen += char
    proc.send_signal(signal.SIGINT)
    _, rest = proc.communicate(timeout=120)
    assert proc.returncode == 130, seen + rest
    assert rest.strip().splitlines()[-1] == "posturelab: interrupted"
    assert list(tmp_path.iterdir()) == []
