"""Centre of gravity (paper eqs. 2–3), ground reaction, centre of pressure, and the
physiological space of Nashner and McCollum.

Positions are relative to the ankle (the base of the chain, on the platform),
x forward and y up. The foot is massless and flat on the platform, so the ground
reaction is the rate of change of the chain's momentum plus its weight, and the
centre of pressure is where that force must act to balance the ankle moment.
"""

from __future__ import annotations

import numpy as np

from .body import Body
from .dynamics import gravity_vector, platform_vector

__all__ = [
    "centre_of_gravity",
    "centre_of_gravity_velocity",
    "physiological_state",
    "centre_of_gravity_acceleration",
    "cog_acceleration_terms_formula",
    "ground_reaction",
    "centre_of_pressure",
]


def centre_of_gravity(body: Body, theta: np.ndarray) -> np.ndarray:
    """Centre of gravity relative to the ankle (eq. 2): x_c = αG/Σm, y_c = αH/Σm.

    Parameters
    ----------
    body : Body
    theta : array_like, shape (..., N)
        Link angles. [rad]

    Returns
    -------
    numpy.ndarray, shape (..., 2)
        ``[x_c, y_c]``, forward and up from the ankle. [m]
    """
    m = body.total_mass
    x = np.sum(gravity_vector(body, theta), axis=-1) / m
    y = np.sum(platform_vector(body, theta), axis=-1) / m
    return np.stack([x, y], axis=-1)


def centre_of_gravity_velocity(body: Body, theta: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Velocity of the centre of gravity relative to the ankle (eq. 3).

    ẋ_c = Θ̇ᵀH/Σm, ẏ_c = −Θ̇ᵀG/Σm.

    Parameters
    ----------
    theta, omega : array_like, shape (..., N)
        Link angles [rad] and rates [rad/s].

    Returns
    -------
    numpy.ndarray, shape (..., 2)
        ``[ẋ_c, ẏ_c]``. [m/s]
    """
    omega = np.asarray(omega, dtype=float)
    m = body.total_mass
    xd = np.sum(omega * platform_vector(body, theta), axis=-1) / m
    yd = -np.sum(omega * gravity_vector(body, theta), axis=-1) / m
    return np.stack([xd, yd], axis=-1)


def physiological_state(body: Body, state: np.ndarray) -> np.ndarray:
    """Map ``[Θ, Θ̇]`` to the physiological space [θ1, θN, r_c, θ̇1, θ̇N, ṙ_c].

    r_c is the distance of the centre of gravity from the ankle and
    ṙ_c = (x_c ẋ_c + y_c ẏ_c)/r_c its rate (Section II.B).

    Parameters
    ----------
    state : array_like, shape (..., 2N)
        ``[θ1 … θN, θ̇1 … θ̇N]`` in [rad], [rad/s].

    Returns
    -------
    numpy.ndarray, shape (..., 6)
        [θ1 [rad], θN [rad], r_c [m], θ̇1 [rad/s], θ̇N [rad/s], ṙ_c [m/s]].
    """
    state = np.asarray(state, dtype=float)
    n = body.n_links
    theta, omega = state[..., :n], state[..., n:]
    pos = centre_of_gravity(body, theta)
    vel = centre_of_gravity_velocity(body, theta, omega)
    r = np.linalg.norm(pos, axis=-1)
    rdot = np.sum(pos * vel, axis=-1) / r
    return np.stack(
        [theta[..., 0], theta[..., -1], r, omega[..., 0], omega[..., -1], rdot], axis=-1
    )


def cog_acceleration_terms_formula(gravity_coefficient, angle, rate, acceleration, xp=np):
    """Link i's part of Σm times the centre of gravity's acceleration (ẍ_c, ÿ_c):
    a_i (θ̈_i cos θ_i − θ̇_i² sin θ_i) and −a_i (θ̈_i sin θ_i + θ̇_i² cos θ_i); over a math
    namespace ``xp`` (numpy, or sympy when the compiled engine is generated). [N]"""
    s, c = xp.sin(angle), xp.cos(angle)
    return (gravity_coefficient * (acceleration * c - rate * rate * s),
            -gravity_coefficient * (acceleration * s + rate * rate * c))


def centre_of_gravity_acceleration(body: Body, theta: np.ndarray, omega: np.ndarray,
                                   alpha: np.ndarray) -> np.ndarray:
    """Acceleration of the centre of gravity relative to the ankle.

    ẍ_c = (Σ a_i θ̈_i cos θ_i − Σ a_i θ̇_i² sin θ_i)/Σm,
    ÿ_c = (−Σ a_i θ̈_i sin θ_i − Σ a_i θ̇_i² cos θ_i)/Σm.

    Parameters
    ----------
    theta, omega, alpha : array_like, shape (..., N)
        Link angles [rad], rates [rad/s] and accelerations [rad/s²].

    Returns
    -------
    numpy.ndarray, shape (..., 2)
        ``[ẍ_c, ÿ_c]``. [m/s²]
    """
    theta = np.asarray(theta, dtype=float)
    omega = np.asarray(omega, dtype=float)
    alpha = np.asarray(alpha, dtype=float)
    tx, ty = cog_acceleration_terms_formula(body.gravity_coefficients, theta, omega, alpha)
    return np.stack([np.sum(tx, axis=-1), np.sum(ty, axis=-1)], axis=-1) / body.total_mass


def ground_reaction(body: Body, theta: np.ndarray, omega: np.ndarray, alpha: np.ndarray,
                    platform_acceleration: np.ndarray) -> np.ndarray:
    """Force of the platform on the (massless) foot: F = Σm (a_platform + a_cog + g ŷ).

    Parameters
    ----------
    theta, omega, alpha : array_like, shape (..., N)
        Link angles [rad], rates [rad/s] and accelerations [rad/s²].
    platform_acceleration : array_like, shape (..., 2)
        (ẍ_d, ÿ_d). [m/s²]

    Returns
    -------
    numpy.ndarray, shape (..., 2)
        ``[F_x, F_y]``. [N]
    """
    acc = np.asarray(platform_acceleration, dtype=float)
    cog = centre_of_gravity_acceleration(body, theta, omega, alpha)
    gravity = np.array([0.0, body.gravity])
    return body.total_mass * (acc + cog + gravity)


def centre_of_pressure(ankle_moment: np.ndarray, vertical_force: np.ndarray) -> np.ndarray:
    """Centre of pressure under the massless foot, x_p = τ_ankle / F_y, from the ankle. [m]

    Parameters
    ----------
    ankle_moment : array_like, shape (...)
        Net muscle moment at the ankle τ_ankle. [N·m]
    vertical_force : array_like, shape (...)
        Vertical ground reaction F_y. [N]

    Returns
    -------
    numpy.ndarray, shape (...)
        x_p [m]; NaN where F_y <= 0 (the foot is not pressed on the platform).
    """
    tau = np.asarray(ankle_moment, dtype=float)
    fy = np.asarray(vertical_force, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(fy > 0.0, tau / np.where(fy > 0.0, fy, 1.0), np.nan)


# ---- strategies: the ankle (in-phase) and hip (anti-phase) modes -----------------------
# (after Creath et al. 2005; definitions in posturelab.studies.strategy, which re-exports these)

__all__ += ["strategy_modes", "hip_fraction"]


def strategy_modes(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The ankle (in-phase) and hip (anti-phase) modes of a trajectory.

    With u(t) and w(t) the leg angle θ_1 and the trunk angle θ_N less their values at the
    start, a = (u + w)/2 (leg and trunk lean together) and b = (u − w)/2 (they counter-rotate
    about the hip); see :mod:`posturelab.studies.strategy`.

    Parameters
    ----------
    theta : array_like, shape (T, N), N >= 2
        Link angles. [rad]

    Returns
    -------
    (numpy.ndarray, numpy.ndarray), each shape (T,)
        a(t), b(t). [rad]
    """
    from ..errors import ParameterError

    theta = np.asarray(theta, dtype=float)
    if theta.ndim != 2 or theta.shape[1] < 2:
        raise ParameterError(f"theta must have shape (T, N) with N >= 2 links, got "
                             f"{theta.shape}")
    u = theta[:, 0] - theta[0, 0]
    w = theta[:, -1] - theta[0, -1]
    return 0.5 * (u + w), 0.5 * (u - w)


def hip_fraction(theta: np.ndarray) -> float:
    """Σ b² / (Σ a² + Σ b²) of :func:`strategy_modes` [-]; NaN if nothing moves (0/0: no
    sway, no strategy) and for N = 1."""
    theta = np.asarray(theta, dtype=float)
    if theta.ndim == 2 and theta.shape[1] == 1:
        return float("nan")
    a, b = strategy_modes(theta)
    total = float(a @ a + b @ b)
    return float("nan") if total == 0.0 else float(b @ b) / total
