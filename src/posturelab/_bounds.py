"""Estimates on a search bound, and intervals within a parameter's range (both fits).

A least-squares fit inside a search box can stop on the box's edge: the estimate there is
the bound, not a value the data determine, and estimate ± q·se there reaches outside what
the parameter may be (a negative delay, a gain beyond the box). Both fits
(:func:`posturelab.frequency.fit.fit_frf`,
:func:`posturelab.studies.identification.fit_stiffness`) flag an estimate within
:data:`AT_BOUND_TOLERANCE` of the box's width from either end as "at its search bound" (not
determined), and clip every interval to the parameter's accepted range (the parameter
table, :mod:`posturelab.parameters`) and to the search box.
"""

from __future__ import annotations

import numpy as np

from .parameters import QUANTITIES
from .parameters import unit as parameter_unit

__all__ = ["AT_BOUND_TOLERANCE", "at_bound", "clip_intervals", "bound_note"]

#: An estimate this close to an end of its search box, relative to the box's width, is on
#: that bound (posturelab's choice: well above the optimisers' tolerances of 1e-8 to 1e-12,
#: well below any resolution a fit could claim). [-]
AT_BOUND_TOLERANCE = 1e-6


def at_bound(estimates, low, high) -> tuple[str | None, ...]:
    """Which search bound each estimate sits on.

    Parameters
    ----------
    estimates, low, high : array_like, shape (K,)
        The estimates and each one's search box. [its unit]

    Returns
    -------
    tuple of {"low", "high", None}
        Per parameter: "low"/"high" when within ``AT_BOUND_TOLERANCE`` of the box's width
        from that end, else None.
    """
    p, lo, hi = (np.asarray(v, dtype=float) for v in (estimates, low, high))
    tol = AT_BOUND_TOLERANCE * (hi - lo)
    return tuple("low" if e - a <= t else "high" if b - e <= t else None
                 for e, a, b, t in zip(p, lo, hi, tol, strict=True))


def _base(name: str) -> str:
    """The quantity of a fitted name (``active_stiffness:ankle#2`` -> ``active_stiffness``)."""
    return name.partition("#")[0].partition(":")[0]


def clip_intervals(names, intervals, low, high) -> tuple[np.ndarray, np.ndarray]:
    """Each interval clipped to its parameter's accepted range and its search box.

    Parameters
    ----------
    names : sequence of str
        The parameter table's names (a ``#k`` suffix is ignored).
    intervals : array_like, shape (K, 2)
        [its unit]
    low, high : array_like, shape (K,)
        The search boxes. [its unit]

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        The clipped intervals (K, 2) (a NaN end stays NaN), and per parameter whether either
        end was clipped.
    """
    ci = np.array(intervals, dtype=float, copy=True)
    floor = np.array([max(QUANTITIES[_base(n)].low, a) for n, a in
                      zip(names, np.asarray(low, float), strict=True)])
    ceiling = np.array([min(QUANTITIES[_base(n)].high, b) for n, b in
                        zip(names, np.asarray(high, float), strict=True)])
    with np.errstate(invalid="ignore"):
        clipped = (ci[:, 0] < floor) | (ci[:, 1] > ceiling)
        ci[:, 0] = np.where(ci[:, 0] < floor, floor, ci[:, 0])
        ci[:, 1] = np.where(ci[:, 1] > ceiling, ceiling, ci[:, 1])
    return ci, clipped


def bound_note(name: str, side: str, low: float, high: float) -> str:
    """``at its search bound HI = 1e+05 N·m/rad`` (the text both fits print)."""
    unit = parameter_unit(_base(name))
    value = low if side == "low" else high
    return (f"at its search bound {'LO' if side == 'low' else 'HI'} = {value:.4g}"
            f"{'' if unit == '-' else ' ' + unit}")
