"""The extrapolated centre of mass and the margin of stability (Hof, Gazendam & Sinke 2005).

Hof AL, Gazendam MGJ, Sinke WE (2005) The condition for dynamic stability. J Biomech
38:1–8. For a linear inverted pendulum of length l (the centre of mass at height l above
the ankle) the centre of mass x [m] moving at v [m/s] obeys ẍ = ω0² (x − p), with p the
centre of pressure and ω0 = √(g/l) its eigenfrequency. The quantity

    ξ = x + v/ω0                 the extrapolated centre of mass (XCoM) [m]

obeys ξ̇ = ω0 (ξ − p): it runs away from the centre of pressure exponentially. With the
centre of pressure confined to the base of support [heel, toe], the pendulum can be
brought to rest over the foot only while ξ stays inside it; Hof's margin of stability

    b = toe − ξ   (forward),   b = ξ − heel   (backward)        [m]

is the distance the centre of pressure still has to spare, and b < 0 means that no
ankle moment the foot can react stops the fall: a step is needed.

Positions here are along x (forward), relative to the ankle, in a frame in which the
foot is at rest. Pure functions over arrays: any leading shape.
"""

from __future__ import annotations

import numpy as np

from .._validation import positive_float
from ..errors import ParameterError

__all__ = ["pendulum_frequency", "xcom", "margin_of_stability", "ankle_moment_cap"]


def pendulum_frequency(com_height, gravity=9.81) -> np.ndarray:
    """Eigenfrequency of the linear inverted pendulum, ω0 = √(g/l). [1/s]

    Parameters
    ----------
    com_height : float or array_like
        l, the height of the centre of mass above the ankle (the pendulum length of Hof et
        al. 2005). [m]
    gravity : float
        g. [m/s²]

    Examples
    --------
    >>> from posturelab.model.stepping import pendulum_frequency
    >>> round(float(pendulum_frequency(0.981)), 4)  # l = 0.981 m: ω0 = √10 [1/s]
    3.1623
    """
    positive_float("gravity [m/s²]", gravity)
    length = np.asarray(com_height, dtype=float)
    if not np.all(np.isfinite(length)) or np.any(length <= 0.0):
        raise ParameterError(f"com_height [m] must be finite and > 0, got {com_height!r}")
    return np.sqrt(gravity / length)


def xcom(position, velocity, omega0) -> np.ndarray:
    """The extrapolated centre of mass ξ = x + v/ω0 (Hof et al. 2005, eq. 6). [m]

    Parameters
    ----------
    position : array_like
        x, the horizontal position of the centre of mass. [m]
    velocity : array_like
        v, its horizontal velocity, in the frame of ``position``. [m/s]
    omega0 : float or array_like
        ω0 = √(g/l) (:func:`pendulum_frequency`). [1/s]

    Returns
    -------
    numpy.ndarray
        ξ, broadcast over the inputs. [m]

    Examples
    --------
    >>> from posturelab.model.stepping import xcom
    >>> float(xcom(0.02, 0.1, 4.0))  # 0.02 m + (0.1 m/s)/(4 1/s) [m]
    0.045
    """
    x = np.asarray(position, dtype=float)
    v = np.asarray(velocity, dtype=float)
    return x + v / np.asarray(omega0, dtype=float)


def margin_of_stability(xcom_position, heel, toe, side: str = "nearer") -> np.ndarray:
    """Hof's margin of stability toward the nearer edge of the base of support. [m]

    b = min(toe − ξ, ξ − heel) (or one side of it): positive while the extrapolated centre of
    mass is over the foot (the distance the centre of pressure can still move to catch it),
    negative by how far it is beyond the toe (forward) or the heel (backward).

    Parameters
    ----------
    xcom_position : array_like
        ξ (:func:`xcom`). [m]
    heel, toe : float
        The base of support along x, from the ankle: heel < toe. [m]
    side : {"nearer", "toe", "heel"}
        ``"toe"``: Hof's b = toe − ξ for forward motion; ``"heel"``: ξ − heel for backward
        motion; ``"nearer"`` (default): the smaller of the two.

    Examples
    --------
    >>> from posturelab.model.stepping import margin_of_stability
    >>> round(float(margin_of_stability(0.15, -0.06, 0.19)), 6)  # 4 cm in front of ξ is the toe [m]
    0.04
    >>> round(float(margin_of_stability(-0.08, -0.06, 0.19)), 6)  # 2 cm behind the heel [m]
    -0.02
    """
    if not float(heel) < float(toe):
        raise ParameterError(f"heel [m] must be behind toe [m], got heel = {heel!r}, "
                             f"toe = {toe!r}")
    xi = np.asarray(xcom_position, dtype=float)
    if side == "toe":
        return float(toe) - xi
    if side == "heel":
        return xi - float(heel)
    if side != "nearer":
        raise ParameterError(f"side must be 'nearer', 'toe' or 'heel', got {side!r}")
    return np.minimum(float(toe) - xi, xi - float(heel))


def ankle_moment_cap(strength: float, weight: float, toe: float) -> float:
    """The largest ankle moment a flat foot can use: min(strength, m g × toe). [N·m]

    Beyond m g × toe the centre of pressure would have to leave the foot in front of the
    toe; a real foot then rolls onto the toes (the heel rises), which a flat massless foot
    cannot do, so the moment is capped there (static weight; the vertical ground reaction's
    changes during the motion are neglected).

    Parameters
    ----------
    strength : float
        Largest plantarflexion moment the muscles can give. [N·m]
    weight : float
        m g, the weight the foot carries. [N]
    toe : float
        Toe from the ankle. [m]

    Examples
    --------
    >>> from posturelab.model.stepping import ankle_moment_cap
    >>> ankle_moment_cap(264.0, 700.0, 0.2)  # the toe binds [N·m]
    140.0
    >>> ankle_moment_cap(100.0, 700.0, 0.2)  # the muscles bind [N·m]
    100.0
    """
    return min(positive_float("strength [N·m]", strength),
               positive_float("weight [N]", weight) * positive_float("toe [m]", toe))
