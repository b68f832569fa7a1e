"""Independent check of posturelab.model.dynamics against a symbolic derivation.

The equations of motion of a planar chain of N links hinged at their ends,
standing on a platform that translates by (x_d(t), y_d(t)), are derived here
from scratch with ``sympy.physics.mechanics`` (rigid bodies, a Lagrangian and
``LagrangesMethod``); nothing of posturelab is used in the derivation. The
result, M(Θ) Θ̈ = F(Θ, Θ̇, U, ẍ_d, ÿ_d, ẋ_d, ẏ_d), is compared numerically with

    J(Θ) Θ̈ + B(Θ, Θ̇) Θ̇ − (g + ÿ_d) G(Θ) + ẍ_d H(Θ) = U

(posturelab's model, docs/design.md), so that M = J and F = U − BΘ̇ + (g + ÿ_d)G − ẍ_d H.

Geometry (conventions.py): x forward, y up; link i is rotated by −θ_i about z,
so its axis is (sin θ_i, cos θ_i) and θ_i > 0 leans it forward. A generalised
torque U_i on θ_i is a torque −U_i ẑ on link i (its angular velocity is −θ̇_i ẑ).

The paper's printed Appendix B matrices (N = 3) are written out by hand at the
end and compared too.

Tolerances: relative 1e-10 of the magnitude of the compared quantity (both
sides are double-precision evaluations of closed forms).
"""

import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import (
    LagrangesMethod,
    Lagrangian,
    Point,
    ReferenceFrame,
    RigidBody,
    dynamicsymbols,
    inertia,
    msubs,
)

from _bodies import random_body
from posturelab.model.body import Body, paper_body
from posturelab.model.dynamics import (
    angular_acceleration,
    gravity_vector,
    mass_matrix,
    platform_vector,
    velocity_terms,
)

RTOL = 1e-10
N_SAMPLES = 6


class Derivation:
    """Numerical callables of a symbolic derivation for N links."""

    def __init__(self, n: int):
        self.n = n
        t = dynamicsymbols._t
        q = dynamicsymbols(f"theta1:{n + 1}")
        xd, yd = dynamicsymbols("x_d y_d")
        m = sp.symbols(f"m1:{n + 1}", positive=True)
        l = sp.symbols(f"l1:{n + 1}", positive=True)
        k = sp.symbols(f"k1:{n + 1}", nonnegative=True)
        inert = sp.symbols(f"I1:{n + 1}", positive=True)
        u = sp.symbols(f"U1:{n + 1}")
        g = sp.symbols("g", positive=True)

        frame = ReferenceFrame("N")
        origin = Point("O")
        origin.set_vel(frame, 0)
        joint = origin.locatenew("P0", xd * frame.x + yd * frame.y)  # the ankle
        bodies, loads = [], []
        for i in range(n):
            link = frame.orientnew(f"A{i + 1}", "Axis", (-q[i], frame.z))
            com = joint.locatenew(f"C{i + 1}", k[i] * link.y)
            com.set_vel(frame, com.pos_from(origin).dt(frame))
            body = RigidBody(f"B{i + 1}", com, link, m[i], (inertia(link, 0, 0, inert[i]), com))
            body.potential_energy = m[i] * g * com.pos_from(origin).dot(frame.y)
            bodies.append(body)
            loads.append((link, -u[i] * frame.z))
            joint = joint.locatenew(f"P{i + 1}", l[i] * link.y)

        lm = LagrangesMethod(Lagrangian(frame, *bodies), q, forcelist=loads, frame=frame)
        lm.form_lagranges_equations()

        th = sp.symbols(f"th1:{n + 1}")
        om = sp.symbols(f"om1:{n + 1}")
        ax, ay, vx, vy = sp.symbols("ax ay vx vy")
        sub = {xd.diff(t, 2): ax, yd.diff(t, 2): ay, xd.diff(t): vx, yd.diff(t): vy}
        sub.update({qi.diff(t): w for qi, w in zip(q, om, strict=True)})
        sub.update(dict(zip(q, th, strict=True)))
        mass = msubs(lm.mass_matrix, sub)
        forcing = msubs(lm.forcing, sub)
        # The platform velocity must not matter (Galilean invariance), but it is
        # kept as an argument so that this can be checked numerically.
        self.platform_velocity_symbols_present = bool({vx, vy} & forcing.free_symbols)
        params = (m, l, k, inert, g)
        self._mass = sp.lambdify([th, *params], mass, "numpy")
        self._forcing = sp.lambdify([th, om, u, ax, ay, vx, vy, *params], forcing, "numpy")

    @staticmethod
    def _params(body: Body, g=None):
        g = body.gravity if g is None else g
        return (body.masses, body.lengths, body.com_distances, body.inertias, g)

    def mass(self, body, theta):
        return np.array(self._mass(theta, *self._params(body)), dtype=float)

    def forcing(self, body, theta, omega, u=None, ax=0.0, ay=0.0, vx=0.0, vy=0.0, g=None):
        """F of M Θ̈ = F; ``g`` overrides the body's gravity (0 is allowed here)."""
        u = np.zeros(self.n) if u is None else u
        out = self._forcing(theta, omega, u, ax, ay, vx, vy, *self._params(body, g))
        return np.array(out, dtype=float).reshape(self.n)


@pytest.fixture(scope="module", params=[1, 2, 3, 4], ids=lambda n: f"N{n}")
def derivation(request):
    """Symbolic equations of motion, derived once per N for the whole module."""
    return Derivation(request.param)




def samples(n, seed=12345):
    """(body, theta, omega, U, ax, ay, vx, vy) at random, from a seeded generator."""
    rng = np.random.default_rng(seed + n)
    for _ in range(N_SAMPLES):
        yield (
            random_body(rng, n, gravity=None),
            rng.uniform(-np.pi, np.pi, n),
            rng.normal(0.0, 3.0, n),
            rng.normal(0.0, 100.0, n),
            rng.normal(0.0, 5.0),
            rng.normal(0.0, 5.0),
            rng.normal(0.0, 2.0),
            rng.normal(0.0, 2.0),
        )


def close(actual, expected, rtol=RTOL):
    scale = max(1.0, float(np.max(np.abs(expected))))
    np.testing.assert_allclose(actual, expected, rtol=rtol, atol=rtol * scale)


# ---------------------------------------------------------------------------
# Symbolic derivation vs posturelab.model.dynamics, N = 1..4
# ---------------------------------------------------------------------------


def test_mass_matrix_equals_symbolic(derivation):
    """J(Θ) of posturelab equals the symbolic mass matrix of the Lagrangian."""
    for body, theta, *_ in samples(derivation.n):
        close(mass_matrix(body, theta), derivation.mass(body, theta))


def test_velocity_terms_equal_symbolic(derivation):
    """BΘ̇ equals minus the symbolic forcing with g = 0, U = 0 and the platform still."""
    for body, theta, omega, *_ in samples(derivation.n):
        expected = -derivation.forcing(body, theta, omega, g=0.0)
        close(velocity_terms(body, theta, omega), expected)


def test_gravity_and_platform_vectors_equal_symbolic(derivation):
    """G is the symbolic forcing per unit g, H minus the forcing per unit ẍ_d (Θ̇ = 0)."""
    for body, theta, *_ in samples(derivation.n):
        zero = np.zeros(derivation.n)
        close(gravity_vector(body, theta), derivation.forcing(body, theta, zero, g=1.0))
        close(platform_vector(body, theta), -derivation.forcing(body, theta, zero, ax=1.0, g=0.0))


def test_angular_acceleration_equals_symbolic(derivation):
    """Θ̈ with torques U and both platform accelerations equals M⁻¹F of the derivation."""
    for body, theta, omega, u, ax, ay, vx, vy in samples(derivation.n):
        expected = np.linalg.solve(
            derivation.mass(body, theta),
            derivation.forcing(body, theta, omega, u, ax, ay, vx, vy),
        )
        close(angular_acceleration(body, theta, omega, u, ax, ay), expected)


def test_specification_of_the_compiled_engine_equals_symbolic(derivation):
    """The equation of motion the compiled engine's C is generated from (the entry formulas
    of posturelab.model.dynamics, assembled on sympy symbols by _codegen.spec) has the
    Lagrangian's mass matrix and forcing: J = M and U − BΘ̇ + (g + ÿ_d)G − ẍ_d H = F."""
    from posturelab.simulation.compiled._codegen.spec import equation_of_motion

    n = derivation.n
    J, B, G, H, sym = equation_of_motion(n)
    pairs = sorted(sym["coupling"].items())
    args = [sym["theta"], sym["omega"], sym["inertia"], sym["gravity_coefficient"],
            [s for _, s in pairs]]
    spec_J = sp.lambdify(args, J, "numpy")
    spec_BGH = sp.lambdify(args, (B, G, H), "numpy")
    for body, theta, omega, u, ax, ay, vx, vy in samples(n):
        params = [theta, omega, body.inertia_diagonal, body.gravity_coefficients,
                  [body.coupling[i, j] for (i, j), _ in pairs]]
        close(np.array(spec_J(*params), dtype=float), derivation.mass(body, theta))
        b, g, h = (np.array(v, dtype=float).reshape(n) for v in spec_BGH(*params))
        close(u - b + (body.gravity + ay) * g - ax * h,
              derivation.forcing(body, theta, omega, u, ax, ay, vx, vy))


@pytest.mark.parametrize("general", [False, True], ids=["small", "general"])
def test_generated_c_right_hand_side_equals_symbolic(derivation, general):
    """The compiled engine's right-hand side (C generated from the model's formulas: the
    straight-line code for N <= 3 and the general-N elimination) gives the derivation's
    M⁻¹F, with joint moments τ entering as U_i = τ_{i+1} − τ_i and both platform
    accelerations."""
    from posturelab.model.feedback import moments_to_link_torques
    from posturelab.model.muscles import MusclePair, MuscleSet
    from posturelab.simulation import compiled

    n = derivation.n
    muscles = MuscleSet((MusclePair("p", 0, 1, 100.0, 10.0),), n)
    rng = np.random.default_rng(2024 + n)
    for body, theta, omega, _, ax, ay, vx, vy in samples(n):
        moments = rng.normal(0.0, 100.0, n)
        expected = np.linalg.solve(
            derivation.mass(body, theta),
            derivation.forcing(body, theta, omega, moments_to_link_torques(moments), ax, ay,
                               vx, vy))
        out = compiled.state_derivative(body, muscles, np.concatenate([theta, omega]),
                                        active=np.zeros(1), platform_acceleration=(ax, ay),
                                        delayed_moments=moments, general=general)
        close(out[:n], omega)
        close(out[n:], expected)


def test_joint_torque_enters_as_generalised_force(derivation):
    """With g = 0 and the body at rest, the forcing is exactly U (U is the generalised force)."""
    rng = np.random.default_rng(12345)
    body = random_body(rng, derivation.n, gravity=None)
    u = rng.normal(0.0, 10.0, derivation.n)
    theta = rng.uniform(-1.0, 1.0, derivation.n)
    close(derivation.forcing(body, theta, np.zeros(derivation.n), u, g=0.0), u)


def test_platform_velocity_does_not_matter(derivation):
    """Galilean invariance: a constant platform velocity drops out of the forcing."""
    for body, theta, omega, u, ax, ay, *_ in samples(derivation.n):
        still = derivation.forcing(body, theta, omega, u, ax, ay, 0.0, 0.0)
        moving = derivation.forcing(body, theta, omega, u, ax, ay, 3.0, -1.5)
        close(moving, still)


def test_vertical_platform_acceleration_adds_to_gravity_erratum_3(derivation):
    """Erratum 3: the derivation gives −(g + ÿ_d)G on the left of eq. 1, not (ÿ_d − g)G.

    An upward platform acceleration ÿ_d acts exactly like extra gravity, so the
    forcing with (g, ÿ_d) equals the forcing with (g + ÿ_d, 0); and the forcing
    per unit ÿ_d alone is +G (the printed sign would make it −G).
    """
    rng = np.random.default_rng(12345)
    body = random_body(rng, derivation.n, gravity=9.81)
    theta = rng.uniform(-1.0, 1.0, derivation.n)
    omega = rng.normal(0.0, 1.0, derivation.n)
    ay = 2.5
    close(
        derivation.forcing(body, theta, omega, ay=ay),
        derivation.forcing(body.with_gravity(9.81 + ay), theta, omega),
    )
    per_unit_ay = derivation.forcing(body, theta, np.zeros(derivation.n), ay=1.0, g=0.0)
    g_vec = gravity_vector(body, theta)
    close(per_unit_ay, g_vec)
    assert not np.allclose(per_unit_ay, -g_vec)


# ---------------------------------------------------------------------------
# The paper's printed Appendix B (N = 3), written out by hand
# ---------------------------------------------------------------------------


def appendix_b(p, th, thd):
    """J, B, G, H exactly as printed in Appendix B, for parameters p and state (th, thd)."""
    I1, I2, I3 = p["I"]
    m1, m2, m3 = p["m"]
    l1, l2, _ = p["l"]
    k1, k2, k3 = p["k"]
    t1, t2, t3 = th
    d1, d2, d3 = thd
    cos, sin = np.cos, np.sin
    J = np.array([
        [I1 + m1 * k1**2 + (m2 + m3) * l1**2,
         (m2 * k2 + m3 * l2) * l1 * cos(t2 - t1),
         m3 * k3 * l1 * cos(t3 - t1)],
        [(m2 * k2 + m3 * l2) * l1 * cos(t2 - t1),
         I2 + m2 * k2**2 + m3 * l2**2,
         m3 * k3 * l2 * cos(t3 - t2)],
        [m3 * k3 * l1 * cos(t3 - t1),
         m3 * k3 * l2 * cos(t3 - t2),
         I3 + m3 * k3**2],
    ])
    B = np.array([
        [0.0,
         (m2 * k2 + m3 * l2) * l1 * d2 * sin(t1 - t2),
         m3 * k3 * l1 * d3 * sin(t1 - t3)],
        [(m2 * k2 + m3 * l2) * l1 * d1 * sin(t2 - t1),
         0.0,
         m3 * k3 * l2 * d3 * sin(t2 - t3)],
        [m3 * k3 * l1 * d1 * sin(t3 - t1),
         m3 * k3 * l2 * d2 * sin(t3 - t2),
         0.0],
    ])
    G = np.array([
        (m1 * k1 + (m2 + m3) * l1) * sin(t1),
        (m2 * k2 + m3 * l2) * sin(t2),
        m3 * k3 * sin(t3),
    ])
    H = np.array([
        (m1 * k1 + (m2 + m3) * l1) * cos(t1),
        (m2 * k2 + m3 * l2) * cos(t2),
        m3 * k3 * cos(t3),
    ])
    return J, B, G, H


APPENDIX_A = {
    "I": (0.17, 0.5, 2.1),
    "m": (5.05, 18.67, 41.87),
    "l": (0.401, 0.412, 0.619),
    "k": (0.21, 0.26, 0.24),
}


def appendix_b_cases():
    """The paper's body (Appendix A) and random three-link bodies, at random states."""
    rng = np.random.default_rng(12345)
    out = [(APPENDIX_A, paper_body())]
    for _ in range(3):
        body = random_body(rng, 3, gravity=9.81)
        p = {"I": body.inertias, "m": body.masses, "l": body.lengths, "k": body.com_distances}
        out.append((p, body))
    for p, body in out:
        for _ in range(4):
            yield p, body, rng.uniform(-np.pi, np.pi, 3), rng.normal(0.0, 3.0, 3)


def test_paper_body_is_appendix_a():
    """Appendix A: the preset holds the printed I, m, l, k and g = 9.81."""
    body = paper_body()
    np.testing.assert_array_equal(body.inertias, APPENDIX_A["I"])
    np.testing.assert_array_equal(body.masses, APPENDIX_A["m"])
    np.testing.assert_array_equal(body.lengths, APPENDIX_A["l"])
    np.testing.assert_array_equal(body.com_distances, APPENDIX_A["k"])
    assert body.gravity == 9.81


def test_appendix_b_matrices_equal_ours():
    """Appendix B: printed J(Θ), B(Θ,Θ̇)Θ̇, G(Θ), H(Θ) equal posturelab's, for any parameters."""
    for p, body, th, thd in appendix_b_cases():
        J, B, G, H = appendix_b(p, th, thd)
        close(mass_matrix(body, th), J)
        close(velocity_terms(body, th, thd), B @ thd)
        close(gravity_vector(body, th), G)
        close(platform_vector(body, th), H)


@pytest.mark.parametrize("derivation", [3], indirect=True, ids=["N3"])
def test_appendix_b_matrices_equal_symbolic(derivation):
    """Appendix B's J, B, G, H also agree with the symbolic derivation (eq. 1 with y up)."""
    for p, body, th, thd in appendix_b_cases():
        J, B, G, H = appendix_b(p, th, thd)
        close(derivation.mass(body, th), J)
        g = body.gravity
        rhs = derivation.forcing(body, th, thd, ax=0.7, ay=-0.4)
        close(rhs, -B @ thd + (g - 0.4) * G - 0.7 * H)
