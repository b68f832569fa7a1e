"""Step and time budgets: a runaway integration ends as ``failed`` with a message that says
which budget ran out, in both engines, batches, sweeps, scenario files and on the command
line, instead of a hang. The run keeps the samples it computed."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import posturelab as pl
from posturelab.errors import ParameterError, ScenarioError
from posturelab.scenarios import load_scenario
from posturelab.simulation.compiled import simulate_batch
from posturelab.simulation.setup import default_step_budget

BODY = pl.paper_body()
CASE1 = pl.paper_muscles("1")
STEP = pl.VelocityStep.backward(0.5)
#: The stiffest gains allowed, on the ankle and hip: a very stiff run for explicit methods.
STIFF = CASE1.with_stiffness(ankle=1e8, hip=1e8)


def cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "posturelab", *args], capture_output=True,
                          text=True, timeout=120, cwd=cwd)


@pytest.mark.parametrize("engine", ["reference", "compiled"])
def test_step_budget_ends_the_run_as_failed_keeping_its_samples(engine):
    full = pl.simulate(BODY, CASE1, STEP, 3.0, engine=engine)
    cut = pl.simulate(BODY, CASE1, STEP, 3.0, engine=engine, max_steps=40)
    assert full.status == "completed"
    assert cut.status == "failed" and cut.outcome.kind == "failed" and not cut.fell
    assert "the step budget of 40 integrator steps ran out" in cut.message
    assert cut.outcome.message == f"failed: {cut.message}"
    assert 0 < cut.time[-1] < 3.0
    # the same integration up to the stop: the samples are the full run's first ones
    k = cut.time.size
    np.testing.assert_array_equal(cut.time, full.time[:k])
    np.testing.assert_array_equal(cut.theta, full.theta[:k])


@pytest.mark.parametrize("engine, method", [("reference", "DOP853"), ("compiled", "RK45")])
def test_time_limit_ends_a_very_stiff_run(engine, method):
    """Stiffness 1e8 N·m/rad on an explicit method: hours of work for an hour's run; the
    time limit stops it."""
    r = pl.simulate(BODY, STIFF, STEP, 3600.0, engine=engine, method=method, time_limit=0.2,
                    sample_rate=10.0)
    assert r.status == "failed" and r.outcome.kind == "failed"
    assert "the time limit of 0.2 s (wall clock) ran out" in r.message
    assert r.time[-1] < 3600.0


def test_budgets_in_a_batch_and_their_words():
    k = np.tile(CASE1.stiffnesses, (3, 1))
    batch = simulate_batch(BODY, k, 0.25 * k, STEP, 3.0, max_steps=40)
    assert list(batch.status_code) == [6, 6, 6]
    assert list(batch.outcome) == ["failed"] * 3
    assert list(batch.failure) == ["step budget spent"] * 3
    assert list(batch.n_steps) == [40, 40, 40]
    ok = simulate_batch(BODY, k, 0.25 * k, STEP, 3.0)
    assert list(ok.failure) == [""] * 3 and list(ok.status) == ["completed"] * 3


def test_the_default_budget_and_bad_budgets():
    assert default_step_budget(5.0) == 1_050_000
    assert default_step_budget(86_400.0) == 1_000_000 + 864_000_000
    for bad, words in ((0, "max_steps must be an integer in [1, 10,000,000,000], got 0"),
                       (True, "max_steps must be an integer"),
                       (2.5, "max_steps must be an integer")):
        with pytest.raises(ParameterError, match=words.replace("[", r"\[").replace("]", r"\]")):
            pl.simulate(BODY, CASE1, STEP, 1.0, max_steps=bad)
    with pytest.raises(ParameterError, match=r"time_limit \[s\] must be in \(0, 604800\] s"):
        pl.simulate(BODY, CASE1, STEP, 1.0, time_limit=0.0)


def _scenario(tmp_path, solver: str):
    path = tmp_path / "s.toml"
    path.write_text(f"""duration = 3.0
[muscles]
case = "1"
[disturbance]
type = "velocity-step"
direction = "backward"
speed = 0.5
[solver]
{solver}
""", encoding="utf-8")
    return path


def test_scenario_file_budgets(tmp_path):
    sc = load_scenario(_scenario(tmp_path, "max_steps = 40\ntime_limit = 30.0"))
    assert sc.max_steps == 40 and sc.time_limit == 30.0
    assert "step budget of 40" in sc.run(engine="compiled").message
    for text, words in (("max_steps = true", "solver.max_steps"),
                        ("max_steps = 0", "solver.max_steps must be an integer in [1,"),
                        ("time_limit = -1.0", "solver.time_limit [s] must be in (0, 604800]")):
        with pytest.raises(ScenarioError) as info:
            load_scenario(_scenario(tmp_path, text))
        assert words in str(info.value)


def test_cli_budgets(tmp_path):
    p = cli("simulate", "--case", "1", "--disturbance", "backward", "--max-steps", "10",
            "--engine", "compiled")
    assert p.returncode == 1
    assert "outcome: failed: stopped at t = " in p.stdout
    err = p.stderr.strip().splitlines()
    assert len(err) == 1 and "step budget of 10 integrator steps" in err[0]
    assert "Traceback" not in p.stderr
    p = cli("simulate", "--stiffness", "3e7,300,3e7,300,818", "--disturbance", "backward",
            "--duration", "10", "--time-limit", "0.5", "--json", "--engine", "reference")
    assert p.returncode == 1 and "Traceback" not in p.stderr
    assert '"outcome": "failed"' in p.stdout and "time limit of 0.5 s" in p.stdout
    p = cli("simulate", "--case", "1", "--max-steps", "0")
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1
    assert "max_steps must be an integer in [1, 10,000,000,000], got 0" in p.stderr
    # a sweep row that spends its budget says so in its failure column
    out = tmp_path / "rows.csv"
    p = cli("sweep", "--scenario", str(_scenario(tmp_path, "max_steps = 40")), "--vary",
            "stiffness:ankle=600:900:2", "--out", str(out))
    assert p.returncode == 0, p.stderr
    header, *rows = [line.split(",") for line in out.read_text().splitlines()]
    at = header.index("failure")
    assert [r[at] for r in rows] == ["step budget spent"] * 2
    assert [r[header.index("outcome")] for r in rows] == ["failed"] * 2
    assert "2 runs failed" in p.stderr
