"""Support-surface tilt (posturelab.model.tilt) and sensory weighting, in both engines.

Checked against: the linear static solve under a constant tilt; the closed-form steady
state of the one-link body under a sine tilt; a 1 kHz sampled sine against the analytic
one; the PRTS's defining properties; the engines against each other; a batch against its
single runs; and bad input.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import posturelab as pl
from posturelab.errors import ParameterError
from posturelab.model.muscles import MusclePair, MuscleSet
from posturelab.model.tilt import (
    MeasuredTilt,
    PRTSTilt,
    RaisedCosineTilt,
    SineTilt,
    prts_sequence,
)
from posturelab.simulation.compiled import simulate_batch

ENGINES = ["reference", "compiled"]
LOOSE_FALL = pl.FallCriteria(math.pi / 2)


def split_case_1(weight_share=0.5):
    k = pl.paper_muscles("1").stiffnesses
    return pl.paper_muscles(stiffness=(1 - weight_share) * k, active_stiffness=weight_share * k,
                            active_viscosity_ratio=0.25)


@pytest.mark.parametrize("engine", ENGINES)
def test_constant_tilt_equilibrium_is_the_linear_solve(engine):
    """Held at α: (K − gA) Θ = −Eᵀ diag(k_i + W k_a) f α (f: pairs that span the foot)."""
    body, muscles, alpha, w = pl.paper_body(), split_case_1(), 0.002, 0.6
    r = pl.simulate(body, muscles, None, 20.0, tilt=RaisedCosineTilt(alpha, 1.0),
                    proprioceptive_weight=w, feedback_delay=0.02, sample_rate=50,
                    engine=engine)
    E = muscles.selection_matrix
    ki, ka = muscles.stiffnesses, muscles.active_stiffnesses
    K = E.T @ ((ki + ka)[:, None] * E)
    G = body.gravity * np.diag(body.gravity_coefficients)
    rhs = -E.T @ ((ki + w * ka) * muscles.spans_foot) * alpha
    expected = np.linalg.solve(K - G, rhs)
    np.testing.assert_allclose(r.theta[-1], expected, rtol=1e-4, atol=1e-9)
    assert np.all(np.abs(r.omega[-1]) < 1e-9)


def pendulum(k=1000.0, l=300.0):
    return pl.get_body("paper-1link"), MuscleSet((MusclePair("ankle", 0, 1, k, l),), 1)


@pytest.mark.parametrize("engine", ENGINES)
def test_sine_tilt_on_one_link_reaches_the_closed_form_steady_state(engine):
    """J θ̈ + L θ̇ + (K − mgh) θ = −(K α + L α̇): θ = A·Im[H e^{iωt}],
    H = −(K + iωL)/(K − mgh − Jω² + iωL), once the start has decayed (poles at −2.6 1/s)."""
    body, muscles = pendulum()
    amplitude, frequency = 1e-3, 0.7
    r = pl.simulate(body, muscles, None, 14.0, tilt=SineTilt(amplitude, frequency),
                    sample_rate=100, engine=engine, fall=LOOSE_FALL)
    J, load, w = body.inertia_diagonal[0], body.load_stiffness, 2 * math.pi * frequency
    H = -(1000.0 + 1j * w * 300.0) / (1000.0 - load - J * w * w + 1j * w * 300.0)
    late = r.time > 11.0
    expected = amplitude * np.imag(H * np.exp(1j * w * r.time[late]))
    np.testing.assert_allclose(r.theta[late, 0], expected, rtol=0, atol=1e-8)


@pytest.mark.parametrize("engine", ENGINES)
def test_a_1_khz_sampled_sine_reproduces_the_analytic_sine(engine):
    body, muscles = pendulum()
    t = np.arange(0, 6.0005, 0.001)
    sampled = MeasuredTilt(t, 0.01 * np.sin(2 * math.pi * 0.8 * t))
    kwargs = dict(sample_rate=100, engine=engine, fall=LOOSE_FALL)
    a = pl.simulate(body, muscles, None, 6.0, tilt=SineTilt(0.01, 0.8), **kwargs)
    b = pl.simulate(body, muscles, None, 6.0, tilt=sampled, **kwargs)
    np.testing.assert_allclose(b.theta, a.theta, rtol=0, atol=1e-6)


@pytest.mark.parametrize("tilt", [SineTilt(0.03, 0.4, 0.3), RaisedCosineTilt(-0.04, 0.6, 0.3),
                                  PRTSTilt.named("posturelab-80", 0.06)])
def test_the_engines_agree_on_tilt_with_delay_and_sensory_weight(tilt):
    body, muscles = pl.paper_body(), split_case_1()
    kwargs = dict(tilt=tilt, proprioceptive_weight=0.7, feedback_delay=0.03, sample_rate=100,
                  initial_state=[0.02, 0.0, 0.01, 0.0, 0.0, 0.0])
    fast = pl.simulate(body, muscles, None, 4.0, engine="compiled", rtol=1e-10, atol=1e-13,
                       **kwargs)
    ref = pl.simulate(body, muscles, None, 4.0, engine="reference", rtol=1e-10, atol=1e-12,
                      **kwargs)
    assert fast.status == ref.status == "completed"
    np.testing.assert_allclose(fast.theta, ref.theta, rtol=0, atol=1e-6)
    np.testing.assert_allclose(fast.pair_torques, ref.pair_torques, rtol=0, atol=1e-4)


@pytest.mark.parametrize("engine", ENGINES)
def test_the_sensory_weight_splits_the_active_error(engine):
    """All-active gains with W = 0 feel no tilt at all (relative to the vertical); intrinsic
    gains feel it whatever W is."""
    body, muscles = pendulum()
    tilt = RaisedCosineTilt(0.05, 0.5)
    vertical = pl.simulate(body, muscles, None, 2.0, tilt=tilt, proprioceptive_weight=0.0,
                           feedback_delay=0.05, engine=engine, sample_rate=100)
    assert np.all(vertical.theta == 0.0)
    intrinsic = MuscleSet((MusclePair("ankle", 0, 1, 1000.0, 300.0, active_stiffness=0.0),), 1)
    felt = pl.simulate(body, intrinsic, None, 2.0, tilt=tilt, proprioceptive_weight=0.0,
                       feedback_delay=0.05, engine=engine, sample_rate=100)
    assert felt.theta[-1, 0] < -0.05  # toes-up: the body follows the foot backward, and more


def test_prts_has_the_properties_of_peterkas_sequence():
    v = prts_sequence(4, (1, 1, 0, 0), (1, 0, 0, 0))
    assert v.size == 80 and v.sum() == 0 and np.count_nonzero(v) == 54
    np.testing.assert_array_equal(v[40:], -v[:40])  # half-period antisymmetry: odd harmonics
    tilt = PRTSTilt.named("posturelab-80", 0.0349)
    assert tilt.cycle == 20.0
    t = np.linspace(0, 40, 40_001)
    a, rate = tilt.angle_and_rate(t)
    assert a.max() - a.min() == pytest.approx(0.0349, rel=1e-12)
    np.testing.assert_allclose(a[t < 20], tilt.angle(t[t < 20] + 20.0), atol=1e-15)
    spectrum = np.abs(np.fft.rfft(a[:20_000]))
    even = spectrum[2:60:2].max()
    odd = spectrum[1:60:2].max()
    assert even < 1e-9 * odd
    assert set(np.round(np.unique(rate) / rate.max(), 12)) <= {-1.0, 0.0, 1.0}


def test_batch_with_tilt_equals_its_single_runs(rng):
    m = 4
    k = np.tile(np.asarray(pl.paper_muscles("1").stiffnesses), (m, 1))
    ka = rng.uniform(50.0, 300.0, (m, 5))
    delays = np.array([0.0, 0.02, 0.05, 0.1])
    tilt = SineTilt(0.02, 0.5)
    out = simulate_batch(pl.paper_body(), 0.6 * k, 0.15 * k, None, 3.0, feedback_delay=delays,
                         active_stiffness=ka, active_viscosity=0.25 * ka, tilt=tilt,
                         proprioceptive_weight=0.8)
    for r in range(m):
        muscles = pl.paper_muscles(stiffness=0.6 * k[r], viscosity=0.15 * k[r],
                                   active_stiffness=ka[r], active_viscosity=0.25 * ka[r])
        one = pl.simulate(pl.paper_body(), muscles, None, 3.0, feedback_delay=float(delays[r]),
                          tilt=tilt, proprioceptive_weight=0.8, engine="compiled")
        np.testing.assert_array_equal(out.final_state[r], np.r_[one.theta[-1], one.omega[-1]])
        np.testing.assert_array_equal(out.peak_theta[r], np.abs(one.theta).max(axis=0))


def test_bad_tilt_input_is_refused_naming_the_field():
    body, muscles = pendulum()
    with pytest.raises(ParameterError, match=r"proprioceptive_weight \[-\]"):
        pl.simulate(body, muscles, None, 1.0, tilt=SineTilt(0.01, 1.0),
                    proprioceptive_weight=1.5)
    with pytest.raises(ParameterError, match="tilt amplitude"):
        SineTilt(2.0, 1.0)
    with pytest.raises(ParameterError, match="tilt duration"):
        RaisedCosineTilt(0.1, -1.0)
    with pytest.raises(ParameterError, match="one-sided"):
        pl.simulate(pl.paper_body(), pl.paper_muscles("1", gastrocnemius="one-sided"), None,
                    1.0, tilt=SineTilt(0.01, 1.0))
    with pytest.raises(ParameterError, match="tilt must be a Tilt"):
        pl.simulate(body, muscles, None, 1.0, tilt=0.1)
    with pytest.raises(ParameterError, match="PRTS taps"):
        PRTSTilt(0.05, taps=(1, 0, 0, 0))


def test_an_axis_below_the_ankle_is_a_tilt_about_the_ankle_plus_its_translation():
    """Turning the surface about an axis h below the ankle = the same tilt about the ankle
    plus the ankle's translation on its circle, given as a measured acceleration profile
    (x = −h sin α, y = h(cos α − 1), differentiated here by hand; sampled at 10 kHz, so
    on the compiled engine; the next test checks the reference against it)."""
    engine = "compiled"
    body, muscles = pl.paper_body(), split_case_1()
    tilt, h = RaisedCosineTilt(0.06, 0.4, 0.1), 0.08
    t = np.arange(0.0, 3.0 + 1e-9, 1e-4)
    a, ad, add = tilt.kinematics(t)
    ax = -h * (add * np.cos(a) - ad**2 * np.sin(a))
    ay = -h * (add * np.sin(a) + ad**2 * np.cos(a))
    kwargs = dict(feedback_delay=0.03, sample_rate=100, engine=engine)
    about_axis = pl.simulate(body, muscles, None, 3.0, tilt=tilt, tilt_axis_depth=h, **kwargs)
    split = pl.simulate(body, muscles, pl.MeasuredProfile(t, ax, ay), 3.0, tilt=tilt,
                        **kwargs)
    np.testing.assert_allclose(about_axis.theta, split.theta, rtol=0, atol=2e-6)
    assert np.abs(about_axis.theta - pl.simulate(body, muscles, None, 3.0, tilt=tilt,
                                                 **kwargs).theta).max() > 1e-4


def test_the_engines_agree_about_an_axis_below_the_ankle_with_a_starting_sine():
    """A sine starts turning at once: the ankle's velocity jumps at t = 0 (−h α̇(0)), and the
    rates jump with it (−J⁻¹H Δẋ)."""
    body, muscles = pl.paper_body(), split_case_1()
    kwargs = dict(tilt=SineTilt(0.03, 0.7), tilt_axis_depth=0.08, feedback_delay=0.02,
                  sample_rate=100)
    fast = pl.simulate(body, muscles, None, 3.0, engine="compiled", rtol=1e-10, atol=1e-13,
                       **kwargs)
    ref = pl.simulate(body, muscles, None, 3.0, engine="reference", rtol=1e-10, atol=1e-12,
                      **kwargs)
    np.testing.assert_allclose(fast.theta, ref.theta, rtol=0, atol=1e-6)
    dv = -0.08 * 0.03 * 2 * math.pi * 0.7
    expected = pl.velocity_step_response(body, dv)
    np.testing.assert_allclose(ref.omega[0], expected, rtol=1e-12)
    assert ref.platform_velocity[0, 0] == pytest.approx(dv, rel=1e-12)


def test_an_axis_depth_needs_a_smooth_tilt():
    body, muscles = pendulum()
    with pytest.raises(ParameterError, match="needs a tilt rate without jumps"):
        pl.simulate(body, muscles, None, 1.0, tilt=PRTSTilt.named("posturelab-80", 0.02),
                    tilt_axis_depth=0.05)
    with pytest.raises(ParameterError, match=r"tilt_axis_depth \[m\] needs a tilt"):
        pl.simulate(body, muscles, None, 1.0, tilt_axis_depth=0.05)
    with pytest.raises(ParameterError, match=r"tilt_axis_depth \[m\] must be"):
        pl.simulate(body, muscles, None, 1.0, tilt=SineTilt(0.01, 1.0), tilt_axis_depth=-1)


# --- named PRTS sequences, with their sources (posturelab.model.tilt.PRTS_SEQUENCES) ---


def _pseudogen3(feedback, seed, states):
    """The register as the Matlab script that follows Peterka 2002 writes it out (its lines:
    ``Output(i) = mod(Reg(3)-Reg(4)-Reg(5), 3); Reg(2:5) = Reg(1:4); Reg(1) = Output(i)``,
    here for any feedback), digits 0, 1, 2 to velocities 0, +1, −1."""
    reg, out = list(seed), []
    for _ in range(states):
        new = sum(f * r for f, r in zip(feedback, reg, strict=True)) % 3
        reg[1:] = reg[:-1]
        reg[0] = new
        out.append(new)
    return np.array([0.0, 1.0, -1.0])[np.array(out)]


@pytest.mark.parametrize(("name", "feedback", "seed", "registers"), [
    # Peterka 2002: pseudogen3(5, [0 0 1 −1 −1], [2 0 2 0 2]), "242 state sequence"
    ("peterka-2002-242", (0, 0, 1, -1, -1), (2, 0, 2, 0, 2), 5),
    # COMTEST PRTS2012.m / PRTS2020.m: pseudogen3(4, [0 0 −1 1], [0 0 0 1], 25)
    ("comtest-80", (0, 0, -1, 1), (0, 0, 0, 1), 4),
])
def test_a_named_sequence_is_its_sources_shift_register(name, feedback, seed, registers):
    from posturelab.model.tilt import PRTSTilt, get_prts_sequence

    states = 3 ** registers - 1
    tilt = PRTSTilt.named(name, 0.035)
    v = tilt.velocity_sequence
    expected = _pseudogen3(feedback, seed, 2 * states)
    np.testing.assert_array_equal(v, expected[:states])
    np.testing.assert_array_equal(expected[states:], expected[:states])  # period 3ⁿ − 1
    assert v.size == states and set(np.unique(v)) == {-1.0, 0.0, 1.0} and v.sum() == 0
    assert np.count_nonzero(v) == 2 * 3 ** (registers - 1)
    np.testing.assert_array_equal(v[states // 2:], -v[:states // 2])  # odd harmonics only
    spectrum = np.abs(np.fft.fft(v))
    assert spectrum[0::2].max() < 1e-9
    # a maximum-length ternary sequence: the same power 4·3ⁿ⁻¹ at every odd harmonic
    np.testing.assert_allclose(spectrum[1::2] ** 2, 4 * 3 ** (registers - 1), rtol=1e-12)
    seq = get_prts_sequence(name)
    assert tilt.cycle == seq.cycle == states * 0.25 and tilt.sequence_name == name


def test_peterka_2002s_sequence_has_242_states_and_a_60_5_s_cycle():
    from posturelab.frequency.bands import (
        PETERKA_242_BAND_HARMONICS,
        PETERKA_242_BAND_SIZES,
        band_frequencies,
    )
    from posturelab.model.tilt import PETERKA_2002_CITATION, PRTSTilt

    tilt = PRTSTilt.named("peterka-2002-242", 0.035)
    assert tilt.cycle == 60.5 and tilt.velocity_sequence.size == 242
    assert "242-state PRTS, 0.25 s per state, 60.5 s cycle" in PETERKA_2002_CITATION
    # the band sizes of Peterka's analysis code: "1,1,2,2,3,4,4,4,5,5,6,8,9,10,11,13,15"
    assert tuple(len(b) for b in PETERKA_242_BAND_HARMONICS) == PETERKA_242_BAND_SIZES == (
        1, 1, 2, 2, 3, 4, 4, 4, 5, 5, 6, 8, 9, 10, 11, 13, 15)
    f = band_frequencies(PETERKA_242_BAND_HARMONICS, tilt.cycle)
    assert f[0] == pytest.approx(1 / 60.5) and round(f[0], 3) == 0.017  # the lowest, 0.017 Hz
    assert np.all(np.diff(f) > 0)


def test_the_80_state_default_is_posturelabs_own_and_says_so():
    from posturelab.model.tilt import DEFAULT_PRTS, PRTS_SEQUENCES, PRTSTilt

    assert DEFAULT_PRTS == "posturelab-80"
    with pytest.raises(ParameterError, match="not Peterka 2002's"):
        PRTSTilt.peterka_2002(0.035)  # the former name, which said otherwise
    assert "posturelab's own" in PRTS_SEQUENCES["posturelab-80"].citation
    assert "not Peterka 2002's" in PRTS_SEQUENCES["posturelab-80"].citation
    a, b = (PRTSTilt.named(n).velocity_sequence for n in ("posturelab-80", "comtest-80"))
    assert not any(np.array_equal(np.roll(a, k), s * b) for k in range(80) for s in (1, -1))


def test_an_unknown_sequence_lists_the_known_ones():
    import subprocess
    import sys

    from posturelab.errors import UnknownNameError
    from posturelab.model.tilt import PRTSTilt

    with pytest.raises(UnknownNameError, match="known sequences: posturelab-80, comtest-80, "
                       "peterka-2002-242"):
        PRTSTilt.named("peterka-2002")
    bad = subprocess.run([sys.executable, "-m", "posturelab", "simulate", "--controller",
                          "peterka-2002", "--tilt", "prts:0.035:peterka", "--duration", "1"],
                         capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and bad.stdout == ""
    assert bad.stderr.strip().splitlines() == [
        "posturelab: error: unknown PRTS sequence 'peterka'; known sequences: posturelab-80, "
        "comtest-80, peterka-2002-242"]
    ok = subprocess.run([sys.executable, "-m", "posturelab", "simulate", "--controller",
                         "peterka-2002", "--tilt", "prts:0.035:peterka-2002-242", "--duration",
                         "2", "--engine", "compiled"], capture_output=True, text=True,
                        timeout=120)
    assert ok.returncode == 0, ok.stderr
    assert "(peterka-2002-242), 242 states of 0.25 s (60.5 s cycle)" in ok.stdout


def test_a_242_state_experiment_is_analysed_at_its_own_bands():
    from posturelab.frequency.bands import PETERKA_242_BAND_HARMONICS, band_frequencies
    from posturelab.frequency.experiment import prts_experiment
    from posturelab.model.controllers import get_controller
    from posturelab.model.tilt import PRTSTilt

    body = pl.get_body("paper-1link")
    preset = get_controller("peterka-2002")
    tilt = PRTSTilt.named("peterka-2002-242", 0.035)
    exp = prts_experiment(body, preset.muscles(body), tilt=tilt, cycles=2, discard=1,
                          **preset.run_options())
    np.testing.assert_allclose(exp.estimate.frequency,
                               band_frequencies(PETERKA_242_BAND_HARMONICS, 60.5), rtol=1e-12)
