"""Independent checks of posturelab.model.dynamics: structure, limit cases, energy, symmetry.

Nothing here takes an expected value from the code under test: energies are
rebuilt from the centre-of-mass positions and velocities by hand, the one-link
case from the inverted-pendulum formula, the velocity jump from integrating a
short, strong platform pulse, the gravity coefficients from Appendix A.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from _bodies import random_body
from posturelab.model.body import Body, paper_body
from posturelab.model.dynamics import (
    angular_acceleration,
    gravity_vector,
    kinetic_energy,
    mass_matrix,
    platform_vector,
    potential_energy,
    state_derivative,
    velocity_step_response,
    velocity_terms,
)

SEED = 12345




def com_kinematics(body, theta, omega):
    """Centre-of-mass positions and velocities of each link, from the geometry alone.

    Joint i+1 sits l_i (sin θ_i, cos θ_i) above joint i; the ankle is the origin.
    Returns x, y, vx, vy, each of shape (N,).
    """
    n = body.n_links
    x, y, vx, vy = (np.zeros(n) for _ in range(4))
    jx = jy = jvx = jvy = 0.0
    for i in range(n):
        s, c = np.sin(theta[i]), np.cos(theta[i])
        k, l, w = body.com_distances[i], body.lengths[i], omega[i]
        x[i], y[i] = jx + k * s, jy + k * c
        vx[i], vy[i] = jvx + k * c * w, jvy - k * s * w
        jx, jy, jvx, jvy = jx + l * s, jy + l * c, jvx + l * c * w, jvy - l * s * w
    return x, y, vx, vy


def hand_gravity_coefficients(body):
    """a_i = m_i k_i + (mass above link i) l_i, by a plain loop."""
    m, l, k = body.masses, body.lengths, body.com_distances
    return np.array([m[i] * k[i] + sum(m[i + 1:]) * l[i] for i in range(body.n_links)])


# ---------------------------------------------------------------------------
# The inertia matrix
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("n", range(1, 7))
def test_mass_matrix_symmetric_positive_definite(n):
    """J(Θ) is symmetric and positive-definite at any posture, for any body (N = 1..6)."""
    rng = np.random.default_rng(SEED + n)
    for _ in range(10):
        body = random_body(rng, n)
        theta = rng.uniform(-np.pi, np.pi, (50, n))
        J = mass_matrix(body, theta)
        assert J.shape == (50, n, n)
        np.testing.assert_allclose(J, np.swapaxes(J, -1, -2), rtol=0, atol=1e-14 * J.max())
        eig = np.linalg.eigvalsh(J)
        assert np.all(eig > 0.0)
        # J = diag(I_i) + (translational part, positive semi-definite), so its
        # smallest eigenvalue is at least the smallest own-axis inertia I_i
        assert np.all(eig.min(axis=-1) >= body.inertias.min() * (1 - 1e-12))


@pytest.mark.parametrize("n", range(1, 7))
def test_mass_matrix_upright_is_inertia_of_straight_body(n):
    """1ᵀ J(0) 1 is the moment of inertia about the ankle of the straight rigid body,
    Σ I_i + m_i (height of COM i)², by the parallel-axis theorem."""
    rng = np.random.default_rng(SEED + 10 + n)
    body = random_body(rng, n)
    heights = np.concatenate([[0.0], np.cumsum(body.lengths)[:-1]]) + body.com_distances
    about_ankle = np.sum(body.inertias + body.masses * heights**2)
    J0 = mass_matrix(body, np.zeros(n))
    assert J0.sum() == pytest.approx(about_ankle, rel=1e-12)


@pytest.mark.parametrize("n", [1, 2, 3, 5])
def test_kinetic_and_potential_energy_from_com_motion(n):
    """½Θ̇ᵀJΘ̇ = Σ ½ m_i |v_i|² + ½ I_i θ̇_i² and g Σ a_i cos θ_i = g Σ m_i y_i (by hand)."""
    rng = np.random.default_rng(SEED + 20 + n)
    for _ in range(10):
        body = random_body(rng, n)
        theta = rng.uniform(-np.pi, np.pi, n)
        omega = rng.normal(0.0, 3.0, n)
        _, y, vx, vy = com_kinematics(body, theta, omega)
        ke = 0.5 * np.sum(body.masses * (vx**2 + vy**2) + body.inertias * omega**2)
        pe = body.gravity * np.sum(body.masses * y)
        assert kinetic_energy(body, theta, omega) == pytest.approx(ke, rel=1e-12)
        assert potential_energy(body, theta) == pytest.approx(pe, rel=1e-12, abs=1e-12)


# ---------------------------------------------------------------------------
# Limit case: one link is the inverted pendulum
# ---------------------------------------------------------------------------


def test_one_link_is_inverted_pendulum():
    """N = 1: (I + m k²) θ̈ = (g + ÿ_d) m k sin θ − ẍ_d m k cos θ + U (− nothing from B)."""
    rng = np.random.default_rng(SEED)
    for _ in range(20):
        m, l = rng.uniform(1.0, 80.0), rng.uniform(0.3, 1.5)
        k, inertia, g = rng.uniform(0.0, l), rng.uniform(0.1, 10.0), rng.uniform(1.0, 20.0)
        body = Body.from_arrays([m], [l], [k], [inertia], gravity=g)
        theta, omega = rng.uniform(-np.pi, np.pi), rng.normal(0.0, 3.0)
        u, ax, ay = rng.normal(0.0, 50.0), rng.normal(0.0, 5.0), rng.normal(0.0, 5.0)
        expected = ((g + ay) * m * k * np.sin(theta) - ax * m * k * np.cos(theta) + u) / (
            inertia + m * k**2
        )
        got = angular_acceleration(body, [theta], [omega], [u], ax, ay)
        assert got.shape == (1,)
        assert got[0] == pytest.approx(expected, rel=1e-12, abs=1e-12)
        assert velocity_terms(body, [theta], [omega])[0] == 0.0


# ---------------------------------------------------------------------------
# Energy
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("body_kind", ["paper", "random4"])
def test_energy_conserved_without_torques(body_kind):
    """Zero torques, platform at rest: KE + PE is constant over 2 s (DOP853, rtol 1e-11),
    to 1e-8 of the energy scale KE(0) + g Σ a_i."""
    rng = np.random.default_rng(SEED)
    body = paper_body() if body_kind == "paper" else random_body(rng, 4)
    n = body.n_links
    x0 = np.concatenate([rng.uniform(-0.3, 0.3, n), rng.normal(0.0, 1.0, n)])
    sol = solve_ivp(lambda t, x: state_derivative(body, x), (0.0, 2.0), x0,
                    method="DOP853", rtol=1e-11, atol=1e-12, dense_output=False)
    assert sol.success
    theta, omega = sol.y[:n].T, sol.y[n:].T
    energy = kinetic_energy(body, theta, omega) + potential_energy(body, theta)
    scale = kinetic_energy(body, x0[:n], x0[n:]) + body.gravity * body.gravity_coefficients.sum()
    # the chain falls: energy moves between kinetic and potential
    assert np.ptp(kinetic_energy(body, theta, omega)) > 0.1 * scale
    assert np.max(np.abs(energy - energy[0])) / scale < 1e-8


@pytest.mark.parametrize("n", [1, 2, 3, 4])
def test_power_balance_with_torques_and_platform(n):
    """dE/dt = Θ̇ᵀU − ẍ_d Θ̇ᵀH + ÿ_d Θ̇ᵀG for E = KE + PE in the platform frame.

    The time derivative is taken by central differences of E along (Θ̇, Θ̈), so
    it checks angular_acceleration's torque and both platform terms at once.
    """
    rng = np.random.default_rng(SEED + 30 + n)
    for _ in range(10):
        body = random_body(rng, n)
        theta, omega = rng.uniform(-np.pi, np.pi, n), rng.normal(0.0, 2.0, n)
        u, ax, ay = rng.normal(0.0, 50.0, n), rng.normal(0.0, 5.0), rng.normal(0.0, 5.0)
        alpha = angular_acceleration(body, theta, omega, u, ax, ay)

        def energy(h, theta=theta, omega=omega, alpha=alpha, body=body):
            th, om = theta + h * omega, omega + h * alpha
            return kinetic_energy(body, th, om) + potential_energy(body, th)

        h = 1e-5
        dedt = (energy(h) - energy(-h)) / (2 * h)
        power = omega @ u - ax * omega @ platform_vector(body, theta) + ay * omega @ gravity_vector(
            body, theta)
        scale = np.abs(omega) @ (np.abs(u) + 5 * body.gravity_coefficients) + 1.0
        assert dedt == pytest.approx(power, abs=1e-6 * scale)


# ---------------------------------------------------------------------------
# Sudden platform velocity change
# ---------------------------------------------------------------------------


def test_velocity_step_response_is_minus_jinv_h():
    """ΔΘ̇ = −J(Θ)⁻¹H(Θ)Δẋ_d, linear in Δẋ_d, at upright and at flexed postures."""
    rng = np.random.default_rng(SEED)
    for n in (1, 3, 5):
        body = random_body(rng, n)
        for theta in (None, rng.uniform(-0.5, 0.5, n)):
            th = np.zeros(n) if theta is None else theta
            jinv_h = np.linalg.inv(mass_matrix(body, th)) @ platform_vector(body, th)
            for dv in (-1.0, 0.3, 2.0):
                np.testing.assert_allclose(
                    velocity_step_response(body, dv, theta), -jinv_h * dv, rtol=1e-12, atol=1e-15
                )


def test_velocity_step_response_paper_initial_rates():
    """Section V.B: a backward unit platform velocity step (Δẋ_d = −1 m/s) gives the initial
    rates [2.5580, −0.0654, 0.0027] rad/s, to the 4 printed decimals."""
    rates = velocity_step_response(paper_body(), -1.0)
    np.testing.assert_allclose(rates, [2.5580, -0.0654, 0.0027], rtol=0, atol=5e-5)
    assert rates[0] > 0  # backward platform jerk -> forward sway


@pytest.mark.parametrize("posture", [(0.0, 0.0, 0.0), (0.1, -0.1, 0.1)])
def test_velocity_step_is_the_limit_of_a_short_pulse(posture):
    """Integrate a platform pulse ẍ_d = Δv/ε for ε = 1e-7 s: the rates jump by
    velocity_step_response to within O(ε) (impulse–momentum, independent of J⁻¹H)."""
    body = paper_body()
    dv, eps = -1.0, 1e-7
    x0 = np.concatenate([posture, np.zeros(3)])
    sol = solve_ivp(
        lambda t, x: state_derivative(body, x, platform_acceleration_x=dv / eps),
        (0.0, eps), x0, method="DOP853", rtol=1e-12, atol=1e-14,
    )
    rates = sol.y[3:, -1]
    np.testing.assert_allclose(
        rates, velocity_step_response(body, dv, np.array(posture)), rtol=0, atol=1e-5
    )


# ---------------------------------------------------------------------------
# Batches, G and H, symmetry
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("n", [1, 3, 4])
def test_batch_shapes_match_loops(n):
    """(5, 7, N) inputs give (5, 7, …) outputs equal to element-by-element calls."""
    rng = np.random.default_rng(SEED + 40 + n)
    body = random_body(rng, n)
    theta = rng.uniform(-np.pi, np.pi, (5, 7, n))
    omega = rng.normal(0.0, 2.0, (5, 7, n))
    u = rng.normal(0.0, 50.0, (5, 7, n))
    ax = rng.normal(0.0, 3.0, (5, 7))
    ay = rng.normal(0.0, 3.0, (5, 7))
    state = np.concatenate([theta, omega], axis=-1)

    batch = {
        "J": mass_matrix(body, theta),
        "B": velocity_terms(body, theta, omega),
        "G": gravity_vector(body, theta),
        "H": platform_vector(body, theta),
        "acc": angular_acceleration(body, theta, omega, u, ax, ay),
        "dx": state_derivative(body, state, u, ax, ay),
        "ke": kinetic_energy(body, theta, omega),
        "pe": potential_energy(body, theta),
    }
    shapes = {"J": (5, 7, n, n), "B": (5, 7, n), "G": (5, 7, n), "H": (5, 7, n),
              "acc": (5, 7, n), "dx": (5, 7, 2 * n), "ke": (5, 7), "pe": (5, 7)}
    for key, shape in shapes.items():
        assert batch[key].shape == shape, key
    for a in range(5):
        for b in range(7):
            t, w = theta[a, b], omega[a, b]
            single = {
                "J": mass_matrix(body, t),
                "B": velocity_terms(body, t, w),
                "G": gravity_vector(body, t),
                "H": platform_vector(body, t),
                "acc": angular_acceleration(body, t, w, u[a, b], ax[a, b], ay[a, b]),
                "dx": state_derivative(body, state[a, b], u[a, b], ax[a, b], ay[a, b]),
                "ke": kinetic_energy(body, t, w),
                "pe": potential_energy(body, t),
            }
            for key, value in single.items():
                np.testing.assert_allclose(batch[key][a, b], value, rtol=1e-12, atol=1e-12,
                                           err_msg=key)


def test_state_derivative_layout():
    """state_derivative is [Θ̇, Θ̈] for the state [Θ, Θ̇] (state order of conventions.py)."""
    rng = np.random.default_rng(SEED)
    body = paper_body()
    theta, omega, u = rng.normal(size=3), rng.normal(size=3), rng.normal(size=3)
    dx = state_derivative(body, np.concatenate([theta, omega]), u, 0.4, -0.2)
    np.testing.assert_array_equal(dx[:3], omega)
    np.testing.assert_allclose(dx[3:], angular_acceleration(body, theta, omega, u, 0.4, -0.2),
                               rtol=1e-14)


# Appendix B, with Appendix A's numbers: a_i = m_i k_i + (Σ_{j>i} m_j) l_i. [kg·m]
PAPER_A = np.array([
    5.05 * 0.21 + (18.67 + 41.87) * 0.401,
    18.67 * 0.26 + 41.87 * 0.412,
    41.87 * 0.24,
])


def test_gravity_coefficients_appendix_b():
    """The entries of G and H (Appendix B) for the paper's body, and for random bodies."""
    np.testing.assert_allclose(paper_body().gravity_coefficients, PAPER_A, rtol=1e-14)
    rng = np.random.default_rng(SEED)
    for n in range(1, 7):
        body = random_body(rng, n)
        np.testing.assert_allclose(body.gravity_coefficients, hand_gravity_coefficients(body),
                                   rtol=1e-13)


@pytest.mark.parametrize(
    "angle,g_factor,h_factor",
    [(0.0, 0.0, 1.0), (np.pi / 2, 1.0, 0.0), (-np.pi / 2, -1.0, 0.0)],
    ids=["upright", "forward-horizontal", "backward-horizontal"],
)
def test_gravity_and_platform_vectors_at_special_angles(angle, g_factor, h_factor):
    """G = a sin θ and H = a cos θ: upright G = 0, H = a; at ±π/2, G = ±a and H = 0."""
    body = paper_body()
    theta = np.full(3, angle)
    np.testing.assert_allclose(gravity_vector(body, theta), g_factor * PAPER_A,
                               rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(platform_vector(body, theta), h_factor * PAPER_A,
                               rtol=1e-14, atol=1e-14)


def test_upright_is_an_equilibrium_and_leaning_falls_forward():
    """Upright at rest with no torque stays put; a forward lean accelerates forward."""
    body = paper_body()
    np.testing.assert_array_equal(angular_acceleration(body, np.zeros(3), np.zeros(3)), 0.0)
    acc = angular_acceleration(body, np.full(3, 0.05), np.zeros(3))
    assert np.sum(mass_matrix(body, np.full(3, 0.05)) @ acc) > 0


def test_sagittal_mirror_symmetry():
    """Mirroring x (θ → −θ, Θ̇ → −Θ̇, U → −U, ẍ_d → −ẍ_d, ÿ_d unchanged) mirrors Θ̈."""
    rng = np.random.default_rng(SEED)
    for n in (1, 2, 3, 5):
        body = random_body(rng, n)
        theta, omega = rng.uniform(-np.pi, np.pi, n), rng.normal(0.0, 2.0, n)
        u, ax, ay = rng.normal(0.0, 50.0, n), rng.normal(0.0, 3.0), rng.normal(0.0, 3.0)
        forward = angular_acceleration(body, theta, omega, u, ax, ay)
        mirrored = angular_acceleration(body, -theta, -omega, -u, -ax, ay)
        np.testing.assert_allclose(mirrored, -forward, rtol=1e-12, atol=1e-12)
