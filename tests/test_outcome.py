"""Every run says what happened: recovered, not recovered, steady sway, fell or failed
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
    assert text.stdout.splitlines()[0].startswith("outcome: not recovered: ended 1.0")


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


# --- sustained stimuli: a steady sway, no settling time; settling from the end of a motion ---


def _steady_by_hand(run, start):
    """RMS about upright and peak |·| of θ_i and of the centre of pressure over t >= start,
    straight from the samples."""
    keep = run.time >= start
    theta, cop = run.theta[keep], run.centre_of_pressure[keep]
    return (np.sqrt((theta ** 2).mean(axis=0)), np.abs(theta).max(axis=0),
            np.sqrt((cop ** 2).mean()), np.abs(cop).max())


def test_a_prts_run_is_a_steady_sway_measured_after_its_first_cycle():
    from posturelab.model.controllers import get_controller
    from posturelab.model.tilt import PRTSTilt

    body = pl.get_body("paper-1link")
    preset = get_controller("peterka-2002")
    tilt = PRTSTilt.named("posturelab-80", 0.035)
    run = pl.simulate(body, preset.muscles(body), None, 41.0, tilt=tilt, engine="compiled",
                      **preset.run_options())
    out = run.outcome
    assert out.kind == "steady sway" and out.settling_time is None
    assert run.settling_time(UPRIGHT_BAND) is None
    assert out.steady.start == 20.0 == tilt.cycle  # after the first 20 s cycle
    rms, peak, rms_cop, peak_cop = _steady_by_hand(run, 20.0)
    np.testing.assert_allclose(out.steady.rms_theta, rms, rtol=1e-12)
    np.testing.assert_allclose(out.steady.peak_theta, peak, rtol=1e-12)
    np.testing.assert_allclose([out.steady.rms_cop, out.steady.peak_cop], [rms_cop, peak_cop],
                               rtol=1e-12)
    assert 0 < rms[0] < peak[0] and "PRTS tilt; no settling time" in out.message
    summary = run.summary()
    assert summary["outcome"] == "steady sway" and summary["perturbation_end"] is None
    assert summary["steady_rms_theta"] == list(out.steady.rms_theta)
    assert summary["steady_from"] == 20.0


def test_a_sine_run_is_a_steady_sway_on_both_engines():
    from posturelab.model.controllers import get_controller
    from posturelab.model.tilt import SineTilt

    body = pl.get_body("paper-1link")
    preset = get_controller("peterka-2002")
    runs = [pl.simulate(body, preset.muscles(body), None, 4.0, tilt=SineTilt(0.02, 0.5),
                        engine=engine, **preset.run_options())
            for engine in ("reference", "compiled")]
    for run in runs:
        out = run.outcome
        assert out.kind == "steady sway" and out.steady.start == 2.0  # one 2 s period
        rms, peak, rms_cop, peak_cop = _steady_by_hand(run, 2.0)
        np.testing.assert_allclose(out.steady.rms_theta, rms, rtol=1e-12)
        np.testing.assert_allclose(out.steady.peak_cop, peak_cop, rtol=1e-12)
    np.testing.assert_allclose(runs[0].outcome.steady.rms_theta,
                               runs[1].outcome.steady.rms_theta, rtol=1e-3)


def test_a_short_sustained_run_uses_its_second_half():
    from posturelab.model.tilt import SineTilt
    from posturelab.simulation.outcome import stimulus_timing

    timing = stimulus_timing(None, SineTilt(0.02, 0.1))  # a 10 s period
    assert timing.sustained and timing.period == 10.0 and timing.steady_start(6.0) == 3.0
    assert timing.steady_start(25.0) == 10.0


def test_settling_is_counted_from_the_end_of_the_platform_motion():
    ramp = pl.RampAndHold(-0.05, 0.8, start=0.5)  # the platform stops at 1.3 s
    run = pl.simulate(pl.paper_body(), pl.paper_muscles("1"), ramp, 6.0, engine="compiled")
    out = run.outcome
    assert out.kind == "recovered" and out.perturbation_end == 1.3
    outside = np.any(np.abs(run.theta) > UPRIGHT_BAND, axis=1)
    last = run.time[np.nonzero(outside)[0][-1]]
    assert last > 1.3
    assert out.settling_time == last - 1.3  # not the time from t = 0
    assert run.summary()["perturbation_end"] == 1.3
    # the batch engine's rows count it the same way
    from posturelab.simulation.compiled import simulate_batch

    muscles = pl.paper_muscles("1")
    batch = simulate_batch(pl.paper_body(), np.array([muscles.stiffnesses]),
                           np.array([muscles.viscosities]), ramp, 6.0, muscles=muscles)
    assert batch.outcome.tolist() == ["recovered"]
    np.testing.assert_allclose(batch.settling_time, [out.settling_time], atol=1e-12)
    # a velocity step ends at t = 0: its settling time is the last time outside
    step = pl.simulate(pl.paper_body(), pl.paper_muscles("1"), pl.VelocityStep.backward(0.5),
                       5.0, engine="compiled")
    outside = np.any(np.abs(step.theta) > UPRIGHT_BAND, axis=1)
    assert step.outcome.settling_time == step.time[np.nonzero(outside)[0][-1]]


def test_simulate_prts_on_the_command_line_reports_a_steady_sway():
    p = posturelab_cli("simulate", "--controller", "peterka-2002", "--tilt", "prts:0.035",
                       "--duration", "30", "--engine", "compiled", "--json")
    assert p.returncode == 0, p.stderr
    summary = json.loads(p.stdout)
    assert summary["outcome"] == "steady sway" and summary["settling_time"] is None
    assert summary["steady_from"] == 15.0  # 30 s is under two 20 s cycles: the second half
    assert 0 < summary["steady_rms_theta"][0] < summary["steady_peak_theta"][0]
    text = posturelab_cli("simulate", "--controller", "peterka-2002", "--tilt", "prts:0.035",
                          "--duration", "30", "--engine", "compiled")
    assert "outcome: steady sway under a sustained stimulus (PRTS tilt" in text.stdout
    assert "not recovered" not in text.stdout


def test_a_steady_sway_without_a_defined_centre_of_pressure_still_writes_json():
    from posturelab.simulation.outcome import steady_sway

    t = np.linspace(0.0, 4.0, 401)
    sway = steady_sway(t, np.sin(t)[:, None], np.where(t > 3.0, np.nan, 0.01), start=2.0)
    assert np.isnan(sway.rms_cop)
    d = sway.to_dict()
    assert d["steady_rms_cop"] is None and d["steady_peak_cop"] is None
    json.dumps(d, allow_nan=False)  # no NaN reaches the JSON
    keep = t >= 2.0
    np.testing.assert_allclose(d["steady_rms_theta"][0], np.sqrt(np.mean(np.sin(t[keep]) ** 2)),
                               rtol=1e-13)
