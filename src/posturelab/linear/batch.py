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

Everything per set runs in one compiled function (:mod:`._batch_kernels`,
``nogil=True``), called on blocks of sets from a small thread pool (one thread
per core, ``NUMBA_NUM_THREADS``); it is safe to call from several Python threads
at once. The first call in a fresh environment compiles (a few seconds); later
processes load the cached machine code (:mod:`posturelab._jit`).

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
ratio) over ranges, every other parameter taken from a Table I case; they are
defined in :mod:`._batch_grid` (which imports no numba) and public here.
"""


from __future__ import annotations

import math
from dataclasses import dataclass, replace

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
    stability_map,
)
from ._batch_kernels import MAX_ITERATIONS as _MAX_ITERATIONS
from ._batch_kernels import STABILITY_MARGIN
from .analysis import sorted_poles

__all__ = [
    "STABILITY_MARGIN",
    "GRID_PARAMETERS",
    "GRID_PARAMETER_UNITS",
    "BodyArrays",
    "BatchLinearAnalysis",
    "ParameterRange",
    "ParameterGrid",
    "StabilityMap",
    "characteristic_polynomials",
    "batch_stable",
    "batch_analyse",
    "parameter_grid",
    "stability_map",
]


# ---------------------------------------------------------------------------
# Inputs
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class BodyArrays:
    """Body parameters per parameter set, for sweeps over the body itself.

    Each per-link array has shape (N,) (shared by every set) or (M, N) (one
    row per set); ``gravity`` is a scalar or shape (M,).

    Parameters
    ----------
    masses : array_like, shape (N,) or (M, N)
        Link masses, lowest link first. [kg]
    lengths : array_like, shape (N,) or (M, N)
        Link lengths. [m]
    com_distances : array_like, shape (N,) or (M, N)
        Centre-of-mass distances from each link's lower joint, in [0, length]. [m]
    inertias : array_like, shape (N,) or (M, N)
        Inertias about each centre of mass. [kg·m²]
    gravity : float or array_like, shape (M,)
        Gravitational acceleration, > 0. [m/s²]
    """

    masses: np.ndarray
    lengths: np.ndarray
    com_distances: np.ndarray
    inertias: np.ndarray
    gravity: float | np.ndarray = 9.81

    def __post_init__(self) -> None:
        fields = {}
        for name, unit in (("masses", "kg"), ("lengths", "m"), ("com_distances", "m"),
                           ("inertias", "kg·m²")):
            arr = finite_array(f"{name} [{unit}]", getattr(self, name))
            if arr.ndim not in (1, 2) or arr.shape[-1] < 1:
                raise ParameterError(
                    f"{name} [{unit}] must have shape (N,) or (M, N), got shape {arr.shape}"
                )
            fields[name] = arr
        n_links = {a.shape[-1] for a in fields.values()}
        if len(n_links) != 1:
            raise ParameterError(
                "masses, lengths, com_distances and inertias must have the same number of "
                f"links (last axis), got {sorted(n_links)}"
            )
        for name in ("masses", "lengths", "inertias"):
            if np.any(fields[name] <= 0):
                raise ParameterError(f"{name} must be > 0, got {fields[name].min():g}")
        com = fields["com_distances"]
        if np.any(com < 0) or np.any(com > fields["lengths"]):
            raise ParameterError("com_distances [m] must lie in [0, length] for every link")
        gravity = finite_array("gravity [m/s²]", self.gravity)
        if gravity.ndim > 1 or np.any(gravity <= 0):
            raise ParameterError("gravity [m/s²] must be > 0, a scalar or shape (M,)")
        for name, arr in fields.items():
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        gravity.setflags(write=False)
        object.__setattr__(self, "gravity", gravity)

    @classmethod
    def from_body(cls, body: Body) -> BodyArrays:
        """The parameters of one :class:`~posturelab.model.body.Body`, shared by every set."""
        return cls(body.masses, body.lengths, body.com_distances, body.inertias, body.gravity)

    @property
    def n_links(self) -> int:
        """Number of links N. [-]"""
        return int(self.masses.shape[-1])

    def set_count(self) -> int | None:
        """Number of sets M the per-set arrays describe, or None when all are shared."""
        counts = {a.shape[0] for a in (self.masses, self.lengths, self.com_distances,
                                       self.inertias) if a.ndim == 2}
        if self.gravity.ndim == 1:
            counts.add(self.gravity.shape[0])
        if len(counts) > 1:
            raise ParameterError(f"body arrays disagree on the number of sets: {sorted(counts)}")
        return counts.pop() if counts else None

    def upright_matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """J(0) and g·a per set: shapes (B, N, N) [kg·m²] and (B, N) [N·m/rad], B = M or 1."""
        count = self.set_count()
        size = 1 if count is None else count
        n = self.n_links

        def per_set(arr: np.ndarray) -> np.ndarray:
            return np.broadcast_to(arr, (size, n)) if arr.ndim == 1 else arr

        masses, lengths, com, inertias = (per_set(arr) for arr in (
            self.masses, self.lengths, self.com_distances, self.inertias))
        mass_above = np.cumsum(masses[:, ::-1], axis=1)[:, ::-1] - masses  # Σ_{j>i} m_j
        gravity_coefficients = masses * com + mass_above * lengths  # a_i [kg·m]
        jac = np.empty((size, n, n))
        for i in range(n):
            jac[:, i, i] = (inertias[:, i] + masses[:, i] * com[:, i] ** 2
                            + mass_above[:, i] * lengths[:, i] ** 2)
            for j in range(i + 1, n):
                jac[:, i, j] = jac[:, j, i] = lengths[:, i] * gravity_coefficients[:, j]
        gravity = np.broadcast_to(self.gravity, (size,))
        return jac, np.ascontiguousarray(gravity[:, None] * gravity_coefficients)


@dataclass(frozen=True)
class _Prepared:
    E_rows: np.ndarray
    E_cols: np.ndarray
    E_pair: np.ndarray
    E_weight: np.ndarray
    stiffness: np.ndarray
    viscosity: np.ndarray
    ratio: np.ndarray
    use_ratio: bool
    inertia: np.ndarray
    gravity_torque: np.ndarray
    masks: np.ndarray
    mask_start: np.ndarray

    def args(self) -> tuple:
        return (self.E_rows, self.E_cols, self.E_pair, self.E_weight, self.stiffness,
                self.viscosity, self.ratio, self.use_ratio, self.inertia, self.gravity_torque,
                self.masks, self.mask_start)

    @property
    def n_sets(self) -> int:
        return int(self.stiffness.shape[0])

    @property
    def n_links(self) -> int:
        return int(self.inertia.shape[1])


def _run_kernel(prep: _Prepared, mode: int, *, keep_poles: bool = False,
                max_iterations: int = _MAX_ITERATIONS) -> dict[str, np.ndarray]:
    """Run the compiled kernel in ``mode`` on the prepared sets (see ``_batch_kernels.run``)."""
    return _kernels.run(mode, prep.args(), prep.n_sets, prep.n_links, keep_poles=keep_poles,
                        max_iterations=max_iterations)


def _subset_tables(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Column subsets by size (sizes 1..N−1 all, size N only the full set)."""
    masks: list[int] = []
    start = [0, 0]
    for size in range(1, n + 1):
        if size < n:
            masks.extend(s for s in range(1 << n) if bin(s).count("1") == size)
        else:
            masks.append((1 << n) - 1)
        start.append(len(masks))
    return np.array(masks, dtype=np.int64), np.array(start, dtype=np.int64)


def _prepare(
    pair_stiffness, viscosity_ratio, pair_viscosity, body, muscles
) -> _Prepared:
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
    if pair_viscosity is not None:
        if viscosity_ratio is not None:
            raise ParameterError("give viscosity_ratio or pair_viscosity, not both")
        viscosity = _gain_array("pair_viscosity [N·m·s/rad]", pair_viscosity, n_pairs)
        if viscosity.shape[0] not in (1, n_sets):
            raise ParameterError(
                f"pair_viscosity [N·m·s/rad] must have {n_sets} rows (one per set), "
                f"got {viscosity.shape[0]}"
            )
        ratio = np.zeros(1)
        use_ratio = False
    else:
        viscosity = np.zeros((1, n_pairs))
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
        use_ratio = True
    body_sets = body.set_count()
    if body_sets is not None and body_sets != n_sets:
        raise ParameterError(
            f"body arrays describe {body_sets} sets but pair_stiffness has {n_sets} rows"
        )
    inertia, gravity_torque = body.upright_matrices()
    E = muscles.selection_matrix
    rows, cols, pairs, weights = [], [], [], []
    for p in range(n_pairs):
        nz = np.flatnonzero(E[p])
        for r in nz:
            for c in nz:
                rows.append(r)
                cols.append(c)
                pairs.append(p)
                weights.append(E[p, r] * E[p, c])
    masks, mask_start = _subset_tables(body.n_links)
    return _Prepared(
        np.array(rows, dtype=np.int64), np.array(cols, dtype=np.int64),
        np.array(pairs, dtype=np.int64), np.array(weights, dtype=float),
        stiffness, np.ascontiguousarray(viscosity, dtype=float), ratio, use_ratio,
        np.ascontiguousarray(inertia, dtype=float),
        np.ascontiguousarray(gravity_torque, dtype=float), masks, mask_start,
    )


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


# ---------------------------------------------------------------------------
# Public batch API
# ---------------------------------------------------------------------------


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


def characteristic_polynomials(
    pair_stiffness: np.ndarray,
    viscosity_ratio: float | np.ndarray | None = None,
    *,
    pair_viscosity: np.ndarray | None = None,
    body: Body | BodyArrays | None = None,
    muscles: MuscleSet | None = None,
) -> np.ndarray:
    """Coefficients of p(s) = det(s² J0 + s L + K − g diag(a)) for each set.

    Parameters
    ----------
    pair_stiffness : array_like, shape (M, P) or (P,)
        Stiffness of each muscle pair, columns in the order of ``muscles``. [N·m/rad]
    viscosity_ratio : float or array_like, shape (M,), optional
        Pair viscosity = ratio × pair stiffness; 0.25 (the paper's) when
        neither this nor ``pair_viscosity`` is given. [s]
    pair_viscosity : array_like, shape (M, P), optional
        Per-pair viscosity instead of a ratio. [N·m·s/rad]
    body : Body or BodyArrays, optional
        The chain (one body, or per-set parameters); the paper's body by default.
    muscles : MuscleSet, optional
        Gives the pair spans (the matrix E) only; its own gains are ignored.
        The paper's five pairs by default.

    Returns
    -------
    numpy.ndarray, shape (M, 2N + 1)
        ``c[:, j]`` multiplies s^j (ascending powers); ``c[:, 2N] = det J0``.
        Units: [(N·m/rad)^N · s^j] (a determinant of N×N torque-per-angle entries).
    """
    prep = _prepare(pair_stiffness, viscosity_ratio, pair_viscosity, body, muscles)
    return _run_kernel(prep, _kernels.MODE_COEFFICIENTS)["coefficients"]


def batch_stable(
    pair_stiffness: np.ndarray,
    viscosity_ratio: float | np.ndarray | None = None,
    *,
    pair_viscosity: np.ndarray | None = None,
    body: Body | BodyArrays | None = None,
    muscles: MuscleSet | None = None,
) -> np.ndarray:
    """Stable flags of M parameter sets by the Routh–Hurwitz test (fastest path).

    Parameters
    ----------
    pair_stiffness, viscosity_ratio, pair_viscosity, body, muscles
        As in :func:`characteristic_polynomials`: [N·m/rad], [s], [N·m·s/rad].

    Returns
    -------
    numpy.ndarray of bool, shape (M,)
        True when every pole has real part < −δ (module notes); equal to
        ``batch_analyse(...).stable`` except within rounding of that boundary.
    """
    prep = _prepare(pair_stiffness, viscosity_ratio, pair_viscosity, body, muscles)
    return _run_kernel(prep, _kernels.MODE_FLAGS)["stable"]


def batch_analyse(
    pair_stiffness: np.ndarray,
    viscosity_ratio: float | np.ndarray | None = None,
    *,
    pair_viscosity: np.ndarray | None = None,
    body: Body | BodyArrays | None = None,
    muscles: MuscleSet | None = None,
    keep_poles: bool = False,
    _max_iterations: int = _MAX_ITERATIONS,
) -> BatchLinearAnalysis:
    """Poles, largest real part and stable flag of M parameter sets.

    Parameters
    ----------
    pair_stiffness, viscosity_ratio, pair_viscosity, body, muscles
        As in :func:`characteristic_polynomials`: [N·m/rad], [s], [N·m·s/rad].
    keep_poles : bool, optional
        Also return all 2N poles of every set, shape (M, 2N) [1/s] (32·N bytes
        per set).

    Returns
    -------
    BatchLinearAnalysis
    """
    prep = _prepare(pair_stiffness, viscosity_ratio, pair_viscosity, body, muscles)
    out = _run_kernel(prep, _kernels.MODE_POLES, keep_poles=keep_poles,
                      max_iterations=_max_iterations)
    poles = out["poles"] if keep_poles else None
    bad = np.flatnonzero(~out["converged"])
    if bad.size:
        _eigvals_fallback(prep, bad, poles, out["max_real"], out["stable"])
    return BatchLinearAnalysis(stable=out["stable"], max_real_part=out["max_real"], poles=poles)


def _subset(prep: _Prepared, index: np.ndarray) -> _Prepared:
    """The prepared inputs of the sets ``index`` only."""
    def rows(arr: np.ndarray) -> np.ndarray:
        return np.ascontiguousarray(arr[index]) if arr.shape[0] > 1 else arr

    return replace(prep, stiffness=rows(prep.stiffness), viscosity=rows(prep.viscosity),
                   ratio=rows(prep.ratio), inertia=rows(prep.inertia),
                   gravity_torque=rows(prep.gravity_torque))


def _state_matrices(prep: _Prepared) -> np.ndarray:
    """State matrices A (M, 2N, 2N), built as :func:`posturelab.linear.state_matrix` does."""
    n, n_sets = prep.n_links, prep.n_sets
    stiff = np.zeros((n_sets, n, n))
    visc = np.zeros((n_sets, n, n))
    ratio = np.broadcast_to(prep.ratio, (n_sets,))
    for r, c, p, w in zip(prep.E_rows, prep.E_cols, prep.E_pair, prep.E_weight, strict=True):
        stiff[:, r, c] += w * prep.stiffness[:, p]
        if prep.use_ratio:
            visc[:, r, c] += w * (ratio * prep.stiffness[:, p])
        else:
            visc[:, r, c] += w * np.broadcast_to(prep.viscosity[:, p], (n_sets,))
    inertia = np.broadcast_to(prep.inertia, (n_sets, n, n))
    gravity = np.broadcast_to(prep.gravity_torque, (n_sets, n))
    out = np.zeros((n_sets, 2 * n, 2 * n))
    out[:, :n, n:] = np.eye(n)
    out[:, n:, :n] = np.linalg.solve(inertia, gravity[:, :, None] * np.eye(n) - stiff)
    out[:, n:, n:] = -np.linalg.solve(inertia, visc)
    return out


def _eigvals_fallback(prep: _Prepared, index: np.ndarray, poles: np.ndarray | None,
                      max_real: np.ndarray, stable: np.ndarray) -> None:
    """Recompute some sets with numpy eigvals of the state matrix (the single-case method)."""
    sub = _subset(prep, index)
    coefs = _run_kernel(sub, _kernels.MODE_COEFFICIENTS)["coefficients"]
    ev = sorted_poles(np.linalg.eigvals(_state_matrices(sub)))
    max_real[index] = ev.real.max(axis=1)
    stable[index] = max_real[index] < np.array([-_margin_py(c) for c in coefs])
    if poles is not None:
        poles[index] = ev


def _margin_py(coef: np.ndarray) -> float:
    """Python twin of the compiled δ (module notes). [1/s]"""
    lead = abs(coef[-1])
    return STABILITY_MARGIN * max(1.0, abs(coef[-2]) / lead, math.sqrt(abs(coef[-3]) / lead))


