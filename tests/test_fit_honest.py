"""The time-domain fit says what the data cannot determine and when it does not describe
the data (issue 18's reproducers), instead of confident numbers."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import posturelab as pl
from posturelab.studies.identification import FitError, _describes, _determinacy, fit_stiffness


def run_cli(*argv):
    env = dict(os.environ, PYTHONIOENCODING="utf-8")
    return subprocess.run([sys.executable, "-m", "posturelab", *argv], capture_output=True,
                          encoding="utf-8", env=env, timeout=300, check=False)


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    """Case 1 after a backward step, 2 s at 100 Hz, noise-free, no feedback delay: the
    user's measured2.csv, written by ``posturelab simulate``."""
    path = tmp_path_factory.mktemp("fit") / "measured2.csv"
    proc = run_cli("simulate", "--case", "1", "--disturbance", "backward", "--duration", "2",
                   "--sample-rate", "100", "--out", str(path))
    assert proc.returncode == 0, proc.stderr
    return path


def test_a_fit_stuck_far_from_the_data_is_no_success(measured):
    """Freeing the delay of delay-free data: no start reaches the data (sway 0.17 rad RMS),
    so the fit is no success, says why in one line and shows no interval (it printed a
    delay of 0.126 ± 9.5e-09 s)."""
    free = "stiffness:quadriceps,stiffness:gastrocnemius,viscosity:knee,feedback_delay"
    args = ["fit", "--data", str(measured), "--case", "1", "--disturbance", "backward",
            "--free", free]
    proc = run_cli(*args, "--json")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["success"] is False and out["describes_data"] is False
    assert out["residual_rms"] > 0.5 * out["sway_rms"]
    assert out["sway_rms"] == pytest.approx(0.170, abs=0.002)
    assert out["n_starts"] > 1  # restarts were tried
    assert "does not describe the data" in out["warning"]
    assert all(p["ci95"] is None for p in out["parameters"].values())
    text = run_cli(*args)
    assert text.returncode == 0, text.stderr
    warnings = [ln for ln in text.stdout.splitlines() if ln.startswith("warning:")]
    assert len(warnings) == 1 and "does not describe the data" in warnings[0]
    assert "±" not in text.stdout and "95 % CI" not in text.stdout


def test_a_model_that_predicts_no_motion_is_refused(measured):
    """Without --disturbance the model stays upright: refused in one line, exit 2 (it
    returned the starting value, 500 ± nan)."""
    proc = run_cli("fit", "--data", str(measured), "--case", "1", "--free", "stiffness:ankle")
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.strip().count("\n") == 0 and "Traceback" not in proc.stderr
    assert "the model predicts no motion for this experiment" in proc.stderr
    assert "check --disturbance/--tilt" in proc.stderr
    sc = pl.builtin_scenario("paper-backward-case1").replace(
        disturbance=pl.NoDisturbance(), initial_state=None, duration=1.0, sample_rate=50)
    t = np.linspace(0.0, 1.0, 51)
    with pytest.raises(FitError, match="predicts no motion"):
        fit_stiffness(sc, t, np.full((51, 3), 0.01), ["stiffness:ankle"])


def test_parameters_that_are_not_separable_are_named(measured):
    """With the ankle's viscosity free too, its intrinsic and (undelayed) active stiffness
    act only through their sum: neither can be determined, each names the other; the
    viscosity is determined."""
    proc = run_cli("fit", "--data", str(measured), "--case", "1", "--disturbance", "backward",
                   "--free", "stiffness:ankle,active_stiffness:ankle,viscosity:ankle", "--json")
    assert proc.returncode == 0, proc.stderr
    p = json.loads(proc.stdout)["parameters"]
    assert p["stiffness:ankle"]["determined"] is False
    assert p["stiffness:ankle"]["reason"] == "not separable from active_stiffness:ankle"
    assert p["active_stiffness:ankle"]["reason"] == "not separable from stiffness:ankle"
    assert p["stiffness:ankle"]["ci95"] is None and p["stiffness:ankle"]["standard_error"] is None
    assert p["viscosity:ankle"]["determined"] is True
    assert p["viscosity:ankle"]["estimate"] == pytest.approx(125.0, rel=1e-5)
    text = run_cli("fit", "--data", str(measured), "--case", "1", "--disturbance", "backward",
                   "--free", "stiffness:ankle,active_stiffness:ankle,viscosity:ankle").stdout
    assert ("stiffness:ankle        cannot be determined from these data: not separable from "
            "active_stiffness:ankle") in text


def test_intrinsic_and_active_stiffness_separate_through_the_viscosity_model(rng):
    """Without the viscosity free, intrinsic stiffness brings its viscosity (ratio × K) and
    the active gain does not: the stiffness is determined (its interval holds 500 with
    seeded 2 mrad noise), and the active gain, whose truth 0 is its search bound, stops on
    that bound and is said to (it printed 5.05e-06 ± nan, then an interval below 0)."""
    sc = pl.builtin_scenario("paper-backward-case1").replace(duration=2.0, sample_rate=50)
    truth = sc.run()
    noisy = truth.theta + rng.normal(0.0, 0.002, truth.theta.shape)
    fit = fit_stiffness(sc, truth.time, noisy, ["stiffness:ankle", "active_stiffness:ankle"])
    assert fit.success and fit.describes_data and fit.n_starts == 1
    assert fit.determined.tolist() == [True, False] and fit.at_bound == (None, "low")
    assert fit.undetermined_reasons == ("", "at its search bound LO = 0 N·m/rad")
    lo, hi = fit.confidence_intervals[0]
    assert 0.0 <= lo <= 500.0 <= hi
    active = fit.to_dict()["parameters"]["active_stiffness:ankle"]
    assert active["at_bound"] == "low" and active["determined"] is False


def test_a_well_posed_noisy_fit_is_determined_and_covers_the_truth(rng):
    sc = pl.builtin_scenario("paper-backward-case1").replace(duration=2.0, sample_rate=50)
    truth = sc.run()
    noisy = truth.theta + rng.normal(0.0, 0.002, truth.theta.shape)
    start = sc.replace(muscles=pl.paper_muscles(stiffness=[700, 300, 300, 300, 200]))
    fit = fit_stiffness(start, truth.time, noisy, ["stiffness:ankle", "stiffness:gastrocnemius",
                                                   "viscosity_ratio"])
    assert fit.success and fit.converged and fit.describes_data and not fit.warning
    assert fit.determined.all()
    lo, hi = fit.confidence_intervals.T
    assert np.all(lo <= [500.0, 300.0, 0.25]) and np.all([500.0, 300.0, 0.25] <= hi)
    d = fit.to_dict()
    assert d["success"] is True and d["warning"] is None
    assert all(p["determined"] and p["ci95"] for p in d["parameters"].values())


def test_a_slack_pair_is_one_the_data_do_not_depend_on():
    sc = pl.builtin_scenario("paper-forward-case1").replace(
        muscles=pl.paper_muscles("1", gastrocnemius="one-sided"), duration=1.0, sample_rate=50)
    data = sc.run()
    fit = fit_stiffness(sc, data.time, data.theta, ["stiffness:ankle", "stiffness:gastrocnemius"])
    assert fit.determined.tolist() == [True, False]
    assert fit.undetermined_reasons[1] == "the data do not depend on it"
    assert fit.to_dict()["parameters"]["stiffness:gastrocnemius"]["determined"] is False


def test_determinacy_of_a_written_out_jacobian():
    """A zero column: no effect; two proportional columns: not separable, each naming the
    other; a parameter at 0 is judged by its scale, not its value."""
    rng = np.random.default_rng(4)
    a, b = rng.normal(size=(2, 200))
    jac = np.column_stack([a, 2.0 * a, np.zeros(200), b])
    good, why = _determinacy(jac, np.ones(4), ["p", "q", "r", "s"], sway=0.1, samples=200)
    assert good.tolist() == [False, False, False, True]
    assert why == ["not separable from q", "not separable from p",
                   "the data do not depend on it", ""]
    good, _ = _determinacy(np.column_stack([a, b]), np.array([1.0, 1e-3]), ["p", "q"],
                           sway=0.1, samples=200)
    assert good.all()


def test_describes_tells_a_smooth_misfit_from_noise(rng):
    """Residuals larger than half the sway: a smooth misfit does not describe the data,
    independent noise of that size does (it is the measurement's, not the model's)."""
    time = np.linspace(0.0, 2.0, 201)
    smooth = 0.08 * np.sin(3.0 * time)[:, None] * np.ones((1, 3))
    assert not _describes(smooth.ravel(), sway=0.1, n_links=3)
    assert _describes(0.3 * smooth.ravel(), sway=0.1, n_links=3)
    assert _describes(rng.normal(0.0, 0.08, (201, 3)).ravel(), sway=0.1, n_links=3)


def test_a_fit_that_ran_out_of_simulations_is_no_success():
    """Three simulations cannot converge: the fit says so, and shows no interval."""
    sc = pl.builtin_scenario("paper-backward-case1").replace(duration=2.0, sample_rate=50)
    truth = sc.run()
    start = sc.replace(muscles=pl.paper_muscles(stiffness=[700, 300, 300, 300, 200]))
    fit = fit_stiffness(start, truth.time, truth.theta,
                        ["stiffness:ankle", "stiffness:gastrocnemius"], max_simulations=3)
    assert not fit.converged and not fit.success
    assert fit.warning.startswith("the optimiser did not converge")
    d = fit.to_dict()
    assert d["success"] is False and d["converged"] is False
    assert all(p["ci95"] is None for p in d["parameters"].values())


def test_the_command_line_says_an_estimate_is_on_its_search_bound(measured):
    """Case 1 has no active feedback: the active gain stops on its lower search bound, 0,
    and `fit` says so in text and JSON instead of an interval reaching below 0."""
    args = ["fit", "--data", str(measured), "--case", "1", "--disturbance", "backward",
            "--free", "stiffness:ankle,active_stiffness:ankle"]
    proc = run_cli(*args, "--json")
    assert proc.returncode == 0, proc.stderr
    p = json.loads(proc.stdout)["parameters"]
    assert p["active_stiffness:ankle"]["at_bound"] == "low"
    assert p["active_stiffness:ankle"]["determined"] is False
    assert p["stiffness:ankle"]["at_bound"] is None and p["stiffness:ankle"]["determined"]
    assert p["stiffness:ankle"]["ci95"][0] >= 0.0
    text = run_cli(*args)
    assert text.returncode == 0, text.stderr
    assert ("active_stiffness:ankle cannot be determined from these data: at its search "
            "bound LO = 0 N·m/rad") in text.stdout
