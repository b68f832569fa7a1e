"""Batched linear stability about upright for millions of parameter sets.

For each parameter set the chain linearised about upright (see
:mod:`posturelab.linear`) has the state matrix::

    A = [[0, I], [J0⁻¹ (g diag(a) − K), −J0⁻¹ L]],   K = Eᵀ diag(k) E,  L = Eᵀ diag(v) E

Its poles are the roots of the characteristic polynomial of degree 2N::

    p(s) = det(s² J0 + s L + (K − g diag(a))) = det(J0) · det(s I − A)

whose coefficients are polynomials in the pair gains. This module computes
them per set by an exact expansion of the polynomial determinant (Laplace
expansion along rows, memoised over column subsets: 2ᴺ minors, any N), then

* :func:`batch_stable` — the stable flags only, by the Routh–Hurwitz test
  (Routh array, whose first column holds the ratios of consecutive Hurwitz
  determinants) on the shifted polynomial p(s − δ) (see *Stability margin*);
* :func:`batch_analyse` — all 2N poles by the Aberth–Ehrlich simultaneous
  iteration (Newton-polygon starting points, stopping at the rounding level of
  the polynomial), conjugate pairs made exact and real roots made exactly
  real, sorted like :func:`posturelab.linear.sorted_poles`. A set whose
  iteration does not converge (not seen in practice) is recomputed with
  ``numpy.linalg.eigvals`` of its state matrix.

The matrices J0, L and K − g diag(a) of every set are those of the one linear
system (:class:`posturelab.linear.system.LinearSystem`, built by
:func:`posturelab.linear.system.linear_system`); everything else per set runs in one
compiled function (:mod:`._batch_kernels`, ``nogil=True``), called on blocks of sets
from a small thread pool (one thread per core, ``NUMBA_NUM_THREADS``); it is safe to
call from several Python threads at once. A stability map starts each set's
root iteration from the roots of its neighbour along x (a row starts afresh), which
takes about a third of the time of starting afresh (same roots to rounding). The first
call in a fresh environment compiles (a few seconds); later processes load the cached
machine code (:mod:`posturelab._jit`).

Stability margin
----------------
A set is *stable* when every pole has real part below −δ, with::

    δ = STABILITY_MARGIN · max(1 [1/s], ρ),   ρ = max(|c_{2N−1}| / c_{2N}, √(|c_{2N−2}| / c_{2N}))

with c_j the coefficients of p (ascending powers). ρ is a root scale of the
polynomial: c_{2N−1}/c_{2N} = −Σ λ and c_{2N−2}/c_{2N} = Σ_{i<j} λ_i λ_j, so for a
stable polynomial max |λ| <= ρ <= 2N · max |λ|. With
``STABILITY_MARGIN = 1e-9`` the flags equal those of
:func:`posturelab.linear.analyse` (all real parts < 0) except for sets whose
largest real part lies in [−δ, 0): there both numbers are at the rounding
level of the computation (e.g. zero viscosity, where the poles lie on the
imaginary axis), and we report *not stable* — such a set is at best
marginally stable, not asymptotically stable. The Routh test of
:func:`batch_stable` and the pole test of :func:`batch_analyse` use the same δ,
so the two agree except within rounding of the −δ boundary.

Accuracy: the poles agree with ``numpy.linalg.eigvals`` of the state matrix
to better than 1e-8 · max(1, |λ|) [1/s] (tested; typically 1e-13).

Parameter grids
---------------
:func:`parameter_grid` and :func:`stability_map` sweep two named parameters
(:data:`GRID_PARAMETERS`: the paper's five pair stiffnesses and the viscosity
ratio) over ranges, every other parameter taken from a Table I case; the grid is
defined in :mod:`._batch_grid` (which imports no numba) and public here.
"""


from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TypedDict, Unpack

import numpy as np

from .._validation import finite_array
from ..errors import ParameterError
from ..model.body import Body, paper_body
from ..model.muscles import DEFAULT_VISCOSITY_RATIO, MuscleSet, paper_muscles
from . import _batch_kernels as _kernels
from ._batch_grid import (
    GRID_PARAMETER_UNITS,
    GRID_PARAMETERS,
    ParameterGrid,
    ParameterRange,
    StabilityMap,
    parameter_grid,
)
from ._batch_kernels import MAX_ITERATIONS as _MAX_ITERATIONS
from ._batch_kernels import STABILITY_MARGIN
from ._batch_kernels import subset_tables as _subset_tables  # noqa: F401 (tests use it)
from .analysis import sorted_poles
from .system import BodyArrays, LinearSystem, linear_system

__all__ = [
    "STABILITY_MARGIN",
    "GRID_PARAMETERS",
    "GRID_PARAMETER_UNITS",
    "BatchLinearAnalysis",
    "ParameterRange",
    "ParameterGrid",
    "StabilityMap",
    "characteristic_polynomials",
    "SetKeywords",
    "batch_stable",
    "batch_analyse",
    "parameter_grid",
    "stability_map",
]

#: Parameter sets per system built and evaluated at once (bounds the memory of a call). [-]
_BLOCK = 65_536


# ---------------------------------------------------------------------------
# Inputs: the one linear system of each block of sets
# ---------------------------------------------------------------------------


def _gains(pair_stiffness, viscosity_ratio, pair_viscosity, body, muscles):
    """Checked inputs: (body, muscles, stiffness (M, P), viscosity (M or 1, P) or None,
    ratio (M or 1,) or None)."""
    muscles = paper_muscles("1") if muscles is None else muscles
    if not isinstance(muscles, MuscleSet):
        raise ParameterError(f"muscles must be a MuscleSet, got {type(muscles).__name__}")
    body = paper_body() if body is None else body
    if isinstance(body, Body):
        body = BodyArrays.from_body(body)
    if not isinstance(body, BodyArrays):
        raise ParameterError(f"body must be a Body or BodyArrays, got {type(body).__name__}")
    if body.n_links != muscles.n_links:
        raise ParameterError(
            f"muscle set is for {muscles.n_links} links but the body has {body.n_links}"
        )
    n_pairs = len(muscles.pairs)
    stiffness = _gain_array("pair_stiffness [N·m/rad]", pair_stiffness, n_pairs)
    n_sets = stiffness.shape[0]
    ratio = viscosity = None
    if pair_viscosity is not None:
        if viscosity_ratio is not None:
            raise ParameterError("give viscosity_ratio or pair_viscosity, not both")
        viscosity = _gain_array("pair_viscosity [N·m·s/rad]", pair_viscosity, n_pairs)
        if viscosity.shape[0] not in (1, n_sets):
            raise ParameterError(
                f"pair_viscosity [N·m·s/rad] must have {n_sets} rows (one per set), "
                f"got {viscosity.shape[0]}"
            )
    else:
        ratio = finite_array("viscosity_ratio [s]",
                             DEFAULT_VISCOSITY_RATIO if viscosity_ratio is None
                             else viscosity_ratio)
        ratio = np.ascontiguousarray(np.atleast_1d(ratio), dtype=float)
        if ratio.ndim != 1 or ratio.shape[0] not in (1, n_sets):
            raise ParameterError(
                f"viscosity_ratio [s] must be a scalar or have shape ({n_sets},), "
                f"got shape {np.shape(viscosity_ratio)}"
            )
        if np.any(ratio < 0):
            raise ParameterError(f"viscosity_ratio [s] must be >= 0, got {ratio.min():g}")
    body_sets = body.set_count()
    if body_sets is not None and body_sets != n_sets:
        raise ParameterError(
            f"body arrays describe {body_sets} sets but pair_stiffness has {n_sets} rows"
        )
    return body, muscles, stiffness, viscosity, ratio


def _rows(arr: np.ndarray | None, lo: int, hi: int):
    return arr if arr is None or arr.shape[0] == 1 else arr[lo:hi]


def _body_rows(body: BodyArrays, lo: int, hi: int) -> BodyArrays:
    if body.set_count() is None:
        return body
    return BodyArrays(*(a[lo:hi] if a.ndim == 2 else a for a in (
        body.masses, body.lengths, body.com_distances, body.inertias)),
        body.gravity[lo:hi] if body.gravity.ndim == 1 else body.gravity)


def _systems(pair_stiffness, viscosity_ratio, pair_viscosity=None, body=None, muscles=None):
    """The checked inputs as linear systems of blocks of at most _BLOCK sets:
    (M, [(lo, hi, LinearSystem), ...])."""
    body, muscles, k, v, ratio = _gains(pair_stiffness, viscosity_ratio, pair_viscosity,
                                        body, muscles)
    m = k.shape[0]
    blocks = []
    for lo in range(0, max(m, 1), _BLOCK):
        hi = min(m, lo + _BLOCK)
        system = linear_system(_body_rows(body, lo, hi), muscles, stiffness=k[lo:hi],
                               viscosity=_rows(v, lo, hi), viscosity_ratio=_rows(ratio, lo, hi),
                               inputs=False)
        blocks.append((lo, hi, system))
    return m, blocks


def _gain_array(name: str, value, n_pairs: int) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be numeric") from None
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != n_pairs:
        raise ParameterError(
            f"{name} must have shape (M, {n_pairs}) (one column per muscle pair), "
            f"got shape {np.shape(value)}"
        )
    if not np.isfinite(arr).all():
        raise ParameterError(f"{name} must contain only finite numbers")
    if arr.size and arr.min() < 0:
        raise ParameterError(f"{name} must be >= 0, got {arr.min():g}")
    return np.ascontiguousarray(arr)


def _run(system: LinearSystem, mode: int, **options) -> dict[str, np.ndarray]:
    """The compiled kernel in ``mode`` on the system's matrices without delay."""
    return _kernels.run(mode, system.without_delay(), system.n_sets, **options)


def _blocks(m: int, blocks, mode: int, **options) -> dict[str, np.ndarray]:
    """:func:`_run` on every block, the outputs concatenated."""
    if len(blocks) == 1:
        out = _run(blocks[0][2], mode, **options)
        if m == 0:
            out = {key: val[:0] if val.shape[0] == 1 and key in _FILLED[mode] else val
                   for key, val in out.items()}
        return out
    parts = [_run(system, mode, **options) for _, _, system in blocks]
    return {key: (np.concatenate([p[key] for p in parts]) if key in _FILLED[mode]
                  else parts[0][key]) for key in parts[0]}


_FILLED = {
    _kernels.MODE_COEFFICIENTS: {"coefficients"},
    _kernels.MODE_FLAGS: {"stable"},
    _kernels.MODE_POLES: {"poles", "max_real", "stable", "converged"},
}


# ---------------------------------------------------------------------------
# Public batch API
# ---------------------------------------------------------------------------


class SetKeywords(TypedDict, total=False):
    """The keywords that, beside the pair stiffness and the viscosity ratio, give the M
    parameter sets of :func:`characteristic_polynomials`, :func:`batch_stable` and
    :func:`batch_analyse`.

    Attributes
    ----------
    pair_viscosity : array_like, shape (M, P)
        Per-pair viscosity instead of a ratio. [N·m·s/rad]
    body : Body or BodyArrays
        The chain (one body, or per-set parameters); the paper's body by default.
    muscles : MuscleSet
        Gives the pair spans (the matrix E) only; its own gains are ignored.
        The paper's five pairs by default.
    """

    pair_viscosity: np.ndarray | None
    body: Body | BodyArrays | None
    muscles: MuscleSet | None



@dataclass(frozen=True)
class BatchLinearAnalysis:
    """Linear stability of M parameter sets about upright.

    Attributes
    ----------
    stable : numpy.ndarray of bool, shape (M,)
        True when every pole has real part < −δ, δ = 1e-9 · max(1, ρ) [1/s] with
        max |λ| <= ρ <= 2N · max |λ| (module notes, *Stability margin*).
    max_real_part : numpy.ndarray, shape (M,)
        Largest real part among each set's poles: the growth rate of its
        slowest-decaying (or fastest-growing) mode. [1/s]
    poles : numpy.ndarray of complex, shape (M, 2N), or None
        All poles of each set, real part ascending and a conjugate pair with
        +imag first (as :func:`posturelab.linear.sorted_poles`); None unless
        asked for. [1/s]
    """

    stable: np.ndarray
    max_real_part: np.ndarray
    poles: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.stable.shape[0])


def characteristic_polynomials(pair_stiffness: np.ndarray,
                               viscosity_ratio: float | np.ndarray | None = None,
                               **sets: Unpack[SetKeywords]) -> np.ndarray:
    """Coefficients of p(s) = det(s² J0 + s L + K − g diag(a)) for each set.

    Parameters
    ----------
    pair_stiffness : array_like, shape (M, P) or (P,)
        Stiffness of each muscle pair, columns in the order of ``muscles``. [N·m/rad]
    viscosity_ratio : float or array_like, shape (M,), optional
        Pair viscosity = ratio × pair stiffness; 0.25 (the paper's) when
        neither this nor ``pair_viscosity`` is given. [s]
    **sets
        ``pair_viscosity`` [N·m·s/rad], ``body``, ``muscles``: :class:`SetKeywords`.

    Returns
    -------
    numpy.ndarray, shape (M, 2N + 1)
        ``c[:, j]`` multiplies s^j (ascending powers); ``c[:, 2N] = det J0``.
        Units: [(N·m/rad)^N · s^j] (a determinant of N×N torque-per-angle entries).
    """
    m, blocks = _systems(pair_stiffness, viscosity_ratio, **sets)
    return _blocks(m, blocks, _kernels.MODE_COEFFICIENTS)["coefficients"]


def batch_stable(pair_stiffness: np.ndarray, viscosity_ratio: float | np.ndarray | None = None,
                 **sets: Unpack[SetKeywords]) -> np.ndarray:
    """Stable flags of M parameter sets by the Routh–Hurwitz test (fastest path); the
    arguments as for :func:`characteristic_polynomials` ([N·m/rad], [s], [N·m·s/rad]).

    Returns
    -------
    numpy.ndarray of bool, shape (M,)
        True when every pole has real part < −δ (module notes); equal to
        ``batch_analyse(...).stable`` except within rounding of that boundary.
    """
    m, blocks = _systems(pair_stiffness, viscosity_ratio, **sets)
    return _blocks(m, blocks, _kernels.MODE_FLAGS)["stable"]


def batch_analyse(pair_stiffness: np.ndarray, viscosity_ratio: float | np.ndarray | None = None,
                  *, keep_poles: bool = False, _max_iterations: int = _MAX_ITERATIONS,
                  **sets: Unpack[SetKeywords]) -> BatchLinearAnalysis:
    """Poles, largest real part and stable flag of M parameter sets; the sets as for
    :func:`characteristic_polynomials` ([N·m/rad], [s], [N·m·s/rad]).

    Parameters
    ----------
    keep_poles : bool, optional
        Also return all 2N poles of every set, shape (M, 2N) [1/s] (32·N bytes
        per set).

    Returns
    -------
    BatchLinearAnalysis
    """
    m, blocks = _systems(pair_stiffness, viscosity_ratio, **sets)
    parts = [_analyse(system, keep_poles=keep_poles, max_iterations=_max_iterations)
             for _, _, system in blocks]
    if len(parts) == 1:
        res = parts[0]
        if m == 0:
            return BatchLinearAnalysis(res.stable[:0], res.max_real_part[:0],
                                       None if res.poles is None else res.poles[:0])
        return res
    return BatchLinearAnalysis(
        stable=np.concatenate([p.stable for p in parts]),
        max_real_part=np.concatenate([p.max_real_part for p in parts]),
        poles=np.concatenate([p.poles for p in parts]) if keep_poles else None)


def _analyse(system: LinearSystem, *, keep_poles: bool = False,
             max_iterations: int = _MAX_ITERATIONS, chain: int = 0,
             threads: int | None = None) -> BatchLinearAnalysis:
    """Poles of the sets of ``system`` (:func:`batch_analyse`); ``chain``, ``threads``: as
    :func:`posturelab.linear._batch_kernels.run`."""
    out = _run(system, _kernels.MODE_POLES, keep_poles=keep_poles,
               max_iterations=max_iterations, chain=chain, threads=threads)
    poles = out["poles"] if keep_poles else None
    bad = np.flatnonzero(~out["converged"])
    if bad.size:
        _eigvals_fallback(system, bad, poles, out["max_real"], out["stable"])
    return BatchLinearAnalysis(stable=out["stable"], max_real_part=out["max_real"], poles=poles)


def _eigvals_fallback(system: LinearSystem, index: np.ndarray, poles: np.ndarray | None,
                      max_real: np.ndarray, stable: np.ndarray) -> None:
    """Recompute some sets with numpy eigvals of the state matrix (the single-case method)."""
    sub = system[index]
    coefs = _run(sub, _kernels.MODE_COEFFICIENTS)["coefficients"]
    ev = sorted_poles(np.linalg.eigvals(sub.state_matrix()))
    max_real[index] = ev.real.max(axis=1)
    stable[index] = max_real[index] < np.array([-_margin_py(c) for c in coefs])
    if poles is not None:
        poles[index] = ev


def _margin_py(coef: np.ndarray) -> float:
    """Python twin of the compiled δ (module notes). [1/s]"""
    lead = abs(coef[-1])
    return STABILITY_MARGIN * max(1.0, abs(coef[-2]) / lead, math.sqrt(abs(coef[-3]) / lead))


# ---------------------------------------------------------------------------
# Stability maps
# ---------------------------------------------------------------------------

#: Parameter sets per block of a stability map (one system and one kernel call each). [-]
_MAP_BLOCK = 16_384


def stability_map(
    x: ParameterRange | tuple[str, float, float],
    y: ParameterRange | tuple[str, float, float],
    resolution: int | tuple[int, int] = 200,
    *,
    case: str = "1",
    viscosity_ratio: float | None = None,
    body: Body | None = None,
    progress: Callable[[int, int], None] | None = None,
    muscles: MuscleSet | None = None,
) -> StabilityMap:
    """Largest real part and stability over a two-parameter grid of pair gains.

    Parameters
    ----------
    x, y, resolution, case, viscosity_ratio, muscles
        As in :func:`parameter_grid`; ``muscles`` (its pairs, any number of links) is
        needed for a body other than three links.
    body : Body, optional
        The body; the paper's by default.
    progress : callable(done, total), optional
        Called after each block of sets with the number of sets done and the
        total. [-]

    Returns
    -------
    StabilityMap
    """
    from concurrent.futures import ThreadPoolExecutor

    from numba import config

    grid = parameter_grid(x, y, resolution, case=case, viscosity_ratio=viscosity_ratio,
                          muscles=muscles)
    body = paper_body() if body is None else body
    if not isinstance(body, Body):
        raise ParameterError(f"body must be a Body, got {type(body).__name__}")
    layout = muscles
    if layout is None:
        if body.n_links != 3:
            raise ParameterError(f"a map over Table I's pairs is for three links; this body "
                                 f"has {body.n_links}: give muscles (its pairs)")
        layout = paper_muscles("1")
    elif layout.n_links != body.n_links:
        raise ParameterError(f"muscle set is for {layout.n_links} links but the body has "
                             f"{body.n_links}")
    ny, nx = grid.shape
    max_real = np.empty((ny, nx))
    stable = np.empty((ny, nx), dtype=bool)
    rows_per_block = max(1, _MAP_BLOCK // nx)

    def block(start: int) -> int:
        """Rows start … of the grid: their system, then their poles, each row a chain."""
        stop = min(ny, start + rows_per_block)
        stiffness, ratio = grid.rows(start, stop)
        system = linear_system(body, layout, stiffness=stiffness, viscosity_ratio=ratio,
                               inputs=False)
        res = _analyse(system, chain=nx, threads=1)
        max_real[start:stop] = res.max_real_part.reshape(stop - start, nx)
        stable[start:stop] = res.stable.reshape(stop - start, nx)
        return (stop - start) * nx

    starts = range(0, ny, rows_per_block)
    done = 0
    if progress is not None:
        progress(0, grid.size)
    threads = max(1, min(config.NUMBA_NUM_THREADS, len(starts)))
    with ThreadPoolExecutor(max_workers=threads) as pool:
        try:
            for count in pool.map(block, starts):
                done += count
                if progress is not None:
                    progress(done, grid.size)
        except BaseException:  # Ctrl-C: drop the blocks not started
            pool.shutdown(wait=True, cancel_futures=True)
            raise
    return StabilityMap(grid, max_real, stable, body.name)
