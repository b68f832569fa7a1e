"""The compiled kernels of :mod:`posturelab.linear.batch` and the thread pool that runs them.

Everything per parameter set runs in one compiled entry point, :func:`batch_kernel`
(``nogil=True``), in one of three modes: the coefficients of the characteristic
polynomial p(s) = det(s² J0 + s L + K − g diag(a)) (ascending powers), the
Routh–Hurwitz stable flags, or all 2N roots (Aberth–Ehrlich) with the largest
real part and the flag. The matrices come from the one linear system
(:meth:`posturelab.linear.system.LinearSystem.without_delay`); the kernels do not
build them. The helpers it calls are kernels without a Python wrapper
(:func:`posturelab._jit.kernel`); the mathematics is described in
:mod:`posturelab.linear.batch`.

:func:`run` allocates the outputs and calls the entry point on blocks of sets from
a small thread pool (one thread per core, ``NUMBA_NUM_THREADS``): measured as fast
as ``parallel=True``/``prange`` on two cores, it compiles in half the time and is
safe to call from several Python threads at once.

The kernels are compiled without floating-point contraction (``fastmath=False``), so a
stability map's CSV does not change with the compiler's choice of fused multiply-adds.

Units: stiffness [N·m/rad], viscosity [N·m·s/rad], viscosity ratio [s], inertia
[kg·m²], gravity torque per angle g·a [N·m/rad], poles [1/s].
"""

from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .._jit import kernel

#: Relative stability margin: stable means every Re λ < −STABILITY_MARGIN·max(1, ρ). [-]
STABILITY_MARGIN = 1e-9

MAX_ITERATIONS = 80  # Aberth iterations before the caller falls back to eigvals [-]
WARM_ITERATIONS = 12  # Aberth iterations from a neighbour's roots before a cold start [-]
MIN_BLOCK = 4096  # fewest parameter sets worth a thread of their own [-]
_EPS = float(np.finfo(float).eps)

MODE_COEFFICIENTS = 0  # characteristic polynomial coefficients only
MODE_FLAGS = 1  # Routh–Hurwitz flags only
MODE_POLES = 2  # roots: largest real part and flags (and the poles if asked)


@kernel(fastmath=False)
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


@kernel(inline="always", fastmath=False)
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


@kernel(fastmath=False)
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


@kernel(fastmath=False)
def _margin(coef):
    """δ = STABILITY_MARGIN · max(1, ρ) for ``coef`` (ascending) [1/s]; see
    :mod:`posturelab.linear.batch`, *Stability margin*."""
    deg = coef.shape[0] - 1
    lead = abs(coef[deg])
    rho = max(1.0, abs(coef[deg - 1]) / lead, math.sqrt(abs(coef[deg - 2]) / lead))
    return STABILITY_MARGIN * rho


@kernel(fastmath=False)
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


@kernel(fastmath=False)
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


def start_directions(degree: int) -> np.ndarray:
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


@kernel(fastmath=False)
def _start(c, deg, deg_full, z, hull, logs, directions):
    """Aberth starting points of ``c`` (degree ``deg``) into ``z``."""
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


@kernel(fastmath=False)
def _aberth(coef, roots, done, hull, logs, directions, max_iterations, warm):
    """All roots of the real polynomial ``coef`` (ascending) into ``roots``.

    ``directions`` is :func:`start_directions` of the full degree. Returns True
    on convergence. Exact zero roots are split off first. ``warm``: start from the
    values in ``roots`` (the roots of a neighbouring polynomial) instead of the
    Newton polygon's (when no root is zero).
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
    if not (warm and low == 0):
        _start(c, deg, deg_full, z, hull, logs, directions)
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


@kernel(fastmath=False)
def _tidy_roots(roots, paired, sort):
    """Make conjugate pairs exact and near-real roots real, then (``sort``) sort like
    sorted_poles; the largest real part does not depend on the order."""
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
    if not sort:
        return
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


@kernel(nogil=True, entry=True, fastmath=False)
def batch_kernel(start, stop, mode, inertia, damp, load, masks, mask_start, directions,
                 max_iterations, keep_poles, chain, coefficients, poles, max_real, stable,
                 converged):
    """Sets ``start:stop`` in one of three modes (one compiled function, GIL released).

    ``inertia``, ``damp`` and ``load`` are J0, L and K − g diag(a) of
    :meth:`posturelab.linear.system.LinearSystem.without_delay`, each with a first axis
    of M sets or 1 (shared). With ``chain`` > 0, the roots of set i start from those of
    set i − 1 unless i is a multiple of ``chain`` (neighbouring sets of a map).
    """
    n = inertia.shape[1]
    if start < stop:
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
        previous = False  # the roots of set i − 1 are in ``roots``
        for i in range(start, stop):
            jac = inertia[i if inertia.shape[0] > 1 else 0]
            d = damp[i if damp.shape[0] > 1 else 0]
            k = load[i if load.shape[0] > 1 else 0]
            if n == 3:
                _polynomial_determinant3(jac, d, k, coef)
            else:
                _polynomial_determinant(jac, d, k, masks, mask_start, minors, coef)
            if mode == MODE_COEFFICIENTS:
                for j in range(2 * n + 1):
                    coefficients[i, j] = coef[j]
            elif mode == MODE_FLAGS:
                stable[i] = _routh_stable(coef, shifted, row_a, row_b, row_c)
            else:
                ok = False
                if previous and chain > 0 and i % chain != 0:
                    ok = _aberth(coef, roots, done, hull, logs, directions, WARM_ITERATIONS,
                                 True)
                if not ok:
                    ok = _aberth(coef, roots, done, hull, logs, directions, max_iterations,
                                 False)
                converged[i] = ok
                previous = ok and coef[0] != 0.0
                _tidy_roots(roots, done, keep_poles)
                top = roots[0].real
                for j in range(1, 2 * n):
                    if roots[j].real > top:
                        top = roots[j].real
                max_real[i] = top
                stable[i] = top < -_margin(coef)
                if keep_poles:
                    for j in range(2 * n):
                        poles[i, j] = roots[j]


def run(mode: int, matrices: tuple, n_sets: int, *, keep_poles: bool = False,
        max_iterations: int = MAX_ITERATIONS, chain: int = 0,
        threads: int | None = None) -> dict[str, np.ndarray]:
    """Allocate the outputs of ``mode`` (size-1 placeholders for the others) and run it.

    Parameters
    ----------
    mode : int
        MODE_COEFFICIENTS, MODE_FLAGS or MODE_POLES.
    matrices : tuple of numpy.ndarray
        (J0, L, K − g diag(a)), each (M or 1, N, N): the system without delay
        (:meth:`posturelab.linear.system.LinearSystem.without_delay`). [kg·m²],
        [N·m·s/rad], [N·m/rad]
    n_sets : int
        Number of parameter sets M. [-]
    keep_poles : bool, optional
        MODE_POLES: also return all 2N poles of every set. [1/s]
    max_iterations : int, optional
        Aberth iterations before a set counts as not converged. [-]
    chain : int, optional
        Warm-start the roots of each set from the previous one, restarting at every
        multiple of ``chain`` (0: never); the blocks of the thread pool start at such
        multiples, so the result does not depend on the number of threads. [-]
    threads : int, optional
        At most this many threads (default: one per core). [-]

    Returns
    -------
    dict of numpy.ndarray
        ``coefficients`` (M, 2N + 1), ``poles`` (M, 2N) [1/s], ``max_real`` (M,) [1/s],
        ``stable`` (M,) and ``converged`` (M,); the ones ``mode`` does not fill have
        one row.
    """
    from numba import config

    n = matrices[0].shape[-1]

    def size(wanted: bool) -> int:
        return n_sets if wanted else 1

    out = {
        "coefficients": np.empty((size(mode == MODE_COEFFICIENTS), 2 * n + 1)),
        "poles": np.empty((size(mode == MODE_POLES and keep_poles), 2 * n),
                          dtype=np.complex128),
        "max_real": np.empty(size(mode == MODE_POLES)),
        "stable": np.empty(size(mode != MODE_COEFFICIENTS), dtype=np.bool_),
        "converged": np.empty(size(mode == MODE_POLES), dtype=np.bool_),
    }
    masks, mask_start = subset_tables(n)
    args = (mode, *(np.ascontiguousarray(m, dtype=float) for m in matrices), masks, mask_start,
            start_directions(2 * n), int(max_iterations), bool(keep_poles), int(chain),
            out["coefficients"], out["poles"], out["max_real"], out["stable"],
            out["converged"])
    limit = config.NUMBA_NUM_THREADS if threads is None else threads
    threads = max(1, min(limit, n_sets // MIN_BLOCK))
    if threads == 1:
        batch_kernel(0, n_sets, *args)
        return out
    # Blocks of sets on a thread pool: the kernel releases the GIL (nogil=True).
    bounds = np.linspace(0, n_sets, 4 * threads + 1).astype(np.int64)
    if chain > 0:  # each block starts a chain
        bounds = np.unique(np.minimum(n_sets, (bounds + chain - 1) // chain * chain))
    with ThreadPoolExecutor(max_workers=threads) as pool:
        jobs = [pool.submit(batch_kernel, int(a), int(b), *args)
                for a, b in zip(bounds[:-1], bounds[1:], strict=True)]
        for job in jobs:
            job.result()
    return out


def subset_tables(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Column subsets by size (sizes 1..N−1 all, size N only the full set), for the
    general determinant expansion."""
    masks: list[int] = []
    start = [0, 0]
    for size in range(1, n + 1):
        if size < n:
            masks.extend(s for s in range(1 << n) if bin(s).count("1") == size)
        else:
            masks.append((1 << n) - 1)
        start.append(len(masks))
    return np.array(masks, dtype=np.int64), np.array(start, dtype=np.int64)
