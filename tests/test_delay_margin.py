"""The delay margin and the rightmost roots with a feedback delay (posturelab.linear.delay).

Checked against: the closed form of the delayed inverted pendulum; an independent frequency
sweep for the three-link model (the crossings |z(ω)| = 1 of the pencil M0(ω) + z M1(ω),
written here from the model's matrices, not from the module under test); the poles without
delay; and the nonlinear simulation of both engines just below and just above the margin.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import eig
from scipy.optimize import brentq

import posturelab as pl
from posturelab.errors import ParameterError
from posturelab.linear.delay import delay_margin, rightmost_roots
from posturelab.model.dynamics import mass_matrix
from posturelab.model.muscles import MusclePair, MuscleSet


def pendulum_margin(inertia, load, stiffness, viscosity):
    """Closed form for J θ̈ − mgh θ + K θ(t − τ) + L θ̇(t − τ) = 0 (s = iω on the axis):
    (J ω² + mgh)² = K² + L² ω², and τ = atan2(L ω, K) / ω."""
    w = brentq(lambda w: (inertia * w * w + load) ** 2 - stiffness**2 - (viscosity * w) ** 2,
               1e-9, 1e4, xtol=1e-15, rtol=1e-15)
    return math.atan2(viscosity * w, stiffness) / w, w


def swept_margin(body, muscles, omega_max=3000.0, points=60_000):
    """The smallest crossing delay by a frequency sweep: on a grid of ω the eigenvalues z of
    det(M0(ω) + z M1(ω)) = 0, M0 = −ω² J0 − g A, M1 = K + iω L (all feedback delayed);
    where Π(|z_j| − 1) changes sign a root crosses |z| = 1; τ = −arg z / ω there."""
    J0 = mass_matrix(body, np.zeros(body.n_links))
    G = body.gravity * np.diag(body.gravity_coefficients)
    K, L = muscles.stiffness_matrix(), muscles.viscosity_matrix()

    def zs(w):
        return eig(-w * w * J0 - G, -(K + 1j * w * L), right=False)

    def g(w):
        return float(np.prod(np.abs(zs(w)) - 1.0))

    grid = np.geomspace(1e-3, omega_max, points)
    values = np.array([g(w) for w in grid])
    best = (math.inf, None)
    for i in np.nonzero(np.sign(values[:-1]) != np.sign(values[1:]))[0]:
        w = brentq(g, grid[i], grid[i + 1], xtol=1e-14, rtol=1e-15)
        z = zs(w)
        j = int(np.argmin(np.abs(np.abs(z) - 1.0)))
        tau = (-np.angle(z[j])) % (2 * math.pi) / w
        best = min(best, (tau, w), key=lambda p: p[0])
    return best


def test_delayed_inverted_pendulum_margin_matches_its_closed_form():
    body = pl.get_body("paper-1link")
    for k, l in [(1000.0, 100.0), (700.0, 300.0), (2000.0, 50.0)]:
        muscles = MuscleSet((MusclePair("ankle", 0, 1, k, l),), 1)
        tau, w = pendulum_margin(body.inertia_diagonal[0], body.load_stiffness, k, l)
        out = delay_margin(body, muscles)
        assert out.stable_without_delay and out.verdict == "crossing"
        assert out.delay_margin == pytest.approx(tau, rel=1e-8)
        assert out.crossing_frequency == pytest.approx(w, rel=1e-8)
        assert out.crossings[0].direction == 1


def test_pendulum_with_intrinsic_and_active_parts_matches_its_closed_form():
    """Intrinsic K_i acts at once: the delayed pendulum sees mgh − K_i as its load."""
    body = pl.get_body("paper-1link")
    ki, ka, la = 200.0, 900.0, 250.0
    muscles = MuscleSet((MusclePair("ankle", 0, 1, ki, 0.0, active_stiffness=ka,
                                    active_viscosity=la),), 1)
    tau, w = pendulum_margin(body.inertia_diagonal[0], body.load_stiffness - ki, ka, la)
    out = delay_margin(body, muscles)
    assert out.delay_margin == pytest.approx(tau, rel=1e-8)
    assert out.crossing_frequency == pytest.approx(w, rel=1e-8)


@pytest.mark.parametrize("case", ["1", "3", "4"])
def test_three_link_margin_agrees_with_a_frequency_sweep(case):
    body, muscles = pl.paper_body(), pl.paper_muscles(case)
    out = delay_margin(body, muscles)
    tau, w = swept_margin(body, muscles)
    assert out.delay_margin == pytest.approx(tau, rel=1e-7)
    assert out.crossing_frequency == pytest.approx(w, rel=1e-7)


def test_paper_case_1_loses_stability_within_a_few_milliseconds_near_90_hz():
    out = delay_margin(pl.paper_body(), pl.paper_muscles("1"))
    assert 0.001 < out.delay_margin < 0.005
    assert 80.0 < out.crossing_frequency / (2 * math.pi) < 100.0


def test_rightmost_roots_are_the_poles_without_delay_and_sit_on_the_axis_at_the_margin():
    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    poles = pl.analyse(body, muscles).poles
    roots = rightmost_roots(body, muscles, 0.0, 6)
    np.testing.assert_allclose(np.sort_complex(roots), np.sort_complex(poles), rtol=1e-9)
    out = delay_margin(body, muscles)
    at = rightmost_roots(body, muscles, out.delay_margin, 2)
    assert abs(at[0].real) < 1e-6
    assert abs(abs(at[0].imag) - out.crossing_frequency) < 1e-6 * out.crossing_frequency
    # the spectral guesses alone (few nodes) are already close to the refined roots
    coarse = rightmost_roots(body, muscles, 0.02, 4, nodes=20)
    fine = rightmost_roots(body, muscles, 0.02, 4, nodes=80)
    np.testing.assert_allclose(coarse, fine, rtol=1e-9)


@pytest.mark.parametrize("engine", ["reference", "compiled"])
def test_below_the_margin_a_perturbation_decays_above_it_grows_at_the_predicted_rate(engine):
    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    margin = delay_margin(body, muscles).delay_margin
    x0 = [1e-4, 0.0, 0.0, 0.0, 0.0, 0.0]
    below = pl.simulate(body, muscles, None, 3.0, initial_state=x0,
                        feedback_delay=0.8 * margin, sample_rate=500, engine=engine)
    assert below.status == "completed"
    assert np.abs(below.theta[below.time > 2.5]).max() < 0.1 * 1e-4
    tau = 1.2 * margin
    root = rightmost_roots(body, muscles, tau, 1)[0]
    assert root.real > 0
    above = pl.simulate(body, muscles, None, 0.25, initial_state=x0, feedback_delay=tau,
                        sample_rate=20_000, engine=engine, rtol=1e-9, atol=1e-12)
    t, knee = above.time, above.theta[:, 1] - above.theta[:, 0]
    # the fast mode, apart from the slow ones: the knee angle less its mean over one period
    period = int(round(20_000 * 2 * math.pi / root.imag))
    fast = knee - np.convolve(knee, np.ones(period) / period, mode="same")
    # its envelope grows at Re s (while it is still small: linear) and oscillates at Im s
    peaks = [np.abs(fast[(t >= a) & (t < a + 0.02)]).max() for a in (0.06, 0.18)]
    assert peaks[1] < 0.01
    growth = math.log(peaks[1] / peaks[0]) / 0.12
    assert growth == pytest.approx(root.real, rel=0.1)
    window = (t > 0.06) & (t < 0.2)
    crossings = np.nonzero(np.diff(np.sign(fast[window])) != 0)[0]
    frequency = (crossings.size - 1) / 2 / (t[window][crossings[-1]] - t[window][crossings[0]])
    assert frequency == pytest.approx(root.imag / (2 * math.pi), rel=0.02)


def test_verdicts_and_their_json():
    body = pl.get_body("paper-1link")
    weak = MuscleSet((MusclePair("ankle", 0, 1, 300.0, 30.0),), 1)  # < mgh: unstable
    out = delay_margin(body, weak)
    assert out.verdict == "unstable without delay"
    assert out.to_dict() == {"delay_margin": None, "crossing_frequency": None,
                             "stable_without_delay": False}
    intrinsic = MuscleSet((MusclePair("ankle", 0, 1, 1000.0, 100.0, active_stiffness=0.0),), 1)
    out = delay_margin(body, intrinsic)  # nothing is delayed: no crossing ever
    assert out.verdict == "no crossing"
    assert out.to_dict() == {"delay_margin": "infinite", "crossing_frequency": None,
                             "stable_without_delay": True}
    with pytest.raises(ParameterError, match="delay"):
        rightmost_roots(body, intrinsic, -0.1)


# ---------------------------------------------------------------------------
# Batched delayed stability (posturelab.linear.delay_batch)
# ---------------------------------------------------------------------------


def unstable_count(body, muscles, delay):
    """Roots in the right half-plane at ``delay``: those at τ = 0 plus two for every
    crossing below ``delay`` into it, minus two for every one out of it (delay_margin's
    crossings, each a conjugate pair)."""
    from posturelab.linear.delay import delayed_system

    A0, A1 = delayed_system(body, muscles).first_order()
    count = int(np.sum(np.linalg.eigvals(A0 + A1).real > 0))
    out = delay_margin(body, muscles, max_delay=delay)
    return count + 2 * sum(c.direction for c in out.crossings if c.delay < delay)


@pytest.mark.parametrize("delay", [0.003, 0.03, 0.15])
def test_batched_flags_equal_the_crossing_count(rng, delay):
    from posturelab.linear.delay_batch import batch_delay_stable

    m = 60
    k = rng.uniform(0.0, 1200.0, (m, 5))
    ka = rng.uniform(0.0, 1200.0, (m, 5))
    flags = batch_delay_stable(pl.paper_body(), pl.paper_muscles("1"), k, 0.25 * k, ka,
                               0.3 * ka, delay)
    for i in range(m):
        muscles = pl.paper_muscles(stiffness=k[i], viscosity=0.25 * k[i],
                                   active_stiffness=ka[i], active_viscosity=0.3 * ka[i])
        assert flags[i] == (unstable_count(pl.paper_body(), muscles, delay) == 0), i
    assert 0 < flags.sum() < m


def test_batched_rightmost_root_without_delay_is_the_largest_pole(rng):
    from posturelab.linear.delay_batch import batch_rightmost_root

    k = rng.uniform(0.0, 1500.0, (30, 5))
    r = batch_rightmost_root(pl.paper_body(), pl.paper_muscles("1"), k, 0.25 * k)
    for i in range(30):
        a = pl.analyse(pl.paper_body(), pl.paper_muscles(stiffness=k[i]))
        assert r[i].real == pytest.approx(a.max_real_part, rel=1e-9, abs=1e-12)


def test_d_subdivision_map_of_the_delayed_pendulum():
    """Over K_a × L_a at τ = 0.15 s: stable exactly where τ is below the delay margin of the
    set (and it is stable without delay), for the one-link body with a small intrinsic
    part; and the stable region lies right of the static line K_a = mgh − K_i."""
    from posturelab.linear.delay_batch import delay_stability_map

    body = pl.get_body("paper-1link")
    mgh = body.load_stiffness
    base = MuscleSet((MusclePair("ankle", 0, 1, 0.05 * mgh, 0.02 * mgh, active_stiffness=0.0,
                                 active_viscosity=0.0),), 1)
    out = delay_stability_map(body, base, 0.15, (0.0, 3 * mgh), (0.0, 1.2 * mgh), 13)
    for iy, la in enumerate(out.active_viscosity):
        for ix, ka in enumerate(out.active_stiffness):
            muscles = MuscleSet((MusclePair("ankle", 0, 1, 0.05 * mgh, 0.02 * mgh,
                                            active_stiffness=ka, active_viscosity=la),), 1)
            dm = delay_margin(body, muscles)
            expected = dm.stable_without_delay and 0.15 < dm.delay_margin
            assert out.stable[iy, ix] == expected, (ka, la)
    assert out.stable.any() and not out.stable.all()
    assert not out.stable[:, out.active_stiffness < 0.95 * mgh].any()
