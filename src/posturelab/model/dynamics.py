"""Equations of motion of a planar N-link chain on a translating platform.

Pure functions over arrays. Angles may carry leading batch axes: ``theta`` of
shape ``(..., N)`` gives results of shape ``(..., N)`` or ``(..., N, N)``.

The model (docs/design.md, N links; paper eq. 1 with y up, erratum 3)::

    J(Θ) Θ̈ + B(Θ, Θ̇) Θ̇ − (g + ÿ_d) G(Θ) + ẍ_d H(Θ) = U

with, for links i, j (lowest first), a_i = m_i k_i + (Σ_{j>i} m_j) l_i and
c_ij = l_i a_j (i < j):

* J_ii = I_i + m_i k_i² + (Σ_{j>i} m_j) l_i²,  J_ij = c_ij cos(θ_j − θ_i)
* (B Θ̇)_i = Σ_j c_ij sin(θ_i − θ_j) θ̇_j²
* G_i = a_i sin θ_i,  H_i = a_i cos θ_i
"""

from __future__ import annotations

import numpy as np

from .body import Body

__all__ = [
    "mass_matrix",
    "velocity_terms",
    "gravity_vector",
    "platform_vector",
    "angular_acceleration",
    "state_derivative",
    "kinetic_energy",
    "potential_energy",
    "velocity_step_response",
    "knee_constraint_row",
    "constrained_acceleration",
    "constrained_velocity",
]


# The entries of the equation of motion, over a math namespace ``xp`` (numpy here; sympy when
# the compiled engine's C is generated from them, posturelab.simulation.compiled._codegen).

def coupling_formula(coupling, theta_i, theta_j, xp=np):
    """J_ij = c_ij cos(θ_j − θ_i) (i ≠ j). [kg·m²]"""
    return coupling * xp.cos(theta_j - theta_i)


def centripetal_formula(coupling, theta_i, theta_j, omega_j, xp=np):
    """Link j's part of (BΘ̇)_i: c_ij sin(θ_i − θ_j) θ̇_j². [N·m]"""
    return coupling * xp.sin(theta_i - theta_j) * (omega_j * omega_j)


def load_formula(gravity_coefficient, theta_i, gravity_and_lift, platform_x, xp=np):
    """Gravity and platform acceleration on link i: a_i ((g + ÿ_d) sin θ_i − ẍ_d cos θ_i),
    that is (g + ÿ_d) G_i − ẍ_d H_i. [N·m]"""
    return gravity_coefficient * (gravity_and_lift * xp.sin(theta_i)
                                  - platform_x * xp.cos(theta_i))


def mass_matrix(body: Body, theta: np.ndarray) -> np.ndarray:
    """Inertia matrix J(Θ).

    Parameters
    ----------
    body : Body
        The chain.
    theta : array_like, shape (..., N)
        Absolute link angles from the vertical, forward positive. [rad]

    Returns
    -------
    numpy.ndarray, shape (..., N, N)
        Symmetric positive-definite inertia matrix. [kg·m²]
    """
    theta = np.asarray(theta, dtype=float)
    J = coupling_formula(body.coupling, theta[..., :, None], theta[..., None, :])
    n = body.n_links
    J[..., np.arange(n), np.arange(n)] = body.inertia_diagonal
    return J


def velocity_terms(body: Body, theta: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Centripetal term B(Θ, Θ̇) Θ̇.

    Parameters
    ----------
    theta : array_like, shape (..., N)
        Link angles. [rad]
    omega : array_like, shape (..., N)
        Link angular rates. [rad/s]

    Returns
    -------
    numpy.ndarray, shape (..., N)
        (B Θ̇)_i = Σ_j c_ij sin(θ_i − θ_j) θ̇_j². [N·m]
    """
    theta = np.asarray(theta, dtype=float)
    omega = np.asarray(omega, dtype=float)
    return np.sum(centripetal_formula(body.coupling, theta[..., :, None], theta[..., None, :],
                                      omega[..., None, :]), axis=-1)


def gravity_vector(body: Body, theta: np.ndarray) -> np.ndarray:
    """G(Θ): G_i = a_i sin θ_i. [kg·m]

    Multiplied by (g + ÿ_d) [m/s²] it is the gravitational torque [N·m]
    that tips each link forward.
    """
    return body.gravity_coefficients * np.sin(np.asarray(theta, dtype=float))


def platform_vector(body: Body, theta: np.ndarray) -> np.ndarray:
    """H(Θ): H_i = a_i cos θ_i, the coupling of horizontal platform acceleration. [kg·m]"""
    return body.gravity_coefficients * np.cos(np.asarray(theta, dtype=float))


def angular_acceleration(
    body: Body,
    theta: np.ndarray,
    omega: np.ndarray,
    link_torques: np.ndarray | float = 0.0,
    platform_acceleration_x: np.ndarray | float = 0.0,
    platform_acceleration_y: np.ndarray | float = 0.0,
    *,
    joint_torques: np.ndarray | float | None = None,
) -> np.ndarray:
    """Θ̈ from eq. 1: J⁻¹ [U − BΘ̇ + (g + ÿ_d) G − ẍ_d H].

    Parameters
    ----------
    theta, omega : array_like, shape (..., N)
        Link angles [rad] and rates [rad/s].
    link_torques : array_like, shape (..., N) or scalar
        Generalised torques U on the link-angle coordinates (U_i = τ_{i+1} − τ_i from the
        joint moments τ: :func:`posturelab.model.feedback.moments_to_link_torques`). [N·m]
    platform_acceleration_x : array_like, shape (...) or scalar
        Horizontal platform acceleration ẍ_d, forward positive. [m/s²]
    platform_acceleration_y : array_like, shape (...) or scalar
        Vertical platform acceleration ÿ_d, up positive. [m/s²]

    Returns
    -------
    numpy.ndarray, shape (..., N)
        Link angular accelerations. [rad/s²]
    """
    if joint_torques is not None:  # the former name of link_torques
        link_torques = joint_torques
    theta = np.asarray(theta, dtype=float)
    omega = np.asarray(omega, dtype=float)
    ax = np.asarray(platform_acceleration_x, dtype=float)[..., None]
    ay = np.asarray(platform_acceleration_y, dtype=float)[..., None]
    rhs = (
        np.asarray(link_torques, dtype=float)
        - velocity_terms(body, theta, omega)
        + load_formula(body.gravity_coefficients, theta, body.gravity + ay, ax)
    )
    J = mass_matrix(body, theta)
    return np.linalg.solve(J, rhs[..., None])[..., 0]


def state_derivative(
    body: Body,
    state: np.ndarray,
    link_torques: np.ndarray | float = 0.0,
    platform_acceleration_x: np.ndarray | float = 0.0,
    platform_acceleration_y: np.ndarray | float = 0.0,
    **former_names: np.ndarray | float,
) -> np.ndarray:
    """Time derivative of the state ``[Θ, Θ̇]``.

    Parameters
    ----------
    state : array_like, shape (..., 2N)
        ``[θ1 … θN, θ̇1 … θ̇N]`` in [rad] and [rad/s].
    link_torques, platform_acceleration_x, platform_acceleration_y, **former_names
        As in :func:`angular_acceleration`, which takes the former names
        (``joint_torques`` for ``link_torques``). [N·m], [m/s²], [m/s²]

    Returns
    -------
    numpy.ndarray, shape (..., 2N)
        ``[Θ̇, Θ̈]`` in [rad/s] and [rad/s²].
    """
    state = np.asarray(state, dtype=float)
    n = body.n_links
    theta, omega = state[..., :n], state[..., n:]
    acc = angular_acceleration(body, theta, omega, link_torques, platform_acceleration_x,
                               platform_acceleration_y, **former_names)
    return np.concatenate([omega, acc], axis=-1)


def kinetic_energy(body: Body, theta: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Kinetic energy ½ Θ̇ᵀ J(Θ) Θ̇ in the platform frame (platform at rest). [J]"""
    omega = np.asarray(omega, dtype=float)
    J = mass_matrix(body, theta)
    return 0.5 * np.einsum("...i,...ij,...j->...", omega, J, omega)


def potential_energy(body: Body, theta: np.ndarray) -> np.ndarray:
    """Gravitational potential energy g Σ a_i cos θ_i, relative to the ankle. [J]"""
    return body.gravity * np.sum(platform_vector(body, theta), axis=-1)


def velocity_step_response(
    body: Body, platform_velocity_change: float, theta: np.ndarray | None = None
) -> np.ndarray:
    """Jump of link rates caused by a sudden platform velocity change.

    ΔΘ̇ = −J(Θ)⁻¹ H(Θ) Δẋ_d (the paper's "unit impulse" of platform motion).

    Parameters
    ----------
    platform_velocity_change : float
        Δẋ_d, forward positive; a backward platform jerk is negative. [m/s]
    theta : array_like, shape (N,), optional
        Posture at the jump; upright (zeros) by default. [rad]

    Returns
    -------
    numpy.ndarray, shape (N,)
        ΔΘ̇. [rad/s]
    """
    from .._validation import finite_array, finite_float

    dv = finite_float("platform_velocity_change [m/s]", platform_velocity_change)
    theta = (np.zeros(body.n_links) if theta is None
             else finite_array("theta [rad]", theta, (body.n_links,)))
    J = mass_matrix(body, theta)
    return -np.linalg.solve(J, platform_vector(body, theta)) * dv


def knee_constraint_row(n_links: int) -> np.ndarray:
    """The row C of the knee constraint C·Θ̈ = 0 (the knee angle θ2 − θ1 held), (−1, 1, 0, …). [-]"""
    row = np.zeros(n_links)
    row[0], row[1] = -1.0, 1.0
    return row


def constrained_acceleration(body: Body, theta: np.ndarray, acceleration: np.ndarray,
                             row: np.ndarray) -> np.ndarray:
    """Accelerations with the constraint C·Θ̈ = 0: Θ̈ − J⁻¹C (C·Θ̈)/(C·J⁻¹C).

    The constraint force acts along C (a torque pair at the joint), so the
    free accelerations ``acceleration`` [rad/s²] lose their component along J⁻¹C.

    Parameters
    ----------
    theta : array_like, shape (N,)
        Link angles. [rad]
    acceleration : array_like, shape (N,)
        Accelerations without the constraint. [rad/s²]
    row : array_like, shape (N,)
        C, e.g. :func:`knee_constraint_row`. [-]

    Returns
    -------
    numpy.ndarray, shape (N,)
        Constrained accelerations. [rad/s²]
    """
    J = mass_matrix(body, theta)
    JiC = np.linalg.solve(J, row)
    acc = np.asarray(acceleration, dtype=float)
    return acc - JiC * (row @ acc) / (row @ JiC)


def constrained_velocity(body: Body, theta: np.ndarray, omega: np.ndarray,
                         row: np.ndarray) -> np.ndarray:
    """Rates after a plastic impact onto C·Θ̇ = 0 (momentum conserved along the constraint):
    Θ̇ − J⁻¹C (C·Θ̇)/(C·J⁻¹C). [rad/s]"""
    return constrained_acceleration(body, theta, omega, row)
