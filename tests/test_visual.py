"""The visual channel (Peterka 2002's independent channels) and dual-stimulus trials.

Checked against: the one-link closed forms of the surface- and scene-tilt FRFs; the engines
against each other and a batch against its single runs; a scene tilt with no weight, or on
intrinsic gains only, against no scene tilt at all (no mechanical effect); a simulated visual
PRTS's estimate against the model FRF; a dual-stimulus trial's two estimates against the
model and the weights recovered by the joint fit; the scenario file and the command line
against the API; bad input.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import posturelab as pl
from posturelab.cli import main
from posturelab.errors import ParameterError
from posturelab.frequency.dual import dual_prts, estimate_frfs, harmonic_step
from posturelab.frequency.estimate import estimate_frf
from posturelab.frequency.fit import fit_frf
from posturelab.frequency.model import model_frf
from posturelab.linear.system import linear_system
from posturelab.model.muscles import MusclePair, MuscleSet
from posturelab.model.noise import MotorNoise
from posturelab.model.tilt import PRTSTilt, RaisedCosineTilt, SineTilt
from posturelab.simulation.compiled import simulate_batch
from posturelab.simulation.options import RunOptions

LOOSE_FALL = pl.FallCriteria(math.pi / 2)


def one_link(ki=0.2, li=0.05, ka=1.2, la=0.35):
    """The paper's body as one link with intrinsic and active gains as fractions of mgh."""
    body = pl.get_body("paper-1link")
    mgh = body.load_stiffness
    pair = MusclePair("ankle", 0, 1, ki * mgh, li * mgh, active_stiffness=ka * mgh,
                      active_viscosity=la * mgh)
    return body, MuscleSet((pair,), 1)


def split_case_1(share=0.5):
    k = pl.paper_muscles("1").stiffnesses
    return pl.paper_muscles(stiffness=(1 - share) * k, active_stiffness=share * k,
                            active_viscosity_ratio=0.25)


# ---- the linear model: closed forms ---------------------------------------------------------


@pytest.mark.parametrize("delay", [0.0, 0.12])
def test_the_one_link_frfs_are_the_closed_forms(delay):
    """H_v = W_v C/D and H_α = (K_i + L_i s + W_p C)/D, D = J s² − mgh + K_i + L_i s + C,
    C = (K_a + L_a s) e^{−sτ}, from the one linear system (and from model_frf)."""
    body, muscles = one_link()
    wp, wv = 0.45, 0.35
    (pair,) = muscles.pairs
    f = np.geomspace(0.01, 5.0, 40)
    s = 2j * np.pi * f
    J, mgh = body.inertia_diagonal[0], body.load_stiffness
    C = (pair.active_stiffness + pair.active_viscosity * s) * np.exp(-s * delay)
    D = J * s * s - mgh + pair.stiffness + pair.viscosity * s + C
    expected = {"visual-tilt": wv * C / D,
                "tilt": (pair.stiffness + pair.viscosity * s + wp * C) / D}
    system = linear_system(body, muscles, delay=delay, proprioceptive_weight=wp,
                           visual_weight=wv)
    for source, H in expected.items():
        linear = -system.frequency_response(f, source, [1.0])[0]  # −θ/u: the literature's sign
        np.testing.assert_allclose(linear, H, rtol=1e-12, atol=0)
        via_model = model_frf(body, muscles, f, input=source, feedback_delay=delay,
                              proprioceptive_weight=wp, visual_weight=wv)
        np.testing.assert_allclose(via_model, H, rtol=1e-12, atol=0)


def test_the_scene_frf_follows_the_scene_at_low_frequency_with_full_visual_weight():
    """W_v = 1 with no intrinsic gains: a slow scene tilt is followed, H → K_a/(K_a − mgh)
    at s → 0 (the closed form's limit)."""
    body, muscles = one_link(ki=0.0, li=0.0)
    (pair,) = muscles.pairs
    H = model_frf(body, muscles, [1e-4], input="visual-tilt", feedback_delay=0.1,
                  proprioceptive_weight=0.0, visual_weight=1.0)
    ka, mgh = pair.active_stiffness, body.load_stiffness
    assert H[0] == pytest.approx(ka / (ka - mgh), rel=1e-3)


# ---- both engines -----------------------------------------------------------------------------


@pytest.mark.parametrize("visual", [SineTilt(0.03, 0.4, 0.3), RaisedCosineTilt(-0.04, 0.6, 0.3),
                                    PRTSTilt(0.06, 0.125)])
def test_the_engines_agree_on_a_visual_tilt(visual):
    body, muscles = pl.paper_body(), split_case_1()
    kwargs = dict(tilt=SineTilt(0.02, 0.3), visual_tilt=visual, proprioceptive_weight=0.5,
                  visual_weight=0.3, feedback_delay=0.03, sample_rate=100,
                  initial_state=[0.02, 0.0, 0.01, 0.0, 0.0, 0.0])
    fast = pl.simulate(body, muscles, None, 4.0, engine="compiled", rtol=1e-10, atol=1e-13,
                       **kwargs)
    ref = pl.simulate(body, muscles, None, 4.0, engine="reference", rtol=1e-10, atol=1e-12,
                      **kwargs)
    assert fast.status == ref.status == "completed"
    np.testing.assert_allclose(fast.theta, ref.theta, rtol=0, atol=1e-6)
    np.testing.assert_allclose(fast.pair_torques, ref.pair_torques, rtol=0, atol=1e-4)
    np.testing.assert_array_equal(fast.visual_tilt, visual.angle(fast.time))


def test_the_engines_agree_on_a_visual_tilt_under_torque_feedback():
    """The torque feedback filters the scene's delayed part too (its input P is every
    delayed active torque): the compiled engine's generated filter inputs against the
    reference engine's, with the surface and the scene tilted on different sequences."""
    body, muscles = pl.paper_body(), split_case_1()
    kwargs = dict(tilt=SineTilt(0.02, 0.3), visual_tilt=PRTSTilt(0.03, 0.125),
                  proprioceptive_weight=0.4, visual_weight=0.4, feedback_delay=0.05,
                  torque_feedback_gain=0.6, torque_feedback_time_constant=1.5,
                  sample_rate=100, initial_state=[0.02, 0.0, 0.01, 0.0, 0.0, 0.0])
    fast = pl.simulate(body, muscles, None, 6.0, engine="compiled", rtol=1e-10, atol=1e-13,
                       **kwargs)
    ref = pl.simulate(body, muscles, None, 6.0, engine="reference", rtol=1e-10, atol=1e-12,
                      **kwargs)
    without = pl.simulate(body, muscles, None, 6.0, engine="reference", rtol=1e-10,
                          atol=1e-12, **{**kwargs, "torque_feedback_gain": 0.0})
    assert fast.status == ref.status == "completed"
    np.testing.assert_allclose(fast.theta, ref.theta, rtol=0, atol=1e-6)
    assert np.max(np.abs(ref.theta - without.theta)) > 1e-3  # the filter matters here


@pytest.mark.parametrize("engine", ["reference", "compiled"])
def test_the_scene_acts_only_through_the_weighted_active_feedback(engine):
    """W_v = 0, or gains that are all intrinsic, give the run without a scene tilt exactly;
    with W_v > 0 the scene moves the body, the way the surface's active part does."""
    body, muscles = one_link()
    common = dict(feedback_delay=0.1, sample_rate=100, engine=engine, fall=LOOSE_FALL)
    scene = RaisedCosineTilt(0.05, 0.5)
    still = pl.simulate(body, muscles, None, 3.0, **common)
    assert np.all(still.theta == 0.0)
    blind = pl.simulate(body, muscles, None, 3.0, visual_tilt=scene, visual_weight=0.0,
                        **common)
    assert np.all(blind.theta == 0.0)
    intrinsic = MuscleSet((MusclePair("ankle", 0, 1, 1000.0, 300.0, active_stiffness=0.0),), 1)
    felt = pl.simulate(body, intrinsic, None, 3.0, visual_tilt=scene, visual_weight=0.5,
                       proprioceptive_weight=0.5, **common)
    assert np.all(felt.theta == 0.0)
    seen = pl.simulate(body, muscles, None, 3.0, visual_tilt=scene, visual_weight=0.5,
                       proprioceptive_weight=0.0, **common)
    assert seen.theta[-1, 0] < -0.02  # toes-up scene: the body follows it backward
    # without intrinsic gains a surface tilt also acts only through the active part: the
    # scene with W_v is then the surface with W = W_v, to the integrator's tolerance
    (pair,) = muscles.pairs
    active_only = MuscleSet((MusclePair("ankle", 0, 1, 0.0, 0.0,
                                        active_stiffness=pair.active_stiffness,
                                        active_viscosity=pair.active_viscosity),), 1)
    by_scene = pl.simulate(body, active_only, None, 3.0, visual_tilt=scene, visual_weight=0.4,
                           proprioceptive_weight=0.0, **common)
    by_surface = pl.simulate(body, active_only, None, 3.0, tilt=scene,
                             proprioceptive_weight=0.4, **common)
    assert np.abs(by_scene.theta).max() > 0.01
    np.testing.assert_allclose(by_scene.theta, by_surface.theta, rtol=0, atol=1e-9)


def test_a_batch_with_a_visual_tilt_equals_its_single_runs(rng):
    m = 3
    k = np.tile(np.asarray(pl.paper_muscles("1").stiffnesses), (m, 1))
    ka = rng.uniform(50.0, 300.0, (m, 5))
    delays = np.array([0.0, 0.02, 0.05])
    scene = SineTilt(0.02, 0.5)
    out = simulate_batch(pl.paper_body(), 0.6 * k, 0.15 * k, None, 3.0, feedback_delay=delays,
                         active_stiffness=ka, active_viscosity=0.25 * ka, visual_tilt=scene,
                         proprioceptive_weight=0.6, visual_weight=0.3)
    for r in range(m):
        muscles = pl.paper_muscles(stiffness=0.6 * k[r], viscosity=0.15 * k[r],
                                   active_stiffness=ka[r], active_viscosity=0.25 * ka[r])
        one = pl.simulate(pl.paper_body(), muscles, None, 3.0, feedback_delay=float(delays[r]),
                          visual_tilt=scene, proprioceptive_weight=0.6, visual_weight=0.3,
                          engine="compiled")
        np.testing.assert_array_equal(out.final_state[r], np.r_[one.theta[-1], one.omega[-1]])


# ---- the weights and their checks --------------------------------------------------------------


def test_the_weights_sum_to_at_most_one_naming_both():
    with pytest.raises(ParameterError, match=r"proprioceptive_weight \+ visual_weight .* "
                       r"at most 1 .* 0\.8 \+ 0\.3"):
        RunOptions(proprioceptive_weight=0.8, visual_weight=0.3)
    with pytest.raises(ParameterError, match=r"visual_weight \[-\] must be in \[0, 1\]"):
        RunOptions(proprioceptive_weight=0.0, visual_weight=1.5)
    assert RunOptions(proprioceptive_weight=0.6, visual_weight=0.4).visual_weight == 0.4
    with pytest.raises(ParameterError, match="visual_weight"):
        model_frf(*one_link(), [0.1], proprioceptive_weight=0.9, visual_weight=0.2)


def test_the_command_line_names_both_flags(capsys):
    code = main(["simulate", "--controller", "peterka-2002", "--visual-weight", "0.5",
                 "--duration", "1"])
    err = capsys.readouterr().err
    assert code == 2 and "--proprioceptive-weight + --visual-weight" in err
    assert len(err.strip().splitlines()) == 1


SCENARIO = """
duration = 2.0
[muscles]
case = "1"
feedback_delay = 0.1
proprioceptive_weight = 0.6
visual_weight = 0.25
[visual_tilt]
type = "prts"
amplitude = 0.035
state_duration = 0.125
"""


def test_a_scenario_the_command_line_and_the_api_give_equal_options(tmp_path):
    import tomllib

    from posturelab.cli import build_parser
    from posturelab.cli.simulate import scenario_from_args
    from posturelab.scenarios import parse_scenario

    expected = RunOptions(duration=2.0, feedback_delay=0.1, proprioceptive_weight=0.6,
                          visual_weight=0.25, visual_tilt=PRTSTilt(0.035, 0.125),
                          rtol=1e-8, atol=1e-10)  # (a scenario's default tolerances)
    sc = parse_scenario(tomllib.loads(SCENARIO), tmp_path, "s.toml")
    assert sc.options == expected
    args = build_parser("simulate").parse_args([
        "simulate", "--case", "1", "--duration", "2", "--feedback-delay", "0.1",
        "--proprioceptive-weight", "0.6", "--visual-weight", "0.25",
        "--visual-tilt", "prts:0.035:0.125"])
    assert scenario_from_args(args).options.replace(description="") == expected


def test_a_visual_tilt_table_takes_no_axis_depth(tmp_path):
    import tomllib

    from posturelab.errors import ScenarioError
    from posturelab.scenarios import parse_scenario

    bad = SCENARIO + "axis_depth = 0.1\n"
    with pytest.raises(ScenarioError, match="visual_tilt"):
        parse_scenario(tomllib.loads(bad), tmp_path, "s.toml")


# ---- estimation -------------------------------------------------------------------------------

#: The noise-free estimation error of a PRTS FRF sampled at 400 Hz: the aliasing of the
#: PRTS's corners and the rest of the start's transient (measured 1e-4 at most: 5× margin).
NOISE_FREE = 5e-4


def test_a_simulated_visual_prts_is_estimated_as_the_model_frf():
    body, muscles = one_link()
    wp, wv, tau, fs = 0.5, 0.3, 0.12, 400
    r = pl.simulate(body, muscles, None, 60.0, visual_tilt=PRTSTilt.named("posturelab-80",
                                                                           0.035),
                    proprioceptive_weight=wp, visual_weight=wv, feedback_delay=tau,
                    sample_rate=fs, rtol=1e-10, atol=1e-12)
    n = 60 * fs
    est = estimate_frf(r.visual_tilt[:n], r.com_angle[:n], fs, 20.0, discard_cycles=1,
                       response_sign=-1)
    model = est.band_average(lambda f: model_frf(body, muscles, f, input="visual-tilt",
                                                 feedback_delay=tau, proprioceptive_weight=wp,
                                                 visual_weight=wv))
    assert np.max(np.abs(est.frf / model - 1)) < NOISE_FREE


@pytest.fixture(scope="module")
def dual_trial():
    """A noise-free dual-stimulus trial: the 80-state PRTS on the surface (20 s) and at half
    its state duration on the scene (10 s), 100 s at 400 Hz."""
    body, muscles = one_link()
    surface, scene = dual_prts(0.035, 0.035)
    truth = dict(proprioceptive_weight=0.55, visual_weight=0.3, feedback_delay=0.12)
    r = pl.simulate(body, muscles, None, 100.0, tilt=surface, visual_tilt=scene,
                    sample_rate=400, rtol=1e-10, atol=1e-12, **truth)
    n = 100 * 400
    est = estimate_frfs({"tilt": r.tilt[:n], "visual_tilt": r.visual_tilt[:n]},
                        r.com_angle[:n], 400, 20.0, discard_cycles=1, response_sign=-1)
    return body, muscles, truth, est


def test_the_dual_stimuli_have_disjoint_harmonics(dual_trial):
    surface, scene = dual_prts(0.035, 0.035)
    t = np.arange(0, 20.0, 0.01)
    assert harmonic_step(surface.angle(t), 100, 20.0) == 1
    assert harmonic_step(scene.angle(t), 100, 20.0) == 2
    # uncorrelated over a cycle: no bin carries both
    a, b = np.fft.rfft(surface.angle(t)), np.fft.rfft(scene.angle(t))
    assert np.max(np.abs(a * np.conj(b))) < 1e-12 * np.max(np.abs(a)) * np.max(np.abs(b))


def test_a_dual_trial_gives_both_model_frfs(dual_trial):
    body, muscles, truth, est = dual_trial
    for name, source in (("tilt", "tilt"), ("visual_tilt", "visual-tilt")):
        e = est[name]
        model = e.band_average(lambda f, s=source: model_frf(body, muscles, f, input=s,
                                                             **truth))
        assert np.max(np.abs(e.frf / model - 1)) < NOISE_FREE, name
    assert est["visual_tilt"].frequency[0] == pytest.approx(0.1)  # its own cycle, 10 s
    assert est["tilt"].frequency[0] == pytest.approx(0.05)


def test_the_joint_fit_gives_back_both_weights_noise_free(dual_trial):
    """Fitted from wrong starts (0.9, 0.05): W_p and W_v within 1e-3 (the noise-free
    estimation error of the FRFs, a few 1e-4, moves them by less)."""
    body, muscles, truth, est = dual_trial
    fit = fit_frf(body, muscles, [est["tilt"], est["visual_tilt"]],
                  ["proprioceptive_weight", "visual_weight"], input=["tilt", "visual-tilt"],
                  feedback_delay=truth["feedback_delay"], proprioceptive_weight=0.9,
                  visual_weight=0.05)
    got = dict(zip(fit.names, fit.estimates, strict=True))
    assert got["proprioceptive_weight"] == pytest.approx(0.55, abs=1e-3)
    assert got["visual_weight"] == pytest.approx(0.3, abs=1e-3)


def test_the_joint_fit_of_a_noisy_trial_covers_the_weights():
    """Seeded motor noise (2 N·m, 1 Hz low-pass): W_p, W_v and K_a within 3 standard errors
    of the truth, each standard error below 0.05 (the stated tolerance)."""
    body, muscles = one_link()
    surface, scene = dual_prts(0.035, 0.035)
    truth = dict(proprioceptive_weight=0.55, visual_weight=0.3, feedback_delay=0.12)
    r = pl.simulate(body, muscles, None, 100.0, tilt=surface, visual_tilt=scene,
                    sample_rate=100, motor_noise=MotorNoise((2.0,), cutoff=1.0, seed=3),
                    **truth)
    n = 100 * 100
    est = estimate_frfs({"tilt": r.tilt[:n], "visual_tilt": r.visual_tilt[:n]},
                        r.com_angle[:n], 100, 20.0, discard_cycles=1, response_sign=-1)
    fit = fit_frf(body, muscles, [est["tilt"], est["visual_tilt"]],
                  ["proprioceptive_weight", "visual_weight", "active_stiffness"],
                  input=["tilt", "visual-tilt"], feedback_delay=0.12,
                  proprioceptive_weight=0.9, visual_weight=0.05)
    true = {"proprioceptive_weight": 0.55, "visual_weight": 0.3,
            "active_stiffness:ankle": muscles.pairs[0].active_stiffness}
    for name, e, se in zip(fit.names, fit.estimates, fit.standard_errors, strict=True):
        assert abs(e - true[name]) < 3 * se, (name, e, se)
        if name.endswith("weight"):
            assert se < 0.05


def test_stimuli_that_share_harmonics_are_refused():
    t = np.arange(0, 40.0, 0.01)
    a = PRTSTilt.named("posturelab-80", 0.035).angle(t)
    b = PRTSTilt.named("comtest-80", 0.035).angle(t)
    with pytest.raises(ParameterError, match="share harmonics"):
        estimate_frfs({"tilt": a, "visual_tilt": b}, a + b, 100, 20.0)


# ---- the command line ---------------------------------------------------------------------


def test_simulate_frf_and_fit_frf_on_a_dual_trial(tmp_path, capsys):
    path = tmp_path / "trial.csv"
    assert main(["simulate", "--stiffness", "113", "--active-stiffness", "677",
                 "--active-viscosity", "197", "--viscosity", "28", "--body", "paper-1link",
                 "--feedback-delay", "0.12", "--proprioceptive-weight", "0.55",
                 "--visual-weight", "0.3", "--tilt", "prts:0.035",
                 "--visual-tilt", "prts:0.035:0.125", "--duration", "60",
                 "--sample-rate", "100", "--out", str(path)]) == 0
    header = path.read_text(encoding="utf-8").splitlines()[0].split(",")
    assert header[-3:] == ["tilt", "visual_tilt", "com_angle"]
    capsys.readouterr()
    assert main(["frf", "--data", str(path), "--cycle-length", "20", "--discard-cycles", "1",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out) == {"tilt", "visual_tilt"}
    assert out["visual_tilt"]["frequency"][0] == pytest.approx(0.1)
    assert main(["fit-frf", "--data", str(path), "--cycle-length", "20", "--discard-cycles",
                 "1", "--body", "paper-1link", "--stiffness", "113", "--viscosity", "28",
                 "--active-stiffness", "677", "--active-viscosity", "197",
                 "--feedback-delay", "0.12", "--free", "proprioceptive_weight,visual_weight",
                 "--json"]) == 0
    fit = json.loads(capsys.readouterr().out)
    assert [c["input"] for c in fit["conditions"]] == ["tilt", "visual-tilt"]
    got = {q["name"]: q["estimate"] for q in fit["parameters"]}
    assert got["proprioceptive_weight"] == pytest.approx(0.55, abs=0.01)
    assert got["visual_weight"] == pytest.approx(0.3, abs=0.01)


# ---- the explorer -------------------------------------------------------------------------


def test_the_explorer_takes_the_visual_weight_and_a_visual_tilt():
    from posturelab.explore import compute_views, parse_parameters

    with pytest.raises(ParameterError, match=r"W \+ visual weight W_v must be at most 1") as e:
        parse_parameters({"visual_weight": 0.5})  # W is 1 by default
    assert e.value.field == "visual_weight"
    p = parse_parameters({"perturbation": "visual tilt", "proprioceptive_weight": 0.5,
                          "visual_weight": 0.4, "feedback_delay": 0.0, "duration": 2.0})
    v = compute_views(p)
    from posturelab.explore.views import FRF_FREQUENCIES, build_model

    body, muscles, _, scene = build_model(p)
    H = model_frf(body, muscles, FRF_FREQUENCIES, input="visual-tilt", feedback_delay=0.0,
                  proprioceptive_weight=0.5, visual_weight=0.4)
    np.testing.assert_allclose(v["frf"]["gain"], np.abs(H), rtol=0, atol=1e-9)  # (9 decimals)
    assert np.all(np.asarray(v["run"]["surface_tilt"]) == 0.0)  # the scene moves, not the floor
    run = pl.simulate(body, muscles, None, 2.0, visual_tilt=scene, visual_weight=0.4,
                      proprioceptive_weight=0.5, sample_rate=100)
    assert np.abs(run.theta).max() > 0


def test_the_harmonic_step_of_a_measured_stimulus_with_noise(rng):
    """A PRTS of half the cycle, recorded with noise 1 % of its amplitude: step 2 still."""
    t = np.arange(0, 40.0, 0.01)
    scene = PRTSTilt(0.035, 0.125).angle(t)
    noisy = scene + 0.01 * 0.035 * rng.standard_normal(t.size)
    assert harmonic_step(noisy, 100, 20.0) == 2
    with pytest.raises(ParameterError, match="not a PRTS"):
        harmonic_step(rng.standard_normal(t.size), 100, 20.0)
