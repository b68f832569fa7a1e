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

**On a moving platform** the foot is not at rest. With the platform (and the foot) at p(t)
in the lab and the centre of pressure at p + u, u in [heel, toe], the pendulum obeys
ẍ_lab = ω0² (x_lab − p − u), so ξ_lab = x_lab + ẋ_lab/ω0 obeys ξ̇_lab = ω0 (ξ_lab − p − u)
and stays bounded only if ξ_lab(t) = ω0 ∫_t^∞ e^{−ω0 (s − t)} (p(s) + u(s)) ds. Some u in
[heel, toe] does this exactly when

    ξ(t) + Δ(t)  is in [heel, toe],   Δ(t) = ṗ(t)/ω0 − ∫_t^∞ e^{−ω0 (s − t)} ṗ(s) ds    [m]

with ξ = x + v/ω0 taken relative to the foot (x, v relative to the ankle)
(:func:`platform_path_offset`; posturelab's derivation, the same steps as Hof et al.'s for a
foot at rest). Δ = 0 while the platform keeps a constant velocity, so the criterion is Hof's
in the frame moving with the platform; a platform that is going to stop gives Δ of the
opposite sign to its velocity: its deceleration will push the centre of mass back over the
foot, so a subject who stands on (rather than steps) is judged by the whole move.
"""

from __future__ import annotations

import numpy as np

from .._validation import finite_array, positive_float
from ..errors import ParameterError

__all__ = ["pendulum_frequency", "xcom", "margin_of_stability", "ankle_moment_cap",
           "platform_path_offset"]


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
    length = finite_array("com_height [m]", com_height)
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
    x = finite_array("position [m]", position)
    v = finite_array("velocity [m/s]", velocity)
    return x + v / finite_array("omega0 [1/s]", omega0)


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
    heel = float(finite_array("heel [m]", heel))
    toe = float(finite_array("toe [m]", toe))
    if not heel < toe:
        raise ParameterError(f"heel [m] must be behind toe [m], got heel = {heel!r}, "
                             f"toe = {toe!r}")
    xi = finite_array("xcom_position [m]", xcom_position)
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


def platform_path_offset(time, platform_velocity, omega0: float) -> np.ndarray:
    """Δ(t) = ṗ(t)/ω0 − ∫_t^∞ e^{−ω0 (s − t)} ṗ(s) ds: what the platform's path still to come
    adds to the extrapolated centre of mass (see the module's text). [m]

    ṗ is taken linear between samples (the integral of each interval is exact for that) and,
    after the last sample, constant at its last value (the platform keeps moving as it
    moved): Δ = 0 at the last sample and for any platform at a constant velocity.

    Parameters
    ----------
    time : array_like, shape (T,)
        Increasing sample times. [s]
    platform_velocity : array_like, shape (..., T)
        ṗ at those times, in the lab frame. [m/s]
    omega0 : float
        ω0 = √(g/l) (:func:`pendulum_frequency`). [1/s]

    Returns
    -------
    numpy.ndarray, shape (..., T)
        Δ. [m]

    Examples
    --------
    >>> import numpy as np
    >>> from posturelab.model.stepping import platform_path_offset
    >>> t = np.linspace(0.0, 2.0, 5)
    >>> [round(float(v), 12) for v in platform_path_offset(t, np.full(5, 0.3), 3.0)]
    [0.0, 0.0, 0.0, 0.0, 0.0]
    >>> # moving at 0.3 m/s until it stops at once at t = 1 s: Δ(0) = (0.3/ω0)·e^{−ω0}, more
    >>> # or less (the step is a ramp between samples here) [m]
    >>> round(float(platform_path_offset([0, 1, 1 + 1e-9, 3], [0.3, 0.3, 0, 0], 3.0)[0]), 6)
    0.004979
    """
    t = finite_array("time [s]", time)
    v = finite_array("platform_velocity [m/s]", platform_velocity)
    w = positive_float("omega0 [1/s]", omega0)
    if t.ndim != 1 or v.shape[-1:] != t.shape or t.size < 1:
        raise ParameterError(f"time must be 1-D with one sample per platform_velocity sample, "
                             f"got shapes {t.shape} and {v.shape}")
    h = np.diff(t)
    if not np.all(np.isfinite(t)) or np.any(h <= 0.0) or not np.all(np.isfinite(v)):
        raise ParameterError("time must be finite and increasing, platform_velocity finite")
    decay = np.exp(-w * h)
    # ∫_0^h e^{−ω0 s} ds and ∫_0^h s e^{−ω0 s} ds / h: weights of the interval's ends
    mean = -np.expm1(-w * h) / w
    first = (1.0 - decay * (1.0 + w * h)) / (w * w * h)
    future = np.empty_like(v)
    future[..., -1] = v[..., -1] / w
    for k in range(t.size - 2, -1, -1):
        future[..., k] = (v[..., k] * (mean[k] - first[k]) + v[..., k + 1] * first[k]
                          + decay[k] * future[..., k + 1])
    return v / w - future
