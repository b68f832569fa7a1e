"""Independent checks of posturelab.linear: finite differences, limit cases, symmetries.

Expected values come from outside the code under test: central differences
of the nonlinear model, the inverted-pendulum characteristic polynomial, the
rigid-body limit (parallel-axis inertia about the ankle), the printed E and K
of Appendix C, and invariances that any correct linearisation must respect.
"""

import numpy as np
import pytest

from _bodies import random_body
from posturelab.linear import (
    analyse,
    analyse_both_sides,
    finite_difference_state_matrix,
    state_matrix,
)
from posturelab.model.body import Body, paper_body
from posturelab.model.dynamics import state_derivative
from posturelab.model.muscles import (
    STIFFNESS_CASES,
    MusclePair,
    MuscleSet,
    joint_torques,
    paper_muscles,
)

SEED = 12345




def random_muscles(rng, n):
    """1..6 random pairs (lo, hi) with 0 <= lo < hi <= n, random stiffness and viscosity."""
    spans = [(lo, hi) for hi in range(1, n + 1) for lo in range(hi)]
    count = int(rng.integers(1, 7))
    pairs = []
    for p in range(count):
        lo, hi = spans[int(rng.integers(len(spans)))]
        pairs.append(MusclePair(f"p{p}", lo, hi, rng.uniform(0.0, 2000.0),
                                rng.uniform(0.0, 500.0)))
    return MuscleSet(tuple(pairs), n)


def single_pair(k, l, name="ankle"):
    return MuscleSet((MusclePair(name, 0, 1, k, l),), 1)


def inverted_pendulum(rng):
    m, length = rng.uniform(20.0, 80.0), rng.uniform(0.8, 1.2)
    k = rng.uniform(0.4, 0.7) * length
    return m, k, Body.from_arrays([m], [length], [k], [rng.uniform(1.0, 10.0)])


def assert_matrix_close(actual, expected, rtol=1e-6):
    np.testing.assert_allclose(actual, expected, rtol=rtol, atol=rtol * np.abs(expected).max())


def same_poles(a, b, tol=1e-9):
    """Compare two pole sets as multisets (order-free), to tol relative to the largest."""
    a, b = np.sort_complex(np.asarray(a)), np.sort_complex(np.asarray(b))
    scale = max(1.0, np.abs(b).max())
    np.testing.assert_allclose(a, b, rtol=0, atol=tol * scale)


# ---------------------------------------------------------------------------
# Analytic vs finite differences of the nonlinear model
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("case", list(STIFFNESS_CASES))
def test_state_matrix_equals_finite_differences_table_i(case):
    """Table I cases: A equals central differences of the nonlinear model, rtol 1e-6."""
    body, muscles = paper_body(), paper_muscles(case)
    assert_matrix_close(state_matrix(body, muscles),
                        finite_difference_state_matrix(body, muscles))


def fd_jacobian(body, muscles, h=1e-6):
    """Central differences written here, on state_derivative and joint_torques only."""
    n = body.n_links
    A = np.zeros((2 * n, 2 * n))
    for j in range(2 * n):
        e = np.zeros(2 * n)
        e[j] = h
        fp = state_derivative(body, e, joint_torques(muscles, e[:n], e[n:]))
        fm = state_derivative(body, -e, joint_torques(muscles, -e[:n], -e[n:]))
        A[:, j] = (fp - fm) / (2 * h)
    return A


@pytest.mark.parametrize("n", [1, 2, 3, 4])
def test_state_matrix_equals_finite_differences_random(n):
    """Random bodies with random muscle pairs: analytic A equals both finite-difference A's."""
    rng = np.random.default_rng(SEED + n)
    for _ in range(8):
        body, muscles = random_body(rng, n), random_muscles(rng, n)
        A = state_matrix(body, muscles)
        assert A.shape == (2 * n, 2 * n)
        np.testing.assert_array_equal(A[:n, :n], 0.0)
        np.testing.assert_array_equal(A[:n, n:], np.eye(n))
        assert_matrix_close(A, finite_difference_state_matrix(body, muscles))
        assert_matrix_close(A, fd_jacobian(body, muscles))


# ---------------------------------------------------------------------------
# Appendix C: E and K as printed
# ---------------------------------------------------------------------------


def test_selection_matrix_is_printed_eq_4():
    """Appendix C eq. 4: E for ankle, knee, hip, quadriceps, gastrocnemius."""
    E = paper_muscles("1").selection_matrix
    np.testing.assert_array_equal(
        E, [[1, 0, 0], [-1, 1, 0], [0, -1, 1], [-1, 0, 1], [0, 1, 0]]
    )


@pytest.mark.parametrize("case", list(STIFFNESS_CASES))
def test_stiffness_matrix_is_printed_eq_5(case):
    """Appendix C eq. 5: K = [[K1+K2+K4, −K2, −K4], [−K2, K2+K3+K5, −K3], [−K4, −K3, K3+K4]];
    L is the same with 0.25 K."""
    K1, K2, K3, K4, K5 = STIFFNESS_CASES[case]
    printed = np.array([
        [K1 + K2 + K4, -K2, -K4],
        [-K2, K2 + K3 + K5, -K3],
        [-K4, -K3, K3 + K4],
    ])
    muscles = paper_muscles(case)
    np.testing.assert_allclose(muscles.stiffness_matrix(), printed, rtol=1e-14)
    np.testing.assert_allclose(muscles.viscosity_matrix(), 0.25 * printed, rtol=1e-14)


# ---------------------------------------------------------------------------
# Limit case: the inverted pendulum (N = 1, one ankle pair)
# ---------------------------------------------------------------------------


def test_one_link_poles_are_roots_of_characteristic_polynomial():
    """N = 1, ankle pair (K, L): poles solve (I + m k²) s² + L s + (K − m g k) = 0."""
    rng = np.random.default_rng(SEED)
    for _ in range(20):
        m, k, body = inverted_pendulum(rng)
        K, L = rng.uniform(0.0, 3000.0), rng.uniform(0.0, 600.0)
        J = body.inertias[0] + m * k**2
        expected = np.roots([J, L, K - m * body.gravity * k])
        res = analyse(body, single_pair(K, L))
        same_poles(res.poles, expected)
        assert res.stable == bool(np.all(expected.real < 0))
        assert np.all(np.diff(res.poles.real) >= 0)  # sorted by real part ascending


def test_one_link_stability_flips_at_load_stiffness():
    """N = 1: stable iff K > m g k (with L > 0); at K = m g k a pole sits exactly at 0."""
    rng = np.random.default_rng(SEED)
    for _ in range(10):
        m, k, body = inverted_pendulum(rng)
        load = m * body.gravity * k
        assert body.load_stiffness == pytest.approx(load, rel=1e-14)
        L = rng.uniform(10.0, 300.0)
        below = analyse(body, single_pair(load * (1 - 1e-6), L))
        above = analyse(body, single_pair(load * (1 + 1e-6), L))
        assert not below.stable and below.max_real_part > 0
        assert above.stable and above.max_real_part < 0
        assert above.pair_stiffness_fraction_of_load[0] == pytest.approx(1 + 1e-6, rel=1e-12)
        at = analyse(body, single_pair(body.load_stiffness, L))
        assert not at.stable
        assert abs(at.max_real_part) < 1e-12
        assert at.pair_stiffness_fraction_of_load[0] == pytest.approx(1.0, rel=1e-14)


def test_rigid_body_limit_ankle_threshold_is_mgh():
    """Knee and hip locked by very stiff pairs: the chain is one inverted pendulum, and the
    ankle stiffness needed is the load stiffness mgh = g Σ m_i h_i (h_i: COM heights)."""
    body = paper_body()
    heights = np.concatenate([[0.0], np.cumsum(body.lengths)[:-1]]) + body.com_distances
    mgh = body.gravity * np.sum(body.masses * heights)
    assert body.load_stiffness == pytest.approx(mgh, rel=1e-12)

    def locked(fraction):
        return MuscleSet((
            MusclePair("ankle", 0, 1, fraction * mgh, 100.0),
            MusclePair("knee", 1, 2, 1e7, 1e3),
            MusclePair("hip", 2, 3, 1e7, 1e3),
        ), 3)

    below, above = analyse(body, locked(0.99)), analyse(body, locked(1.01))
    assert not below.stable and above.stable
    assert above.pair_stiffness_fraction_of_load[0] == pytest.approx(1.01, rel=1e-12)


def test_rigid_body_limit_slow_poles():
    """Knee and hip locked (stiffness 1e8): the two slow poles solve
    J_ankle s² + L s + (K − mgh) = 0 with J_ankle = Σ I_i + m_i h_i² (parallel axis)."""
    body = paper_body()
    heights = np.concatenate([[0.0], np.cumsum(body.lengths)[:-1]]) + body.com_distances
    j_ankle = np.sum(body.inertias + body.masses * heights**2)
    mgh = body.gravity * np.sum(body.masses * heights)
    K, L = 1000.0, 250.0
    muscles = MuscleSet((
        MusclePair("ankle", 0, 1, K, L),
        MusclePair("knee", 1, 2, 1e8, 0.0),
        MusclePair("hip", 2, 3, 1e8, 0.0),
    ), 3)
    poles = analyse(body, muscles).poles
    slow = poles[np.argsort(np.abs(poles))[:2]]
    same_poles(slow, np.roots([j_ankle, L, K - mgh]), tol=1e-4)


def test_stiffness_fraction_of_load_paper_body():
    """pair_stiffness_fraction_of_load = pair stiffness / (g Σ m_i h_i) for every pair."""
    body = paper_body()
    heights = np.concatenate([[0.0], np.cumsum(body.lengths)[:-1]]) + body.com_distances
    mgh = 9.81 * np.sum(np.array([5.05, 18.67, 41.87]) * heights)
    for case, stiffness in STIFFNESS_CASES.items():
        res = analyse(body, paper_muscles(case))
        np.testing.assert_allclose(res.pair_stiffness, stiffness, rtol=0)
        np.testing.assert_allclose(res.pair_stiffness_fraction_of_load,
                                   np.array(stiffness) / mgh, rtol=1e-12)
        assert res.load_stiffness == pytest.approx(mgh, rel=1e-12)


# ---------------------------------------------------------------------------
# Natural frequency and damping ratio
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("wn,zeta", [(3.0, 0.3), (0.7, 0.05), (12.0, 0.9)])
def test_natural_frequency_and_damping_ratio_of_second_order_system(wn, zeta):
    """Choose K, L so the pendulum is s² + 2ζω_n s + ω_n²; analyse reports ω_n and ζ."""
    rng = np.random.default_rng(SEED)
    m, k, body = inverted_pendulum(rng)
    J = body.inertias[0] + m * k**2
    K = J * wn**2 + m * body.gravity * k
    L = 2 * zeta * wn * J
    res = analyse(body, single_pair(K, L))
    np.testing.assert_allclose(res.natural_frequencies, [wn, wn], rtol=1e-10)
    np.testing.assert_allclose(res.damping_ratios, [zeta, zeta], rtol=1e-10)
    wd = wn * np.sqrt(1 - zeta**2)
    np.testing.assert_allclose(res.poles, [-zeta * wn + 1j * wd, -zeta * wn - 1j * wd],
                               rtol=1e-10)
    assert res.stable
    assert res.max_real_part == pytest.approx(-zeta * wn, rel=1e-10)


def test_damping_ratio_of_real_poles():
    """A real pole −a has |λ| = a and ζ = 1; a real pole +a has ζ = −1 (unstable)."""
    rng = np.random.default_rng(SEED)
    m, k, body = inverted_pendulum(rng)
    J = body.inertias[0] + m * k**2
    p1, p2 = 2.0, 5.0  # (s + 2)(s + 5) = s² + 7 s + 10
    res = analyse(body, single_pair(J * p1 * p2 + m * body.gravity * k, J * (p1 + p2)))
    np.testing.assert_allclose(res.poles, [-p2, -p1], rtol=1e-10)
    np.testing.assert_allclose(res.natural_frequencies, [p2, p1], rtol=1e-10)
    np.testing.assert_allclose(res.damping_ratios, [1.0, 1.0], rtol=1e-12)
    # no muscles at all: ±sqrt(m g k / J), the unstable one has ζ = −1
    bare = analyse(body, single_pair(0.0, 0.0))
    rate = np.sqrt(m * body.gravity * k / J)
    np.testing.assert_allclose(bare.poles, [-rate, rate], rtol=1e-10)
    np.testing.assert_allclose(bare.damping_ratios, [1.0, -1.0], rtol=1e-12)
    assert not bare.stable


# ---------------------------------------------------------------------------
# One-sided pairs
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("case", list(STIFFNESS_CASES))
def test_one_sided_inactive_equals_gastrocnemius_removed(case):
    """One-sided gastrocnemius, slack side: same as the gastrocnemius stiffness set to 0."""
    body = paper_body()
    one_sided = paper_muscles(case, gastrocnemius="one-sided")
    zero = paper_muscles(stiffness=list(STIFFNESS_CASES[case][:4]) + [0.0])
    slack = analyse(body, one_sided, one_sided="inactive")
    np.testing.assert_allclose(slack.state_matrix, state_matrix(body, zero), rtol=1e-14)
    same_poles(slack.poles, analyse(body, zero).poles, tol=1e-12)
    # the acting side is the two-sided pair (the paper's artificial antagonist)
    acting = analyse(body, one_sided, one_sided="active")
    same_poles(acting.poles, analyse(body, paper_muscles(case)).poles, tol=1e-12)
    both = analyse_both_sides(body, one_sided)
    same_poles(both[0].poles, acting.poles, tol=0)
    same_poles(both[1].poles, slack.poles, tol=0)


def test_one_sided_matters_for_case_1():
    """Case 1 is stable with the gastrocnemius acting; with it slack it is case 2 (unstable)."""
    body = paper_body()
    active, slack = analyse_both_sides(body, paper_muscles("1", gastrocnemius="one-sided"))
    assert active.stable
    assert not slack.stable
    same_poles(slack.poles, analyse(body, paper_muscles("2")).poles, tol=1e-12)


# ---------------------------------------------------------------------------
# Symmetries and invariances
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("n", [1, 2, 3, 4])
def test_closed_loop_model_is_mirror_symmetric(n):
    """With two-sided pairs the closed-loop vector field is odd, f(−x) = −f(x), at any x
    (mirroring the sagittal plane); so its linearisation is the same on both sides."""
    rng = np.random.default_rng(SEED + 10 + n)
    for _ in range(5):
        body, muscles = random_body(rng, n), random_muscles(rng, n)
        x = np.concatenate([rng.uniform(-1.0, 1.0, n), rng.normal(0.0, 2.0, n)])

        def f(s, body=body, muscles=muscles):
            return state_derivative(body, s, joint_torques(muscles, s[:n], s[n:]))

        np.testing.assert_allclose(f(-x), -f(x), rtol=1e-12, atol=1e-9)


def test_one_sided_pair_breaks_mirror_symmetry():
    """A one-sided gastrocnemius acts for θ2 > 0 only, so f(−x) ≠ −f(x) there."""
    body = paper_body()
    muscles = paper_muscles("1", gastrocnemius="one-sided")
    x = np.array([0.05, 0.1, 0.02, 0.0, 0.0, 0.0])

    def f(s):
        return state_derivative(body, s, joint_torques(muscles, s[:3], s[3:]))

    assert not np.allclose(f(-x), -f(x), rtol=1e-6)


@pytest.mark.parametrize("n", [1, 2, 3, 4])
def test_poles_invariant_under_mass_scaling(n):
    """Scaling every mass, inertia, stiffness and viscosity by c leaves A (and the poles)
    unchanged: the equations are homogeneous of degree 1 in those quantities."""
    rng = np.random.default_rng(SEED + 20 + n)
    body, muscles = random_body(rng, n), random_muscles(rng, n)
    c = 3.7
    heavy = Body.from_arrays(c * body.masses, body.lengths, body.com_distances,
                             c * body.inertias, gravity=body.gravity)
    stiff = MuscleSet(tuple(MusclePair(p.name, p.lo, p.hi, c * p.stiffness, c * p.viscosity)
                            for p in muscles.pairs), n)
    np.testing.assert_allclose(state_matrix(heavy, stiff), state_matrix(body, muscles),
                               rtol=1e-12, atol=1e-12 * np.abs(state_matrix(body, muscles)).max())


@pytest.mark.parametrize("n", [1, 2, 3, 4])
def test_poles_scale_with_time(n):
    """Time scaling t → t/c: g → c² g, stiffness → c² K, viscosity → c L multiplies every
    pole by c."""
    rng = np.random.default_rng(SEED + 30 + n)
    body, muscles = random_body(rng, n), random_muscles(rng, n)
    c = 2.5
    fast_body = body.with_gravity(c**2 * body.gravity)
    fast = MuscleSet(tuple(MusclePair(p.name, p.lo, p.hi, c**2 * p.stiffness, c * p.viscosity)
                           for p in muscles.pairs), n)
    same_poles(analyse(fast_body, fast).poles, c * analyse(body, muscles).poles, tol=1e-9)


@pytest.mark.parametrize("n", [2, 3, 4])
def test_pair_order_and_splitting_do_not_matter(n):
    """Pairs act in parallel: reordering them, or splitting one into two halves on the
    same span, leaves A unchanged (K = Eᵀ K_d E is a sum over pairs)."""
    rng = np.random.default_rng(SEED + 40 + n)
    body, muscles = random_body(rng, n), random_muscles(rng, n)
    A = state_matrix(body, muscles)
    pairs = list(muscles.pairs)
    shuffled = MuscleSet(tuple(pairs[i] for i in rng.permutation(len(pairs))), n)
    first = pairs[0]
    halves = MuscleSet(tuple(
        [MusclePair("a", first.lo, first.hi, first.stiffness / 2, first.viscosity / 2),
         MusclePair("b", first.lo, first.hi, first.stiffness / 2, first.viscosity / 2)]
        + pairs[1:]), n)
    atol = 1e-12 * np.abs(A).max()
    np.testing.assert_allclose(state_matrix(body, shuffled), A, rtol=1e-12, atol=atol)
    np.testing.assert_allclose(state_matrix(body, halves), A, rtol=1e-12, atol=atol)


def test_poles_of_real_matrix_come_in_conjugate_pairs():
    """Every complex pole is listed with its conjugate (A is real), +imag first."""
    body = paper_body()
    for case in STIFFNESS_CASES:
        poles = analyse(body, paper_muscles(case)).poles
        same_poles(poles, np.conj(poles), tol=1e-12)
        for i, z in enumerate(poles):
            if z.imag > 1e-9:
                assert poles[i + 1] == pytest.approx(np.conj(z), rel=1e-12)
