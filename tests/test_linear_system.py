"""The one linear system (posturelab.linear.system) against independent statements: the
nonlinear model's finite differences, the dynamics module's J(Θ) and G, the muscle set's
own stiffness and viscosity matrices, and the state matrix's characteristic polynomial."""

from __future__ import annotations

import numpy as np
import pytest

import posturelab as pl
from posturelab.errors import ParameterError
from posturelab.linear import finite_difference_state_matrix, linear_system
from posturelab.linear.delay import system_rightmost_roots
from posturelab.linear.system import BodyArrays, joint_matrices
from posturelab.model.dynamics import mass_matrix
from posturelab.model.muscles import STIFFNESS_CASES


def test_upright_matrices_are_the_dynamics_at_upright(rng):
    for body in (pl.paper_body(), pl.get_body("paper-1link"), pl.get_body("paper-2link")):
        jac, gravity_torque = body.upright_matrices()
        np.testing.assert_array_equal(jac, mass_matrix(body, np.zeros(body.n_links)))
        np.testing.assert_array_equal(gravity_torque, body.gravity * body.gravity_coefficients)
    body = pl.paper_body()
    scale = rng.uniform(0.8, 1.2, (4, 1))
    arrays = BodyArrays(body.masses * scale, body.lengths, body.com_distances, body.inertias,
                        np.full(4, 9.7))
    jac, gravity_torque = arrays.upright_matrices()
    for i in range(4):
        one = pl.Body.from_arrays(arrays.masses[i], body.lengths, body.com_distances,
                                  body.inertias, gravity=9.7)
        np.testing.assert_allclose(jac[i], mass_matrix(one, np.zeros(3)), rtol=1e-14)
        np.testing.assert_allclose(gravity_torque[i], 9.7 * one.gravity_coefficients,
                                   rtol=1e-14)


@pytest.mark.parametrize("case", list(STIFFNESS_CASES))
def test_state_matrix_is_the_finite_difference_one(case):
    body, muscles = pl.paper_body(), pl.paper_muscles(case)
    A = linear_system(body, muscles).state_matrix()[0]
    expected = finite_difference_state_matrix(body, muscles)
    np.testing.assert_allclose(A, expected, rtol=1e-6, atol=1e-6 * np.abs(expected).max())


def test_characteristic_matrix_is_written_from_the_muscle_set(rng):
    """Δ(s) = s² J0 − g diag(a) + K_i + s L_i + (K_a + s L_a) e^{−sτ}, K = muscles'
    stiffness_matrix (without active gains the whole of it delayed)."""
    body = pl.paper_body()
    tau = 0.04
    s = rng.normal(size=5) + 1j * rng.normal(size=5) * 10
    G = body.gravity * np.diag(body.gravity_coefficients)
    J0 = mass_matrix(body, np.zeros(3))
    plain = pl.paper_muscles("3")
    K, L = plain.stiffness_matrix(), plain.viscosity_matrix()
    D = linear_system(body, plain, delay=tau).characteristic_matrix(s[None])[0]
    for j, z in enumerate(s):
        np.testing.assert_allclose(D[j], z * z * J0 - G + (K + z * L) * np.exp(-z * tau),
                                   rtol=1e-12, atol=1e-9)
    active = pl.paper_muscles("3", active_stiffness=[400.0] * 5,
                              active_viscosity=[50.0] * 5)
    E = active.selection_matrix
    Ka = E.T @ np.diag(active.active_stiffnesses) @ E
    La = E.T @ np.diag(active.active_viscosities) @ E
    D = linear_system(body, active, delay=tau).characteristic_matrix(s[None])[0]
    for j, z in enumerate(s):
        np.testing.assert_allclose(
            D[j], z * z * J0 - G + K + z * L + (Ka + z * La) * np.exp(-z * tau),
            rtol=1e-12, atol=1e-9)


def test_without_delay_det_delta_is_det_j0_times_the_characteristic_polynomial(rng):
    body, muscles = pl.paper_body(), pl.paper_muscles("1", active_stiffness=[100.0] * 5,
                                                      active_viscosity=[20.0] * 5)
    system = linear_system(body, muscles)
    A = system.state_matrix()[0]
    J0 = mass_matrix(body, np.zeros(3))
    for z in rng.normal(size=4) + 1j * rng.normal(size=4):
        lhs = np.linalg.det(system.characteristic_matrix(np.array([z]))[0])
        rhs = np.linalg.det(J0) * np.linalg.det(z * np.eye(6) - A)
        assert lhs == pytest.approx(rhs, rel=1e-9)


def test_a_batch_of_gains_is_the_systems_of_each_set(rng):
    body, layout = pl.paper_body(), pl.paper_muscles("1")
    k = rng.uniform(0.0, 1500.0, (6, 5))
    ka = rng.uniform(0.0, 800.0, (6, 5))
    tau = rng.uniform(0.0, 0.1, 6)
    batch = linear_system(body, layout, stiffness=k, viscosity=0.25 * k, active_stiffness=ka,
                          active_viscosity=0.1 * ka, delay=tau, proprioceptive_weight=0.7)
    assert len(batch) == 6 and batch.n_links == 3
    for i in range(6):
        muscles = pl.paper_muscles(stiffness=k[i], viscosity=0.25 * k[i],
                                   active_stiffness=ka[i], active_viscosity=0.1 * ka[i])
        one = linear_system(body, muscles, delay=tau[i], proprioceptive_weight=0.7)
        row = batch[i]
        for name in ("inertia", "stiffness", "viscosity", "delayed_stiffness",
                     "delayed_viscosity", "delay", "tilt_input", "translation_input"):
            np.testing.assert_allclose(np.broadcast_to(getattr(row, name),
                                                       getattr(one, name).shape),
                                       getattr(one, name), rtol=1e-14, err_msg=name)
    np.testing.assert_allclose(batch[[1, 3]].poles(), batch.poles()[[1, 3]])


def test_joint_matrices_are_e_transpose_diag_e(rng):
    E = pl.paper_muscles("1").selection_matrix
    g = rng.uniform(0.0, 10.0, (9000, 5))  # more rows than one matrix product takes
    np.testing.assert_allclose(joint_matrices(g, E), np.einsum("pi,mp,pj->mij", E, g, E),
                               rtol=1e-14)


def test_translation_input_is_minus_the_platform_vector():
    body = pl.paper_body()
    system = linear_system(body, pl.paper_muscles("1"))
    np.testing.assert_array_equal(system.translation_input[0],
                                  -pl.platform_vector(body, np.zeros(3)))


def test_bad_arguments():
    body, layout = pl.paper_body(), pl.paper_muscles("1")
    with pytest.raises(ParameterError, match="delay"):
        linear_system(body, layout, delay=-1.0)
    with pytest.raises(ParameterError, match="together"):
        linear_system(body, layout, stiffness=np.ones(5), viscosity=np.ones(5),
                      active_stiffness=np.ones(5))
    with pytest.raises(ParameterError, match="one_sided"):
        linear_system(body, layout, one_sided="both")
    with pytest.raises(ParameterError, match="without its inputs"):
        linear_system(body, layout, inputs=False).frequency_response([1.0], "tilt", np.ones(3))


def test_the_system_gives_the_rightmost_roots_at_its_delay():
    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    system = linear_system(body, muscles)
    np.testing.assert_array_equal(system_rightmost_roots(system, 0.002, 4),
                                  pl.rightmost_roots(body, muscles, 0.002, 4))
