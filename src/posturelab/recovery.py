"""Largest recoverable perturbation: bisection on a disturbance's size.

With physiological limits (torque saturation, a foot that tips) a run either
recovers or falls; for a family of disturbances ordered by size the boundary
between the two is a number a researcher can compare across subjects or
stiffness sets.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ._validation import positive_float
from .errors import ParameterError
from .results import SimulationResult

__all__ = ["RecoveryBoundary", "largest_recoverable"]


@dataclass(frozen=True)
class RecoveryBoundary:
    """Bracket of the largest recoverable size.

    Attributes
    ----------
    recovered : float
        Largest size tried that did not fall. [unit of the size]
    fell : float
        Smallest size tried that fell. [unit of the size]
    fall_reason : str
        Why the run at ``fell`` fell.
    n_simulations : int
        Simulations run. [-]
    """

    recovered: float
    fell: float
    fall_reason: str
    n_simulations: int

    @property
    def estimate(self) -> float:
        """Midpoint of the bracket. [unit of the size]"""
        return 0.5 * (self.recovered + self.fell)


def largest_recoverable(
    run: Callable[[float], SimulationResult],
    low: float,
    high: float,
    tolerance: float = 1e-3,
    max_simulations: int = 60,
) -> RecoveryBoundary:
    """Bisect for the largest size ``s`` at which ``run(s)`` does not fall.

    Parameters
    ----------
    run : callable
        Maps a disturbance size (e.g. platform speed [m/s] or displacement
        [m]) to a simulation result; assumed to fall for every size beyond
        the boundary.
    low, high : float
        A size that recovers and a size that falls. [unit of the size]
    tolerance : float
        Width of the final bracket. [unit of the size]

    Raises
    ------
    ParameterError
        When ``low`` falls or ``high`` recovers (the bracket is wrong).
    """
    positive_float("tolerance", tolerance)
    if not low < high:
        raise ParameterError(f"low must be < high, got {low:g} and {high:g}")
    r_low, r_high = run(low), run(high)
    if r_low.fell:
        raise ParameterError(f"the run at low = {low:g} already falls ({r_low.fall_reason})")
    if not r_high.fell:
        raise ParameterError(f"the run at high = {high:g} recovers; raise high")
    count, reason = 2, r_high.fall_reason or ""
    while high - low > tolerance and count < max_simulations:
        mid = 0.5 * (low + high)
        r = run(mid)
        count += 1
        if r.fell:
            high, reason = mid, r.fall_reason or ""
        else:
            low = mid
    return RecoveryBoundary(low, high, reason, count)
