"""Every resource a user can ask for is bounded, with one line naming the field, the value
and the limit (on the command line as a real subprocess), instead of a traceback, a hang or
running out of memory."""

from __future__ import annotations

import subprocess
import sys

import pytest

import posturelab as pl
from posturelab.errors import ParameterError
from posturelab.model.body import MAX_LINKS, Segment


def cli(*args):
    return subprocess.run([sys.executable, "-m", "posturelab", *args], capture_output=True,
                          text=True, timeout=60)


@pytest.mark.parametrize("args, words", [
    (["--duration", "1e308"], "duration [s] must be in (0, 86400] s, got 1e+308"),
    (["--duration", "1e6"], "duration [s] must be in (0, 86400] s"),
    (["--duration", "50000"], "gives 50,000,001 output samples (floor(duration × "
     "sample_rate) + 1, both ends); at most 2,000,000"),
    (["--duration", "2000"], "gives 2,000,001 output samples"),
    (["--speed", "1e300"], "--speed [m/s] must be in (0, 20] (the step's size; "
     "--disturbance gives its direction), got 1e+300"),
])
def test_unbounded_runs_are_refused_at_once(args, words):
    p = cli("simulate", "--case", "1", "--disturbance", "backward", *args)
    err = p.stderr.strip()
    assert p.returncode == 2 and len(err.splitlines()) == 1 and words in err, err


def test_huge_gains_and_grids_are_refused():
    p = cli("simulate", "--stiffness", "1e12,1e12,1e12,1e12,1e12", "--disturbance", "backward")
    assert p.returncode == 2
    assert "stiffness must be in [0, 1e+08] N·m/rad, got 1000000000000.0" in p.stderr
    p = cli("sweep", "--case", "1", "--disturbance", "backward", "--vary",
            "stiffness:ankle=0:1:10000",
            "--vary", "stiffness:knee=0:1:10000", "--out", "never.csv")
    assert p.returncode == 2 and "100,000,000 runs" in p.stderr and "at most 10,000,000" in p.stderr


def test_a_body_of_too_many_links_is_refused():
    seg = Segment("s", 1.0, 0.1, 0.05, 0.001)
    pl.Body((seg,) * MAX_LINKS)
    with pytest.raises(ParameterError, match=f"at most {MAX_LINKS} links, got 50"):
        pl.Body((seg,) * 50)


def test_the_api_names_an_argument_of_the_wrong_type():
    """A string where a Body or MuscleSet belongs: the package's error naming it, never an
    AttributeError from inside."""
    import numpy as np

    from posturelab.frequency import model_frf
    from posturelab.linear.delay import delay_margin, rightmost_roots
    from posturelab.simulation.compiled import simulate_batch

    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    for call, words in [
        (lambda: pl.analyse("paper", muscles), "body must be a Body, got str 'paper'"),
        (lambda: pl.analyse(body, "1"), "muscles must be a MuscleSet, got str '1'"),
        (lambda: model_frf("paper", muscles, [1.0]), "body must be a Body"),
        (lambda: delay_margin(body, "x"), "muscles must be a MuscleSet"),
        (lambda: rightmost_roots("b", muscles, 0.1), "body must be a Body"),
        (lambda: simulate_batch("b", np.ones((1, 5)), np.ones((1, 5))), "body must be a Body"),
        (lambda: pl.disturbance_sensitivity("b"), "body must be a Body"),
        (lambda: pl.simulate(body, muscles, "backward"), "disturbance must be a Disturbance"),
        (lambda: pl.analyse(pl.get_body("paper-1link"), muscles), "for 3 links but the body has 1"),
    ]:
        with pytest.raises(ParameterError, match=words.replace("(", r"\(")):
            call()


def test_fit_data_spanning_a_million_seconds_is_refused(tmp_path):
    """The fit sets the run's duration from the data: 1e6 s is refused by the duration
    bound in one line, instead of running out of memory."""
    path = tmp_path / "long.csv"
    path.write_text("t,theta1,theta2,theta3\n0,0.1,-0.1,0.1\n1,0,0,0\n1000000,0,0,0\n")
    p = cli("fit", "--case", "1", "--disturbance", "backward", "--data", str(path), "--free",
            "stiffness:ankle")
    err = p.stderr.strip()
    assert p.returncode == 2 and len(err.splitlines()) == 1
    assert "duration [s] must be in (0, 86400] s, got 1000000.0" in err
