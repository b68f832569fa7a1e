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

Everything per set runs in one numba function (``cache=True``, ``nogil=True``),
called on blocks of sets from a small thread pool (one thread per core,
``NUMBA_NUM_THREADS``). This was measured as fast as ``parallel=True``/``prange``
on two cores, compiles in half the time, and is safe to call from several
Python threads at once. The first call in a fresh environment compiles (a few
seconds); later processes load the cached machine code.

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
ratio) over ranges, every other parameter taken from a Table I case.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace
from typing import IO

import numba
import numpy as np

from .._validation import finite_array, nonnegative_float
from ..errors import ParameterError, UnknownNameError
from ..model.body import Body, paper_body
from ..model.muscles import (
    DEFAULT_VISCOSITY_RATIO,
    PAPER_PAIR_NAMES,
    STIFFNESS_CASES,
    MuscleSet,
    get_stiffness_case,
    paper_muscles,
)
from .analysis import sorted_poles

__all__ = [
    "STABILITY_MARGIN",
    "GRID_PARAMETERS",
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

#: Relative stability margin: stable means every Re λ < −STABILITY_MARGIN·max(1, ρ). [-]
STABILITY_MARGIN = 1e-9

#: Parameters a grid can sweep: the paper's five pair stiffnesses [N·m/rad] and
#: the viscosity ratio [s].
GRID_PARAMETERS: tuple[str, ...] = (*PAPER_PAIR_NAMES, "viscosity_ratio")

#: Unit of each grid parameter.
GRID_PARAMETER_UNITS: dict[str, str] = {
    **{name: "N·m/rad" for name in PAPER_PAIR_NAMES},
    "viscosity_ratio": "s",
}

_MIN_BLOCK = 4096  # fewest parameter sets worth a thread of their own
_MAX_ITERATIONS = 80  # Aberth iterations before falling back to eigvals
_EPS = float(np.finfo(float).eps)


# ---------------------------------------------------------------------------
# Compiled kernels
# ---------------------------------------------------------------------------


@numba.njit(cache=True, error_model="numpy")
def _set_matrices(i, E_rows, E_cols, E_pair, E_weight, stiffness, viscosity, ratio,
                  use_ratio, inertia, gravity_torque, jac, damp, load):
    """J0, L and K − g·diag(a) of set ``i`` into ``jac``, ``damp``, ``load``."""
    n = jac.shape[0]
    b = i if inertia.shape[0] > 1 else 0
    r = ratio[i if ratio.shape[0] > 1 else 0]
    for row in range(n):
        for col in range(n):
            jac[row, col] = inertia[b, row, col]
            damp[row, col] = 0.0
            load[row, col] = 0.0
        load[row, row] = -gravity_torque[b, row]
    vi = i if viscosity.shape[0] > 1 else 0
    for t in range(E_rows.shape[0]):
        p = E_pair[t]
        w = E_weight[t]
        ks = stiffness[i, p]
        load[E_rows[t], E_cols[t]] += w * ks
        if use_ratio:
            damp[E_rows[t], E_cols[t]] += w * (r * ks)
        else:
            damp[E_rows[t], E_cols[t]] += w * viscosity[vi, p]


@numba.njit(cache=True, error_model="numpy")
def _polynomial_determinant(jac, damp, load, masks, mask_start, minors, coef):
    """det(s² jac + s damp + load) into ``coef`` (ascending powers), any N."""
    n = jac.shape[0]
    # Laplace expansion along rows, memoised over column subsets: minors[S] is
    # the determinant (a polynomial in s, ascending) of rows 0..|S|-1, columns S.
    minors[0, 0] = 1.0
    for level in range(1, n + 1):
        row = level - 1
        deg = 2 * level
        for t in range(mask_start[level], mask_start[level + 1]):
            S = masks[t]
            for d in range(deg + 1):
                minors[S, d] = 0.0
            below = 0  # number of columns of S greater than the current one
            for col in range(n - 1, -1, -1):
                bit = 1 << col
                if S & bit:
                    child = S ^ bit
                    sign = 1.0 if below % 2 == 0 else -1.0
                    q0 = sign * load[row, col]
                    q1 = sign * damp[row, col]
                    q2 = sign * jac[row, col]
                    for d in range(deg - 1):
                        m = minors[child, d]
                        minors[S, d] += q0 * m
                        minors[S, d + 1] += q1 * m
                        minors[S, d + 2] += q2 * m
                    below += 1
    full = masks[mask_start[n]]
    for d in range(2 * n + 1):
        coef[d] = minors[full, d]


@numba.njit(cache=True, error_model="numpy", inline="always")
def _minor3(jac, damp, load, left, right):
    """2×2 minor of rows 1, 2 and columns ``left``, ``right`` of s² jac + s damp + load.

    Returns its 5 coefficients (ascending powers of s).
    """
    a0, a1, a2 = load[1, left], damp[1, left], jac[1, left]
    b0, b1, b2 = load[2, right], damp[2, right], jac[2, right]
    c0, c1, c2 = load[1, right], damp[1, right], jac[1, right]
    d0, d1, d2 = load[2, left], damp[2, left], jac[2, left]
    return (a0 * b0 - c0 * d0,
            a0 * b1 + a1 * b0 - c0 * d1 - c1 * d0,
            a0 * b2 + a1 * b1 + a2 * b0 - c0 * d2 - c1 * d1 - c2 * d0,
            a1 * b2 + a2 * b1 - c1 * d2 - c2 * d1,
            a2 * b2 - c2 * d2)


@numba.njit(cache=True, error_model="numpy")
def _polynomial_determinant3(jac, damp, load, coef):
    """det(s² jac + s damp + load) into ``coef`` for N = 3: cofactor expansion unrolled.

    Entry (r, c) is the quadratic load[r, c] + damp[r, c] s + jac[r, c] s².
    """
    for d in range(7):
        coef[d] = 0.0
    for col in range(3):
        if col == 0:
            minor = _minor3(jac, damp, load, 1, 2)
            sign = 1.0
        elif col == 1:
            minor = _minor3(jac, damp, load, 0, 2)
            sign = -1.0
        else:
            minor = _minor3(jac, damp, load, 0, 1)
            sign = 1.0
        q0 = sign * load[0, col]
        q1 = sign * damp[0, col]
        q2 = sign * jac[0, col]
        for d in range(5):
            coef[d] += q0 * minor[d]
            coef[d + 1] += q1 * minor[d]
            coef[d + 2] += q2 * minor[d]


@numba.njit(cache=True, error_model="numpy")
def _margin(coef):
    """δ = STABILITY_MARGIN · max(1, ρ) for ``coef`` (ascending); see the module notes."""
    deg = coef.shape[0] - 1
    lead = abs(coef[deg])
    rho = max(1.0, abs(coef[deg - 1]) / lead, math.sqrt(abs(coef[deg - 2]) / lead))
    return STABILITY_MARGIN * rho


@numba.njit(cache=True, error_model="numpy")
def _routh_stable(coef, shifted, row_a, row_b, row_c):
    """True when every root of ``coef`` (ascending) has real part < −δ (Routh–Hurwitz)."""
    deg = coef.shape[0] - 1
    lead = coef[deg]
    # Necessary condition on the unshifted polynomial: all coefficients of one sign.
    for j in range(deg + 1):
        if coef[j] * lead <= 0.0:
            return False
    delta = _margin(coef)
    # shifted (descending) = coefficients of p(s − δ), by repeated synthetic division.
    for j in range(deg + 1):
        shifted[j] = coef[deg - j] / lead
    h = -delta
    for it in range(deg):
        for j in range(1, deg + 1 - it):
            shifted[j] += h * shifted[j - 1]
    for j in range(deg + 1):
        if shifted[j] <= 0.0:
            return False
    width = row_a.shape[0]
    for j in range(width):
        row_a[j] = 0.0
        row_b[j] = 0.0
    for j in range(0, deg + 1, 2):
        row_a[j // 2] = shifted[j]
    for j in range(1, deg + 1, 2):
        row_b[j // 2] = shifted[j]
    # Rows 2..deg of the Routh array; each first-column entry must be > 0.
    for _ in range(deg - 1):
        pivot = row_b[0]
        if pivot <= 0.0:
            return False
        f = row_a[0] / pivot
        for j in range(width - 1):
            row_c[j] = row_a[j + 1] - f * row_b[j + 1]
        row_c[width - 1] = 0.0
        for j in range(width):
            row_a[j] = row_b[j]
            row_b[j] = row_c[j]
    return row_b[0] > 0.0


@numba.njit(cache=True, error_model="numpy")
def _horner(coef, deg, z):
    """p(z), p'(z) and Σ|c_j||z|^j for ascending real ``coef`` of degree ``deg``."""
    p = complex(coef[deg], 0.0)
    dp = complex(0.0, 0.0)
    az = math.sqrt(z.real * z.real + z.imag * z.imag)
    bound = abs(coef[deg])
    for j in range(deg - 1, -1, -1):
        dp = dp * z + p
        p = p * z + coef[j]
        bound = bound * az + abs(coef[j])
    return p, dp, bound


def _start_directions(degree: int) -> np.ndarray:
    """Unit vectors of the Aberth starting points, [a, m, t] for a hull segment (a, a + m).

    Angle 2πt/m + 2πa/degree + 0.7 (Bini's choice: an offset breaks the symmetry
    with respect to the real axis). [-]
    """
    out = np.zeros((degree + 1, degree + 1, degree + 1), dtype=np.complex128)
    for a in range(degree + 1):
        for m in range(1, degree + 1):
            t = np.arange(m)
            out[a, m, :m] = np.exp(1j * (2 * np.pi * t / m + 2 * np.pi * a / degree + 0.7))
    return out


@numba.njit(cache=True, error_model="numpy")
def _aberth(coef, roots, done, hull, logs, directions, max_iterations):
    """All roots of the real polynomial ``coef`` (ascending) into ``roots``.

    ``directions`` is :func:`_start_directions` of the full degree. Returns True
    on convergence. Exact zero roots are split off first.
    """
    deg_full = coef.shape[0] - 1
    low = 0
    while low < deg_full and coef[low] == 0.0:
        roots[low] = 0.0
        low += 1
    c = coef[low:]
    deg = deg_full - low
    z = roots[low:]
    if deg == 0:
        return True
    # Starting points from the Newton polygon (upper convex hull of (j, log|c_j|)):
    # a hull segment from a to b holds b − a roots of modulus (|c_a|/|c_b|)^(1/(b−a)).
    nh = 0
    for j in range(deg + 1):
        if c[j] == 0.0:
            continue
        logs[j] = math.log(abs(c[j]))
        while nh >= 2:
            j1 = hull[nh - 2]
            j2 = hull[nh - 1]
            # drop j2 if it lies on or below the chord from j1 to j
            if (logs[j2] - logs[j1]) * (j - j1) <= (logs[j] - logs[j1]) * (j2 - j1):
                nh -= 1
            else:
                break
        hull[nh] = j
        nh += 1
    for s in range(nh - 1):
        a = hull[s]
        m = hull[s + 1] - a
        radius = math.exp((logs[a] - logs[a + m]) / m)
        for t in range(m):
            if deg == deg_full:
                z[a + t] = radius * directions[a, m, t]
            else:
                angle = 2.0 * math.pi * t / m + 2.0 * math.pi * a / deg + 0.7
                z[a + t] = complex(radius * math.cos(angle), radius * math.sin(angle))
    for j in range(deg):
        done[j] = False
    remaining = deg
    tol = 4.0 * (deg + 1) * _EPS
    tol2 = tol * tol
    for _ in range(max_iterations):
        for j in range(deg):
            if done[j]:
                continue
            zj = z[j]
            p, dp, bound = _horner(c, deg, zj)
            if p.real * p.real + p.imag * p.imag <= tol2 * bound * bound:
                done[j] = True
                remaining -= 1
            # Aberth correction p / (p' − p Σ_{t≠j} 1/(z_j − z_t)), one real division
            acc_re = 0.0
            acc_im = 0.0
            for t in range(deg):
                if t != j:
                    d = zj - z[t]
                    inv = 1.0 / (d.real * d.real + d.imag * d.imag)
                    acc_re += d.real * inv
                    acc_im -= d.imag * inv
            den = dp - p * complex(acc_re, acc_im)
            step = p * den.conjugate() / (den.real * den.real + den.imag * den.imag)
            z[j] = zj - step
        if remaining == 0:
            break
    return remaining == 0


@numba.njit(cache=True, error_model="numpy")
def _tidy_roots(roots, paired):
    """Make conjugate pairs exact and near-real roots real, then sort like sorted_poles."""
    n = roots.shape[0]
    for j in range(n):
        paired[j] = False
    for j in range(n):
        if paired[j]:
            continue
        zj = roots[j]
        target = zj.conjugate()
        best = -1
        best_dist = 4.0 * zj.imag * zj.imag  # squared distance to its own conjugate
        for t in range(n):
            if t != j and not paired[t]:
                e = roots[t] - target
                d = e.real * e.real + e.imag * e.imag
                if d < best_dist:
                    best_dist = d
                    best = t
        paired[j] = True
        if best < 0:
            roots[j] = complex(zj.real, 0.0)
        else:
            paired[best] = True
            w = 0.5 * (zj + roots[best].conjugate())
            roots[j] = w
            roots[best] = w.conjugate()
    # insertion sort: real part rounded to 9 decimals ascending, then imag descending
    for j in range(1, n):
        z = roots[j]
        key = np.rint(z.real * 1e9)
        t = j - 1
        while t >= 0:
            kt = np.rint(roots[t].real * 1e9)
            if kt > key or (kt == key and roots[t].imag < z.imag):
                roots[t + 1] = roots[t]
                t -= 1
            else:
                break
        roots[t + 1] = z


_MODE_COEFFICIENTS = 0  # characteristic polynomial coefficients only
_MODE_FLAGS = 1  # Routh–Hurwitz flags only
_MODE_POLES = 2  # roots: largest real part and flags (and the poles if asked)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _batch_kernel(start, stop, mode, E_rows, E_cols, E_pair, E_weight, stiffness, viscosity,
                  ratio, use_ratio, inertia, gravity_torque, masks, mask_start, directions,
                  max_iterations, keep_poles, coefficients, poles, max_real, stable, converged):
    """Sets ``start:stop`` in one of three modes (one compiled function, GIL released)."""
    n = inertia.shape[1]
    if start < stop:
        jac = np.empty((n, n))
        damp = np.empty((n, n))
        load = np.empty((n, n))
        minors = np.zeros((1 << n, 2 * n + 1))
        coef = np.empty(2 * n + 1)
        shifted = np.empty(2 * n + 1)
        row_a = np.empty(n + 2)
        row_b = np.empty(n + 2)
        row_c = np.empty(n + 2)
        roots = np.empty(2 * n, dtype=np.complex128)
        done = np.empty(2 * n, dtype=np.bool_)
        hull = np.empty(2 * n + 1, dtype=np.int64)
        logs = np.empty(2 * n + 1)
        for i in range(start, stop):
            _set_matrices(i, E_rows, E_cols, E_pair, E_weight, stiffness, viscosity, ratio,
                          use_ratio, inertia, gravity_torque, jac, damp, load)
            if n == 3:
                _polynomial_determinant3(jac, damp, load, coef)
            else:
                _polynomial_determinant(jac, damp, load, masks, mask_start, minors, coef)
            if mode == _MODE_COEFFICIENTS:
                for j in range(2 * n + 1):
                    coefficients[i, j] = coef[j]
            elif mode == _MODE_FLAGS:
                stable[i] = _routh_stable(coef, shifted, row_a, row_b, row_c)
            else:
                converged[i] = _aberth(coef, roots, done, hull, logs, directions, max_iterations)
                _tidy_roots(roots, done)
                top = roots[0].real
                for j in range(1, 2 * n):
                    if roots[j].real > top:
                        top = roots[j].real
                max_real[i] = top
                stable[i] = top < -_margin(coef)
                if keep_poles:
                    for j in range(2 * n):
                        poles[i, j] = roots[j]


def _run_kernel(prep: _Prepared, mode: int, *, keep_poles: bool = False,
                max_iterations: int = _MAX_ITERATIONS) -> dict[str, np.ndarray]:
    """Allocate the outputs of ``mode`` (size-1 placeholders for the others) and run."""
    n_sets, n = prep.n_sets, prep.n_links

    def size(wanted: bool) -> int:
        return n_sets if wanted else 1

    out = {
        "coefficients": np.empty((size(mode == _MODE_COEFFICIENTS), 2 * n + 1)),
        "poles": np.empty((size(mode == _MODE_POLES and keep_poles), 2 * n),
                          dtype=np.complex128),
        "max_real": np.empty(size(mode == _MODE_POLES)),
        "stable": np.empty(size(mode != _MODE_COEFFICIENTS), dtype=np.bool_),
        "converged": np.empty(size(mode == _MODE_POLES), dtype=np.bool_),
    }
    args = (mode, *prep.args(), _start_directions(2 * n), int(max_iterations), bool(keep_poles),
            out["coefficients"], out["poles"], out["max_real"], out["stable"], out["converged"])
    threads = max(1, min(numba.config.NUMBA_NUM_THREADS, n_sets // _MIN_BLOCK))
    if threads == 1:
        _batch_kernel(0, n_sets, *args)
        return out
    # Blocks of sets on a thread pool: the kernel releases the GIL (nogil=True).
    bounds = np.linspace(0, n_sets, 4 * threads + 1).astype(np.int64)
    with ThreadPoolExecutor(max_workers=threads) as pool:
        jobs = [pool.submit(_batch_kernel, int(a), int(b), *args)
                for a, b in zip(bounds[:-1], bounds[1:], strict=True)]
        for job in jobs:
            job.result()
    return out


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
        """The parameters of one :class:`~posturelab.body.Body`, shared by every set."""
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
    return _run_kernel(prep, _MODE_COEFFICIENTS)["coefficients"]


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
    return _run_kernel(prep, _MODE_FLAGS)["stable"]


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
    out = _run_kernel(prep, _MODE_POLES, keep_poles=keep_poles, max_iterations=_max_iterations)
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
    coefs = _run_kernel(sub, _MODE_COEFFICIENTS)["coefficients"]
    ev = sorted_poles(np.linalg.eigvals(_state_matrices(sub)))
    max_real[index] = ev.real.max(axis=1)
    stable[index] = max_real[index] < np.array([-_margin_py(c) for c in coefs])
    if poles is not None:
        poles[index] = ev


def _margin_py(coef: np.ndarray) -> float:
    """Python twin of the compiled δ (module notes). [1/s]"""
    lead = abs(coef[-1])
    return STABILITY_MARGIN * max(1.0, abs(coef[-2]) / lead, math.sqrt(abs(coef[-3]) / lead))


# ---------------------------------------------------------------------------
# Parameter grids and stability maps
# ---------------------------------------------------------------------------


def _check_parameter_name(name: str) -> str:
    if name not in GRID_PARAMETERS:
        raise UnknownNameError(
            f"unknown parameter {name!r}; known parameters: {', '.join(GRID_PARAMETERS)}"
        )
    return name


@dataclass(frozen=True)
class ParameterRange:
    """A named parameter swept over [low, high].

    Parameters
    ----------
    name : str
        One of :data:`GRID_PARAMETERS`: a pair name (stiffness [N·m/rad]) or
        ``"viscosity_ratio"`` [s].
    low, high : float
        Range ends, 0 <= low < high. [N·m/rad] or [s]
    """

    name: str
    low: float
    high: float

    def __post_init__(self) -> None:
        _check_parameter_name(self.name)
        unit = GRID_PARAMETER_UNITS[self.name]
        low = nonnegative_float(f"{self.name} low [{unit}]", self.low)
        high = nonnegative_float(f"{self.name} high [{unit}]", self.high)
        if not low < high:
            raise ParameterError(
                f"{self.name} range must satisfy low < high [{unit}], got {low:g} .. {high:g}"
            )
        object.__setattr__(self, "low", low)
        object.__setattr__(self, "high", high)

    @property
    def unit(self) -> str:
        """Unit of the parameter: "N·m/rad" or "s"."""
        return GRID_PARAMETER_UNITS[self.name]

    @property
    def label(self) -> str:
        """Axis label with unit, e.g. ``"ankle pair stiffness [N·m/rad]"``."""
        if self.name == "viscosity_ratio":
            return "viscosity ratio (viscosity / stiffness) [s]"
        return f"{self.name} pair stiffness [N·m/rad]"

    def values(self, count: int) -> np.ndarray:
        """``count`` evenly spaced values from low to high inclusive. [unit]"""
        return np.linspace(self.low, self.high, count)


def _as_range(value: ParameterRange | tuple) -> ParameterRange:
    if isinstance(value, ParameterRange):
        return value
    try:
        name, low, high = value
    except (TypeError, ValueError):
        raise ParameterError(
            f"a parameter range must be ParameterRange or (name, low, high), got {value!r}"
        ) from None
    return ParameterRange(str(name), low, high)


@dataclass(frozen=True)
class ParameterGrid:
    """A two-parameter grid of the paper model's gains around a Table I case.

    Set index ``iy * nx + ix`` has ``x = x_values[ix]`` and ``y = y_values[iy]``
    (row-major, y along rows as an image).

    Attributes
    ----------
    x, y : ParameterRange
        The swept parameters.
    x_values : numpy.ndarray, shape (nx,)
        Values along x. [N·m/rad] or [s]
    y_values : numpy.ndarray, shape (ny,)
        Values along y. [N·m/rad] or [s]
    base_case : str
        Table I case giving every parameter not swept.
    base_stiffness : numpy.ndarray, shape (5,)
        That case's pair stiffness (ankle, knee, hip, quadriceps, gastrocnemius). [N·m/rad]
    base_viscosity_ratio : float
        Viscosity ratio when not swept. [s]
    """

    x: ParameterRange
    y: ParameterRange
    x_values: np.ndarray
    y_values: np.ndarray
    base_case: str
    base_stiffness: np.ndarray
    base_viscosity_ratio: float

    @property
    def shape(self) -> tuple[int, int]:
        """(ny, nx). [-]"""
        return (self.y_values.size, self.x_values.size)

    @property
    def size(self) -> int:
        """Number of parameter sets nx·ny. [-]"""
        return self.x_values.size * self.y_values.size

    def rows(self, start: int = 0, stop: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Gains of grid rows ``start:stop`` (y indices), flattened row-major.

        Returns
        -------
        pair_stiffness : numpy.ndarray, shape (rows·nx, 5)
            [N·m/rad]
        viscosity_ratio : numpy.ndarray, shape (rows·nx,)
            [s]
        """
        ys = self.y_values[start:stop]
        xs = self.x_values
        count = ys.size * xs.size
        stiffness = np.empty((count, len(PAPER_PAIR_NAMES)))
        stiffness[:] = self.base_stiffness
        ratio = np.full(count, self.base_viscosity_ratio)
        for rng, vals in ((self.x, np.tile(xs, ys.size)), (self.y, np.repeat(ys, xs.size))):
            if rng.name == "viscosity_ratio":
                ratio[:] = vals
            else:
                stiffness[:, PAPER_PAIR_NAMES.index(rng.name)] = vals
        return stiffness, ratio

    @property
    def pair_stiffness(self) -> np.ndarray:
        """All sets' pair stiffness, shape (nx·ny, 5). [N·m/rad]"""
        return self.rows()[0]

    @property
    def viscosity_ratio(self) -> np.ndarray:
        """All sets' viscosity ratio, shape (nx·ny,). [s]"""
        return self.rows()[1]

    def table_i_points(self) -> list[tuple[str, float, float]]:
        """Table I cases that lie in this plane: (case, x, y).

        A case lies in the plane when every parameter not swept equals the
        grid's base (a Table I case's viscosity ratio is the paper's 0.25 [s])
        and its two swept values fall within the ranges.
        """
        points = []
        names = list(PAPER_PAIR_NAMES)
        for case, stiffness in STIFFNESS_CASES.items():
            params = dict(zip(names, stiffness, strict=True))
            params["viscosity_ratio"] = DEFAULT_VISCOSITY_RATIO
            base = dict(zip(names, self.base_stiffness, strict=True))
            base["viscosity_ratio"] = self.base_viscosity_ratio
            if any(params[n] != base[n] for n in GRID_PARAMETERS
                   if n not in (self.x.name, self.y.name)):
                continue
            px, py = params[self.x.name], params[self.y.name]
            if self.x.low <= px <= self.x.high and self.y.low <= py <= self.y.high:
                points.append((case, float(px), float(py)))
        return points


def parameter_grid(
    x: ParameterRange | tuple[str, float, float],
    y: ParameterRange | tuple[str, float, float],
    resolution: int | tuple[int, int] = 200,
    *,
    case: str = "1",
    viscosity_ratio: float | None = None,
) -> ParameterGrid:
    """Grid over two named parameters, every other one from a Table I case.

    Parameters
    ----------
    x, y : ParameterRange or (name, low, high)
        Parameters to sweep, names from :data:`GRID_PARAMETERS`; different names.
        [N·m/rad] for a pair stiffness, [s] for ``"viscosity_ratio"``.
    resolution : int or (nx, ny)
        Points per axis, each in [2, 5000]. [-]
    case : str, optional
        Table I case for the parameters not swept ("1" … "7", "6a", "6b").
    viscosity_ratio : float, optional
        Viscosity ratio when it is not swept; the paper's 0.25 by default. [s]

    Returns
    -------
    ParameterGrid
    """
    x, y = _as_range(x), _as_range(y)
    if x.name == y.name:
        raise ParameterError(f"x and y must be different parameters, both are {x.name!r}")
    if isinstance(resolution, int | np.integer):
        nx = ny = int(resolution)
    else:
        try:
            nx, ny = (int(v) for v in resolution)
        except (TypeError, ValueError):
            raise ParameterError(
                f"resolution must be an integer or (nx, ny), got {resolution!r}"
            ) from None
    for label, count in (("nx", nx), ("ny", ny)):
        if not 2 <= count <= 5000:
            raise ParameterError(f"resolution {label} must be in [2, 5000], got {count}")
    base = np.array(get_stiffness_case(case), dtype=float)
    case_key = str(case).strip().lower().replace("case", "").replace(" ", "")
    if viscosity_ratio is None:
        ratio = DEFAULT_VISCOSITY_RATIO
    else:
        if "viscosity_ratio" in (x.name, y.name):
            raise ParameterError(
                "viscosity_ratio is swept along an axis; do not also give it as a fixed value"
            )
        ratio = nonnegative_float("viscosity_ratio [s]", viscosity_ratio)
    base.setflags(write=False)
    xv, yv = x.values(nx), y.values(ny)
    xv.setflags(write=False)
    yv.setflags(write=False)
    return ParameterGrid(x, y, xv, yv, case_key, base, ratio)


@dataclass(frozen=True)
class StabilityMap:
    """Largest real part and stability over a :class:`ParameterGrid`.

    Attributes
    ----------
    grid : ParameterGrid
        The parameter sets.
    max_real_part : numpy.ndarray, shape (ny, nx)
        Largest real part of the poles at each grid point. [1/s]
    stable : numpy.ndarray of bool, shape (ny, nx)
        True where every pole has real part < −δ (module notes).
    """

    grid: ParameterGrid
    max_real_part: np.ndarray
    stable: np.ndarray

    @property
    def stable_fraction(self) -> float:
        """Fraction of grid points that are stable. [-]"""
        return float(self.stable.mean())

    def write_csv(self, stream: IO[str], *, rows_per_block: int = 100_000,
                  progress: Callable[[int, int], None] | None = None) -> None:
        """Write ``x name, y name, max_real_part, stable`` rows (stable as 1/0).

        One row per grid point, row-major (x fastest); x, y in their units,
        max_real_part in [1/s], numbers with 12 significant digits.

        Parameters
        ----------
        stream : text stream
            Where to write (opened with ``newline=""``).
        rows_per_block : int, optional
            Rows formatted at a time. [-]
        progress : callable(done, total), optional
            Called after each block with the rows written and the total. [-]
        """
        g = self.grid
        stream.write(f"{g.x.name},{g.y.name},max_real_part,stable\n")
        nx = g.x_values.size
        flat_re = self.max_real_part.ravel()
        flat_st = self.stable.ravel()
        for start in range(0, g.size, rows_per_block):
            stop = min(g.size, start + rows_per_block)
            idx = np.arange(start, stop)
            block = np.column_stack([g.x_values[idx % nx], g.y_values[idx // nx],
                                     flat_re[start:stop], flat_st[start:stop]])
            # one %-format of the whole block: the same text as numpy.savetxt, 2× faster
            row_format = "%.12g,%.12g,%.12g,%d\n" * (stop - start)
            stream.write(row_format % tuple(block.ravel().tolist()))
            if progress is not None:
                progress(stop, g.size)


def stability_map(
    x: ParameterRange | tuple[str, float, float],
    y: ParameterRange | tuple[str, float, float],
    resolution: int | tuple[int, int] = 200,
    *,
    case: str = "1",
    viscosity_ratio: float | None = None,
    body: Body | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> StabilityMap:
    """Largest real part and stability over a two-parameter grid of the paper model.

    Parameters
    ----------
    x, y, resolution, case, viscosity_ratio
        As in :func:`parameter_grid`.
    body : Body, optional
        Three-link body; the paper's by default.
    progress : callable(done, total), optional
        Called after each block of sets with the number of sets done and the
        total. [-]

    Returns
    -------
    StabilityMap
    """
    grid = parameter_grid(x, y, resolution, case=case, viscosity_ratio=viscosity_ratio)
    body = paper_body() if body is None else body
    ny, nx = grid.shape
    max_real = np.empty((ny, nx))
    stable = np.empty((ny, nx), dtype=bool)
    rows_per_block = max(1, 131_072 // nx)
    done = 0
    if progress is not None:
        progress(0, grid.size)
    for start in range(0, ny, rows_per_block):
        stop = min(ny, start + rows_per_block)
        stiffness, ratio = grid.rows(start, stop)
        res = batch_analyse(stiffness, ratio, body=body)
        max_real[start:stop] = res.max_real_part.reshape(stop - start, nx)
        stable[start:stop] = res.stable.reshape(stop - start, nx)
        done += (stop - start) * nx
        if progress is not None:
            progress(done, grid.size)
    return StabilityMap(grid, max_real, stable)

