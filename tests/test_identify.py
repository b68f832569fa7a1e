"""Fitting pair stiffness to measured angles: recovery of known gains from synthetic data."""

import json

import numpy as np
import pytest

import posturelab as pl
from posturelab.cli import main
from posturelab.studies.identification import fit_stiffness, read_trajectory_csv


@pytest.fixture(scope="module")
def experiment():
    """A 2 s backward-step run of case 1 sampled at 50 Hz: the 'measurement'."""
    sc = pl.builtin_scenario("paper-backward-case1").replace(duration=2.0, sample_rate=50)
    return sc, sc.run()


def test_noise_free_data_recovers_gains_exactly(experiment):
    sc, truth = experiment
    start = sc.replace(muscles=pl.paper_muscles(stiffness=[800, 300, 300, 300, 100]))
    fit = fit_stiffness(start, truth.time, truth.theta, ["stiffness:ankle",
                                                         "stiffness:gastrocnemius"])
    assert fit.success
    np.testing.assert_allclose(fit.estimates, [500.0, 300.0], rtol=1e-5)
    assert fit.residual_rms < 1e-7


def test_fast_and_reference_engines_give_the_same_fit(experiment):
    """The compiled simulator (default) and scipy's inside the same fit: the same estimates
    and standard errors, to far below their own uncertainty."""
    sc, truth = experiment
    rng = np.random.default_rng(7)
    noisy = truth.theta + rng.normal(0.0, 0.001, truth.theta.shape)
    start = sc.replace(muscles=pl.paper_muscles(stiffness=[800, 300, 300, 300, 100]))
    fits = {engine: fit_stiffness(start, truth.time, noisy, ["stiffness:ankle",
                                                             "stiffness:gastrocnemius"],
                                  engine=engine) for engine in ("fast", "reference")}
    np.testing.assert_allclose(fits["fast"].estimates, fits["reference"].estimates, rtol=1e-5)
    np.testing.assert_allclose(fits["fast"].standard_errors,
                               fits["reference"].standard_errors, rtol=1e-3)
    with pytest.raises(pl.PostureLabError, match="engine"):
        fit_stiffness(start, truth.time, noisy, ["stiffness:ankle"], engine="turbo")


def test_noisy_data_true_values_inside_confidence_intervals(experiment):
    """Seeded 2 mrad noise: each true value lies within its 95 % interval, which is narrow."""
    sc, truth = experiment
    rng = np.random.default_rng(20261122)
    noisy = truth.theta + rng.normal(0.0, 0.002, truth.theta.shape)
    start = sc.replace(muscles=pl.paper_muscles(stiffness=[700, 300, 300, 300, 200]))
    fit = fit_stiffness(start, truth.time, noisy, ["stiffness:ankle", "stiffness:gastrocnemius",
                                                   "viscosity_ratio"])
    truth_values = np.array([500.0, 300.0, 0.25])
    lo, hi = fit.confidence_intervals.T
    assert np.all(lo <= truth_values) and np.all(truth_values <= hi)
    assert np.all(fit.standard_errors / truth_values < 0.05)
    # the residual RMS estimates the noise level
    assert fit.residual_rms == pytest.approx(0.002, rel=0.15)
    assert fit.correlation.shape == (3, 3)
    np.testing.assert_allclose(np.diag(fit.correlation), 1.0)


def test_unidentifiable_parameter_reported():
    """A one-sided gastrocnemius that stays slack (θ2 < 0 throughout) leaves no trace in the
    angles: its stiffness is reported as not identifiable (NaN standard error)."""
    sc = pl.builtin_scenario("paper-forward-case1").replace(
        muscles=pl.paper_muscles("1", gastrocnemius="one-sided"), duration=1.0, sample_rate=50)
    data = sc.run()
    assert np.all(data.theta[:, 1] < 0)
    fit = fit_stiffness(sc, data.time, data.theta, ["stiffness:ankle", "stiffness:gastrocnemius"])
    assert fit.estimates[0] == pytest.approx(500.0, rel=1e-5)
    assert np.isfinite(fit.standard_errors[0])
    assert not np.isfinite(fit.standard_errors[1])
    assert fit.to_dict()["parameters"]["stiffness:gastrocnemius"]["ci95"] is None


@pytest.mark.parametrize("kwargs,needle", [
    ({"free": ["ankel"]}, "unknown parameter"),
    ({"free": ["active_ankle"]}, "'active_ankle' is now called 'active_stiffness:ankle'"),
    ({"free": ["stiffness"]}, "needs its pair: stiffness:ankle, stiffness:knee"),
    ({"free": ["torque_limit:ankle"]}, "cannot be 'torque_limit:ankle'"),
    ({"free": []}, "at least one"),
    ({"free": ["stiffness:ankle", "stiffness:ankle"]}, "unique"),
    ({"theta": np.zeros((5, 2))}, "theta"),
    ({"time": [0.0, 3.0, 9.0]}, "duration"),
])
def test_bad_fit_input(experiment, kwargs, needle):
    sc, truth = experiment
    args = {"time": truth.time, "theta": truth.theta, "free": ["stiffness:ankle"]} | kwargs
    if "time" in kwargs and "theta" not in kwargs:
        args["theta"] = np.zeros((len(args["time"]), 3))
    with pytest.raises(pl.PostureLabError, match=needle):
        fit_stiffness(sc, args["time"], args["theta"], args["free"])


def test_cli_fit_round_trip(tmp_path, capsys):
    data = tmp_path / "meas.csv"
    assert main(["simulate", "--case", "1", "--disturbance", "backward", "--duration", "1.5",
                 "--sample-rate", "50", "--out", str(data)]) == 0
    capsys.readouterr()
    report = tmp_path / "fit.json"
    code = main(["fit", "--data", str(data), "--stiffness", "700,300,300,300,300",
                 "--disturbance", "backward", "--free", "stiffness:ankle", "--json",
                 "--report", str(report)])
    out = json.loads(capsys.readouterr().out)
    assert code == 0
    assert out["parameters"]["stiffness:ankle"]["estimate"] == pytest.approx(500.0, rel=1e-4)
    assert json.loads(report.read_text())["parameters"]["stiffness:ankle"]["unit"] == "N·m/rad"
    t, theta = read_trajectory_csv(data, 3)
    assert theta.shape == (t.size, 3)


def test_cli_fit_bad_input_one_line(tmp_path, capsys):
    data = tmp_path / "m.csv"
    data.write_text("t,theta1,theta2\n0,0,0\n0.1,0,0\n")
    code = main(["fit", "--data", str(data), "--case", "1", "--disturbance", "backward",
                 "--free", "stiffness:ankle"])
    err = capsys.readouterr().err
    assert code == 2 and "theta3" in err and len(err.strip().splitlines()) == 1


def test_the_time_domain_fit_learns_delay_active_gain_and_weight(rng):
    """A tilted one-link run with intrinsic and delayed active gains, seeded noise on the
    angle: the active stiffness, the delay and W come back inside their 95 % intervals."""
    import posturelab as pl
    from posturelab.model.controllers import get_controller
    from posturelab.model.tilt import SineTilt
    from posturelab.scenarios import Scenario
    from posturelab.studies.identification import fit_stiffness

    body = pl.get_body("paper-1link")
    preset = get_controller("icm-pmc5664365")
    true = preset.muscles(body)
    sc = Scenario(name="t", description="", source="test", body=body, muscles=true,
                  disturbance=pl.NoDisturbance(), duration=12.0, initial_state=None,
                  rates_from="upright", knee=pl.KneeModel(), fall=pl.FallCriteria(1.5),
                  sample_rate=50.0, tilt=SineTilt(0.03, 0.4), feedback_delay=0.097,
                  proprioceptive_weight=0.8)
    r = sc.run(engine="compiled")
    theta = r.theta + rng.normal(0.0, 2e-4, r.theta.shape)
    start = sc.replace(muscles=true.with_active_feedback([700.0], true.active_viscosities),
                       feedback_delay=0.12, proprioceptive_weight=0.6)
    fit = fit_stiffness(start, r.time, theta, ["active_stiffness:ankle", "feedback_delay",
                                               "proprioceptive_weight"],
                        viscosity_ratio=true.viscosities[0] / true.stiffnesses[0])
    truth = [true.active_stiffnesses[0], 0.097, 0.8]
    for (lo, hi), value in zip(fit.confidence_intervals, truth, strict=True):
        assert lo <= value <= hi, (fit.estimates, truth)


# -- the uncertainty of correlated residuals ----------------------------------------------


def _naive_ar1_sandwich(jac, residuals, n_links, rho, variance):
    """The same covariance with every S × S matrix written out (slow, obvious)."""
    samples = residuals.size // n_links
    j = jac.reshape(samples, n_links, -1)
    lags = np.abs(np.subtract.outer(np.arange(samples), np.arange(samples)))
    bread = np.linalg.inv(jac.T @ jac)
    meat = sum(variance[i] * j[:, i, :].T @ (rho[i] ** lags) @ j[:, i, :]
               for i in range(n_links))
    return bread @ meat @ bread


def test_ar1_covariance_equals_the_written_out_sandwich():
    from posturelab.studies.identification import _ar1_covariance, ar1_filter_sum

    rng = np.random.default_rng(11)
    samples, n_links, p = 60, 3, 2
    jac = rng.normal(size=(samples * n_links, p))
    residuals = rng.normal(size=samples * n_links) * 1e-3
    cov, se, rho, dof = _ar1_covariance(jac, np.array([500.0, 0.25]), residuals, n_links)
    r = residuals.reshape(samples, n_links)
    shrink = residuals.size / (residuals.size - p)
    lag1 = np.array([r[1:, i] @ r[:-1, i] / (r[:, i] @ r[:, i]) for i in range(n_links)])
    np.testing.assert_allclose(rho, lag1 + (1 + 3 * lag1) / samples, rtol=1e-12)
    variance = (r**2).mean(axis=0) * shrink
    np.testing.assert_allclose(cov, _naive_ar1_sandwich(jac, residuals, n_links, rho,
                                                        variance), rtol=1e-10)
    np.testing.assert_allclose(se, np.sqrt(np.diag(cov)))
    assert dof == pytest.approx(
        np.sum(np.minimum(samples, samples * (1 - rho) / (1 + rho))) - p)
    x = rng.normal(size=(samples, 4))
    lags = np.abs(np.subtract.outer(np.arange(samples), np.arange(samples)))
    np.testing.assert_allclose(ar1_filter_sum(x, 0.7), (0.7**lags) @ x, rtol=1e-12)


def test_intervals_cover_the_truth_under_correlated_noise():
    """Seeded AR(1) sensor noise of lag-1 correlation 0.8: the textbook intervals cover
    the truth in about half the trials, the AR(1) residual model's in about 95 % (the
    full table, 300 trials a row: examples/fit_coverage.py)."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "fit_coverage.py"
    spec = importlib.util.spec_from_file_location("fit_coverage", path)
    study = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(study)
    ar1 = study.coverage(0.8, 60, "ar1")
    independent = study.coverage(0.8, 60, "independent")
    assert np.all(ar1 >= 0.87), ar1  # 95 % expected; 60 trials: SD of a coverage 0.03
    assert np.all(independent <= 0.65), independent


def test_fit_reports_its_residual_model(experiment):
    sc, truth = experiment
    rng = np.random.default_rng(5)
    noisy = truth.theta + rng.normal(0.0, 0.002, truth.theta.shape)
    start = sc.replace(muscles=pl.paper_muscles(stiffness=[700, 300, 300, 300, 200]))
    a = fit_stiffness(start, truth.time, noisy, ["stiffness:ankle", "stiffness:gastrocnemius"])
    b = fit_stiffness(start, truth.time, noisy, ["stiffness:ankle", "stiffness:gastrocnemius"],
                      residual_model="independent")
    np.testing.assert_array_equal(a.estimates, b.estimates)  # the model only sets the errors
    assert a.residual_model == "ar1" and b.residual_model == "independent"
    assert np.all(np.abs(a.residual_autocorrelation) < 0.3)  # independent noise: ρ near 0
    np.testing.assert_allclose(a.standard_errors, b.standard_errors, rtol=0.3)
    d = a.to_dict()
    assert d["residual_model"] == "ar1" and len(d["residual_autocorrelation"]) == 3
    assert d["parameters"]["stiffness:ankle"]["unit"] == "N·m/rad"
    with pytest.raises(pl.PostureLabError, match="residual_model 'white'; known: ar1"):
        fit_stiffness(start, truth.time, noisy, ["stiffness:ankle"], residual_model="white")


def test_a_fit_never_uses_a_run_that_stopped_short(experiment, tmp_path):
    """A spent budget inside a fit stops the fit with the run's message (the CLI: one line,
    exit 2), instead of fitting to a truncated run."""
    import subprocess
    import sys

    from posturelab.studies.identification import FitError

    sc, truth = experiment
    start = sc.replace(muscles=pl.paper_muscles(stiffness=[800, 300, 300, 300, 100]),
                       max_steps=20)
    with pytest.raises(FitError, match="a simulation inside the fit failed at stiffness:ankle = "
                                       "800: stopped at t = .* the step budget of 20"):
        fit_stiffness(start, truth.time, truth.theta, ["stiffness:ankle"])
    data = tmp_path / "m.csv"
    truth.to_csv(data)
    p = subprocess.run([sys.executable, "-m", "posturelab", "fit", "--data", str(data),
                        "--stiffness", "800,300,300,300,100", "--disturbance", "backward",
                        "--free", "stiffness:ankle", "--max-steps", "20"],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1
    assert "a simulation inside the fit failed" in p.stderr and "Traceback" not in p.stderr


def test_cli_fit_prints_the_residual_correlation_it_used(tmp_path, capsys):
    """The text's residual line carries the JSON's numbers."""
    data = tmp_path / "meas.csv"
    assert main(["simulate", "--case", "1", "--disturbance", "backward", "--duration", "1.5",
                 "--sample-rate", "50", "--out", str(data)]) == 0
    rng = np.random.default_rng(3)
    lines = data.read_text().splitlines()
    header = lines[0].split(",")
    cols = [header.index(f"theta{i}") for i in (1, 2, 3)]
    noisy = [lines[0]]
    for line in lines[1:]:
        cells = line.split(",")
        for c in cols:
            cells[c] = repr(float(cells[c]) + rng.normal(0.0, 0.002))
        noisy.append(",".join(cells))
    data.write_text("\n".join(noisy) + "\n")
    capsys.readouterr()
    args = ["fit", "--data", str(data), "--stiffness", "700,300,300,300,300", "--disturbance",
            "backward", "--free", "stiffness:ankle"]
    assert main([*args, "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert main(args) == 0
    text = capsys.readouterr().out
    rho = ", ".join(f"{v:.2f}" for v in summary["residual_autocorrelation"])
    assert (f"residuals: lag-1 correlation per link {rho} (allowed for in the intervals; "
            f"{summary['degrees_of_freedom']:.0f} effective degrees of freedom)") in text
