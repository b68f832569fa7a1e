"""Every run says what happened: recovered, not recovered, fell or failed
(posturelab.simulation.outcome), with the linear verdict about upright beside it.

Checked against: the rule at its thresholds on hand-made states; the two misleading runs
of the issue (a body left leaning 59°, an anthropometric body unstable with case 1's
gains) on the command line as a real subprocess; a fall and a failure; a sweep row against
its single run.
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np

import posturelab as pl
from posturelab.linear.verdict import upright_verdict
from posturelab.simulation.outcome import REST_RATE, UPRIGHT_BAND, classify, classify_rows


def test_the_rule_at_its_thresholds():
    n = 3
    at_rest = np.zeros(2 * n)
    leaning = at_rest.copy()
    leaning[1] = 1.001 * UPRIGHT_BAND
    moving = at_rest.copy()
    moving[n + 2] = -1.001 * REST_RATE
    edge = at_rest.copy()
    edge[0], edge[n] = UPRIGHT_BAND, REST_RATE
    status = np.array(["completed", "completed", "completed", "completed", "fell", "failed"])
    settle = np.array([1.0, np.nan, 1.0, 2.0, np.nan, np.nan])
    states = np.stack([at_rest, leaning, moving, edge, at_rest, at_rest])
    assert classify_rows(status, settle, states).tolist() == [
        "recovered", "not recovered", "not recovered", "recovered", "fell", "failed"]
    out = classify("completed", None, leaning)
    assert out.kind == "not recovered" and out.final_lean == leaning[1]
    assert "ended 0.01001 rad from upright" in out.message and out.settling_time is None


def posturelab_cli(*args):
    return subprocess.run([sys.executable, "-m", "posturelab", *args], capture_output=True,
                          text=True, timeout=300)


def test_a_body_left_leaning_is_not_recovered_and_warned_of():
    """The issue's case: no ankle stiffness leaves the body leaning about 59° at 5 s."""
    p = posturelab_cli("simulate", "--stiffness", "0,300,300,300,818.18", "--disturbance",
                       "backward", "--engine", "compiled", "--json")
    assert p.returncode == 0, p.stderr
    summary = json.loads(p.stdout)
    assert summary["outcome"] == "not recovered" and summary["status"] == "completed"
    assert summary["final_lean"] > 1.0 and summary["settling_time"] is None
    assert summary["linear_stability"]["stable"] is False
    assert summary["linear_stability"]["rightmost_root"]["re"] > 0
    err = p.stderr.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("posturelab: warning: these gains are unstable")
    text = posturelab_cli("simulate", "--stiffness", "0,300,300,300,818.18", "--disturbance",
                          "backward", "--engine", "compiled")
    assert text.stdout.splitlines()[1].startswith("outcome: not recovered: ended 1.0")


def test_an_anthropometric_body_unstable_with_case_1_gains_is_not_called_recovered():
    body = pl.body_from_anthropometry(1.80, 82.0)
    muscles = pl.paper_muscles("1")
    verdict = upright_verdict(body, muscles)
    assert not verdict.stable
    r = pl.simulate(body, muscles, pl.VelocityStep.backward(1.0), 5.0, engine="compiled",
                    initial_state=np.array([0.1, -0.1, 0.1, 0, 0, 0]))
    assert r.outcome.kind in ("not recovered", "fell")
    assert r.outcome.kind != "recovered"


def test_a_fall_and_a_failure_say_so():
    r = pl.simulate(pl.paper_body(), pl.paper_muscles("2"), pl.VelocityStep.forward(1.0), 5.0,
                    engine="compiled", initial_state=np.array([0.1, -0.1, 0.1, 0, 0, 0]))
    out = r.outcome
    assert out.kind == "fell" and out.fall_time == r.fall_time and out.fall_reason
    assert r.summary()["fall_reason"] == r.fall_reason
    failed = pl.simulate(pl.paper_body(), pl.paper_muscles("1"), pl.VelocityStep.backward(1.0),
                         3.0, engine="compiled", max_switches=0,
                         torque_limits=[300.0, np.inf, np.inf],
                         initial_state=np.array([0.1, -0.1, 0.1, 0, 0, 0]))
    assert failed.status == "failed" and failed.outcome.kind == "failed"
    assert failed.outcome.message == f"failed: {failed.message}"


def test_a_recovered_run_and_its_settling_time():
    r = pl.simulate(pl.paper_body(), pl.paper_muscles("1"), pl.VelocityStep.backward(1.0), 5.0,
                    engine="compiled", initial_state=np.array([0.1, -0.1, 0.1, 0, 0, 0]))
    out = r.outcome
    assert out.kind == "recovered" and out.settling_time == r.settling_time(UPRIGHT_BAND)
    assert 0 < out.settling_time < 5 and out.final_rate <= REST_RATE
