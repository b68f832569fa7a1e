"""Frequency-domain identification: bands, FRF estimation, model FRFs (posturelab.frequency).

Checked against: the closed form of the one-link delayed PD with an intrinsic part; the
state-space transfer function of the three-link model (W = 1, no delay), built here from
the model's own matrices; a noise-free simulated PRTS experiment (the estimate equals the
model's band average to 1e-6); band averaging by hand; and the coverage of the 95 % bounds
over seeded noisy trials.
"""

from __future__ import annotations

import numpy as np
import pytest

import posturelab as pl
from posturelab.errors import ParameterError
from posturelab.frequency import estimate_frf, model_frf
from posturelab.frequency.bands import (
    PETERKA_BAND_FREQUENCIES,
    PETERKA_BAND_HARMONICS,
    band_frequencies,
    odd_harmonic_frequency,
)
from posturelab.frequency.model import model_frf_batch
from posturelab.model.controllers import get_controller
from posturelab.model.muscles import MusclePair, MuscleSet
from posturelab.model.tilt import PRTSTilt


def test_peterka_bands_give_the_printed_frequencies():
    """Peterka 2002: 11 bands of a 20 s, 80-state PRTS at 0.05 … 2.20 Hz (printed to 2
    decimals)."""
    f = band_frequencies(PETERKA_BAND_HARMONICS, 20.0)
    np.testing.assert_allclose(f, PETERKA_BAND_FREQUENCIES, atol=0.005)
    assert len(PETERKA_BAND_HARMONICS) == 11
    np.testing.assert_allclose(band_frequencies(PETERKA_BAND_HARMONICS, 10.0), 2 * f)


def test_one_link_delayed_pd_with_an_intrinsic_part_has_its_closed_form():
    """H(s) = [(K_i + sL_i) + W(K_a + sL_a)e^{−sτ}] / (Js² − mgh + K_i + sL_i +
    (K_a + sL_a)e^{−sτ}) for a tilt; for a translation −a s² c/(…) with c = 1."""
    body = pl.get_body("paper-1link")
    ki, li, ka, la, tau, w = 60.0, 20.0, 800.0, 280.0, 0.15, 0.7
    muscles = MuscleSet((MusclePair("ankle", 0, 1, ki, li, active_stiffness=ka,
                                    active_viscosity=la),), 1)
    f = np.geomspace(0.01, 5.0, 40)
    s = 2j * np.pi * f
    J, mgh = body.inertia_diagonal[0], body.load_stiffness
    ex = np.exp(-s * tau)
    den = J * s * s - mgh + ki + s * li + (ka + s * la) * ex
    closed = ((ki + s * li) + w * (ka + s * la) * ex) / den
    H = model_frf(body, muscles, f, feedback_delay=tau, proprioceptive_weight=w)
    np.testing.assert_allclose(H, closed, rtol=1e-12)
    Hx = model_frf(body, muscles, f, input="translation", feedback_delay=tau)
    np.testing.assert_allclose(Hx, -body.gravity_coefficients[0] * s * s / den, rtol=1e-12)
    # a stiff body that feels only the foot follows the surface: H -> 1
    stiff = MuscleSet((MusclePair("ankle", 0, 1, 1e7, 1e5),), 1)
    assert abs(model_frf(body, stiff, [0.01])[0] - 1) < 1e-3


@pytest.mark.parametrize("output", ["com_angle", "theta2", "knee_angle"])
def test_three_link_tilt_and_translation_frfs_are_the_state_space_transfer_functions(output):
    """W = 1, no delay: H(s) = −c·[I 0](sI − A)⁻¹(B0 + s B1) with A the state matrix and
    B0, B1 the joint torques per α and α̇ of the run set-up (the model's own tilt gains)."""
    from posturelab.frequency.model import output_vector
    from posturelab.model.muscles import moments_to_link_torques
    from posturelab.model.tilt import SineTilt
    from posturelab.simulation.setup import prepare_run

    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    n = 3
    A = pl.state_matrix(body, muscles)
    setup = prepare_run(body, muscles, None, 1.0, tilt=SineTilt(0.01, 1.0))
    J0 = pl.mass_matrix(body, np.zeros(n))
    tg = setup.tilt_gains @ muscles.crossing_matrix
    B0 = np.r_[np.zeros(n), np.linalg.solve(J0, moments_to_link_torques(tg[0]))]
    B1 = np.r_[np.zeros(n), np.linalg.solve(J0, moments_to_link_torques(tg[1]))]
    Bx = np.r_[np.zeros(n), -np.linalg.solve(J0, body.gravity_coefficients)]
    c = np.r_[output_vector(body, output), np.zeros(n)]
    f = np.geomspace(0.02, 10.0, 25)
    H = model_frf(body, muscles, f, output=output)
    Hx = model_frf(body, muscles, f, input="translation", output=output)
    for k, fk in enumerate(f):
        s = 2j * np.pi * fk
        R = np.linalg.inv(s * np.eye(2 * n) - A)
        assert H[k] == pytest.approx(-c @ R @ (B0 + s * B1), rel=1e-10)
        assert Hx[k] == pytest.approx(c @ R @ (s * s * Bx), rel=1e-10)


def test_batched_model_frfs_equal_single_ones(rng):
    body, layout = pl.paper_body(), pl.paper_muscles("1")
    k = rng.uniform(100, 1500, (5, 5))
    ka = rng.uniform(0, 500, (5, 5))
    tau = rng.uniform(0, 0.05, 5)
    f = np.array(PETERKA_BAND_FREQUENCIES)
    out = model_frf_batch(body, layout, f, k, 0.25 * k, ka, 0.3 * ka, tau, 0.8)
    for r in range(5):
        m = pl.paper_muscles(stiffness=k[r], active_stiffness=ka[r], active_viscosity=0.3 * ka[r])
        np.testing.assert_allclose(out[r], model_frf(body, m, f, feedback_delay=tau[r],
                                                     proprioceptive_weight=0.8), rtol=1e-12)


def band_average(H_at_harmonics, weights, bands):
    """Σ w_k H_k / Σ w_k over each band's harmonics: the band FRF of a noise-free linear
    system whose stimulus has power w_k at harmonic k."""
    return np.array([np.sum(weights[np.array(b) - 1] * H_at_harmonics[np.array(b) - 1])
                     / np.sum(weights[np.array(b) - 1]) for b in bands])


def test_a_noise_free_simulated_prts_experiment_returns_the_model_frf():
    """Peterka's PRTS (35 µrad peak to peak: the model is linear there to 1e-10) on the
    independent-channel preset, 5 cycles on the compiled engine, the first discarded: the
    estimate equals the model's band average (stimulus-power weighted) to 1e-6 at every band.
    Sampled at 5 kHz: the sampled PRTS aliases its harmonics above Nyquist (coefficients
    falling as 1/k²), an error of about (f/f_s)² that 5 kHz keeps below 1e-6 at 2.2 Hz."""
    body = pl.get_body("paper-1link")
    preset = get_controller("icm-pmc5664365")
    muscles = preset.muscles(body)
    tilt = PRTSTilt.named("posturelab-80", 3.5e-5)
    fs = 5000.0
    r = pl.simulate(body, muscles, None, 100.0, tilt=tilt, sample_rate=fs, engine="compiled",
                    rtol=1e-11, atol=1e-16, **preset.run_options())
    t = r.time[:-1]
    x, y = tilt.angle(t), r.theta[:-1, 0]
    est = estimate_frf(x, y, fs, 20.0, discard_cycles=1, response_sign=-1)
    K = 25
    H_k = model_frf(body, muscles, odd_harmonic_frequency(np.arange(1, K + 1), 20.0),
                    **preset.run_options())
    X = np.fft.rfft(x[int(fs * 20):int(fs * 40)])
    weights = np.abs(X[2 * np.arange(1, K + 1) - 1]) ** 2
    expected = band_average(H_k, weights, PETERKA_BAND_HARMONICS)
    np.testing.assert_allclose(est.frf, expected, rtol=1e-6)
    # noise-free, the band coherence is below 1 only as H varies over the band's harmonics:
    # |Σ w H|² / (Σ w · Σ w |H|²)
    coh = [abs(np.sum(weights[np.array(b) - 1] * H_k[np.array(b) - 1])) ** 2
           / (np.sum(weights[np.array(b) - 1])
              * np.sum(weights[np.array(b) - 1] * np.abs(H_k[np.array(b) - 1]) ** 2))
           for b in PETERKA_BAND_HARMONICS]
    np.testing.assert_allclose(est.coherence, coh, rtol=1e-5)
    assert est.coherence[0] == pytest.approx(1.0, abs=1e-9)
    assert est.n_cycles == 4 and est.cycle_stimulus.size == 100_000


def test_band_averaging_by_hand():
    """Two cycles of sinusoids at chosen odd harmonics with chosen complex gains: band 3 of
    Peterka's (odd harmonics 3 and 4: bins 5 and 7) averages the spectra before the ratio."""
    L, T = 400, 20.0
    t = np.arange(2 * L) * T / L
    amps = {5: 2.0, 7: 1.0}
    gains = {5: 0.5 * np.exp(-0.3j), 7: 2.0 * np.exp(-1.2j)}
    x = sum(a * np.cos(2 * np.pi * b * t / T) for b, a in amps.items())
    y = sum(a * abs(gains[b]) * np.cos(2 * np.pi * b * t / T + np.angle(gains[b]))
            for b, a in amps.items())
    est = estimate_frf(x, y, L / T, T, bands=[[3, 4]])
    # X_b ∝ a_b, Y_b ∝ a_b g_b: G_xy/G_xx = (a5² g5 + a7² g7) / (a5² + a7²)
    expected = (4 * gains[5] + 1 * gains[7]) / 5
    assert est.frf[0] == pytest.approx(expected, rel=1e-12)
    assert est.frequency[0] == pytest.approx((5 + 7) / 2 / T)
    assert est.averages[0] == 4  # 2 cycles × 2 harmonics


def test_the_95_percent_bounds_cover_the_true_frf_at_about_their_rate(rng):
    """600 seeded trials of a random-phase odd multisine (the same every cycle, as a PRTS is)
    through a known H, white noise in the response: the periodic-stimulus circle covers the
    true band FRF in 93–97 % of 6,600 band estimates (measured 95 %), its gain and phase
    intervals in at least 95 %; Peterka's Otnes–Enochson form over-covers (above 99 %)."""
    L, T, cycles = 200, 20.0, 6
    n_h = 25
    bins = 2 * np.arange(1, n_h + 1) - 1
    # nearly constant within a band: an H that varies across a band's harmonics lowers the
    # band coherence and so widens the bounds (conservative; 98.6 % with a 0.15 s delay)
    true_h = 0.8 / (1 + 0.02j * bins / T)
    truth = np.array([true_h[np.array(b) - 1].mean() for b in PETERKA_BAND_HARMONICS])
    hits = {"circle": 0, "gain": 0, "phase": 0, "otnes": 0}
    total = 0
    for _ in range(600):
        spec = np.zeros(L // 2 + 1, complex)
        spec[bins] = np.exp(2j * np.pi * rng.random(n_h)) * L / 2
        spec_y = np.zeros_like(spec)
        spec_y[bins] = spec[bins] * true_h
        x = np.tile(np.fft.irfft(spec, L), cycles)
        y = np.tile(np.fft.irfft(spec_y, L), cycles) + rng.normal(0.0, 0.6, L * cycles)
        est = estimate_frf(x, y, L / T, T)
        other = estimate_frf(x, y, L / T, T, ci="otnes-enochson")
        r = (est.gain_ci95[:, 1] - est.gain) / est.gain
        r_other = (other.gain_ci95[:, 1] - other.gain) / other.gain
        distance = np.abs(truth - est.frf) / est.gain
        hits["circle"] += int(np.sum(distance <= r))
        hits["otnes"] += int(np.sum(distance <= r_other))
        g = np.abs(truth)
        hits["gain"] += int(np.sum((g >= est.gain_ci95[:, 0]) & (g <= est.gain_ci95[:, 1])))
        dp = (np.degrees(np.angle(truth)) - est.phase_deg + 180) % 360 - 180
        half = (est.phase_ci95_deg[:, 1] - est.phase_ci95_deg[:, 0]) / 2
        hits["phase"] += int(np.sum(np.abs(dp) <= half))
        total += truth.size
    rate = {k: v / total for k, v in hits.items()}
    assert 0.93 <= rate["circle"] <= 0.97, rate
    assert rate["gain"] >= 0.95 and rate["phase"] >= 0.95, rate
    assert rate["otnes"] > 0.99, rate


@pytest.mark.parametrize("kwargs,needle", [
    (dict(cycle_length=20.5), "not a whole number of cycles"),
    (dict(cycle_length=20.0, discard_cycles=1), "at least 2 cycles"),
    (dict(cycle_length=20.0, bands=[[300]]), "band 1 must list"),
    (dict(cycle_length=20.0, response_sign=2), "response_sign"),
])
def test_bad_estimation_input(kwargs, needle):
    x = np.sin(np.arange(800) * 0.1)
    with pytest.raises(ParameterError, match=needle):
        estimate_frf(x, x, 20.0, **kwargs)
    with pytest.raises(ParameterError, match="finite"):
        estimate_frf(np.r_[x[:-1], np.nan], x, 20.0, 20.0)
