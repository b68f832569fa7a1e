"""Experiment design (posturelab.frequency.design, posturelab design): the band variance against
simulated experiments, the predicted errors against the spread of fits, 1/√cycles, the
derivatives against the one-link closed form, the search and the command line."""

import json

import numpy as np
import pytest

import posturelab as pl
from _cli import cli, one_line_exit_2
from posturelab.errors import ParameterError
from posturelab.frequency.design import (
    band_noise_covariance,
    frf_derivatives,
    model_band_frf,
    predict_errors,
)
from posturelab.frequency.design_search import optimise_design
from posturelab.frequency.experiment import prts_experiment
from posturelab.frequency.fit import fit_frf
from posturelab.model.controllers import get_controller
from posturelab.model.dynamics import mass_matrix
from posturelab.model.noise import MotorNoise
from posturelab.model.tilt import PRTSTilt, SineTilt

FREE = ["active_stiffness", "active_viscosity", "feedback_delay"]
SEEDS = 40


@pytest.fixture(scope="module")
def model():
    body = pl.get_body("paper-1link")
    preset = get_controller("peterka-2002")
    return body, preset.muscles(body), preset.run_options()


def test_band_variance_matches_simulated_experiments(model):
    """The derived V (sensor noise after the run and motor noise through the nonlinear loop,
    compiled engine) against the scatter of the estimated band FRFs over 40 seeds."""
    body, muscles, options = model
    tilt = PRTSTilt.named("posturelab-80", 0.035)
    sensor, motor = 0.0005, 3.0  # (the motor noise's seeds apart from the sensor noise's)
    frfs = []
    for seed in range(SEEDS):
        exp = prts_experiment(body, muscles, tilt=tilt, cycles=3, discard=1, seed=seed,
                              sensor_noise=sensor,
                              motor_noise=MotorNoise(motor, seed=10_000 + seed),
                              **options)
        frfs.append(exp.estimate.frf)
    frfs = np.array(frfs)
    spread = np.sum(np.abs(frfs - frfs.mean(axis=0)) ** 2, axis=0) / (SEEDS - 1)
    predicted = np.diag(band_noise_covariance(
        body, muscles, tilt, 3, sensor_noise=sensor, motor_noise=MotorNoise(motor),
        **options)["covariance"])
    ratio = spread / predicted
    # each band's sample variance has 2(40 − 1) degrees of freedom: ±16 % (1 sd)
    assert np.all((ratio > 0.55) & (ratio < 1.6)), ratio
    assert abs(np.mean(ratio) - 1) < 0.15, ratio


def test_motor_noise_through_a_three_link_chain_matches_simulated_experiments():
    """Motor noise at the knee and hip only (the joint-torque map Eᵀ matters), the leg angle
    recorded: V against the scatter over 30 seeded experiments of the paper's body."""
    from posturelab.model.body import paper_body
    from posturelab.model.muscles import paper_muscles

    body, muscles = paper_body(), paper_muscles("1")
    tilt = PRTSTilt.named("posturelab-80", 0.02)
    seeds = 30
    frfs = np.array([prts_experiment(
        body, muscles, tilt=tilt, cycles=2, discard=1, seed=seed, output="theta1",
        motor_noise=MotorNoise((0.0, 2.0, 3.0), 2.0, seed=seed)).estimate.frf
        for seed in range(seeds)])
    spread = np.sum(np.abs(frfs - frfs.mean(axis=0)) ** 2, axis=0) / (seeds - 1)
    predicted = np.diag(band_noise_covariance(
        body, muscles, tilt, 2, output="theta1",
        motor_noise=MotorNoise((0.0, 2.0, 3.0), 2.0))["covariance"])
    ratio = spread / predicted
    assert np.all((ratio > 0.5) & (ratio < 1.7)), ratio  # 2(30 − 1) dof: ±19 % (1 sd)
    assert abs(np.mean(ratio) - 1) < 0.15, ratio


@pytest.mark.parametrize("cycles", [3, 8])
def test_predicted_errors_within_25_percent_of_the_spread_of_40_fits(model, cycles):
    """Simulated experiments (compiled engine, motor and sensor noise), estimated and fitted
    by fit_frf: the spread of the fitted values against the predicted standard errors, at
    3 and 8 cycles (so the spread itself falls as the predicted 1/√cycles)."""
    body, muscles, options = model
    tilt = PRTSTilt.named("posturelab-80", 0.035)
    prediction = predict_errors(body, muscles, FREE, tilt=tilt, cycles=cycles, sensor_noise=0.001,
                                motor_noise=MotorNoise(3.0), **options)
    fitted = []
    for seed in range(SEEDS):
        exp = prts_experiment(body, muscles, tilt=tilt, cycles=cycles, discard=1, seed=seed,
                              sensor_noise=0.001,
                              motor_noise=MotorNoise(3.0, seed=10_000 + seed),
                              **options)
        fit = fit_frf(body, muscles, exp.estimate, FREE, **options)
        assert fit.success
        fitted.append(fit.estimates)
    spread = np.std(np.array(fitted), axis=0, ddof=1)
    ratio = spread / prediction.standard_errors
    assert np.all(np.abs(ratio - 1) < 0.25), ratio


def test_errors_fall_as_one_over_root_cycles_and_amplitude(model):
    body, muscles, options = model
    errors = {}
    for cycles in (2, 8, 32):
        for amplitude in (0.02, 0.04):
            tilt = PRTSTilt.named("posturelab-80", amplitude)
            errors[cycles, amplitude] = predict_errors(
                body, muscles, FREE, tilt=tilt, cycles=cycles, sensor_noise=0.002,
                motor_noise=MotorNoise(2.0, 2.0), **options).standard_errors
    np.testing.assert_allclose(errors[8, 0.02] / errors[2, 0.02], 0.5, rtol=1e-9)
    np.testing.assert_allclose(errors[32, 0.02] / errors[2, 0.02], 0.25, rtol=1e-9)
    np.testing.assert_allclose(errors[8, 0.04] / errors[8, 0.02], 0.5, rtol=1e-9)


def test_central_differences_match_the_one_link_closed_form(model):
    """One link, no intrinsic gains: H = N/D, N = W P e, D = J s² − mgh + P e, P = K_a + s L_a,
    e = e^{−sτ} (H = −θ/α, conventions.md); its analytic derivatives against the central
    differences the design uses, band-averaged alike."""
    body, muscles, options = model
    tilt = PRTSTilt.named("posturelab-80", 0.035)
    noise = band_noise_covariance(body, muscles, tilt, 2, sensor_noise=0.001, **options)
    hf, hw = noise["harmonic_frequency"], noise["harmonic_weight"]
    specs = [("active_stiffness", 0), ("active_viscosity", 0), ("feedback_delay", None),
             ("proprioceptive_weight", None)]
    w = 0.8  # (inside W's range, so that every difference is central)
    values = np.array([muscles.active_stiffnesses[0], muscles.active_viscosities[0],
                       options["feedback_delay"], w])
    kp, kd, tau, _ = values
    J0 = mass_matrix(body, np.zeros(1))[0, 0]
    mgh = body.gravity * body.gravity_coefficients[0]

    def closed(f):
        s = 2j * np.pi * f
        e = np.exp(-s * tau)
        P = kp + s * kd
        D = J0 * s * s - mgh + P * e
        H = w * P * e / D
        return np.stack([H, w * e / D - H * e / D, s * (w * e / D - H * e / D),
                         -s * P * e * (w / D - H / D), P * e / D])

    def average(values_at):
        out, start = [], 0
        for weight in hw:
            out.append(values_at[:, start:start + weight.size] @ weight / weight.sum())
            start += weight.size
        return np.stack(out, axis=1)

    exact = average(closed(np.concatenate(hf)))
    model_options = {"output": "com_angle", "feedback_delay": tau,
                     "proprioceptive_weight": w}
    H = model_band_frf(body, muscles, specs, values, hf, hw, **model_options)[0]
    np.testing.assert_allclose(H, exact[0], rtol=1e-10)
    D = frf_derivatives(body, muscles, specs, values, hf, hw, **model_options)
    for k in range(4):
        np.testing.assert_allclose(D[:, k], exact[k + 1], rtol=1e-6,
                                   atol=1e-7 * np.abs(exact[k + 1]).max())


def test_optimise_stays_within_budget_and_takes_the_best_row(model):
    body, muscles, options = model
    best = optimise_design(body, muscles, FREE + ["proprioceptive_weight"], budget=240.0,
                           targets=["feedback_delay"], sensor_noise=0.002,
                           motor_noise=MotorNoise(3.0), grid=5, **options)
    p = best.best
    assert p.duration <= 240.0
    assert p.amplitude == pytest.approx(0.07)  # 𝓘 ∝ A²: the largest amplitude searched
    assert best.objective == min(row["objective"] for row in best.table)
    assert best.objective == pytest.approx(
        (p.standard_errors[2] / p.values[2]) ** 2, rel=1e-9)
    with pytest.raises(ParameterError, match="among the free"):
        optimise_design(body, muscles, FREE, budget=240.0, targets=["proprioceptive_weight"],
                        sensor_noise=0.002, **options)
    with pytest.raises(ParameterError, match="budget"):
        optimise_design(body, muscles, FREE, budget=20.0, sensor_noise=0.002, **options)


def test_refusals(model):
    body, muscles, options = model
    with pytest.raises(ParameterError, match="some noise"):
        predict_errors(body, muscles, FREE, **options)
    with pytest.raises(ParameterError, match="PRTS"):
        predict_errors(body, muscles, FREE, tilt=SineTilt(0.01, 0.5), sensor_noise=0.001,
                       **options)
    with pytest.raises(ParameterError, match="cycles"):
        predict_errors(body, muscles, FREE, cycles=1, sensor_noise=0.001, **options)
    with pytest.raises(ParameterError, match="not measurable"):  # τ beyond the delay margin
        predict_errors(body, muscles, FREE, sensor_noise=0.001,
                       feedback_delay=0.4, proprioceptive_weight=1.0)
    with pytest.raises(ParameterError, match="samples"):
        predict_errors(body, muscles, FREE, sensor_noise=0.001, sample_rate=20_000.0,
                       **options)


def test_cli_json_gives_the_api_errors(model):
    body, muscles, options = model
    p = cli("design", "--controller", "peterka-2002", "--tilt", "prts:0.035", "--cycles", "4",
            "--free", ",".join(FREE), "--sensor-noise", "0.002", "--motor-noise", "3", "--json")
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    api = predict_errors(body, muscles, FREE, tilt=PRTSTilt.named("posturelab-80", 0.035),
                         cycles=4, sensor_noise=0.002, motor_noise=MotorNoise(3.0), **options)
    for name, se in zip(api.names, api.standard_errors, strict=True):
        assert out["parameters"][name]["standard_error"] == pytest.approx(se, rel=1e-9)
    one_line_exit_2(cli("design", "--controller", "peterka-2002", "--tilt", "sine:0.01:0.5",
                        "--free", "feedback_delay", "--sensor-noise", "0.001"), "PRTS")
    one_line_exit_2(cli("design", "--controller", "peterka-2002", "--free", "feedback_delay",
                        "--sensor-noise", "0.001", "--budget", "100"), "--optimise")
    one_line_exit_2(cli("design", "--controller", "peterka-2002", "--free", "nonsense",
                        "--sensor-noise", "0.001"), "nonsense")


def test_the_design_guide_python_runs(tmp_path):
    """docs/guide/design.rst's Python, as written."""
    import re
    import subprocess
    import sys
    import textwrap
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "guide" / "design.rst").read_text(
        encoding="utf-8")
    blocks = re.findall(r"\.\. code-block:: python\n\n((?:(?:   .*)?\n)+)", text)
    code = "\n".join(textwrap.dedent(b) for b in blocks)
    assert "predict_errors(" in code
    p = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                       text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert "feedback_delay" in p.stdout


def test_cli_optimise_within_budget_and_its_refusals():
    p = cli("design", "--controller", "peterka-2002", "--free", ",".join(FREE),
            "--sensor-noise", "0.001", "--motor-noise", "2", "--optimise", "--budget", "150",
            "--targets", "feedback_delay", "--grid", "3", "--json")
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert out["design"]["duration"] <= 150
    assert out["optimised"]["targets"] == ["feedback_delay"]
    assert out["optimised"]["objective"] == pytest.approx(
        out["parameters"]["feedback_delay"]["relative_error"] ** 2, rel=1e-9)
    base = ("design", "--controller", "peterka-2002", "--free", "feedback_delay")
    one_line_exit_2(cli(*base, "--sensor-noise", "-1"), "--sensor-noise")
    one_line_exit_2(cli(*base, "--sensor-noise", "0.001", "--cycles", "1"), "--cycles")
    one_line_exit_2(cli(*base, "--sensor-noise", "0.001", "--optimise", "--budget", "100",
                        "--amplitudes", "0.1:0.01"), "--amplitudes")
    one_line_exit_2(cli(*base, "--sensor-noise", "0.001", "--optimise"), "--budget")
