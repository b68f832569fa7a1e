"""A run's outcome is measured within the run, and a run without a perturbation says so.

Checked against: profiles (translation and tilt) with a negative first time, refused with
their line; profiles, a raised-cosine tilt and a pulse that start after the run ends,
refused in one line on the command line and in the API; a run that ends while its
perturbation still acts (not recovered, no settling time, single run and batch row alike,
even when the body is still within the upright band); a run with no perturbation from rest
upright, and one from an initial lean only.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import posturelab as pl
from posturelab.errors import DataFileError, ParameterError
from posturelab.model.tilt import MeasuredTilt, RaisedCosineTilt, read_tilt_csv
from posturelab.simulation.outcome import UPRIGHT_BAND


def posturelab_cli(*args):
    return subprocess.run([sys.executable, "-m", "posturelab", *args], capture_output=True,
                          text=True, timeout=300)


def _csv(path, header, rows):
    path.write_text(header + "\n" + "".join(",".join(f"{v:g}" for v in r) + "\n"
                                            for r in rows))
    return path


def test_a_profile_before_t0_is_refused_with_its_line(tmp_path):
    early = _csv(tmp_path / "early.csv", "time,x_acceleration",
                 [(-1.0, 0.0), (0.5, 1.0), (1.0, 0.0)])
    p = posturelab_cli("simulate", "--case", "1", "--platform-profile", str(early),
                       "--duration", "2")
    assert p.returncode == 2 and p.stdout == ""
    err = p.stderr.strip().splitlines()
    assert len(err) == 1 and "line 2: time -1 s is before 0" in err[0]
    with pytest.raises(DataFileError, match="line 2: time -1 s is before 0"):
        pl.read_profile_csv(early)
    with pytest.raises(ParameterError, match="start at t >= 0.*-1"):
        pl.MeasuredProfile([-1.0, 0.5, 1.0], [0.0, 1.0, 0.0])
    tilt = _csv(tmp_path / "tilt.csv", "time,tilt",
                [(-0.5, 0.0), (0.2, 0.01), (0.4, 0.02), (0.6, 0.02)])
    with pytest.raises(DataFileError, match="line 2: time -0.5 s is before 0"):
        read_tilt_csv(tilt)
    with pytest.raises(ParameterError, match="start at t >= 0"):
        MeasuredTilt([-0.5, 0.2, 0.4, 0.6], [0.0, 0.01, 0.02, 0.02])


def test_a_perturbation_starting_after_the_run_is_refused_in_one_line(tmp_path):
    late = _csv(tmp_path / "late.csv", "time,x_acceleration",
                [(5.0, 0.0), (5.5, 1.0), (6.0, 0.0)])
    p = posturelab_cli("simulate", "--case", "1", "--platform-profile", str(late),
                       "--duration", "2")
    assert p.returncode == 2 and p.stdout == ""
    assert p.stderr.strip().splitlines() == [
        "posturelab: error: the platform profile (late.csv) starts at 5 s, after the run "
        "ends at 2 s (lengthen the run or start it earlier)"]
    late_tilt = _csv(tmp_path / "late_tilt.csv", "time,tilt",
                     [(5.0, 0.0), (5.2, 0.01), (5.4, 0.02), (5.6, 0.02)])
    p = posturelab_cli("simulate", "--case", "1", "--platform-profile", str(late_tilt),
                       "--duration", "2")
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1
    assert "the tilt profile (late_tilt.csv) starts at 5 s, after the run ends at 2 s" in p.stderr
    p = posturelab_cli("simulate", "--case", "1", "--tilt", "raised-cosine:0.02:0.5:3",
                       "--duration", "2")
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1
    assert "the raised-cosine tilt starts at 3 s, after the run ends at 2 s" in p.stderr
    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    for engine in ("reference", "compiled"):
        with pytest.raises(ParameterError, match="profile .late.csv. starts at 5 s, after "
                                                 "the run ends at 2 s"):
            pl.simulate(body, muscles, pl.read_profile_csv(late), 2.0, engine=engine)
        with pytest.raises(ParameterError, match="raised-cosine tilt starts at 2 s, just as "
                                                 "the run ends at 2 s"):
            pl.simulate(body, muscles, None, 2.0, tilt=RaisedCosineTilt(0.02, 0.5, 2.0),
                        engine=engine)
        with pytest.raises(ParameterError, match="half-sine pulse starts at 3 s"):
            pl.simulate(body, muscles, pl.HalfSinePulse(1.0, 0.2, start=3.0), 2.0,
                        engine=engine)


def test_a_run_ending_before_its_perturbation_is_not_recovered():
    # a tiny push that lasts to 6 s: at 2 s the body is still well inside the upright band
    t = np.linspace(1.0, 6.0, 11)
    profile = pl.MeasuredProfile(t, np.full(t.size, 1e-4))
    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    for engine in ("reference", "compiled"):
        run = pl.simulate(body, muscles, profile, 2.0, engine=engine)
        assert run.status == "completed" and run.time[-1] == 2.0
        assert np.abs(run.theta).max() < UPRIGHT_BAND  # would have been "recovered"
        out = run.outcome
        assert out.kind == "not recovered" and out.settling_time is None
        assert run.settling_time(UPRIGHT_BAND) is None
        assert out.message.startswith("not recovered: the run ended at 2 s, before the "
                                      "perturbation did (at 6 s)")
        assert "recovered: within" not in out.message
        assert run.summary()["perturbation_end"] == 6.0
    from posturelab.simulation.compiled import simulate_batch

    batch = simulate_batch(body, np.array([muscles.stiffnesses]),
                           np.array([muscles.viscosities]), profile, 2.0, muscles=muscles)
    assert batch.outcome.tolist() == ["not recovered"]
    assert np.isnan(batch.settling_time).all()
    # a raised-cosine tilt whose ramp ends after the run
    run = pl.simulate(body, muscles, None, 2.0, tilt=RaisedCosineTilt(0.001, 3.0, 1.0),
                      engine="compiled")
    assert run.outcome.kind == "not recovered" and "(at 4 s)" in run.outcome.message


def test_a_run_without_a_perturbation_says_so():
    p = posturelab_cli("simulate", "--case", "1", "--duration", "1")
    assert p.returncode == 0, p.stderr
    assert p.stdout.splitlines()[0] == ("outcome: recovered (no perturbation: started at rest "
                                        "upright and stayed within ±0.01 rad)")
    # an initial lean alone is a perturbation of the state: its settling time is given
    lean = pl.simulate(pl.paper_body(), pl.paper_muscles("1"), None, 5.0, engine="compiled",
                       initial_state=np.array([0.02, 0.02, 0.02, 0.0, 0.0, 0.0]))
    out = lean.outcome
    assert out.kind == "recovered" and out.settling_time > 0
    assert out.message.startswith("recovered: within ±0.01 rad of upright from ")
    assert "no perturbation" not in out.message
    # a velocity step is a perturbation even though it ends at t = 0
    step = pl.simulate(pl.paper_body(), pl.paper_muscles("1"), pl.VelocityStep.backward(0.5),
                       5.0, engine="compiled")
    assert "no perturbation" not in step.outcome.message
