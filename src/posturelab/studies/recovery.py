"""Largest recoverable perturbation: bisection on a disturbance's size.

With physiological limits (torque saturation, a foot that tips) a run either
recovers or falls; for a family of disturbances ordered by size the boundary
between the two is a number a researcher can compare across subjects or
stiffness sets.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .._validation import positive_float
from ..errors import ParameterError
from ..simulation.options import RunOptions
from ..simulation.results import SimulationResult

if TYPE_CHECKING:
    from ..model.muscles import MuscleSet

__all__ = ["RecoveryBoundary", "largest_recoverable", "BatchRecoveryBoundaries",
           "largest_recoverable_batch"]


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


@dataclass(frozen=True)
class BatchRecoveryBoundaries:
    """Brackets of the largest recoverable disturbance scale of many gain sets (row r is
    gain set r).

    Attributes
    ----------
    recovered : numpy.ndarray, shape (M,)
        Largest scale tried that did not fall (``high`` where even that recovered);
        NaN where ``low`` already fell. [-]
    fell : numpy.ndarray, shape (M,)
        Smallest scale tried that fell (``low`` where even that fell); NaN where
        ``high`` still recovered. [-]
    n_simulations : int
        Simulations run in all. [-]
    """

    recovered: np.ndarray
    fell: np.ndarray
    n_simulations: int

    @property
    def estimate(self) -> np.ndarray:
        """Midpoint of each bracket (NaN where there is none). [-]"""
        return 0.5 * (self.recovered + self.fell)

    @property
    def bracketed(self) -> np.ndarray:
        """True where ``low`` recovered and ``high`` fell. [-]"""
        return np.isfinite(self.recovered) & np.isfinite(self.fell)


def largest_recoverable_batch(
    body,
    stiffness: np.ndarray,
    viscosity: np.ndarray,
    disturbance,
    duration: float,
    low: float,
    high: float,
    *,
    tolerance: float = 1e-3,
    max_rounds: int = 60,
    options: RunOptions | None = None,
    muscles: MuscleSet | None = None,
    initial_state: np.ndarray | None = None,
    feedback_delay: float | np.ndarray | None = None,
    proprioceptive_weight: float | np.ndarray | None = None,
    torque_limits: np.ndarray | tuple[float, ...] | None = None,
    parallel: bool = True,
    **run_options: Any,
) -> BatchRecoveryBoundaries:
    """Bisect, for every gain set at once, for the largest factor on ``disturbance`` that
    does not fall (the compiled simulator, :func:`posturelab.simulation.compiled.simulate_batch`).

    Each round runs every still-open gain set at the midpoint of its own bracket
    (``disturbance_scale``), so M gain sets cost about log2((high − low)/tolerance)
    batches. Row r's bracket is the one :func:`largest_recoverable` finds with
    ``run(s) = simulate(..., disturbance.scaled(s), engine="compiled")`` for gain set r.

    Parameters
    ----------
    body : Body
        The chain.
    stiffness, viscosity : array_like, shape (M, P)
        Pair gains per gain set. [N·m/rad], [N·m·s/rad]
    disturbance : Disturbance
        The motion at factor 1 (e.g. a 1 m/s velocity step, so that the factor
        reads as a speed in m/s).
    duration : float
        Simulated time of each run. [s]
    low, high : float
        Factors assumed to recover and to fall (checked per gain set). [-]
    tolerance : float
        Width of the final brackets. [-]
    max_rounds : int
        Most bisection rounds. [-]
    initial_state, muscles, feedback_delay, proprioceptive_weight, torque_limits, parallel
        As for :func:`posturelab.simulation.compiled.simulate_batch` (the state before the
        motion [rad, rad/s]; the pair layout; per gain set or shared [s], [-], [N·m]).
    options : RunOptions, optional
        The options every run shares (:class:`~posturelab.simulation.options.RunOptions`:
        knee, fall criteria, tolerances, …).
    **run_options
        Fields of :class:`~posturelab.simulation.options.RunOptions` by name (``fall=...``,
        ``rtol=...``), replacing those of ``options``.

    Returns
    -------
    BatchRecoveryBoundaries
    """
    from ..simulation.compiled import simulate_batch

    positive_float("tolerance", tolerance)
    if not low < high:
        raise ParameterError(f"low must be < high, got {low:g} and {high:g}")
    if "disturbance_scale" in run_options:
        raise ParameterError("largest_recoverable_batch sets disturbance_scale itself")
    shared = (RunOptions.from_keywords("largest_recoverable_batch", **run_options)
              if options is None else options.replace(**run_options))
    stiffness = np.asarray(stiffness, dtype=float)
    viscosity = np.asarray(viscosity, dtype=float)
    m = stiffness.shape[0] if stiffness.ndim == 2 else 1
    stiffness = stiffness.reshape(m, -1)
    viscosity = viscosity.reshape(m, -1)

    def falls(rows: np.ndarray, scale: np.ndarray) -> np.ndarray:
        out = simulate_batch(body, stiffness[rows], viscosity[rows], disturbance, duration,
                             initial_state, muscles=muscles, options=shared,
                             feedback_delay=_open_rows(feedback_delay, rows, PER_SET),
                             proprioceptive_weight=_open_rows(proprioceptive_weight, rows,
                                                              PER_SET),
                             torque_limits=_open_rows(torque_limits, rows, PER_SET + 1),
                             disturbance_scale=scale, parallel=parallel)
        return out.fell

    every = np.arange(m)
    fell_low = falls(every, np.full(m, float(low)))
    fell_high = falls(every, np.full(m, float(high)))
    count = 2 * m
    open_ = ~fell_low & fell_high
    # outside a bracket: the largest factor tried that recovered, the smallest that fell
    lo = np.where(fell_low, np.nan, np.where(fell_high, float(low), float(high)))
    hi = np.where(fell_low, float(low), np.where(fell_high, float(high), np.nan))
    for _ in range(max_rounds):
        rows = np.nonzero(open_ & (hi - lo > tolerance))[0]
        if rows.size == 0:
            break
        mid = 0.5 * (lo[rows] + hi[rows])
        f = falls(rows, mid)
        count += rows.size
        hi[rows[f]] = mid[f]
        lo[rows[~f]] = mid[~f]
    return BatchRecoveryBoundaries(lo, hi, count)


#: The dimensions of a number given per gain set (one value per set); a per-joint one has one
#: more.
PER_SET = 1


def _open_rows(values, rows: np.ndarray, per_set_ndim: int):
    """``values`` for the gain sets ``rows`` when it is given per gain set (``per_set_ndim``
    dimensions), else as it is (shared by every run)."""
    if values is None or np.ndim(values) != per_set_ndim:
        return values
    return np.asarray(values, dtype=float)[rows]
