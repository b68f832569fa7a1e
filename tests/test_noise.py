"""Motor noise (posturelab.model.noise), in both engines.

Checked against: a plain loop of the AR(1) recursion; the spline through its samples; the
stationary standard deviation and lag-one correlation of a long seeded record; the response
of the linearised one-link body to the same torque (scipy.signal.lsim); the engines against
each other; a batch against its single runs; the scenario file and the command line; bad
input.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import posturelab as pl
from posturelab.cli import main
from posturelab.errors import ParameterError
from posturelab.model.controllers import get_controller
from posturelab.model.muscles import muscles_for
from posturelab.model.noise import MotorNoise, motor_noise_series, noise_samples, torque_at
from posturelab.model.tilt import SineTilt
from posturelab.scenarios import parse_scenario
from posturelab.simulation.compiled import simulate_batch


def naive_ar1(noise: MotorNoise, count: int, n_joints: int) -> np.ndarray:
    """The recursion of the module notes, one sample at a time."""
    sigma = noise.per_joint(n_joints)
    w = np.random.default_rng(noise.seed).standard_normal((count, n_joints))
    a = math.exp(-2 * math.pi * noise.cutoff / noise.sample_rate)
    y = np.empty_like(w)
    y[0] = w[0]
    for k in range(1, count):
        y[k] = a * y[k - 1] + math.sqrt(1 - a * a) * w[k]
    return y * sigma


def test_the_samples_are_the_ar1_recursion_and_the_spline_passes_through_them():
    noise = MotorNoise((3.0, 1.5), cutoff=2.0, sample_rate=100.0, seed=7)
    np.testing.assert_allclose(noise_samples(noise, 500, 3), naive_ar1(noise, 500, 3),
                               rtol=1e-12, atol=1e-12)
    series = motor_noise_series(noise, 4.99, 3)
    assert series.knots[0] == 0.0 and series.knots[-1] >= 4.99
    np.testing.assert_allclose(torque_at(series, series.knots),
                               naive_ar1(noise, series.knots.size, 3), atol=1e-12)
    assert np.all(series.samples[:, 2] == 0.0)  # no σ given for the hip: none there


def test_a_long_record_has_the_stated_deviation_and_correlation():
    """σ = 2 N·m, f_c = 1 Hz at 100 Hz: lag-one correlation a = exp(−2π/100) = 0.9391.
    Over 10⁶ samples (≈ 16,000 correlation times) the standard error of σ̂ is below 1 %."""
    noise = MotorNoise(2.0, cutoff=1.0, sample_rate=100.0, seed=11)
    y = noise_samples(noise, 1_000_000, 1)[:, 0]
    assert abs(y.std() / 2.0 - 1) < 0.02
    rho = np.corrcoef(y[:-1], y[1:])[0, 1]
    assert abs(rho - math.exp(-2 * math.pi / 100)) < 0.002
    white = noise_samples(MotorNoise(2.0, seed=11), 100_000, 1)[:, 0]
    assert abs(np.corrcoef(white[:-1], white[1:])[0, 1]) < 0.01


@pytest.mark.parametrize("engine", ["reference", "compiled"])
def test_one_link_response_is_the_linear_response_to_the_negated_torque(engine):
    """Small enough to be linear: J θ̈ + b θ̇ + (k − g a) θ = −n(t), the noise adding to the
    ankle moment τ (U = −τ on one link)."""
    from scipy.signal import lsim

    body = pl.get_body("paper-1link")
    k, b = 1.5 * body.gravity * body.gravity_coefficients[0], 300.0
    muscles = muscles_for(1, [k], [b])
    noise = MotorNoise(1e-3, cutoff=3.0, seed=2)
    r = pl.simulate(body, muscles, None, 4.0, motor_noise=noise, engine=engine,
                    sample_rate=1000.0, rtol=1e-10, atol=1e-14)
    J, a = body.inertia_diagonal[0], body.gravity_coefficients[0]
    n = torque_at(motor_noise_series(noise, 4.0, 1), r.time)[:, 0]
    _, y, _ = lsim(([-1.0], [J, b, k - body.gravity * a]), n, r.time)
    assert np.abs(y).max() > 1e-7
    np.testing.assert_allclose(r.theta[:, 0], y, atol=2e-3 * np.abs(y).max())
    # the derived joint moment carries the noise
    np.testing.assert_allclose(r.joint_moments[:, 0] - (k * r.theta[:, 0] + b * r.omega[:, 0]),
                               n, atol=1e-12)


def test_the_engines_agree_with_delay_tilt_and_noise_on_three_links():
    body = pl.paper_body()
    k = pl.paper_muscles("1").stiffnesses
    muscles = pl.paper_muscles(stiffness=0.6 * k, active_stiffness=0.5 * k,
                               active_viscosity_ratio=0.25)
    noise = MotorNoise((4.0, 2.0, 2.0), cutoff=1.5, seed=5)
    tilt = SineTilt(0.01, 0.4)
    runs = [pl.simulate(body, muscles, None, 3.0, motor_noise=noise, tilt=tilt,
                        feedback_delay=0.08, proprioceptive_weight=0.7, engine=e,
                        sample_rate=200.0, rtol=1e-10, atol=1e-12)
            for e in ("reference", "compiled")]
    assert all(r.status == "completed" for r in runs)
    np.testing.assert_allclose(runs[1].theta, runs[0].theta, atol=1e-7)


def test_same_seed_same_run_and_a_batch_equals_its_single_runs():
    body = pl.paper_body()
    k = pl.paper_muscles("1").stiffnesses
    noise = MotorNoise(20.0, cutoff=2.0, seed=3)
    scales = np.array([0.6, 0.8, 1.0])
    batch = simulate_batch(body, np.outer(scales, k), np.outer(scales, 0.25 * k), None, 3.0,
                           motor_noise=noise, feedback_delay=0.05)
    for row, s in enumerate(scales):
        r = pl.simulate(body, pl.paper_muscles(stiffness=s * k), None, 3.0, motor_noise=noise,
                        feedback_delay=0.05, engine="compiled")
        assert np.array_equal(r.state[-1], batch.final_state[row]) or r.fell
        assert r.fell == batch.fell[row]
    other = pl.simulate(body, pl.paper_muscles("1"), None, 3.0, engine="compiled",
                        motor_noise=MotorNoise(20.0, cutoff=2.0, seed=4), feedback_delay=0.05)
    assert not np.array_equal(other.state[-1], batch.final_state[2])


def test_a_scenario_file_and_the_command_line_take_motor_noise(tmp_path, capsys):
    sc = parse_scenario({"duration": 2.0, "muscles": {"case": "1"},
                         "motor_noise": {"standard_deviation": [5.0, 1.0], "cutoff": 1.0,
                                         "seed": 9}})
    assert sc.motor_noise == MotorNoise((5.0, 1.0), 1.0, seed=9)
    assert sc.run(engine="compiled").status == "completed"
    out = tmp_path / "run.csv"
    assert main(["simulate", "--case", "1", "--disturbance", "none", "--motor-noise", "5",
                 "--motor-noise-cutoff", "1", "--seed", "9", "--duration", "2", "--engine",
                 "compiled", "--out", str(out)]) == 0
    assert "motor noise σ = 5 N·m" in capsys.readouterr().out
    header = out.read_text().splitlines()[0].split(",")
    assert "theta1" in header


@pytest.mark.parametrize("args, words", [
    (["--seed", "2"], "--seed needs --motor-noise"),
    (["--motor-noise", "abc"], "--motor-noise [N·m] must be comma-separated numbers"),
    (["--motor-noise", "1,1,1,1"], "at most 3 values"),
    (["--motor-noise", "-1"], "standard_deviation[0] [N·m] must be in [0, 1000]"),
    (["--motor-noise", "1", "--motor-noise-cutoff", "80"], "cutoff [Hz] must be in (0, 50)"),
])
def test_bad_motor_noise_on_the_command_line_is_one_line_and_exit_2(args, words, capsys,
                                                                     tmp_path):
    code = main(["simulate", "--case", "1", "--disturbance", "none", "--duration", "1",
                 "--out", str(tmp_path / "x.csv"), *args])
    err = capsys.readouterr().err.strip()
    assert code == 2 and words in err and len(err.splitlines()) == 1
    assert not (tmp_path / "x.csv").exists()


def test_bad_motor_noise_is_refused_naming_the_field():
    for kwargs, words in [({"standard_deviation": ()}, "at least one value"),
                          ({"standard_deviation": 1.0, "seed": -1}, "seed must be an integer"),
                          ({"standard_deviation": 1.0, "sample_rate": 0.5}, "sample_rate [Hz]"),
                          ({"standard_deviation": math.nan}, "standard_deviation[0]")]:
        with pytest.raises(ParameterError, match=r".*" + words.replace("[", r"\[")
                           .replace("]", r"\]")):
            MotorNoise(**kwargs)
    with pytest.raises(ParameterError, match="2 standard deviations but the body has 1"):
        pl.simulate(pl.get_body("paper-1link"), muscles_for(1, [2000.0]), None, 1.0,
                    motor_noise=MotorNoise((1.0, 1.0)))
    with pytest.raises(ParameterError, match="at most 10,000,000"):
        motor_noise_series(MotorNoise(1.0, sample_rate=1e4), 2000.0, 1)


def test_motor_noise_adds_sway_the_stimulus_does_not_explain():
    """A PRTS experiment with motor noise only: the coherence falls below 1 and the FRF
    estimate stays unbiased, its 95 % bounds holding the noise-free model at most bands."""
    from posturelab.frequency import model_frf
    from posturelab.frequency.experiment import prts_experiment

    body = pl.get_body("paper-1link")
    preset = get_controller("icm-pmc5664365")
    muscles = preset.muscles(body)
    exp = prts_experiment(body, preset.muscles(body), cycles=6, seed=1,
                          motor_noise=MotorNoise(3.0, cutoff=1.0, seed=21),
                          **preset.run_options())
    est = exp.estimate
    assert np.all(est.coherence < 0.999) and np.all(est.coherence > 0.2)
    H = est.band_average(lambda f: model_frf(body, muscles, f, **preset.run_options()))
    lo, hi = est.gain_ci95.T
    inside = (lo <= np.abs(H)) & (np.abs(H) <= hi)
    assert inside.sum() >= 9
