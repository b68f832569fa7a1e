"""Torque feedback after Peterka 2002 (J Neurophysiol 88:1097–1118): the active torque fed
back positively through K_t/(τ_t s + 1) (docs/design.md, "Torque feedback")."""

from __future__ import annotations

import numpy as np
import pytest

import posturelab as pl
from posturelab.errors import ParameterError
from posturelab.frequency import estimate_frf, model_frf
from posturelab.frequency.fit import fit_frf
from posturelab.linear.system import linear_system
from posturelab.model.controllers import get_controller
from posturelab.model.tilt import PRTSTilt

BODY = pl.get_body("paper-1link")
PRESET = get_controller("icm-pmc5664365")
TRUE = PRESET.muscles(BODY)
#: PMC5664365 Table 1: K_F = 0.0018 rad/(N·m), τ_F = 17.4 s, K_P = 943.9 N·m/rad, so
#: K_t = K_F·K_P = 1.70 (the source's form's static loop gain).
SOURCE_GAIN = 0.0018 * 943.9
SOURCE_TIME_CONSTANT = 17.4


def one_link_hand_frf(f, gain, time_constant, form="torque"):
    """The tilt FRF of the one-link body written out by hand (H = −θ/α): Jθ̈ = mgh θ − M_i −
    M_a, M_i = (k_i + l_i s)(θ + α), M_a = (k_a + l_a s) e^{−sτ}(θ + W α) + F M_a with
    ``form`` "torque": F = K_t/(τ_t s + 1) (posturelab's form), or "peterka": the fed-back
    torque added to the error before the controller and the delay, F = (k_a + l_a s)
    e^{−sτ} K_F/(τ_t s + 1) with K_F = K_t/k_a (Peterka 2002's block diagram)."""
    m, c = BODY.masses[0], BODY.com_distances[0]
    J, mgh = BODY.inertias[0] + m * c * c, m * BODY.gravity * c
    s = 2j * np.pi * np.asarray(f)
    delay, weight = PRESET.feedback_delay, PRESET.proprioceptive_weight
    intrinsic = TRUE.stiffnesses[0] + TRUE.viscosities[0] * s
    controller = (TRUE.active_stiffnesses[0] + TRUE.active_viscosities[0] * s) * np.exp(-s * delay)
    if form == "torque":
        loop = gain / (time_constant * s + 1.0)
    else:
        loop = controller * (gain / TRUE.active_stiffnesses[0]) / (time_constant * s + 1.0)
    active = controller / (1.0 - loop)
    return (intrinsic + weight * active) / (J * s * s - mgh + intrinsic + active)


def test_one_link_frf_is_the_closed_form():
    f = np.geomspace(0.01, 5.0, 60)
    H = model_frf(BODY, TRUE, f, feedback_delay=PRESET.feedback_delay,
                  proprioceptive_weight=PRESET.proprioceptive_weight,
                  torque_feedback_gain=SOURCE_GAIN,
                  torque_feedback_time_constant=SOURCE_TIME_CONSTANT)
    np.testing.assert_allclose(H, one_link_hand_frf(f, SOURCE_GAIN, SOURCE_TIME_CONSTANT),
                               rtol=1e-12)
    # gain 0 is exactly the model without torque feedback
    without = model_frf(BODY, TRUE, f, feedback_delay=PRESET.feedback_delay,
                        proprioceptive_weight=PRESET.proprioceptive_weight)
    np.testing.assert_array_equal(
        model_frf(BODY, TRUE, f, feedback_delay=PRESET.feedback_delay,
                  proprioceptive_weight=PRESET.proprioceptive_weight,
                  torque_feedback_gain=0.0), without)


def test_torque_feedback_makes_the_sway_lead_at_low_frequency():
    """Issue 20: human sway leads the stimulus by about 20° at 0.05 Hz, which a delayed PD
    cannot do; with PMC5664365's torque feedback the model leads by 10–30°."""
    kwargs = dict(feedback_delay=PRESET.feedback_delay,
                  proprioceptive_weight=PRESET.proprioceptive_weight)
    lag = np.angle(model_frf(BODY, TRUE, [0.05], **kwargs)[0], deg=True)
    lead = np.angle(model_frf(BODY, TRUE, [0.05], torque_feedback_gain=SOURCE_GAIN,
                              torque_feedback_time_constant=SOURCE_TIME_CONSTANT,
                              **kwargs)[0], deg=True)
    assert lag < 0 and 10 < lead < 30, (lag, lead)


def test_posturelab_form_against_the_source_block_diagram():
    """posturelab filters the active torque after the controller; Peterka's diagram adds the
    filtered torque to the error before the controller and the delay. They agree at s → 0
    (K_t = K_F·K_P); over Peterka's 0.017–2.5 Hz with PMC5664365's values they differ by
    less than 5 % in |H| relative and 3° in phase (measured 3.9 %, 2.2°)."""
    f = np.geomspace(0.017, 2.5, 200)
    ours = one_link_hand_frf(f, SOURCE_GAIN, SOURCE_TIME_CONSTANT)
    source = one_link_hand_frf(f, SOURCE_GAIN, SOURCE_TIME_CONSTANT, form="peterka")
    assert np.max(np.abs(ours - source) / np.abs(source)) < 0.05
    assert np.max(np.abs(np.angle(ours / source, deg=True))) < 3.0
    np.testing.assert_allclose(one_link_hand_frf(1e-9, SOURCE_GAIN, 1.0),
                               one_link_hand_frf(1e-9, SOURCE_GAIN, 1.0, form="peterka"),
                               rtol=1e-6)


@pytest.mark.parametrize("body_name", ["paper-1link", "paper"])
def test_poles_with_the_filter_states_are_the_roots_of_the_characteristic_equation(
        body_name):
    """At zero delay the eigenvalues of the first-order form [Θ, Θ̇, Y] are the zeros of
    det Δ(s)·(τ_t s + 1 − K_t)^N; on one link the roots of the cubic by hand."""
    body = pl.get_body(body_name)
    muscles = PRESET.muscles(body) if body.n_links == 1 else pl.paper_muscles("1")
    if body.n_links > 1:
        muscles = muscles.with_active_feedback(muscles.stiffnesses * 0.5,
                                               muscles.viscosities * 0.5)
    gain, tc = 0.6, 5.0
    system = linear_system(body, muscles, delay=0.0, torque_feedback_gain=gain,
                           torque_feedback_time_constant=tc)
    poles = system.poles()[0]
    n = body.n_links
    assert poles.shape == (3 * n,)
    for p in poles:
        D = system.characteristic_matrix(np.array([p]))[0] * (tc * p + 1.0 - gain)
        scale = np.linalg.norm(system.characteristic_matrix(np.array([abs(p) + 1.0]))[0])
        assert abs(np.linalg.det(D)) <= 1e-8 * (scale * (tc * abs(p) + 2.0)) ** n
    if n == 1:
        m, c = body.masses[0], body.com_distances[0]
        J, mgh = body.inertias[0] + m * c * c, m * body.gravity * c
        ki, li = muscles.stiffnesses[0], muscles.viscosities[0]
        ka, la = muscles.active_stiffnesses[0], muscles.active_viscosities[0]
        # (J s² + l_i s + k_i − mgh)(τ_t s + 1 − K_t) + (k_a + l_a s)(τ_t s + 1) = 0
        cubic = np.polyadd(np.polymul([J, li, ki - mgh], [tc, 1.0 - gain]),
                           np.polymul([la, ka], [tc, 1.0]))
        np.testing.assert_allclose(np.sort_complex(poles), np.sort_complex(np.roots(cubic)),
                                   rtol=1e-9)


def test_bounds_and_analyses_that_do_not_take_it():
    with pytest.raises(ParameterError, match="torque_feedback_gain"):
        model_frf(BODY, TRUE, [0.1], torque_feedback_gain=-0.1)
    with pytest.raises(ParameterError, match="torque_feedback_time_constant"):
        model_frf(BODY, TRUE, [0.1], torque_feedback_gain=1.0,
                  torque_feedback_time_constant=0.0)
    system = linear_system(BODY, TRUE, delay=0.1, torque_feedback_gain=1.0)
    with pytest.raises(ParameterError, match="torque feedback"):
        system.without_delay()


L, T = 1000, 20.0


def test_fit_frf_recovers_torque_feedback_from_a_synthetic_frf():
    """One steady PRTS cycle through the exact model FRF with known torque feedback (the
    posturelab-80 sequence, 20 s cycle, lowest band 0.05 Hz), estimated as an experiment
    would be and fitted from a start 30 % off: K_t, τ_t and the active gains come back to
    1e-5 (noise-free)."""
    truth = {"active_stiffness": TRUE.active_stiffnesses[0],
             "active_viscosity": TRUE.active_viscosities[0],
             "torque_feedback_gain": SOURCE_GAIN,
             "torque_feedback_time_constant": SOURCE_TIME_CONSTANT}
    x = PRTSTilt.named("posturelab-80", 0.035).angle(np.arange(L) * T / L)
    X = np.fft.rfft(x)
    f = np.arange(X.size) / T
    H = np.zeros(X.size, complex)
    H[1:] = model_frf(BODY, TRUE, f[1:], feedback_delay=PRESET.feedback_delay,
                      proprioceptive_weight=PRESET.proprioceptive_weight,
                      torque_feedback_gain=SOURCE_GAIN,
                      torque_feedback_time_constant=SOURCE_TIME_CONSTANT)
    y = np.fft.irfft(H * X, L)
    est = estimate_frf(np.tile(x, 3), np.tile(y, 3), L / T, T)
    start = TRUE.with_active_feedback([0.8 * truth["active_stiffness"]],
                                      [1.2 * truth["active_viscosity"]])
    fit = fit_frf(BODY, start, est, list(truth), feedback_delay=PRESET.feedback_delay,
                  proprioceptive_weight=PRESET.proprioceptive_weight,
                  torque_feedback_gain=1.2, torque_feedback_time_constant=25.0)
    assert fit.names[-2:] == ("torque_feedback_gain", "torque_feedback_time_constant")
    np.testing.assert_allclose(fit.estimates, list(truth.values()), rtol=1e-5)


def test_rightmost_roots_with_a_delay_zero_the_characteristic_matrix():
    """With a delay the rightmost roots (collocation over the 3N-state first-order form, then
    Newton on det Δ with g(s)) make Δ(s) singular, and at τ → 0 tend to the poles."""
    from posturelab.linear.delay import system_rightmost_roots

    system = linear_system(BODY, TRUE, delay=PRESET.feedback_delay,
                           torque_feedback_gain=SOURCE_GAIN,
                           torque_feedback_time_constant=SOURCE_TIME_CONSTANT)
    roots = system_rightmost_roots(system, PRESET.feedback_delay, count=3)
    for r in roots:
        D = system.characteristic_matrix(np.array([r]))[0, 0, 0]
        assert abs(D) <= 1e-8 * abs(system.characteristic_matrix(np.array([abs(r) + 1]))[0, 0, 0])
    small = system_rightmost_roots(system, 1e-7, count=3)
    poles = linear_system(BODY, TRUE, delay=0.0, torque_feedback_gain=SOURCE_GAIN,
                          torque_feedback_time_constant=SOURCE_TIME_CONSTANT).poles()[0]
    np.testing.assert_allclose(np.sort_complex(small), np.sort_complex(poles), rtol=1e-4)


def test_frf_model_and_fit_frf_commands_take_torque_feedback(capsys, tmp_path):
    """frf-model --torque-feedback-gain/--torque-feedback-time-constant prints model_frf's
    numbers; fit-frf frees both by name on that table (noise-free: back to 1e-6); an
    unstable loop is refused in one line."""
    import json

    from posturelab.cli import main

    code = main(["frf-model", "--controller", "icm-pmc5664365", "--bands", "peterka",
                 "--torque-feedback-gain", "1.7", "--torque-feedback-time-constant", "17.4",
                 "--json"])
    out = capsys.readouterr().out
    obj = json.loads(out)
    H = model_frf(BODY, TRUE, obj["frequency"], feedback_delay=PRESET.feedback_delay,
                  proprioceptive_weight=PRESET.proprioceptive_weight,
                  torque_feedback_gain=1.7, torque_feedback_time_constant=17.4)
    assert code == 0
    np.testing.assert_allclose([complex(z["re"], z["im"]) for z in obj["frf"]], H, rtol=1e-12)
    table = tmp_path / "frf.json"
    table.write_text(out, encoding="utf-8")
    code = main(["fit-frf", "--data", str(table), "--controller", "icm-pmc5664365",
                 "--free", "torque_feedback_gain,torque_feedback_time_constant",
                 "--torque-feedback-gain", "1.0", "--torque-feedback-time-constant", "30",
                 "--json"])
    fit = json.loads(capsys.readouterr().out)
    assert code == 0
    estimates = {p["name"]: p["estimate"] for p in fit["parameters"]}
    np.testing.assert_allclose([estimates["torque_feedback_gain"],
                                estimates["torque_feedback_time_constant"]], [1.7, 17.4],
                               rtol=1e-6)
    code = main(["frf-model", "--controller", "icm-pmc5664365", "--bands", "peterka",
                 "--torque-feedback-gain", "4.9", "--torque-feedback-time-constant", "1"])
    assert code == 2 and "unstable" in capsys.readouterr().err


def test_a_simulated_prts_trial_with_torque_feedback_is_estimated_and_fitted_back():
    """The nonlinear one-link model with PMC5664365's controller and torque feedback
    (K_t = 1.70, τ_t = 17.4 s) on the reference engine, a PRTS tilt of 0.035 rad peak to
    peak (1 cycle discarded, 2 analysed), estimated as an experiment is: the estimate is the
    model FRF (band-averaged) within 2 % and 1° (measured 0.5 %, 0.3°: the plant's
    nonlinearity), and K_t and τ_t fitted from 1.0 and 30 s come back within 2 % (measured
    −0.6 %, −0.4 %), the truth inside their 95 % intervals."""
    from posturelab.frequency.experiment import prts_experiment

    options = PRESET.run_options()
    torque_feedback = dict(torque_feedback_gain=SOURCE_GAIN,
                           torque_feedback_time_constant=SOURCE_TIME_CONSTANT)
    trial = prts_experiment(BODY, TRUE, cycles=2, discard=1, engine="reference", rtol=1e-6,
                            atol=1e-9, **torque_feedback, **options)
    assert not trial.fell
    est = trial.estimate
    model = est.band_average(lambda f: model_frf(BODY, TRUE, f, **torque_feedback, **options))
    assert np.max(np.abs(est.frf / model - 1.0)) < 0.02
    assert np.max(np.abs(np.angle(est.frf / model, deg=True))) < 1.0
    fit = fit_frf(BODY, TRUE, est, ["torque_feedback_gain", "torque_feedback_time_constant"],
                  torque_feedback_gain=1.0, torque_feedback_time_constant=30.0, **options)
    assert fit.success and fit.determined.all()
    np.testing.assert_allclose(fit.estimates, [SOURCE_GAIN, SOURCE_TIME_CONSTANT], rtol=0.02)
    for (lo, hi), true in zip(fit.confidence_intervals, [SOURCE_GAIN, SOURCE_TIME_CONSTANT],
                              strict=True):
        assert lo <= true <= hi


def test_simulations_state_where_torque_feedback_runs():
    """The filter needs the delayed (active) torque: without a delay it is refused in one
    line on either engine, not ignored (both engines carry it:
    tests/test_compiled_torque_feedback.py)."""
    for engine in ("compiled", "reference"):
        with pytest.raises(ParameterError, match="feedback_delay > 0"):
            pl.simulate(BODY, TRUE, None, 1.0, engine=engine, torque_feedback_gain=1.0)


def test_reference_engine_without_torque_feedback_is_unchanged():
    """Gain 0 adds no filter state: the run is the same as before, to the bit."""
    a = pl.simulate(BODY, TRUE, pl.VelocityStep(0.1), 1.0, engine="reference",
                    feedback_delay=0.1)
    b = pl.simulate(BODY, TRUE, pl.VelocityStep(0.1), 1.0, engine="reference",
                    feedback_delay=0.1, torque_feedback_gain=0.0)
    np.testing.assert_array_equal(a.theta, b.theta)
    assert a.theta.shape[1] == 1


def test_fit_frees_torque_feedback_on_a_tilted_run():
    """posturelab fit (time domain, the reference engine): a one-link run under a 0.1 Hz
    sine tilt with PMC5664365's controller and torque feedback (K_t = 1.7, τ_t = 5 s), seeded
    noise of 0.2 mrad on the angle: K_t and τ_t fitted from 1.0 and 8 s come back within 1 %
    (measured −0.3 %, −0.2 %)."""
    from posturelab.model.tilt import SineTilt
    from posturelab.scenarios import Scenario
    from posturelab.studies.identification import fit_stiffness

    sc = Scenario(name="t", description="", source="test", body=BODY, muscles=TRUE,
                  disturbance=pl.NoDisturbance(), duration=8.0, sample_rate=50.0,
                  fall=pl.FallCriteria(1.5), tilt=SineTilt(0.03, 0.1), feedback_delay=0.097,
                  proprioceptive_weight=0.8, torque_feedback_gain=1.7,
                  torque_feedback_time_constant=5.0)
    r = sc.run(engine="reference")
    theta = r.theta + np.random.default_rng(1).normal(0.0, 2e-4, r.theta.shape)
    start = sc.replace(torque_feedback_gain=1.0, torque_feedback_time_constant=8.0)
    fit = fit_stiffness(start, r.time, theta,
                        ["torque_feedback_gain", "torque_feedback_time_constant"],
                        engine="reference",
                        viscosity_ratio=TRUE.viscosities[0] / TRUE.stiffnesses[0])
    np.testing.assert_allclose(fit.estimates, [1.7, 5.0], rtol=0.01)


def test_explorer_views_take_torque_feedback():
    """The explorer's controls take K_t and τ_t: its FRF is model_frf's with them, its poles
    the first-order form's with the filter states, its delay margin delay_margin's with the
    filter, its run on the compiled engine; K_t > 0
    without a delay and τ_t = 0 are refused naming the control."""
    from posturelab.explore import compute_views, parse_parameters
    from posturelab.explore.views import FRF_FREQUENCIES

    fields = {"controller": "icm-pmc5664365", "body": "paper, one link", "perturbation": "tilt",
              "duration": 2.0, "torque_feedback_gain": 1.7,
              "torque_feedback_time_constant": 17.4}
    p = parse_parameters(fields)
    views = compute_views(p)
    body = pl.get_body("paper-1link")
    muscles = PRESET.muscles(body)
    H = model_frf(body, muscles, FRF_FREQUENCIES, feedback_delay=PRESET.feedback_delay,
                  proprioceptive_weight=PRESET.proprioceptive_weight,
                  torque_feedback_gain=1.7, torque_feedback_time_constant=17.4)
    np.testing.assert_allclose(views["frf"]["gain"], np.abs(H), rtol=1e-6)
    poles = linear_system(body, muscles, delay=0.0, torque_feedback_gain=1.7,
                          torque_feedback_time_constant=17.4).poles()[0]
    np.testing.assert_allclose(sorted(z["re"] for z in views["poles"]), np.sort(poles.real),
                               rtol=1e-9)
    assert views["stable"] and views["delay_margin_note"] is None
    margin = pl.delay_margin(body, muscles, torque_feedback_gain=1.7,
                             torque_feedback_time_constant=17.4)
    assert views["delay_margin"] == pytest.approx(margin.delay_margin, rel=1e-12)
    for bad, field in (({"torque_feedback_time_constant": 0.0}, "torque_feedback_time_constant"),
                       ({"feedback_delay": 0.0}, "torque_feedback_gain")):
        with pytest.raises(ParameterError) as info:
            parse_parameters({**fields, **bad})
        assert info.value.field == field
