"""Joint moment limits: per joint and per side, as given by a user or by a flat foot.

A run's limits are stated once as an array ``bounds`` of shape (2, N) [N·m], both rows
positive (``inf`` where a side has none): row :data:`NEGATIVE` is the largest magnitude of a
negative net moment τ_j, row :data:`POSITIVE` the largest positive one, so τ_j is kept in
[−bounds[0, j], bounds[1, j]]. At the ankle a positive moment is a plantarflexion moment: it
presses the centre of pressure toward the toes (x_p = τ_ankle / F_y,
:func:`.kinematics.centre_of_pressure`); a negative one (dorsiflexion) presses it toward the
heel. A flat foot on the ground therefore carries at most about m g x_toe one way and
m g |x_heel| the other (:func:`foot_moment_limits`).

How a user gives them (``torque_limits`` of a run): one entry per joint, each

* a number L > 0: the same limit both ways, |τ_j| <= L (``inf``: none);
* a pair (lower, upper) with lower < 0 < upper: τ_j in [lower, upper] (``-inf`` / ``inf``
  for no limit on that side);
* ``"foot"`` (the ankle only): the pair of :func:`foot_moment_limits` for the body's weight
  and the run's foot (``FallCriteria.base_of_support``).

The saturation formulas that use the bounds are in :mod:`.switched`
(:func:`~.switched.saturated_moment_formula`, :func:`~.switched.saturated_moments` and the
saturation event's value).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import ParameterError

__all__ = ["NEGATIVE", "POSITIVE", "FOOT", "foot_moment_limits", "torque_limit_array",
           "body_torque_limits", "limit_entries", "limits_as_entries", "start_saturation",
           "clip_moments"]

#: Row of the negative side's magnitude in a bounds array (ankle: dorsiflexion, heel). [-]
NEGATIVE = 0
#: Row of the positive side's limit in a bounds array (ankle: plantarflexion, toes). [-]
POSITIVE = 1
#: The entry that asks for the ankle's limits from the foot.
FOOT = "foot"


def foot_moment_limits(weight: float, heel: float, toe: float) -> tuple[float, float]:
    """The ankle moments a flat, massless foot can carry under a static load.

    The centre of pressure x_p = τ_ankle / F_y stays on the foot, heel <= x_p <= toe, so
    with F_y = m g: m g heel <= τ_ankle <= m g toe.

    Parameters
    ----------
    weight : float
        m g, the body's weight on the foot. [N]
    heel, toe : float
        The foot's ends from the ankle (heel < 0 < toe). [m]

    Returns
    -------
    (lower, upper) : tuple of float
        m g heel (< 0, dorsiflexion) and m g toe (> 0, plantarflexion). [N·m]

    Examples
    --------
    >>> from posturelab.model.limits import foot_moment_limits
    >>> foot_moment_limits(700.0, -0.06, 0.19)  # [N·m]
    (-42.0, 133.0)
    """
    if not (weight > 0 and heel < 0 < toe):
        raise ParameterError(f"foot moment limits need weight [N] > 0 and heel < 0 < toe [m], "
                             f"got {weight!r}, {heel!r}, {toe!r}")
    return float(weight * heel), float(weight * toe)


def _pair(entry: Any, where: str) -> tuple[float, float]:
    """One entry as (negative magnitude, positive limit) [N·m]."""
    if isinstance(entry, str) or isinstance(entry, bool):
        raise ParameterError(f"{where} must be a number > 0, a pair (lower < 0, upper > 0) or "
                             f"'foot' (ankle), got {entry!r:.60}")
    if np.ndim(entry) == 0:
        v = float(entry)
        if math.isnan(v) or v <= 0:
            raise ParameterError(f"{where} must be in (0, inf] (inf: no limit), got {entry!r}")
        return v, v
    try:
        lo, hi = (float(v) for v in entry)
    except (TypeError, ValueError):
        raise ParameterError(f"{where} must be a number > 0 or a pair (lower, upper), got "
                             f"{entry!r:.60}") from None
    if not (lo < 0 < hi):  # (NaN fails too)
        raise ParameterError(f"{where} (lower, upper) must have lower in [-inf, 0) and upper "
                             f"in (0, inf], got ({lo!r}, {hi!r})")
    return -lo, hi


def limit_entries(value: Any) -> tuple:
    """``torque_limits`` as given, normalised: a tuple with a float, a (lower, upper) pair of
    floats or ``"foot"`` per joint (values checked by :func:`torque_limit_array`). [N·m]"""
    if isinstance(value, str) or np.isscalar(value):
        entries = [value]
    elif isinstance(value, (list, tuple)):
        entries = list(value)
    else:
        try:
            entries = list(np.asarray(value))
        except (TypeError, ValueError):
            entries = [value]
    out = []
    for e in entries:
        if isinstance(e, str) and e.strip().lower() == FOOT:
            out.append(FOOT)
        elif np.ndim(e) == 0 and not isinstance(e, str):
            try:
                out.append(float(e))
            except (TypeError, ValueError):
                raise ParameterError(f"torque_limits [N·m] must be numbers, pairs (lower, "
                                     f"upper) or 'foot', got {e!r:.60}") from None
        elif isinstance(e, str):
            raise ParameterError(f"torque_limits [N·m] must be numbers, pairs (lower, upper) "
                                 f"or 'foot', got {e!r:.60}")
        else:
            try:
                out.append(tuple(float(v) for v in e))
            except (TypeError, ValueError):
                raise ParameterError(f"torque_limits [N·m] must be numbers, pairs (lower, "
                                     f"upper) or 'foot', got {e!r:.60}") from None
    return tuple(out)


def torque_limit_array(torque_limits, n_links: int, foot: tuple[float, float] | None = None
                       ) -> np.ndarray | None:
    """Validated joint moment limits as bounds (2, N), or None if no joint is limited.

    Parameters
    ----------
    torque_limits : sequence, or array_like of shape (N,) or (2, N)-free pairs, or None
        One entry per joint (ankle, knee, hip, …): a number > 0 (both ways; ``inf``: none),
        a pair (lower < 0, upper > 0), or ``"foot"`` for the ankle. [N·m]
    n_links : int
        Number of links N. [-]
    foot : (lower, upper), optional
        The ankle's limits from the foot (:func:`foot_moment_limits`), what ``"foot"`` means;
        None if the run has no foot. [N·m]

    Returns
    -------
    numpy.ndarray, shape (2, N), or None
        The magnitudes of the negative (row 0) and positive (row 1) limits [N·m]; None when
        none is given or every one is infinite.
    """
    if torque_limits is None:
        return None
    entries = limit_entries(torque_limits)
    if len(entries) != n_links:
        raise ParameterError(f"torque_limits [N·m] must have {n_links} entries (one per "
                             f"joint), got {len(entries)}: {entries!r:.80}")
    bounds = np.empty((2, n_links))
    for j, e in enumerate(entries):
        where = f"torque_limits[{j}] [N·m]"
        if e == FOOT:
            if j != 0:
                raise ParameterError(f"{where}: 'foot' is for the ankle (joint 0) only")
            if foot is None:
                raise ParameterError(f"{where}: 'foot' needs a foot (fall criteria with a "
                                     "base_of_support, heel and toe)")
            e = foot
        bounds[:, j] = _pair(e, where)
    if np.all(np.isinf(bounds)):
        return None
    bounds.setflags(write=False)
    return bounds


def body_torque_limits(torque_limits, body, base_of_support=None) -> np.ndarray | None:
    """:func:`torque_limit_array` for a run of ``body`` (a :class:`~.body.Body`) on the foot
    ``base_of_support`` (a :class:`~.options.BaseOfSupport` or None): "foot" is
    :func:`foot_moment_limits` of the body's weight m g [N] on that foot. Bounds (2, N) or
    None. [N·m]"""
    bos = base_of_support
    foot = None if bos is None else foot_moment_limits(body.total_mass * body.gravity,
                                                       bos.heel, bos.toe)
    return torque_limit_array(torque_limits, body.n_links, foot)


def limits_as_entries(bounds: np.ndarray) -> tuple:
    """Bounds (2, N) [N·m] back as ``torque_limits`` entries: a float where both sides are
    equal, else the pair (lower, upper)."""
    b = np.asarray(bounds, dtype=float)
    return tuple(float(b[1, j]) if b[0, j] == b[1, j] else (-float(b[0, j]), float(b[1, j]))
                 for j in range(b.shape[1]))


def clip_moments(moments: np.ndarray, bounds: np.ndarray | None) -> np.ndarray:
    """Moments (..., N) clipped into [−bounds[0], bounds[1]] (bounds (2, N)). [N·m]"""
    if bounds is None:
        return moments
    return np.clip(moments, -bounds[NEGATIVE], bounds[POSITIVE])


def start_saturation(moments: np.ndarray, bounds: np.ndarray | None) -> np.ndarray:
    """+1 for each joint whose moment (..., N) starts above its positive limit, −1 below its
    negative one, else 0 (bounds (..., 2, N) [N·m])."""
    moments = np.asarray(moments, dtype=float)
    sat = np.zeros(moments.shape)
    if bounds is not None:
        b = np.asarray(bounds, dtype=float)
        neg = np.broadcast_to(b[..., NEGATIVE, :], moments.shape)
        pos = np.broadcast_to(b[..., POSITIVE, :], moments.shape)
        sat[np.isfinite(pos) & (moments > pos)] = 1.0
        sat[np.isfinite(neg) & (moments < -neg)] = -1.0
    return sat
