"""Torque feedback (Peterka 2002, J Neurophysiol 88:1097–1118; docs/design.md, "Torque
feedback") on the compiled engine: its filter states Y (one per pair, Ẏ = (K_t A − Y)/τ_t)
are carried in the state [Θ, Θ̇, Y] as the reference engine carries them.

Checks: the two engines agree (the parity test's covering array of the model's switches on
the paper's three-link body, a PRTS tilt on one link and on three, with and without a binding
torque limit, each with its own seeded K_t and τ_t); the compiled runs' steady sine response
is the linear model's FRF (an independent check: the frequency-domain form of the filter,
K_t/(τ_t s + 1), not the simulation's); batches, sweeps and the CLI take it.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

import posturelab as pl
from posturelab.frequency import model_frf
from posturelab.model.controllers import get_controller
from posturelab.model.muscles import MuscleSet
from posturelab.model.options import FOOT_FROM_LITERATURE
from posturelab.model.tilt import PRTSTilt, RaisedCosineTilt, SineTilt

TOLERANCES = {"rtol": 1e-9, "atol": 1e-12}
THETA_TOL = 1e-6  # [rad]
TIME_TOL = 1e-6  # [s]
DELAY = 0.01  # [s]
ANKLE_LIMIT = 60.0  # [N·m]
ONE_LINK = pl.get_body("paper-1link")
PRESET = get_controller("icm-pmc5664365")  # one link, active gains, τ = 0.097 s, W = 0.8
PRESET_MUSCLES = PRESET.muscles(ONE_LINK)

#: tests/test_engine_parity.py's strength-2 covering array over (feedback mode and the
#: gastrocnemius' kind, a torque limit, the knee stop, a tilt, centre-of-pressure falls).
from test_engine_parity import PAIRWISE  # noqa: E402
from test_engine_parity import muscles as paper_muscles  # noqa: E402  (case 1 by mode)


def seeded_feedback(seed: int) -> dict:
    """K_t in [0.1, 0.9] [-] and τ_t in [0.2, 5] s, drawn from a seeded generator."""
    rng = np.random.default_rng(seed)
    return {"torque_feedback_gain": float(rng.uniform(0.1, 0.9)),
            "torque_feedback_time_constant": float(rng.uniform(0.2, 5.0))}


def assert_engines_agree(run_with, theta_tol: float = THETA_TOL) -> pl.SimulationResult:
    """``run_with(engine)`` on both engines: the same outcome, switches and fall within
    1e-6 s, angles within ``theta_tol``; returns the compiled run."""
    fast, ref = run_with("compiled"), run_with("reference")
    assert fast.status == ref.status, (fast.message, ref.message)
    assert fast.fall_reason == ref.fall_reason
    if ref.fell:
        assert fast.fall_time == pytest.approx(ref.fall_time, abs=TIME_TOL)
    assert len(fast.switch_times) == len(ref.switch_times)
    np.testing.assert_allclose(fast.switch_times, ref.switch_times, rtol=0, atol=TIME_TOL)
    assert fast.time.shape == ref.time.shape
    error = np.abs(fast.theta - ref.theta).max()
    assert error <= theta_tol, error
    return fast


@pytest.mark.parametrize("seed,run", list(enumerate(PAIRWISE)), ids=lambda v: str(v))
def test_engines_agree_over_the_covering_array(seed, run):
    """The paper's body under a 0.25 m/s backward platform step (a translation), τ = 10 ms,
    1 s, at rtol 1e-9: each run of the covering array with its own K_t and τ_t. Measured
    largest |Δθ| 3.7e-7 rad (whole feedback delayed, one-sided gastrocnemius, knee stop), the
    others 6e-8 rad or less; switch times within 3e-10 s. The runs whose knee hits its stop
    amplify every difference
    (tests/test_engine_parity.py: the reference itself moves by 2e-5 rad between rtol 1e-9
    and 1e-11): 1e-4 rad there."""
    feedback, limit, knee_stop, tilt, cop = run

    def run_with(engine):
        return pl.simulate(
            pl.paper_body(), paper_muscles(feedback), pl.VelocityStep.backward(0.25), 1.0,
            feedback_delay=DELAY, torque_limits=[ANKLE_LIMIT, math.inf, math.inf] if limit
            else None, knee=pl.KneeModel("stop") if knee_stop else None,
            tilt=RaisedCosineTilt(0.05, 0.4) if tilt else None,
            fall=pl.FallCriteria(base_of_support=FOOT_FROM_LITERATURE, centre_of_pressure=True)
            if cop else None, engine=engine, **seeded_feedback(seed), **TOLERANCES)

    amplified = feedback.startswith("whole") and knee_stop
    fast = assert_engines_agree(run_with, 1e-4 if amplified else THETA_TOL)
    if limit:
        assert np.abs(fast.joint_moments[:, 0]).max() <= ANKLE_LIMIT + 1e-6


@pytest.mark.parametrize("seed", [11, 13])
@pytest.mark.parametrize("limit", [None, 40.0, 25.0])
@pytest.mark.parametrize("method", ["RK45", "Radau"])
def test_one_link_prts_tilt_agrees(seed, limit, method):
    """One link, PMC5664365's controller, a PRTS tilt of 0.1 rad (0.25 s states), 6 s, with
    and without an ankle limit that the tilt saturates (40 N·m: it lets go again; 25 N·m: the
    body falls while saturated); the compiled engine's RK45
    and its Radau (whose Newton systems include the filter states) against the reference at
    rtol 1e-9. Measured largest |Δθ| 7e-9 rad (the falls), 1.3e-9 rad otherwise."""
    def run_with(engine):
        return pl.simulate(ONE_LINK, PRESET_MUSCLES, pl.NoDisturbance(), 6.0,
                           tilt=PRTSTilt(0.1), torque_limits=None if limit is None else [limit],
                           fall=pl.FallCriteria(1.5), engine=engine,
                           method=method if engine == "compiled" else None,
                           **seeded_feedback(seed), **PRESET.run_options(), **TOLERANCES)

    fast = assert_engines_agree(run_with)
    if limit is not None:
        assert len(fast.switch_times) > 0  # the limit binds
    plain = pl.simulate(ONE_LINK, PRESET_MUSCLES, pl.NoDisturbance(), 6.0, tilt=PRTSTilt(0.1),
                        torque_limits=None if limit is None else [limit],
                        fall=pl.FallCriteria(1.5), **PRESET.run_options(), **TOLERANCES)
    k = min(fast.time.size, plain.time.size)
    assert np.abs(fast.theta[:k] - plain.theta[:k]).max() > 1e3 * THETA_TOL  # the filters act


@pytest.mark.parametrize("seed", [21, 22])
def test_three_link_prts_tilt_agrees(seed):
    """The paper's body, case 1 split 60 % intrinsic / 40 % active, a PRTS tilt of 0.02 rad,
    τ = 10 ms, 3 s, with the ankle limited to 60 N·m: the two engines at rtol 1e-9, and the
    derived joint moments (which add the filter states) with them (measured |Δθ| 1.3e-11
    rad, moments 2.7e-8 of their peak)."""
    def run_with(engine):
        return pl.simulate(pl.paper_body(), paper_muscles("split/two-sided"), pl.NoDisturbance(),
                           3.0, tilt=PRTSTilt(0.02), feedback_delay=DELAY,
                           torque_limits=[ANKLE_LIMIT, math.inf, math.inf], engine=engine,
                           **seeded_feedback(seed), **TOLERANCES)

    fast = assert_engines_agree(run_with)
    ref = run_with("reference")
    scale = np.abs(ref.joint_moments).max()
    assert np.abs(fast.joint_moments - ref.joint_moments).max() <= 1e-6 * scale


@pytest.mark.parametrize("input", ["tilt", "translation"])
@pytest.mark.parametrize("method", ["RK45", "Radau"])
def test_steady_sine_response_is_the_linear_frf(input, method):
    """Independent check: one link, PMC5664365's controller with K_t = 1, τ_t = 2 s, a small
    0.25 Hz sine (tilt 5 mrad, or platform acceleration 0.05 m/s²) for 40 s on the compiled
    engine; the response over the last two cycles, divided by the input's, is the linear
    model's FRF (frequency.model_frf, the delay as e^{−sτ} and the filter as
    K_t/(τ_t s + 1)) within 1e-4 in ratio and 0.01° (measured 3e-5 and 4e-4°: sin θ ≠ θ);
    without the filter the FRF differs by 40 % (tilt) and 60 % (translation)."""
    f, gain, lag = 0.25, 1.0, 2.0
    feedback = {"torque_feedback_gain": gain, "torque_feedback_time_constant": lag}
    options = PRESET.run_options()
    if input == "tilt":
        disturbance, extra = pl.NoDisturbance(), {"tilt": SineTilt(0.005, f)}
    else:
        disturbance, extra = pl.SumOfSines((0.05,), (f,)), {}
    run = pl.simulate(ONE_LINK, PRESET_MUSCLES, disturbance, 40.0, method=method,
                      sample_rate=200.0, **extra, **feedback, **options, **TOLERANCES)
    assert run.status == "completed"
    w = 2.0 * np.pi * f
    last = (run.time >= 32.0 - 1e-9) & (run.time < 40.0 - 1e-9)  # two whole cycles
    phasor = np.exp(-1j * w * run.time[last])
    response = np.mean(run.theta[last, 0] * phasor)
    if input == "tilt":
        measured = -response / np.mean(run.tilt[last] * phasor)  # H = −θ/α
    else:  # H = θ/x_d, x_d's part at f is −ẍ_d/ω²
        measured = response / (-np.mean(run.platform_acceleration[last, 0] * phasor) / w**2)
    model = model_frf(ONE_LINK, PRESET_MUSCLES, [f], input=input, **feedback, **options)[0]
    assert abs(measured / model - 1.0) < 1e-4
    assert abs(np.angle(measured / model, deg=True)) < 0.01
    without = model_frf(ONE_LINK, PRESET_MUSCLES, [f], input=input, **options)[0]
    assert abs(without / model - 1.0) > 0.3


def test_batch_rows_are_their_single_runs():
    """simulate_batch with torque feedback (and a PRTS tilt, whose delayed part each filter
    feels with its run's gains): each row's peak |θ| is its single run's, to the bit."""
    from posturelab.simulation.compiled import simulate_batch

    k = PRESET_MUSCLES.stiffnesses[0] * np.array([[1.0], [1.3], [0.8]])
    v = PRESET_MUSCLES.viscosities[0] * np.ones((3, 1))
    options = pl.RunOptions(duration=3.0, tilt=PRTSTilt(0.05), fall=pl.FallCriteria(1.5),
                            **seeded_feedback(31), **PRESET.run_options())
    batch = simulate_batch(ONE_LINK, k, v, pl.NoDisturbance(), muscles=PRESET_MUSCLES,
                           options=options,
                           active_stiffness=PRESET_MUSCLES.active_stiffnesses[None].repeat(3, 0),
                           active_viscosity=PRESET_MUSCLES.active_viscosities[None].repeat(3, 0))
    for r in range(3):
        pair = dataclasses.replace(PRESET_MUSCLES.pairs[0], stiffness=float(k[r, 0]))
        single = pl.simulate(ONE_LINK, MuscleSet((pair,), 1), pl.NoDisturbance(),
                             options=options)
        assert batch.peak_theta[r, 0] == np.abs(single.theta).max()
        assert batch.status[r] == single.status


def test_sweep_takes_a_scenario_with_torque_feedback():
    """A sweep over the ankle stiffness of a one-link scenario with torque feedback runs on
    the compiled engine; its peaks are the single runs'."""
    from posturelab.scenarios import Scenario
    from posturelab.studies.sweep import VaryRange, run_sweep

    sc = Scenario(name="t", description="", source="test", body=ONE_LINK,
                  muscles=PRESET_MUSCLES, disturbance=pl.NoDisturbance(), duration=2.0,
                  fall=pl.FallCriteria(1.5), tilt=RaisedCosineTilt(0.02, 0.5),
                  **seeded_feedback(41), **PRESET.run_options())
    base = PRESET_MUSCLES.stiffnesses[0]
    result = run_sweep(sc, [VaryRange("stiffness:ankle", base, 1.2 * base, 2)])
    assert list(result.outcomes.status) == ["completed", "completed"]
    for r, stiffness in enumerate((base, 1.2 * base)):
        pair = dataclasses.replace(PRESET_MUSCLES.pairs[0], stiffness=stiffness,
                                   viscosity=float(result.grid.viscosity[r, 0]))
        single = pl.simulate(ONE_LINK, MuscleSet((pair,), 1), pl.NoDisturbance(),
                             options=sc.run_options("compiled").replace(rtol=1e-6, atol=1e-9))
        assert result.outcomes.peak_theta[r, 0] == pytest.approx(np.abs(single.theta).max(),
                                                              rel=1e-9)


def test_cli_simulate_runs_torque_feedback_on_the_default_engine(tmp_path, capsys):
    """posturelab simulate --torque-feedback-gain 0.3 runs on the compiled engine (the
    default) and writes the run: it is the API's compiled run."""
    from posturelab.cli import main

    out = tmp_path / "run.csv"
    code = main(["simulate", "--controller", "icm-pmc5664365", "--body", "paper-1link",
                 "--tilt", "sine:0.02:0.2", "--duration", "2", "--torque-feedback-gain", "0.3",
                 "--out", str(out), "--json"])
    assert code == 0, capsys.readouterr()
    summary = json.loads(capsys.readouterr().out)
    assert summary["engine"] == "compiled"
    api = pl.simulate(ONE_LINK, PRESET_MUSCLES, pl.NoDisturbance(), 2.0,
                      tilt=SineTilt(0.02, 0.2), torque_feedback_gain=0.3,
                      **PRESET.run_options())
    assert len(summary["final_state"]) == 2  # [θ, θ̇]: the filter state is not part of it
    # (the command's own tolerances and sampling: the same run within 1e-6 rad, rad/s)
    np.testing.assert_allclose(summary["final_state"], api.final_state, rtol=0, atol=1e-6)
    table = np.genfromtxt(out, delimiter=",", names=True)
    assert np.abs(table["theta1"]).max() == pytest.approx(np.abs(api.theta).max(), abs=1e-6)


def test_the_filters_start_at_rest_and_are_kept_through_a_switch():
    """The filters start at Y = 0 and a switch (an ankle that saturates and lets go) leaves
    them as they are: the compiled run's pair torque (which adds Y) is continuous across its
    switches, as the reference's is, and equal to it."""
    def run_with(engine):
        return pl.simulate(ONE_LINK, PRESET_MUSCLES, pl.NoDisturbance(), 4.0,
                           tilt=SineTilt(0.08, 0.5), torque_limits=[20.0],
                           fall=pl.FallCriteria(1.5), engine=engine,
                           **seeded_feedback(51), **PRESET.run_options(), **TOLERANCES)

    fast = assert_engines_agree(run_with)
    ref = run_with("reference")
    assert len(fast.switch_times) >= 2
    assert fast.pair_torques[0, 0] == pytest.approx(ref.pair_torques[0, 0], abs=1e-9)
    np.testing.assert_allclose(fast.pair_torques, ref.pair_torques, rtol=0,
                               atol=1e-6 * np.abs(ref.pair_torques).max())


def test_delayed_stability_map_takes_torque_feedback(tmp_path, capsys):
    """stability-map's D-subdivision map with --torque-feedback-gain: at the controller's own
    active gains its rightmost root is the upright verdict's with the same filter (the
    linear system with the filter states); the map without delay refuses it in one line."""
    from posturelab.cli import main
    from posturelab.linear.delay_batch import delay_stability_map
    from posturelab.linear.verdict import upright_verdict

    ka, va = PRESET_MUSCLES.active_stiffnesses[0], PRESET_MUSCLES.active_viscosities[0]
    feedback = {"torque_feedback_gain": 0.5, "torque_feedback_time_constant": 5.0}
    delay = PRESET.feedback_delay
    dmap = delay_stability_map(ONE_LINK, PRESET_MUSCLES, delay, (ka, 2 * ka), (va, 2 * va), 2,
                               **feedback)
    verdict = upright_verdict(ONE_LINK, PRESET_MUSCLES, delay, **feedback)
    assert dmap.max_real_part[0, 0] == pytest.approx(verdict.rightmost_root.real, abs=1e-6)
    plain = delay_stability_map(ONE_LINK, PRESET_MUSCLES, delay, (ka, 2 * ka), (va, 2 * va), 2)
    assert abs(plain.max_real_part[0, 0] - dmap.max_real_part[0, 0]) > 1e-3  # it matters
    code = main(["stability-map", "--body", "paper-1link", "--controller", "icm-pmc5664365",
                 "--x", f"active_stiffness:{ka}:{2 * ka}", "--y", f"active_viscosity:{va}:{2 * va}",
                 "--resolution", "2", "--torque-feedback-gain", "0.5",
                 "--torque-feedback-time-constant", "5", "--out", str(tmp_path / "d.png")])
    assert code == 0
    table = np.genfromtxt(tmp_path / "d.csv", delimiter=",", names=True)
    assert table["max_real_part"][0] == pytest.approx(dmap.max_real_part[0, 0], abs=1e-12)
    capsys.readouterr()
    code = main(["stability-map", "--x", "stiffness:ankle:0:2000", "--y",
                 "stiffness:gastrocnemius:0:1000", "--torque-feedback-gain", "0.5",
                 "--out", str(tmp_path / "m.png")])
    assert code == 2
    assert "--torque-feedback-gain is for the delayed map" in capsys.readouterr().err


def test_radau_solves_a_stiff_filter_implicitly():
    """Radau's Newton systems include the filter states (the columns ∂Θ̈/∂Y and Ẏ's
    diagonal (K_t a − 1)/τ_t, eliminated exactly): with τ_t = 1 ms (the parameter table's
    lower bound) the filter's mode is at −500 1/s, which an explicit pair must resolve (RK45:
    3,046 steps over 6 s, measured; 862 with τ_t = 10 ms) and an implicit one need not
    (Radau: 1,635; 1,215 with τ_t = 10 ms); both reach the reference's peak |θ| (scipy's
    Radau at rtol 1e-9) within 1e-7 rad."""
    from posturelab.simulation.compiled import simulate_batch

    steps, peaks = {}, {}
    for method in ("Radau", "RK45"):
        options = pl.RunOptions(duration=6.0, tilt=PRTSTilt(0.05), fall=pl.FallCriteria(1.5),
                                method=method, rtol=1e-6, atol=1e-9, torque_feedback_gain=0.5,
                                torque_feedback_time_constant=1e-3, **PRESET.run_options())
        m = PRESET_MUSCLES
        batch = simulate_batch(ONE_LINK, m.stiffnesses[None], m.viscosities[None],
                               pl.NoDisturbance(), muscles=m, options=options,
                               active_stiffness=m.active_stiffnesses[None],
                               active_viscosity=m.active_viscosities[None])
        assert batch.status[0] == "completed"
        steps[method], peaks[method] = int(batch.n_steps[0]), float(batch.peak_theta[0, 0])
    ref = pl.simulate(ONE_LINK, PRESET_MUSCLES, pl.NoDisturbance(), 6.0, tilt=PRTSTilt(0.05),
                      fall=pl.FallCriteria(1.5), engine="reference", method="Radau",
                      torque_feedback_gain=0.5, torque_feedback_time_constant=1e-3,
                      **PRESET.run_options(), **TOLERANCES)
    assert steps["Radau"] < steps["RK45"] / 1.5
    for peak in peaks.values():
        assert peak == pytest.approx(np.abs(ref.theta).max(), abs=1e-7)


def test_overlapping_steps_carry_the_filters():
    """With τ = 0.05 ms (below pl_driver.c's OVERLAP_BELOW) a compiled step reaches into its
    own past; the filters ride along in the state while the history keeps [Θ, Θ̇]: the paper's
    body after a 0.25 m/s step, K_t = 0.5, τ_t = 10 ms, 50 ms, agrees with the reference
    within 1e-9 rad (measured 1.5e-12) and differs from the run without the filter by 1e-3."""
    def run_with(engine, gain=0.5):
        return pl.simulate(pl.paper_body(), pl.paper_muscles("1"), pl.VelocityStep.backward(0.25),
                           0.05, feedback_delay=5e-5, torque_feedback_gain=gain,
                           torque_feedback_time_constant=0.01, engine=engine, **TOLERANCES)

    fast = assert_engines_agree(run_with, 1e-9)
    assert np.abs(fast.theta - run_with("compiled", 0.0).theta).max() > 1e-4
