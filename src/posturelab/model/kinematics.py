"""Centre of gravity (paper eqs. 2–3) and the physiological space of Nashner and McCollum.

Positions are relative to the ankle (the base of the chain, on the platform),
x forward and y up.
"""

from __future__ import annotations

import numpy as np

from .body import Body
from .dynamics import gravity_vector, platform_vector

__all__ = [
    "centre_of_gravity",
    "centre_of_gravity_velocity",
    "physiological_state",
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
