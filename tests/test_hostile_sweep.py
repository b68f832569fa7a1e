"""Sweeps under Ctrl-C and SIGTERM, as real subprocesses: the sweep stops at once (the
chunks not started are dropped), writes the rows that finished and says how many."""

from __future__ import annotations

import csv
import re
import signal
import subprocess
import sys

import pytest

PRTS = ["sweep", "--experiment", "prts", "--controller", "peterka-2002", "--tilt",
        "prts:0.035", "--vary", "feedback_delay=0.12:0.18:40", "--vary",
        "active_stiffness:ankle=650:850:40"]
SIMULATION = ["sweep", "--case", "1", "--disturbance", "backward", "--duration", "30",
              "--vary", "stiffness:ankle=100:2000:400", "--vary", "stiffness:hip=100:1000:400",
              "--chunk-size", "64"]


def _interrupt_after_progress(argv, sig, out):
    """Start the sweep, wait until its bar shows finished runs, send ``sig``; the exit code,
    standard error and the rows written."""
    proc = subprocess.Popen([sys.executable, "-m", "posturelab", *argv, "--progress",
                             "--out", str(out)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    seen = ""
    while not re.search(r"\] +\d+% [1-9]\d*/", seen):
        char = proc.stderr.read(1)
        assert char, f"the sweep ended before any progress: {seen}"
        seen += char
    proc.send_signal(sig)
    _, rest = proc.communicate(timeout=120)
    err = (seen + rest).replace("\r", "\n")
    rows = list(csv.reader(out.open())) if out.exists() else []
    return proc.returncode, err, rows


@pytest.fixture
def prts_names():
    """The PRTS sweep in the vocabulary of the day: QUANTITY:PAIR, else the old name."""
    from posturelab.errors import PostureLabError
    from posturelab.studies.sweep import parse_vary

    try:
        parse_vary("active_stiffness:ankle=650:850:40")
        return PRTS
    except PostureLabError:
        return [a.replace("active_stiffness:ankle", "active_ankle") for a in PRTS]


@pytest.mark.parametrize("sig,code,word", [(signal.SIGINT, 130, "interrupted"),
                                           (signal.SIGTERM, 143, "terminated")])
def test_a_prts_sweep_stops_at_once_and_keeps_what_finished(tmp_path, prts_names, sig, code,
                                                            word):
    status, err, rows = _interrupt_after_progress(prts_names, sig, tmp_path / "pop.csv")
    assert status == code, err
    match = re.search(rf"posturelab: {word}: wrote the ([\d,]+) of 1,600 runs that finished",
                      err)
    assert match, err
    kept = int(match.group(1).replace(",", ""))
    assert 0 < kept < 1600 and len(rows) == 1 + kept
    assert rows[0][0] == "feedback_delay"
    assert "Traceback" not in err
    assert [p.name for p in tmp_path.iterdir()] == ["pop.csv"]  # no temporary left


def test_an_ordinary_sweep_stops_at_once_and_keeps_what_finished(tmp_path):
    status, err, rows = _interrupt_after_progress(SIMULATION, signal.SIGINT,
                                                  tmp_path / "s.csv")
    assert status == 130, err
    match = re.search(r"interrupted: wrote the ([\d,]+) of 160,000 runs", err)
    assert match, err
    kept = int(match.group(1).replace(",", ""))
    assert 0 < kept < 160_000 and len(rows) == 1 + kept and kept % 64 == 0
    assert rows[0][:3] == ["stiffness:ankle", "stiffness:hip", "outcome"]
    assert float(rows[1][0]) == 100.0 and float(rows[1][1]) == 100.0  # the grid's first rows


def _one_line(p, *words):
    err = p.stderr.strip()
    assert p.returncode == 2 and len(err.splitlines()) == 1 and "Traceback" not in err, err
    for w in words:
        assert w in err, err


def test_options_a_sweep_does_not_use_are_named_and_refused(tmp_path, prts_names):
    out = tmp_path / "s.csv"

    def sweep(*argv):
        return subprocess.run([sys.executable, "-m", "posturelab", *argv, "--out", str(out)],
                              capture_output=True, text=True, timeout=120)

    _one_line(sweep("sweep", "--case", "1", "--disturbance", "backward", "--vary",
                    "stiffness:ankle=100:200:2", "--cycles", "3", "--sensor-noise", "0.001"),
              "--cycles, --sensor-noise are not used by a simulation sweep")
    _one_line(sweep(*prts_names[:7], "--vary", "feedback_delay=0.12:0.18:2", "--duration",
                    "9", "--disturbance", "backward"),
              "--disturbance, --duration are not used by --experiment prts")
    _one_line(sweep(*prts_names[:7], "--vary", "feedback_delay=0.12:0.18:2", "--rates-from",
                    "posture"), "--rates-from is not used by --experiment prts")
    assert not out.exists()
