"""The torques and gains of a muscle set: pair torques M, joint moments τ = Cᵀ M, the
generalised torques on the link angles U = −Eᵀ M (:func:`link_torques`), and the pair gains by
when they act (:func:`feedback_gains`, rows named in :mod:`.gains`).

Names: a *pair torque* M_p is what pair p exerts; a *joint moment* τ_j is the net muscle
moment at joint j (the sum of the pairs crossing it); a *link torque* U_i is the generalised
torque on link angle θ_i (U_i = τ_{i+1} − τ_i).
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from .gains import DELAYED_STIFFNESS, DELAYED_VISCOSITY, IMMEDIATE_STIFFNESS, IMMEDIATE_VISCOSITY


class MuscleSet(Protocol):
    """What these functions read of a :class:`posturelab.model.muscles.MuscleSet` (stated
    here as a protocol, so that this module does not import the one that re-exports it)."""

    n_links: int
    pairs: tuple
    selection_matrix: np.ndarray
    crossing_matrix: np.ndarray
    stiffnesses: np.ndarray
    viscosities: np.ndarray
    active_stiffnesses: np.ndarray
    active_viscosities: np.ndarray
    one_sided_mask: np.ndarray
    has_active_feedback: bool

__all__ = [
    "pair_torques",
    "link_torques",
    "joint_torques",
    "joint_crossing_matrix",
    "joint_moments",
    "moments_to_link_torques",
    "feedback_gains",
    "muscle_set_gains",
    "feedback_pair_torques",
]


def pair_torques(muscles: MuscleSet, theta: np.ndarray, omega: np.ndarray,
                 active: np.ndarray | None = None) -> np.ndarray:
    """Pair torques M = K_d E Θ + L_d E Θ̇, zero for an inactive one-sided pair.

    Parameters
    ----------
    theta, omega : array_like, shape (..., N)
        Link angles [rad] and rates [rad/s].
    active : array_like, shape (P,), optional
        Which pairs act (1) or are slack (0), as a simulation tracks them by events;
        by default a one-sided pair acts while its stretch is >= 0. [-]

    Returns
    -------
    numpy.ndarray, shape (..., P)
        One torque per pair, positive when resisting positive stretch. [N·m]
    """
    E = muscles.selection_matrix
    stretch = np.asarray(theta, dtype=float) @ E.T
    rate = np.asarray(omega, dtype=float) @ E.T
    M = muscles.stiffnesses * stretch + muscles.viscosities * rate
    if active is not None:
        return M * np.asarray(active, dtype=float)
    if muscles.one_sided_mask.any():
        M = np.where(muscles.one_sided_mask & (stretch < 0.0), 0.0, M)
    return M


def link_torques(muscles: MuscleSet, theta: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Generalised torques U = −Eᵀ M on the link-angle coordinates, shape (..., N): what the
    equation of motion takes (:func:`posturelab.model.dynamics.angular_acceleration`), not the
    joint moments τ (:func:`joint_moments`). [N·m]"""
    return -pair_torques(muscles, theta, omega) @ muscles.selection_matrix


#: Former name of :func:`link_torques` (deprecated: it returns U, not the joint moments τ).
joint_torques = link_torques


def joint_crossing_matrix(muscles: MuscleSet) -> np.ndarray:
    """C (P, N): C[p, j] = 1 when pair p crosses joint j (:attr:`MuscleSet.crossing_matrix`). [-]"""
    return muscles.crossing_matrix


def joint_moments(muscles: MuscleSet, theta: np.ndarray, omega: np.ndarray,
                  active: np.ndarray | None = None) -> np.ndarray:
    """Net muscle moment at each joint, τ = Cᵀ M: the sum of the pairs crossing it.

    Arguments as for :func:`pair_torques`; returns the ankle, knee, hip, … moments,
    shape (..., N). [N·m]
    """
    return pair_torques(muscles, theta, omega, active) @ muscles.crossing_matrix


def moments_to_link_torques(moments: np.ndarray) -> np.ndarray:
    """Generalised torques on the link angles from joint moments: U_i = −τ_i + τ_{i+1}. [N·m]

    Equal to −EᵀM when τ = CᵀM (see :func:`joint_crossing_matrix`).
    """
    moments = np.asarray(moments, dtype=float)
    above = np.concatenate([moments[..., 1:], np.zeros(moments.shape[:-1] + (1,))], axis=-1)
    return above - moments


def feedback_gains(stiffness, viscosity, active_stiffness=None, active_viscosity=None,
                   delay=0.0) -> np.ndarray:
    """The pair gains by when they act: (immediate k, immediate l, delayed k, delayed l).

    The one statement of which feedback is delayed, for every engine and batch:

    - no active gains (``active_stiffness is None``): the pair gains are the whole
      feedback, delayed when ``delay > 0``, immediate otherwise;
    - active gains: the pair gains (intrinsic) act at once, the active gains after
      ``delay``; with no delay both act at once and are summed.

    Parameters
    ----------
    stiffness, viscosity : array_like, shape (..., P)
        Pair (intrinsic) gains. [N·m/rad], [N·m·s/rad]
    active_stiffness, active_viscosity : array_like, shape (..., P), optional
        Active (neural) gains, or None for none. [N·m/rad], [N·m·s/rad]
    delay : float or array_like, shape (...)
        Feedback delay τ per row. [s]

    Returns
    -------
    numpy.ndarray, shape (..., 4, P)
        [N·m/rad], [N·m·s/rad], [N·m/rad], [N·m·s/rad].
    """
    k = np.asarray(stiffness, dtype=float)
    v = np.asarray(viscosity, dtype=float)
    z = np.zeros(np.broadcast_shapes(k.shape, v.shape))
    k, v = k + z, v + z
    delayed = (np.asarray(delay, dtype=float) > 0)[..., None, None]
    if active_stiffness is None and active_viscosity is None:
        return np.where(delayed, np.stack([z, z, k, v], axis=-2), np.stack([k, v, z, z], axis=-2))
    ka = z if active_stiffness is None else np.asarray(active_stiffness, dtype=float) + z
    va = z if active_viscosity is None else np.asarray(active_viscosity, dtype=float) + z
    return np.where(delayed, np.stack([k, v, ka, va], axis=-2),
                    np.stack([k + ka, v + va, z, z], axis=-2))


def muscle_set_gains(muscles: MuscleSet, delay: float) -> np.ndarray:
    """:func:`feedback_gains` of a muscle set's own gains, shape (4, P)."""
    if muscles.has_active_feedback:
        return feedback_gains(muscles.stiffnesses, muscles.viscosities,
                              muscles.active_stiffnesses, muscles.active_viscosities, delay)
    return feedback_gains(muscles.stiffnesses, muscles.viscosities, None, None, delay)


def feedback_pair_torques(muscles: MuscleSet, gains: np.ndarray, state: np.ndarray,
                          delayed_state: np.ndarray, active: np.ndarray | None = None,
                          ) -> np.ndarray:
    """Pair torques from the immediate part on ``state`` and the delayed part on
    ``delayed_state``: M = k E Θ + l E Θ̇ + k_τ E Θ_τ + l_τ E Θ̇_τ (a part whose gains are
    all zero is left out, so that a run without it is computed exactly as before).

    Parameters
    ----------
    gains : numpy.ndarray, shape (..., 4, P)
        From :func:`feedback_gains`. [N·m/rad], [N·m·s/rad]
    state, delayed_state : array_like, shape (..., 2N)
        ``[Θ, Θ̇]`` now and τ earlier. [rad], [rad/s]
    active : array_like, shape (..., P), optional
        Which pairs act (1) or are slack (0). [-]

    Returns
    -------
    numpy.ndarray, shape (..., P)
        [N·m]
    """
    n = muscles.n_links
    E = muscles.selection_matrix
    gains = np.asarray(gains, dtype=float)
    M = None
    for (stiffness, viscosity), x in (((IMMEDIATE_STIFFNESS, IMMEDIATE_VISCOSITY), state),
                                      ((DELAYED_STIFFNESS, DELAYED_VISCOSITY), delayed_state)):
        k, v = gains[..., stiffness, :], gains[..., viscosity, :]
        if not (np.any(k) or np.any(v)):
            continue
        x = np.asarray(x, dtype=float)
        part = k * (x[..., :n] @ E.T) + v * (x[..., n:] @ E.T)
        M = part if M is None else M + part
    if M is None:
        shape = np.broadcast_shapes(np.shape(state)[:-1], gains.shape[:-2])
        M = np.zeros(shape + (len(muscles.pairs),))
    if active is not None:
        M = M * np.asarray(active, dtype=float)
    return M
