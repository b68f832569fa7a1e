"""Compiled kernels of the fast simulator (numba; every function ``cache=True``).

Everything here works on plain arrays; :mod:`posturelab.fast` packs bodies,
muscles, disturbances and options into them and unpacks the results. The
physics is that of :mod:`posturelab.dynamics` and :mod:`posturelab.simulate`
(DESIGN.md's closed form for N links). The integrators: Radau IIA of order 5
(``ipar[I_METHOD] = METHOD_RADAU``, the default of :mod:`posturelab.fast`;
scipy's ``Radau`` step by step, with the Newton systems reduced to N×N by the
structure of the Jacobian, see :func:`_block_solve`), the Dormand–Prince
5(4) pair of scipy's ``RK45`` (same tableau, error estimate and free
4th-order dense output) and the Bogacki–Shampine 3(2) pair of scipy's
``RK23`` (tableau, error estimate, cubic Hermite dense output, stored as a
quartic with a zero top coefficient). The explicit pairs use Hairer's PI
step-size controller (exponents from the method's error order; the powers
err^α by short log/exp approximations, deterministic and far more accurate
than step-size control needs).

Performance notes (measured; see benchmarks/bench_simulate.py)
--------------------------------------------------------------
* The paper's model is stiff (a real pole near −550 1/s for case 1): an
  explicit step is bounded by stability (RK45: 868 steps of 6 evaluations),
  Radau's by accuracy (166 steps of about 7 evaluations and two 3×3 solves,
  one real and one complex, per Newton iteration). For N = 3 the Newton
  iteration (:func:`_radau_newton3`) is straight-line scalar code around
  :func:`_f3`, with the reduced matrices inverted in closed form once per
  step size.
* For N = 3 a step is straight-line scalar code (:func:`_dp_step3`): no
  array round trips between stages, the 3×3 solve in closed form, and the
  sines and cosines of the stage angles rotated from those at the step's
  start by the angle-sum formulas (:func:`_rotate`), which is exact to
  rounding and shorter than libm's ``sin``/``cos``.
* Calling a compiled function that takes arrays costs atomic reference
  counting unless the callee is a straight-line leaf; the hot loop therefore
  calls only leaves, and the rest is inlined (``inline="always"``).
* ``error_model="numpy"``: a division by zero gives inf/NaN (caught as a
  failed step) instead of raising, which keeps the code free of exception
  paths.
* ``fastmath={"contract"}``: a·b + c may become one fused multiply-add (one
  rounding instead of two; shorter latency). No reassociation or other fast
  math, so a run is deterministic, and a batch row equals the single run bit
  for bit (tested).
* Lock-step structure-of-arrays across runs (several runs per thread, stages
  vectorised across them) was prototyped: about 180 ns per run-step with 8
  lanes against about 190–250 ns for the scalar step, before any per-run
  bookkeeping; not worth its complexity, so batches use one run per thread
  (``prange`` over chunks of runs).

Packed arrays
-------------
``mp`` (model, float64, length 2N + 3N² + 1)::

    [0, N)            a_i [kg·m]
    [N, 2N)           J_ii [kg·m²]
    [2N, 2N+N²)       c_ij, row-major [kg·m²]
    [2N+N², 2N+2N²)   K = Eᵀ diag(k_d·active) E, row-major [N·m/rad]
    [2N+2N², 2N+3N²)  L = Eᵀ diag(l_d·active) E, row-major [N·m·s/rad]
    2N+3N²            g [m/s²]

``dp`` (disturbance, float64): ``dp[0]`` = number of components Q, then Q
rows of five numbers (kind, axis, p0, p1, p2) with the ``DIST_*`` codes
below, then the measured profiles: a ``DIST_PROFILE`` row has p0 = the index
in ``dp`` of its S sample times and p1 = S; its x and then y accelerations
follow the times.

Other arguments: ``E`` (P, N) selection matrix, ``kd``/``ld`` (P,) pair
stiffness [N·m/rad] and viscosity [N·m·s/rad], ``one_sided`` (P,) 0/1,
``bps`` sorted breakpoints inside (0, duration) [s], ``grid`` output times
[s], ``fpar``/``ipar`` scalars at the ``F_*``/``I_*`` indices.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

# ---------------------------------------------------------------------------
# Codes shared with the Python layer
# ---------------------------------------------------------------------------

STATUS_COMPLETED = 0
STATUS_FELL = 1
STATUS_STEP_TOO_SMALL = 2
STATUS_NONFINITE = 3
STATUS_CHATTERING = 4

KNEE_FREE = 0
KNEE_LOCKED = 1
KNEE_STOP = 2

#: a = p0 · sin(π s), s = (t − p2)/p1 in [0, 1]: (peak [m/s²], duration [s], start [s])
DIST_HALF_SINE = 1
#: a = p0 · sin(2π s), s = (t − p2)/p1 in [0, 1]: (peak 2πD/T² [m/s²], T [s], start [s])
DIST_RAMP_AND_HOLD = 2
#: a = p0 sin(2π p1 t + p2): (amplitude [m/s²], frequency [Hz], phase [rad])
DIST_SINE = 3
#: linear interpolation of a packed profile, zero outside: (index of times, S, 0)
DIST_PROFILE = 4

EV_LINK = 0
EV_TOE = 1
EV_HEEL = 2
EV_PAIR = 3
EV_KNEE_HIT = 4
EV_KNEE_RELEASE = 5

# fpar indices
F_GRAVITY = 0
F_TOTAL_MASS = 1
F_MAX_ANGLE = 2
F_HEEL = 3
F_TOE = 4
F_STOP_ANGLE = 5
F_RTOL = 6
F_ATOL = 7
F_MAX_STEP = 8
F_DURATION = 9
F_SWITCH_HYST = 10
F_RELEASE_HYST = 11
F_SETTLE_TOL = 12
N_FPAR = 13

# ipar indices
I_USE_BOS = 0
I_KNEE_MODE = 1
I_MAX_SWITCHES = 2
I_LOCKED0 = 3
I_METHOD = 4
N_IPAR = 5

METHOD_RK45 = 0
METHOD_RK23 = 1
METHOD_RADAU = 2

# layout of the result vector of _integrate
R_STATUS = 0
R_N_SAMPLES = 1
R_FALL_KIND = 2
R_FALL_TIME = 3
R_N_SWITCHES = 4
R_T_REACHED = 5
R_N_STEPS = 6
R_N_REJECTED = 7
R_N_EVALS = 8
R_LAST_OUTSIDE = 9
R_ANY_OUTSIDE = 10
R_FINAL_OUTSIDE = 11
R_FALL_SAMPLE = 12  # 1 when the state at the fall closes the series, off the grid
N_RESULT = 13

_EPS = 2.220446049250313e-16
#: Floating-point contraction only (a·b + c as one fused multiply-add, one rounding): no
#: reassociation or other "fast math", so results stay deterministic and as accurate.
_CONTRACT = {"contract"}

# ---------------------------------------------------------------------------
# Dormand–Prince 5(4): the tableau of scipy's RK45 (Dormand & Prince 1980), its
# error estimate and its free 4th-order dense output (Shampine's optimum c6)
# ---------------------------------------------------------------------------

_C2, _C3, _C4, _C5 = 1 / 5, 3 / 10, 4 / 5, 8 / 9
_A21 = 1 / 5
_A31, _A32 = 3 / 40, 9 / 40
_A41, _A42, _A43 = 44 / 45, -56 / 15, 32 / 9
_A51, _A52, _A53, _A54 = 19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729
_A61, _A62, _A63, _A64, _A65 = 9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656
_B1, _B3, _B4, _B5, _B6 = 35 / 384, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84
_E1, _E3, _E4, _E5, _E6, _E7 = (-71 / 57600, 71 / 16695, -71 / 1920, 17253 / 339200,
                                -22 / 525, 1 / 40)
_P = np.array([
    [1, -8048581381 / 2820520608, 8663915743 / 2820520608, -12715105075 / 11282082432],
    [0, 0, 0, 0],
    [0, 131558114200 / 32700410799, -68118460800 / 10900136933, 87487479700 / 32700410799],
    [0, -1754552775 / 470086768, 14199869525 / 1410260304, -10690763975 / 1880347072],
    [0, 127303824393 / 49829197408, -318862633887 / 49829197408,
     701980252875 / 199316789632],
    [0, -282668133 / 205662961, 2019193451 / 616988883, -1453857185 / 822651844],
    [0, 40617522 / 29380423, -110615467 / 29380423, 69997945 / 29380423],
])

# Hairer's PI step-size control of DOPRI5 (Hairer, Nørsett & Wanner, Solving ODEs I,
# Sec. II.4 and IV.2; dopri5.f): beta = 0.04, safety 0.9, step factor in [0.2, 10].
_BETA = 0.04
_EXPO1 = 0.2 - _BETA * 0.75
_SAFE = 0.9
_FACC1 = 1.0 / 0.2
_FACC2 = 1.0 / 10.0
_LOG_ERR_FLOOR = math.log(1e-4)

# ---------------------------------------------------------------------------
# Bogacki–Shampine 3(2): the tableau of scipy's RK23 (FSAL, three new evaluations per
# step), its error estimate and its cubic Hermite dense output
# ---------------------------------------------------------------------------

_BS_C2, _BS_C3 = 1 / 2, 3 / 4
_BS_A21 = 1 / 2
_BS_A32 = 3 / 4
_BS_B1, _BS_B2, _BS_B3 = 2 / 9, 1 / 3, 4 / 9
_BS_E1, _BS_E2, _BS_E3, _BS_E4 = 5 / 72, -1 / 12, -1 / 9, 1 / 8
_BS_P = np.array([
    [1, -4 / 3, 5 / 9],
    [0, 1, -2 / 3],
    [0, 4 / 3, -8 / 9],
    [0, -1, 1],
])
# PI control of the 3(2) pair (error order 3): h ← h · 0.9 · err^−α · errold^β
_BS_BETA = 0.04
_BS_EXPO1 = 1.0 / 3.0 - _BS_BETA * 0.75
_LN2 = 0.6931471805599453
_SQRT_HALF = 0.7071067811865476


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT, inline="always")
def _log_approx(x):
    """ln x for finite x > 0 to about 1e-6 relative (step-size control needs no more):
    x = m·2^e, ln m = −ln2/2 + 2 atanh z, z = (m − √½)/(m + √½), |z| <= 0.172."""
    m, e = math.frexp(x)
    z = (m - _SQRT_HALF) / (m + _SQRT_HALF)
    z2 = z * z
    return (e - 0.5) * _LN2 + 2.0 * z * (1.0 + z2 * (1.0 / 3.0 + z2 * (1.0 / 5.0
                                                                       + z2 * (1.0 / 7.0))))


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT, inline="always")
def _exp_approx(y):
    """e^y for −700 < y < 700 to about 1e-7 relative: 2^k e^r, |r| <= ln2/2."""
    k = math.floor(y * (1.0 / _LN2) + 0.5)
    r = y - k * _LN2
    p = 1.0 + r * (1.0 + r * (0.5 + r * (1.0 / 6.0 + r * (1.0 / 24.0 + r * (
        1.0 / 120.0 + r * (1.0 / 720.0 + r * (1.0 / 5040.0)))))))
    return math.ldexp(p, int(k))


#: steps between fresh libm sines/cosines of the step's start angles (see _rotate)
_TRIG_REFRESH = 64

# ---------------------------------------------------------------------------
# Platform acceleration
# ---------------------------------------------------------------------------


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT, inline="always")
def _interp0(t, dp, first, count, col):
    """numpy.interp(t, xp, fp, left=0, right=0) with xp = dp[first:first+count] and fp the
    ``col``-th block of ``count`` values after it."""
    lo = first
    hi = first + count - 1
    val = 0.0
    if t >= dp[lo] and t <= dp[hi]:
        off = col * count
        if t == dp[hi]:
            val = dp[hi + off]
        else:
            while hi - lo > 1:
                mid = (lo + hi) >> 1
                if dp[mid] <= t:
                    lo = mid
                else:
                    hi = mid
            slope = (dp[lo + 1 + off] - dp[lo + off]) / (dp[lo + 1] - dp[lo])
            val = slope * (t - dp[lo]) + dp[lo + off]
    return val


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT, inline="always")
def platform_acceleration(t, dp):
    """(ẍ_d, ÿ_d) at time t [s] from the packed disturbance. [m/s²]"""
    ax = 0.0
    ay = 0.0
    nq = int(dp[0])
    for q in range(nq):
        r = 1 + 5 * q
        kind = int(dp[r])
        v = 0.0
        if kind == DIST_HALF_SINE:
            s = (t - dp[r + 4]) / dp[r + 3]
            if s >= 0.0 and s <= 1.0:
                v = dp[r + 2] * math.sin(math.pi * s)
        elif kind == DIST_RAMP_AND_HOLD:
            s = (t - dp[r + 4]) / dp[r + 3]
            if s >= 0.0 and s <= 1.0:
                v = dp[r + 2] * math.sin(2.0 * math.pi * s)
        elif kind == DIST_SINE:
            v = dp[r + 2] * math.sin(2.0 * math.pi * dp[r + 3] * t + dp[r + 4])
        elif kind == DIST_PROFILE:
            first = int(dp[r + 2])
            count = int(dp[r + 3])
            ax += _interp0(t, dp, first, count, 1)
            ay += _interp0(t, dp, first, count, 2)
        if kind != DIST_PROFILE:
            if dp[r + 1] == 0.0:
                ax += v
            else:
                ay += v
    return ax, ay


# ---------------------------------------------------------------------------
# Equations of motion
# ---------------------------------------------------------------------------


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _joint_matrices(E, kd, ld, active, mp, n):
    """K = Eᵀ diag(kd·active) E and L = Eᵀ diag(ld·active) E into the packed model."""
    ok = 2 * n + n * n
    ol = ok + n * n
    for i in range(n):
        for j in range(n):
            sk = 0.0
            sl = 0.0
            for p in range(E.shape[0]):
                w = E[p, i] * E[p, j] * active[p]
                sk += w * kd[p]
                sl += w * ld[p]
            mp[ok + i * n + j] = sk
            mp[ol + i * n + j] = sl


# sin δ and cos δ − 1 by Taylor series: exact to rounding for |δ| <= _MAX_ROTATION [rad]
_MAX_ROTATION = 0.1
_SD3 = -1.0 / 6.0
_SD5 = 1.0 / 120.0
_SD7 = -1.0 / 5040.0
_SD9 = 1.0 / 362880.0
_CD2 = -0.5
_CD4 = 1.0 / 24.0
_CD6 = -1.0 / 720.0
_CD8 = 1.0 / 40320.0


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT, inline="always")
def _rotate(theta, theta_b, s_b, c_b):
    """(sin θ, cos θ) from (sin θ_b, cos θ_b) of a nearby θ_b by the angle-sum formulas.

    δ = θ − θ_b is a few hundredths of a radian within a step; the series of
    sin δ (to δ⁹) and cos δ (to δ⁸) are exact to rounding for |δ| <= 0.1.
    Farther away, libm. With θ = θ_b the result is (s_b, c_b) exactly.
    """
    d = theta - theta_b
    if abs(d) > _MAX_ROTATION:
        return math.sin(theta), math.cos(theta)
    z = d * d
    sd = d + d * z * (_SD3 + z * (_SD5 + z * (_SD7 + z * _SD9)))
    cdm1 = z * (_CD2 + z * (_CD4 + z * (_CD6 + z * _CD8)))
    return s_b + (s_b * cdm1 + c_b * sd), c_b + (c_b * cdm1 - s_b * sd)


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT, inline="always")
def _f3(th1, th2, th3, w1, w2, w3, locked, mp, ax, ay,
        tb1, tb2, tb3, sb1, sb2, sb3, cb1, cb2, cb3):
    """[Θ̇, Θ̈] of a 3-link chain as scalars: straight-line code, closed-form 3×3 solve.

    ``mp`` is the packed model as a tuple (:func:`_model_tuple3`), (ax, ay) the
    platform acceleration [m/s²]. The sines and cosines are rotated from those
    of (tb1, tb2, tb3) (see :func:`_rotate`). Only scalars and tuples come in:
    an inlined function that takes arrays costs reference counting. Returns
    ((θ̇1, θ̇2, θ̇3, θ̈1, θ̈2, θ̈3), (sin θ1…3, cos θ1…3)).
    """
    s1, c1 = _rotate(th1, tb1, sb1, cb1)
    s2, c2 = _rotate(th2, tb2, sb2, cb2)
    s3, c3 = _rotate(th3, tb3, sb3, cb3)
    ga = mp[33] + ay
    # U = −(K Θ + L Θ̇); K at mp[15:24], L at mp[24:33]
    u1 = -((mp[15] * th1 + mp[16] * th2 + mp[17] * th3)
           + (mp[24] * w1 + mp[25] * w2 + mp[26] * w3))
    u2 = -((mp[18] * th1 + mp[19] * th2 + mp[20] * th3)
           + (mp[27] * w1 + mp[28] * w2 + mp[29] * w3))
    u3 = -((mp[21] * th1 + mp[22] * th2 + mp[23] * th3)
           + (mp[30] * w1 + mp[31] * w2 + mp[32] * w3))
    c12 = mp[7]
    c13 = mp[8]
    c23 = mp[11]
    # cos(θj − θi) and c_ij sin(θi − θj) from the angle-sum identities
    k12 = c1 * c2 + s1 * s2
    k13 = c1 * c3 + s1 * s3
    k23 = c2 * c3 + s2 * s3
    n12 = c12 * (s1 * c2 - c1 * s2)
    n13 = c13 * (s1 * c3 - c1 * s3)
    n23 = c23 * (s2 * c3 - c2 * s3)
    q1 = w1 * w1
    q2 = w2 * w2
    q3 = w3 * w3
    # r = U − BΘ̇ + (g + ÿ_d) G − ẍ_d H
    r1 = u1 - (n12 * q2 + n13 * q3) + mp[0] * (ga * s1 - ax * c1)
    r2 = u2 - (n23 * q3 - n12 * q1) + mp[1] * (ga * s2 - ax * c2)
    r3 = u3 + (n13 * q1 + n23 * q2) + mp[2] * (ga * s3 - ax * c3)
    j11 = mp[3]
    j22 = mp[4]
    j33 = mp[5]
    j12 = c12 * k12
    j13 = c13 * k13
    j23 = c23 * k23
    # adjugate of the symmetric J
    m11 = j22 * j33 - j23 * j23
    m12 = j13 * j23 - j12 * j33
    m13 = j12 * j23 - j13 * j22
    m22 = j11 * j33 - j13 * j13
    m23 = j12 * j13 - j11 * j23
    m33 = j11 * j22 - j12 * j12
    inv_det = 1.0 / (j11 * m11 + j12 * m12 + j13 * m13)
    a1 = (m11 * r1 + m12 * r2 + m13 * r3) * inv_det
    a2 = (m12 * r1 + m22 * r2 + m23 * r3) * inv_det
    a3 = (m13 * r1 + m23 * r2 + m33 * r3) * inv_det
    if locked:
        # knee constraint C = (−1, 1, 0): Θ̈ −= J⁻¹C (C·Θ̈) / (C·J⁻¹C)
        y1 = m12 - m11
        y2 = m22 - m12
        y3 = m23 - m13
        lam = (a2 - a1) / (y2 - y1)
        a1 -= y1 * lam
        a2 -= y2 * lam
        a3 -= y3 * lam
    return (w1, w2, w3, a1, a2, a3), (s1, s2, s3, c1, c2, c3)


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _model_tuple3(mp):
    """The packed 3-link model (34 numbers) as a tuple."""
    return (mp[0], mp[1], mp[2], mp[3], mp[4], mp[5], mp[6], mp[7], mp[8], mp[9], mp[10],
            mp[11], mp[12], mp[13], mp[14], mp[15], mp[16], mp[17], mp[18], mp[19], mp[20],
            mp[21], mp[22], mp[23], mp[24], mp[25], mp[26], mp[27], mp[28], mp[29], mp[30],
            mp[31], mp[32], mp[33])


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _deriv3(t, x, out, row, locked, mp, dp):
    """[Θ̇, Θ̈] of a 3-link chain at (t, x) into out[row] (sines and cosines from libm)."""
    s1 = math.sin(x[0])
    s2 = math.sin(x[1])
    s3 = math.sin(x[2])
    c1 = math.cos(x[0])
    c2 = math.cos(x[1])
    c3 = math.cos(x[2])
    if dp[0] > 0.0:
        ax, ay = platform_acceleration(t, dp)
    else:
        ax = 0.0
        ay = 0.0
    d, _ = _f3(x[0], x[1], x[2], x[3], x[4], x[5], locked, _model_tuple3(mp), ax, ay,
               x[0], x[1], x[2], s1, s2, s3, c1, c2, c3)
    for i in range(6):
        out[row, i] = d[i]


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT, inline="always")
def _solve_into(M, n, ncol):
    """Gaussian elimination with partial pivoting on the augmented M[:n, :n+ncol], in place;
    the solutions replace the last ``ncol`` columns."""
    for k in range(n):
        piv = k
        big = abs(M[k, k])
        for i in range(k + 1, n):
            if abs(M[i, k]) > big:
                big = abs(M[i, k])
                piv = i
        if piv != k:
            for j in range(k, n + ncol):
                tmp = M[k, j]
                M[k, j] = M[piv, j]
                M[piv, j] = tmp
        inv = 1.0 / M[k, k]
        for i in range(k + 1, n):
            f = M[i, k] * inv
            if f != 0.0:
                for j in range(k + 1, n + ncol):
                    M[i, j] -= f * M[k, j]
    for c in range(ncol):
        col = n + c
        for i in range(n - 1, -1, -1):
            s = M[i, col]
            for j in range(i + 1, n):
                s -= M[i, j] * M[j, col]
            M[i, col] = s / M[i, i]


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _derivN(t, x, out, row, locked, mp, dp, work):
    """[Θ̇, Θ̈] of an N-link chain into out[row] (Gaussian elimination); work is (N, N + 4)."""
    n = x.size // 2
    oc = 2 * n
    ok = oc + n * n
    ol = ok + n * n
    if dp[0] > 0.0:
        ax, ay = platform_acceleration(t, dp)
    else:
        ax = 0.0
        ay = 0.0
    ga = mp[ol + n * n] + ay
    for i in range(n):
        work[i, n + 2] = math.sin(x[i])
        work[i, n + 3] = math.cos(x[i])
    for i in range(n):
        si = work[i, n + 2]
        ci = work[i, n + 3]
        r = mp[i] * (ga * si - ax * ci)
        for j in range(n):
            r -= mp[ok + i * n + j] * x[j] + mp[ol + i * n + j] * x[n + j]
            if j != i:
                sj = work[j, n + 2]
                cj = work[j, n + 3]
                cij = mp[oc + i * n + j]
                r -= cij * (si * cj - ci * sj) * x[n + j] * x[n + j]
                work[i, j] = cij * (ci * cj + si * sj)
            else:
                work[i, j] = mp[n + i]
        work[i, n] = r
        work[i, n + 1] = 0.0
    ncol = 1
    if locked:
        work[0, n + 1] = -1.0
        work[1, n + 1] = 1.0
        ncol = 2
    _solve_into(work, n, ncol)
    if locked:
        lam = (work[1, n] - work[0, n]) / (work[1, n + 1] - work[0, n + 1])
        for i in range(n):
            work[i, n] -= work[i, n + 1] * lam
    for i in range(n):
        out[row, i] = x[n + i]
        out[row, n + i] = work[i, n]


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _deriv(t, x, out, row, locked, mp, dp, work):
    """[Θ̇, Θ̈] at (t, x) into out[row], free or with the knee locked."""
    if x.size == 6:
        _deriv3(t, x, out, row, locked, mp, dp)
    else:
        _derivN(t, x, out, row, locked, mp, dp, work)


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def state_derivative(t, x, locked, mp0, E, kd, ld, active, dp):
    """[Θ̇, Θ̈] [rad/s, rad/s²] at one state, pairs weighted by ``active`` (0/1)."""
    n = x.size // 2
    mp = mp0.copy()
    _joint_matrices(E, kd, ld, active, mp, n)
    out = np.empty((1, 2 * n))
    work = np.empty((n, n + 4))
    _deriv(t, x, out, 0, locked, mp, dp, work)
    return out[0].copy()


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def project_velocity(theta, omega, mp):
    """Plastic impact onto the knee constraint: Θ̇ − J⁻¹C (C·Θ̇)/(C·J⁻¹C), C = (−1, 1, 0…)."""
    n = theta.size
    M = np.empty((n, n + 1))
    for i in range(n):
        for j in range(n):
            if i == j:
                M[i, j] = mp[n + i]
            else:
                M[i, j] = mp[2 * n + i * n + j] * math.cos(theta[j] - theta[i])
        M[i, n] = 0.0
    M[0, n] = -1.0
    M[1, n] = 1.0
    _solve_into(M, n, 1)
    lam = (omega[1] - omega[0]) / (M[1, n] - M[0, n])
    out = np.empty(n)
    for i in range(n):
        out[i] = omega[i] - M[i, n] * lam
    return out


# ---------------------------------------------------------------------------
# Events
# ---------------------------------------------------------------------------


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT, inline="always")
def _simple_event_value(kind, par, sgn, y, mp, E, fpar):
    """A fall, pair or knee-hit event function at state y."""
    n = y.size // 2
    if kind == EV_LINK:
        val = fpar[F_MAX_ANGLE] - abs(y[par])
    elif kind == EV_PAIR:
        val = sgn * fpar[F_SWITCH_HYST]
        for j in range(n):
            val += E[par, j] * y[j]
    elif kind == EV_KNEE_HIT:
        val = (y[1] - y[0]) - fpar[F_STOP_ANGLE] - fpar[F_SWITCH_HYST]
    else:
        xc = 0.0
        for i in range(n):
            xc += mp[i] * math.sin(y[i])
        xc /= fpar[F_TOTAL_MASS]
        val = fpar[F_TOE] - xc if kind == EV_TOE else xc - fpar[F_HEEL]
    return val


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _release_value(t, y, mp, fpar, dp, scratch, work):
    """Knee release: the free (unconstrained) knee acceleration, plus the release hysteresis."""
    n = y.size // 2
    _deriv(t, y, scratch, 0, False, mp, dp, work)
    return scratch[0, n + 1] - scratch[0, n] + fpar[F_RELEASE_HYST]


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _event_value(kind, par, sgn, t, y, mp, E, fpar, dp, scratch, work):
    """Any event function at (t, y); ``scratch`` is a (1, 2N) array."""
    if kind == EV_KNEE_RELEASE:
        return _release_value(t, y, mp, fpar, dp, scratch, work)
    return _simple_event_value(kind, par, sgn, y, mp, E, fpar)


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _build_events(n, one_sided, active, knee_mode, locked, use_bos, ev_kind, ev_par,
                  ev_sgn, ev_dir):
    """The event list of a smooth segment, in the reference's order; returns its length.

    Falls (links, then toe and heel), one-sided pairs (an acting pair waits for
    its stretch to fall below −hysteresis, a slack one to rise above
    +hysteresis), then the knee stop (hit while free, release while locked).
    """
    m = 0
    for i in range(n):
        ev_kind[m] = EV_LINK
        ev_par[m] = i
        ev_sgn[m] = 0.0
        ev_dir[m] = -1
        m += 1
    if use_bos:
        for kind in (EV_TOE, EV_HEEL):
            ev_kind[m] = kind
            ev_par[m] = 0
            ev_sgn[m] = 0.0
            ev_dir[m] = -1
            m += 1
    for p in range(one_sided.size):
        if one_sided[p]:
            ev_kind[m] = EV_PAIR
            ev_par[m] = p
            if active[p] > 0.0:
                ev_sgn[m] = 1.0
                ev_dir[m] = -1
            else:
                ev_sgn[m] = -1.0
                ev_dir[m] = 1
            m += 1
    if knee_mode == KNEE_STOP:
        ev_par[m] = 0
        ev_sgn[m] = 0.0
        if locked:
            ev_kind[m] = EV_KNEE_RELEASE
            ev_dir[m] = -1
        else:
            ev_kind[m] = EV_KNEE_HIT
            ev_dir[m] = 1
        m += 1
    return m


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _dense(y, Q, t0, h, t, out):
    """The step's 4th-order interpolant at t: y + Q·(σ, σ², σ³, σ⁴), σ = (t − t0)/h."""
    s = (t - t0) / h
    for i in range(y.size):
        out[i] = y[i] + s * (Q[i, 0] + s * (Q[i, 1] + s * (Q[i, 2] + s * Q[i, 3])))


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _event_root(kind, par, sgn, t0, t1, g0, g1, y0, Q, h, mp, E, fpar, dp, scratch, work, ys):
    """Root in [t0, t1] of one event function along the step's interpolant.

    Illinois regula falsi (bisection when a secant leaves the bracket), to the
    tolerance of scipy's brentq in solve_ivp: 4 ε (1 + |t|).
    """
    if g0 == 0.0:
        return t0
    if g1 == 0.0:
        return t1
    ta = t0
    tb = t1
    ga = g0
    gb = g1
    side = 0
    for _ in range(200):
        if abs(tb - ta) <= 4.0 * _EPS + 4.0 * _EPS * abs(tb):
            break
        tc = (ta * gb - tb * ga) / (gb - ga)
        if not (tc > min(ta, tb) and tc < max(ta, tb)):
            tc = 0.5 * (ta + tb)
        _dense(y0, Q, t0, h, tc, ys)
        gc = _event_value(kind, par, sgn, tc, ys, mp, E, fpar, dp, scratch, work)
        if gc == 0.0:
            return tc
        if (gc > 0.0) == (gb > 0.0):
            tb = tc
            gb = gc
            if side == -1:
                ga *= 0.5
            side = -1
        else:
            ta = tc
            ga = gc
            if side == 1:
                gb *= 0.5
            side = 1
    return 0.5 * (ta + tb)


# ---------------------------------------------------------------------------
# Steps
# ---------------------------------------------------------------------------


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _initial_step(t0, y0, f0, t_bound, max_step, rtol, atol, locked, mp, dp, work, y1, f1,
                  order):
    """scipy's select_initial_step (Hairer, Nørsett & Wanner, Sec. II.4) for a method whose
    error estimate has order ``order`` (4 for RK45, 2 for RK23).

    ``f0`` and ``f1`` are (≥1, 2N) arrays whose row 0 holds a derivative.
    """
    m = y0.size
    interval = t_bound - t0
    if interval <= 0.0:
        return 0.0
    d0 = 0.0
    d1 = 0.0
    for i in range(m):
        sc = atol + abs(y0[i]) * rtol
        d0 += (y0[i] / sc) ** 2
        d1 += (f0[0, i] / sc) ** 2
    d0 = math.sqrt(d0 / m)
    d1 = math.sqrt(d1 / m)
    if d0 < 1e-5 or d1 < 1e-5:
        h0 = 1e-6
    else:
        h0 = 0.01 * d0 / d1
    h0 = min(h0, interval)
    for i in range(m):
        y1[i] = y0[i] + h0 * f0[0, i]
    _deriv(t0 + h0, y1, f1, 0, locked, mp, dp, work)
    d2 = 0.0
    for i in range(m):
        sc = atol + abs(y0[i]) * rtol
        d2 += ((f1[0, i] - f0[0, i]) / sc) ** 2
    d2 = math.sqrt(d2 / m) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / (order + 1.0))
    return min(100.0 * h0, h1, interval, max_step)


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT, inline="always")
def _error_norm(h, x, y, stg, m, rtol, atol):
    """Mean square of the scaled embedded error estimate h Σ e_j k_j (the square of scipy's
    RK45 error norm)."""
    acc = 0.0
    for i in range(m):
        e = ((_E1 * stg[0, i] + _E3 * stg[2, i]) + (_E4 * stg[3, i] + _E5 * stg[4, i])
             + (_E6 * stg[5, i] + _E7 * stg[6, i]))
        sc = atol + rtol * max(abs(x[i]), abs(y[i]))
        e = h * e / sc
        acc += e * e
    return acc / m


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _stage_accelerations(t, h, t_new, dp, out):
    """(ẍ_d, ÿ_d) at the six stage times of a step into out (12,). [m/s²]"""
    for s in range(6):
        if s == 0:
            ts = t + _C2 * h
        elif s == 1:
            ts = t + _C3 * h
        elif s == 2:
            ts = t + _C4 * h
        elif s == 3:
            ts = t + _C5 * h
        elif s == 4:
            ts = t + h
        else:
            ts = t_new
        ax, ay = platform_acceleration(ts, dp)
        out[2 * s] = ax
        out[2 * s + 1] = ay


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _bs_stage_accelerations(t, h, t_new, dp, out):
    """(ẍ_d, ÿ_d) at the three new stage times of a Bogacki–Shampine step into out. [m/s²]"""
    for s in range(3):
        if s == 0:
            ts = t + _BS_C2 * h
        elif s == 1:
            ts = t + _BS_C3 * h
        else:
            ts = t_new
        ax, ay = platform_acceleration(ts, dp)
        out[2 * s] = ax
        out[2 * s + 1] = ay


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _bs_step3(h, x, stg, ytmp, locked, mp, acc, base, trig, rtol, atol):
    """One Bogacki–Shampine 3(2) step of the 3-link chain, in scalars (scipy's RK23).

    As :func:`_dp_step3`: from (t, x) with stg[0] = f(t, x), writes the stages to
    stg[1:4] (stg[3] = f(t_new, y_new)), y_new to ``ytmp`` and its sines and
    cosines to ``trig``; returns the mean square of the scaled error estimate.
    ``acc`` (6,) holds the platform acceleration at the three new stage times.
    """
    prm = _model_tuple3(mp)
    x0 = x[0]
    x1 = x[1]
    x2 = x[2]
    x3 = x[3]
    x4 = x[4]
    x5 = x[5]
    tb1 = base[0]
    tb2 = base[1]
    tb3 = base[2]
    sb1 = base[3]
    sb2 = base[4]
    sb3 = base[5]
    cb1 = base[6]
    cb2 = base[7]
    cb3 = base[8]
    a0 = stg[0, 0]
    a1 = stg[0, 1]
    a2 = stg[0, 2]
    a3 = stg[0, 3]
    a4 = stg[0, 4]
    a5 = stg[0, 5]
    p = h * _BS_A21
    (b0, b1, b2, b3, b4, b5), _ = _f3(
        x0 + p * a0, x1 + p * a1, x2 + p * a2, x3 + p * a3, x4 + p * a4,
        x5 + p * a5, locked, prm, acc[0], acc[1], tb1, tb2, tb3, sb1, sb2, sb3, cb1, cb2, cb3)
    q = h * _BS_A32
    (c0, c1, c2, c3, c4, c5), _ = _f3(
        x0 + q * b0, x1 + q * b1, x2 + q * b2, x3 + q * b3, x4 + q * b4,
        x5 + q * b5, locked, prm, acc[2], acc[3], tb1, tb2, tb3, sb1, sb2, sb3, cb1, cb2, cb3)
    p = h * _BS_B1
    q = h * _BS_B2
    r = h * _BS_B3
    y0 = x0 + ((p * a0 + q * b0) + r * c0)
    y1 = x1 + ((p * a1 + q * b1) + r * c1)
    y2 = x2 + ((p * a2 + q * b2) + r * c2)
    y3 = x3 + ((p * a3 + q * b3) + r * c3)
    y4 = x4 + ((p * a4 + q * b4) + r * c4)
    y5 = x5 + ((p * a5 + q * b5) + r * c5)
    (k0, k1, k2, k3, k4, k5), tr = _f3(
        y0, y1, y2, y3, y4, y5, locked, prm, acc[4], acc[5],
        tb1, tb2, tb3, sb1, sb2, sb3, cb1, cb2, cb3)
    ytmp[0] = y0
    ytmp[1] = y1
    ytmp[2] = y2
    ytmp[3] = y3
    ytmp[4] = y4
    ytmp[5] = y5
    for i, val in enumerate((b0, b1, b2, b3, b4, b5)):
        stg[1, i] = val
    for i, val in enumerate((c0, c1, c2, c3, c4, c5)):
        stg[2, i] = val
    for i, val in enumerate((k0, k1, k2, k3, k4, k5)):
        stg[3, i] = val
    for i in range(6):
        trig[i] = tr[i]
    err0 = h * ((_BS_E1 * a0 + _BS_E2 * b0) + (_BS_E3 * c0 + _BS_E4 * k0))
    err1 = h * ((_BS_E1 * a1 + _BS_E2 * b1) + (_BS_E3 * c1 + _BS_E4 * k1))
    err2 = h * ((_BS_E1 * a2 + _BS_E2 * b2) + (_BS_E3 * c2 + _BS_E4 * k2))
    err3 = h * ((_BS_E1 * a3 + _BS_E2 * b3) + (_BS_E3 * c3 + _BS_E4 * k3))
    err4 = h * ((_BS_E1 * a4 + _BS_E2 * b4) + (_BS_E3 * c4 + _BS_E4 * k4))
    err5 = h * ((_BS_E1 * a5 + _BS_E2 * b5) + (_BS_E3 * c5 + _BS_E4 * k5))
    err0 /= atol + rtol * max(abs(x0), abs(y0))
    err1 /= atol + rtol * max(abs(x1), abs(y1))
    err2 /= atol + rtol * max(abs(x2), abs(y2))
    err3 /= atol + rtol * max(abs(x3), abs(y3))
    err4 /= atol + rtol * max(abs(x4), abs(y4))
    err5 /= atol + rtol * max(abs(x5), abs(y5))
    return (err0 * err0 + err1 * err1 + err2 * err2 + err3 * err3 + err4 * err4
            + err5 * err5) / 6.0


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _bs_stepN(t, t_new, h, x, stg, ytmp, m, locked, mp, dp, work, rtol, atol):
    """One Bogacki–Shampine step of an N-link chain (arrays; see :func:`_bs_step3`)."""
    for s in range(1, 4):
        if s == 1:
            for i in range(m):
                ytmp[i] = x[i] + h * (_BS_A21 * stg[0, i])
            ts = t + _BS_C2 * h
        elif s == 2:
            for i in range(m):
                ytmp[i] = x[i] + h * (_BS_A32 * stg[1, i])
            ts = t + _BS_C3 * h
        else:
            for i in range(m):
                ytmp[i] = x[i] + h * ((_BS_B1 * stg[0, i] + _BS_B2 * stg[1, i])
                                      + _BS_B3 * stg[2, i])
            ts = t_new
        _derivN(ts, ytmp, stg, s, locked, mp, dp, work)
    acc = 0.0
    for i in range(m):
        e = ((_BS_E1 * stg[0, i] + _BS_E2 * stg[1, i]) + (_BS_E3 * stg[2, i]
                                                          + _BS_E4 * stg[3, i]))
        sc = atol + rtol * max(abs(x[i]), abs(ytmp[i]))
        e = h * e / sc
        acc += e * e
    return acc / m


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _bs_dense_coefficients(Q, stg, h, m):
    """Q = h Kᵀ P of the Bogacki–Shampine step (cubic Hermite); Q[:, 3] = 0, so that the
    interpolant y + Q·(σ, σ², σ³, σ⁴) is the cubic exactly."""
    for i in range(m):
        for k in range(3):
            Q[i, k] = h * ((stg[0, i] * _BS_P[0, k] + stg[1, i] * _BS_P[1, k])
                           + (stg[2, i] * _BS_P[2, k] + stg[3, i] * _BS_P[3, k]))
        Q[i, 3] = 0.0


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _bs_dense_coefficients3(Q, stg, h):
    """As :func:`_bs_dense_coefficients` for the 6 states of 3 links (constant sizes)."""
    for k in range(3):
        p0 = h * _BS_P[0, k]
        p1 = h * _BS_P[1, k]
        p2 = h * _BS_P[2, k]
        p3 = h * _BS_P[3, k]
        for i in range(6):
            Q[i, k] = (stg[0, i] * p0 + stg[1, i] * p1) + (stg[2, i] * p2 + stg[3, i] * p3)
    for i in range(6):
        Q[i, 3] = 0.0


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _dp_step3(h, x, stg, ytmp, locked, mp, acc, base, trig, rtol, atol):
    """One Dormand–Prince step of the 3-link chain, in scalars.

    From (t, x) with stg[0] = f(t, x): writes the stages to stg[1:7]
    (stg[6] = f(t_new, y_new)), y_new to ``ytmp``, the sines and cosines of
    y_new's angles to ``trig``, and returns the mean square of the scaled error estimate
    (its RMS, scipy's error norm, squared).
    ``base`` = (θ, sin θ, cos θ) at the step's start (see :func:`_rotate`);
    ``acc`` (12,) the platform acceleration (ẍ_d, ÿ_d) at the six stage times.
    """
    prm = _model_tuple3(mp)
    x0 = x[0]
    x1 = x[1]
    x2 = x[2]
    x3 = x[3]
    x4 = x[4]
    x5 = x[5]
    tb1 = base[0]
    tb2 = base[1]
    tb3 = base[2]
    sb1 = base[3]
    sb2 = base[4]
    sb3 = base[5]
    cb1 = base[6]
    cb2 = base[7]
    cb3 = base[8]
    a0 = stg[0, 0]
    a1 = stg[0, 1]
    a2 = stg[0, 2]
    a3 = stg[0, 3]
    a4 = stg[0, 4]
    a5 = stg[0, 5]
    p = h * _A21
    (b0, b1, b2, b3, b4, b5), _ = _f3(
        x0 + p * a0, x1 + p * a1, x2 + p * a2, x3 + p * a3, x4 + p * a4,
        x5 + p * a5, locked, prm, acc[0], acc[1], tb1, tb2, tb3, sb1, sb2, sb3, cb1, cb2, cb3)
    p = h * _A31
    q = h * _A32
    (c0, c1, c2, c3, c4, c5), _ = _f3(
        x0 + (p * a0 + q * b0), x1 + (p * a1 + q * b1), x2 + (p * a2 + q * b2),
        x3 + (p * a3 + q * b3), x4 + (p * a4 + q * b4), x5 + (p * a5 + q * b5), locked, prm,
        acc[2], acc[3],
        tb1, tb2, tb3, sb1, sb2, sb3, cb1, cb2, cb3)
    p = h * _A41
    q = h * _A42
    r = h * _A43
    (d0, d1, d2, d3, d4, d5), _ = _f3(
        x0 + ((p * a0 + q * b0) + r * c0), x1 + ((p * a1 + q * b1) + r * c1),
        x2 + ((p * a2 + q * b2) + r * c2), x3 + ((p * a3 + q * b3) + r * c3),
        x4 + ((p * a4 + q * b4) + r * c4), x5 + ((p * a5 + q * b5) + r * c5), locked, prm,
        acc[4], acc[5],
        tb1, tb2, tb3, sb1, sb2, sb3, cb1, cb2, cb3)
    p = h * _A51
    q = h * _A52
    r = h * _A53
    u = h * _A54
    (e0, e1, e2, e3, e4, e5), _ = _f3(
        x0 + ((p * a0 + q * b0) + (r * c0 + u * d0)),
        x1 + ((p * a1 + q * b1) + (r * c1 + u * d1)), x2 + ((p * a2 + q * b2) + (r * c2 + u * d2)),
        x3 + ((p * a3 + q * b3) + (r * c3 + u * d3)), x4 + ((p * a4 + q * b4) + (r * c4 + u * d4)),
        x5 + ((p * a5 + q * b5) + (r * c5 + u * d5)), locked, prm, acc[6], acc[7],
        tb1, tb2, tb3, sb1, sb2, sb3, cb1, cb2, cb3)
    p = h * _A61
    q = h * _A62
    r = h * _A63
    u = h * _A64
    v = h * _A65
    (g0, g1, g2, g3, g4, g5), _ = _f3(
        x0 + ((p * a0 + q * b0) + (r * c0 + u * d0) + v * e0),
        x1 + ((p * a1 + q * b1) + (r * c1 + u * d1) + v * e1),
        x2 + ((p * a2 + q * b2) + (r * c2 + u * d2) + v * e2),
        x3 + ((p * a3 + q * b3) + (r * c3 + u * d3) + v * e3),
        x4 + ((p * a4 + q * b4) + (r * c4 + u * d4) + v * e4),
        x5 + ((p * a5 + q * b5) + (r * c5 + u * d5) + v * e5), locked, prm, acc[8], acc[9],
        tb1, tb2, tb3, sb1, sb2, sb3, cb1, cb2, cb3)
    p = h * _B1
    r = h * _B3
    u = h * _B4
    v = h * _B5
    w = h * _B6
    y0 = x0 + ((p * a0 + r * c0) + (u * d0 + v * e0) + w * g0)
    y1 = x1 + ((p * a1 + r * c1) + (u * d1 + v * e1) + w * g1)
    y2 = x2 + ((p * a2 + r * c2) + (u * d2 + v * e2) + w * g2)
    y3 = x3 + ((p * a3 + r * c3) + (u * d3 + v * e3) + w * g3)
    y4 = x4 + ((p * a4 + r * c4) + (u * d4 + v * e4) + w * g4)
    y5 = x5 + ((p * a5 + r * c5) + (u * d5 + v * e5) + w * g5)
    (k0, k1, k2, k3, k4, k5), tr = _f3(
        y0, y1, y2, y3, y4, y5, locked, prm, acc[10], acc[11],
        tb1, tb2, tb3, sb1, sb2, sb3, cb1, cb2, cb3)
    ytmp[0] = y0
    ytmp[1] = y1
    ytmp[2] = y2
    ytmp[3] = y3
    ytmp[4] = y4
    ytmp[5] = y5
    for i, val in enumerate((b0, b1, b2, b3, b4, b5)):
        stg[1, i] = val
    for i, val in enumerate((c0, c1, c2, c3, c4, c5)):
        stg[2, i] = val
    for i, val in enumerate((d0, d1, d2, d3, d4, d5)):
        stg[3, i] = val
    for i, val in enumerate((e0, e1, e2, e3, e4, e5)):
        stg[4, i] = val
    for i, val in enumerate((g0, g1, g2, g3, g4, g5)):
        stg[5, i] = val
    for i, val in enumerate((k0, k1, k2, k3, k4, k5)):
        stg[6, i] = val
    for i in range(6):
        trig[i] = tr[i]
    err0 = h * ((_E1 * a0 + _E3 * c0) + (_E4 * d0 + _E5 * e0) + (_E6 * g0 + _E7 * k0))
    err1 = h * ((_E1 * a1 + _E3 * c1) + (_E4 * d1 + _E5 * e1) + (_E6 * g1 + _E7 * k1))
    err2 = h * ((_E1 * a2 + _E3 * c2) + (_E4 * d2 + _E5 * e2) + (_E6 * g2 + _E7 * k2))
    err3 = h * ((_E1 * a3 + _E3 * c3) + (_E4 * d3 + _E5 * e3) + (_E6 * g3 + _E7 * k3))
    err4 = h * ((_E1 * a4 + _E3 * c4) + (_E4 * d4 + _E5 * e4) + (_E6 * g4 + _E7 * k4))
    err5 = h * ((_E1 * a5 + _E3 * c5) + (_E4 * d5 + _E5 * e5) + (_E6 * g5 + _E7 * k5))
    err0 /= atol + rtol * max(abs(x0), abs(y0))
    err1 /= atol + rtol * max(abs(x1), abs(y1))
    err2 /= atol + rtol * max(abs(x2), abs(y2))
    err3 /= atol + rtol * max(abs(x3), abs(y3))
    err4 /= atol + rtol * max(abs(x4), abs(y4))
    err5 /= atol + rtol * max(abs(x5), abs(y5))
    return (err0 * err0 + err1 * err1 + err2 * err2 + err3 * err3 + err4 * err4
            + err5 * err5) / 6.0


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _dp_stepN(t, t_new, h, x, stg, ytmp, m, locked, mp, dp, work, rtol, atol):
    """One Dormand–Prince step of an N-link chain (arrays; see :func:`_dp_step3`)."""
    for s in range(1, 7):
        if s == 1:
            for i in range(m):
                ytmp[i] = x[i] + h * (_A21 * stg[0, i])
            ts = t + _C2 * h
        elif s == 2:
            for i in range(m):
                ytmp[i] = x[i] + h * (_A31 * stg[0, i] + _A32 * stg[1, i])
            ts = t + _C3 * h
        elif s == 3:
            for i in range(m):
                ytmp[i] = x[i] + h * ((_A41 * stg[0, i] + _A42 * stg[1, i])
                                      + _A43 * stg[2, i])
            ts = t + _C4 * h
        elif s == 4:
            for i in range(m):
                ytmp[i] = x[i] + h * ((_A51 * stg[0, i] + _A52 * stg[1, i])
                                      + (_A53 * stg[2, i] + _A54 * stg[3, i]))
            ts = t + _C5 * h
        elif s == 5:
            for i in range(m):
                ytmp[i] = x[i] + h * ((_A61 * stg[0, i] + _A62 * stg[1, i])
                                      + (_A63 * stg[2, i] + _A64 * stg[3, i])
                                      + _A65 * stg[4, i])
            ts = t + h
        else:
            for i in range(m):
                ytmp[i] = x[i] + h * ((_B1 * stg[0, i] + _B3 * stg[2, i])
                                      + (_B4 * stg[3, i] + _B5 * stg[4, i])
                                      + _B6 * stg[5, i])
            ts = t_new
        _derivN(ts, ytmp, stg, s, locked, mp, dp, work)
    return _error_norm(h, x, ytmp, stg, m, rtol, atol)


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _dense_coefficients3(Q, stg, h):
    """As :func:`_dense_coefficients` for the 6 states of 3 links (constant sizes)."""
    for k in range(4):
        p0 = h * _P[0, k]
        p2 = h * _P[2, k]
        p3 = h * _P[3, k]
        p4 = h * _P[4, k]
        p5 = h * _P[5, k]
        p6 = h * _P[6, k]
        for i in range(6):
            Q[i, k] = ((stg[0, i] * p0 + stg[2, i] * p2) + (stg[3, i] * p3 + stg[4, i] * p4)
                       + (stg[5, i] * p5 + stg[6, i] * p6))


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _dense_coefficients(Q, stg, h, m):
    """Q = h Kᵀ P: the step's interpolant is y + Q·(σ, σ², σ³, σ⁴)."""
    for i in range(m):
        for k in range(4):
            Q[i, k] = h * ((stg[0, i] * _P[0, k] + stg[2, i] * _P[2, k])
                           + (stg[3, i] * _P[3, k] + stg[4, i] * _P[4, k])
                           + (stg[5, i] * _P[5, k] + stg[6, i] * _P[6, k]))


# ---------------------------------------------------------------------------
# Radau IIA of order 5: scipy's Radau (Hairer & Wanner's RADAU5), compiled, with the
# Newton systems reduced from 2N×2N to N×N by the structure of the Jacobian
# ---------------------------------------------------------------------------

_S6 = 6.0 ** 0.5
_RC1 = (4.0 - _S6) / 10.0  # collocation nodes c1, c2 (c3 = 1)
_RC2 = (4.0 + _S6) / 10.0
_RE1 = (-13.0 - 7.0 * _S6) / 3.0  # error estimate weights
_RE2 = (-13.0 + 7.0 * _S6) / 3.0
_RE3 = -1.0 / 3.0
# eigenvalues of the inverse of the Radau matrix: one real, a complex pair
_MU_REAL = 3.0 + 3.0 ** (2.0 / 3.0) - 3.0 ** (1.0 / 3.0)
_MU_CRE = 3.0 + 0.5 * (3.0 ** (1.0 / 3.0) - 3.0 ** (2.0 / 3.0))
_MU_CIM = -0.5 * (3.0 ** (5.0 / 6.0) + 3.0 ** (7.0 / 6.0))
# the transformation that diagonalises it (T, T⁻¹), to the digits scipy prints
_T00, _T01, _T02 = 0.09443876248897524, -0.14125529502095421, 0.03002919410514742
_T10, _T11, _T12 = 0.25021312296533332, 0.20412935229379994, -0.38294211275726192
_T20, _T21, _T22 = 1.0, 1.0, 0.0
_TI00, _TI01, _TI02 = 4.17871859155190428, 0.32768282076106237, 0.52337644549944951
_TI10, _TI11, _TI12 = -4.17871859155190428, -0.32768282076106237, 0.47662355450055044
_TI20, _TI21, _TI22 = 0.50287263494578682, -2.57192694985560522, 0.59603920482822492
# the collocation polynomial (dense output): y_old + Σ_k (Σ_s Z_s P_sk) σ^(k+1)
_RP = np.array([
    [13.0 / 3.0 + 7.0 * _S6 / 3.0, -23.0 / 3.0 - 22.0 * _S6 / 3.0, 10.0 / 3.0 + 5.0 * _S6],
    [13.0 / 3.0 - 7.0 * _S6 / 3.0, -23.0 / 3.0 + 22.0 * _S6 / 3.0, 10.0 / 3.0 - 5.0 * _S6],
    [1.0 / 3.0, -8.0 / 3.0, 10.0 / 3.0],
])
_NEWTON_MAXITER = 6
_SQRT_EPS = 1.4901161193847656e-08


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _lu_factor(A, piv, n):
    """LU factorisation with partial pivoting of A[:n, :n] in place (real or complex);
    whole rows are swapped, as LAPACK's getrf does."""
    for k in range(n):
        p = k
        big = abs(A[k, k])
        for i in range(k + 1, n):
            v = abs(A[i, k])
            if v > big:
                big = v
                p = i
        piv[k] = p
        if p != k:
            for j in range(n):
                tmp = A[k, j]
                A[k, j] = A[p, j]
                A[p, j] = tmp
        inv = 1.0 / A[k, k]
        for i in range(k + 1, n):
            A[i, k] *= inv
            f = A[i, k]
            for j in range(k + 1, n):
                A[i, j] -= f * A[k, j]


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _lu_solve(A, piv, b, n):
    """Solve with the factors of :func:`_lu_factor`, b[:n] in place."""
    for k in range(n):
        p = piv[k]
        if p != k:
            tmp = b[k]
            b[k] = b[p]
            b[p] = tmp
    for i in range(n):
        s = b[i]
        for j in range(i):
            s -= A[i, j] * b[j]
        b[i] = s
    for i in range(n - 1, -1, -1):
        s = b[i]
        for j in range(i + 1, n):
            s -= A[i, j] * b[j]
        b[i] = s / A[i, i]


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _radau_jacobian(t, x, f0, jac, n, locked, mp, dp, work, xt, ft):
    """The acceleration rows [∂Θ̈/∂Θ, ∂Θ̈/∂Θ̇] (N, 2N) of the Jacobian by forward differences
    (the velocity rows are [0, I] exactly); ``f0`` = f(t, x). Returns the evaluations used."""
    m = 2 * n
    for j in range(m):
        xt[j] = x[j]
    for j in range(m):
        d = _SQRT_EPS * max(abs(x[j]), 1e-2)
        d = (x[j] + d) - x[j]
        xt[j] = x[j] + d
        _deriv(t, xt, ft, 0, locked, mp, dp, work)
        xt[j] = x[j]
        for i in range(n):
            jac[i, j] = (ft[0, n + i] - f0[n + i]) / d
    return m


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _radau_factor(h, jac, lur, pivr, luc, pivc, n):
    """Factor the Newton matrices μ/h·I − Jacobian, reduced to S(c) = c²I − c·∂Θ̈/∂Θ̇ −
    ∂Θ̈/∂Θ (N×N) for c = μ_real/h (real) and μ_complex/h (complex)."""
    cr = _MU_REAL / h
    cc = complex(_MU_CRE, _MU_CIM) / h
    for i in range(n):
        for j in range(n):
            p = jac[i, j]
            q = jac[i, n + j]
            lur[i, j] = -(cr * q) - p
            luc[i, j] = -(cc * q) - p
        lur[i, i] += cr * cr
        luc[i, i] += cc * cc
    _lu_factor(lur, pivr, n)
    _lu_factor(luc, pivc, n)


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _block_solve(c, jac, lu, piv, r, n, tmp):
    """Solve (c·I − Jacobian) v = r in place (r of length 2N, real or complex).

    With the Jacobian [[0, I], [P, Q]]: the angle part a solves S(c) a = r₂ + (c·I − Q) r₁
    (S factored by :func:`_radau_factor`), the rate part is c·a − r₁.
    """
    for i in range(n):
        s = r[n + i] + c * r[i]
        for j in range(n):
            s -= jac[i, n + j] * r[j]
        tmp[i] = s
    _lu_solve(lu, piv, tmp, n)
    for i in range(n):
        r[n + i] = c * tmp[i] - r[i]
        r[i] = tmp[i]


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _radau_newton(t, h, x, Z, W, F, scale, tol, jac, lur, pivr, luc, pivc, n, locked, mp,
                  dp, work, ys, fr, fc, tmpr, tmpc):
    """Solve the collocation system for Z (3, 2N) (the stage states minus x), starting from
    the guess in Z: scipy's solve_collocation_system. Returns (converged, iterations,
    rate of convergence; −1 when not measured)."""
    m = 2 * n
    cr = _MU_REAL / h
    cc = complex(_MU_CRE, _MU_CIM) / h
    for i in range(m):
        z0 = Z[0, i]
        z1 = Z[1, i]
        z2 = Z[2, i]
        W[0, i] = _TI00 * z0 + _TI01 * z1 + _TI02 * z2
        W[1, i] = _TI10 * z0 + _TI11 * z1 + _TI12 * z2
        W[2, i] = _TI20 * z0 + _TI21 * z1 + _TI22 * z2
    norm_old = -1.0
    rate = -1.0
    converged = False
    iters = 0
    for k in range(_NEWTON_MAXITER):
        iters = k + 1
        for s in range(3):
            cs = _RC1 if s == 0 else (_RC2 if s == 1 else 1.0)
            for i in range(m):
                ys[i] = x[i] + Z[s, i]
            _deriv(t + cs * h, ys, F, s, locked, mp, dp, work)
        finite = True
        for s in range(3):
            for i in range(m):
                if not np.isfinite(F[s, i]):
                    finite = False
        if not finite:
            break
        for i in range(m):
            f0 = F[0, i]
            f1 = F[1, i]
            f2 = F[2, i]
            fr[i] = (_TI00 * f0 + _TI01 * f1 + _TI02 * f2) - cr * W[0, i]
            fc[i] = (complex(_TI10 * f0 + _TI11 * f1 + _TI12 * f2,
                             _TI20 * f0 + _TI21 * f1 + _TI22 * f2)
                     - cc * complex(W[1, i], W[2, i]))
        _block_solve(cr, jac, lur, pivr, fr, n, tmpr)
        _block_solve(cc, jac, luc, pivc, fc, n, tmpc)
        acc = 0.0
        for i in range(m):
            a = fr[i] / scale[i]
            b = fc[i].real / scale[i]
            c = fc[i].imag / scale[i]
            acc += a * a + b * b + c * c
        norm = math.sqrt(acc / (3 * m))
        if norm_old >= 0.0:
            rate = norm / norm_old
        if rate >= 0.0 and (rate >= 1.0 or rate ** (_NEWTON_MAXITER - k) / (1.0 - rate) * norm
                            > tol):
            break
        for i in range(m):
            W[0, i] += fr[i]
            W[1, i] += fc[i].real
            W[2, i] += fc[i].imag
            w0 = W[0, i]
            w1 = W[1, i]
            w2 = W[2, i]
            Z[0, i] = _T00 * w0 + _T01 * w1 + _T02 * w2
            Z[1, i] = _T10 * w0 + _T11 * w1 + _T12 * w2
            Z[2, i] = _T20 * w0 + _T21 * w1 + _T22 * w2
        if norm == 0.0 or (rate >= 0.0 and rate / (1.0 - rate) * norm < tol):
            converged = True
            break
        norm_old = norm
    return converged, iters, rate


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _radau_error(h, x, y, f0, Z, jac, lur, pivr, n, rtol, atol, err, tmpr):
    """Radau's embedded error estimate (μ_real/h·I − Jacobian)⁻¹ (f0 + Σ e_s Z_s / h) into
    ``err``; returns its RMS scaled norm."""
    m = 2 * n
    for i in range(m):
        err[i] = f0[i] + (_RE1 * Z[0, i] + _RE2 * Z[1, i] + _RE3 * Z[2, i]) / h
    _block_solve(_MU_REAL / h, jac, lur, pivr, err, n, tmpr)
    acc = 0.0
    for i in range(m):
        v = err[i] / (atol + rtol * max(abs(x[i]), abs(y[i])))
        acc += v * v
    return math.sqrt(acc / m)


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _radau_predict(h, h_old, err, err_old):
    """scipy's predict_factor (Gustafsson's predictive control, exponent 1/4), except that
    a previous error of exactly 0 (a step from rest before any motion) counts as no
    history: scipy's formula would make the factor 0."""
    if err_old <= 0.0 or h_old <= 0.0 or err == 0.0:
        mult = 1.0
    else:
        mult = h / h_old * (err_old / err) ** 0.25
    if err == 0.0:
        return np.inf
    return min(1.0, mult) * err ** -0.25



@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _radau_factor3(h, jac, S):
    """For 3 links: the inverses of S(c) (see :func:`_radau_factor`) in closed form, real
    c = μ_real/h into S[0:3], complex c = μ_complex/h into S[3:6] (real part) and S[6:9]
    (imaginary part); S is (9, 3)."""
    cr = _MU_REAL / h
    cc = complex(_MU_CRE, _MU_CIM) / h
    for which in range(2):
        c = complex(cr, 0.0) if which == 0 else cc
        c2 = c * c
        a00 = c2 - c * jac[0, 3] - jac[0, 0]
        a01 = -(c * jac[0, 4]) - jac[0, 1]
        a02 = -(c * jac[0, 5]) - jac[0, 2]
        a10 = -(c * jac[1, 3]) - jac[1, 0]
        a11 = c2 - c * jac[1, 4] - jac[1, 1]
        a12 = -(c * jac[1, 5]) - jac[1, 2]
        a20 = -(c * jac[2, 3]) - jac[2, 0]
        a21 = -(c * jac[2, 4]) - jac[2, 1]
        a22 = c2 - c * jac[2, 5] - jac[2, 2]
        m00 = a11 * a22 - a12 * a21
        m01 = a02 * a21 - a01 * a22
        m02 = a01 * a12 - a02 * a11
        m10 = a12 * a20 - a10 * a22
        m11 = a00 * a22 - a02 * a20
        m12 = a02 * a10 - a00 * a12
        m20 = a10 * a21 - a11 * a20
        m21 = a01 * a20 - a00 * a21
        m22 = a00 * a11 - a01 * a10
        inv = 1.0 / (a00 * m00 + a01 * m10 + a02 * m20)
        vals = (m00 * inv, m01 * inv, m02 * inv, m10 * inv, m11 * inv, m12 * inv,
                m20 * inv, m21 * inv, m22 * inv)
        for k in range(9):
            i = k // 3
            j = k % 3
            if which == 0:
                S[i, j] = vals[k].real
            else:
                S[3 + i, j] = vals[k].real
                S[6 + i, j] = vals[k].imag


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _radau_newton3(h, x, Z, W, F, inv_scale, tol, jac, S, prm, locked, acc, base, fr, fi,
                   fc):
    """:func:`_radau_newton` for 3 links: the stage derivatives by :func:`_f3` (sines and
    cosines rotated from ``base``, platform accelerations at the three nodes in ``acc``),
    the reduced systems solved with the closed-form inverses of :func:`_radau_factor3`."""
    cr = _MU_REAL / h
    ccr = _MU_CRE / h
    cci = _MU_CIM / h
    tb1 = base[0]
    tb2 = base[1]
    tb3 = base[2]
    sb1 = base[3]
    sb2 = base[4]
    sb3 = base[5]
    cb1 = base[6]
    cb2 = base[7]
    cb3 = base[8]
    x0 = x[0]
    x1 = x[1]
    x2 = x[2]
    x3 = x[3]
    x4 = x[4]
    x5 = x[5]
    for i in range(6):
        z0 = Z[0, i]
        z1 = Z[1, i]
        z2 = Z[2, i]
        W[0, i] = _TI00 * z0 + _TI01 * z1 + _TI02 * z2
        W[1, i] = _TI10 * z0 + _TI11 * z1 + _TI12 * z2
        W[2, i] = _TI20 * z0 + _TI21 * z1 + _TI22 * z2
    norm_old = -1.0
    rate = -1.0
    converged = False
    iters = 0
    for k in range(_NEWTON_MAXITER):
        iters = k + 1
        for s in range(3):
            d, _ = _f3(x0 + Z[s, 0], x1 + Z[s, 1], x2 + Z[s, 2], x3 + Z[s, 3], x4 + Z[s, 4],
                       x5 + Z[s, 5], locked, prm, acc[2 * s], acc[2 * s + 1],
                       tb1, tb2, tb3, sb1, sb2, sb3, cb1, cb2, cb3)
            for i in range(6):
                F[s, i] = d[i]
        total = 0.0
        for i in range(6):
            f0 = F[0, i]
            f1 = F[1, i]
            f2 = F[2, i]
            total += f0 + f1 + f2
            w1 = W[1, i]
            w2 = W[2, i]
            fr[i] = (_TI00 * f0 + _TI01 * f1 + _TI02 * f2) - cr * W[0, i]
            fc[i] = (_TI10 * f0 + _TI11 * f1 + _TI12 * f2) - (ccr * w1 - cci * w2)
            fi[i] = (_TI20 * f0 + _TI21 * f1 + _TI22 * f2) - (ccr * w2 + cci * w1)
        if not np.isfinite(total):
            break
        # real system: a = S_r⁻¹ (r₂ + c r₁ − Q r₁), b = c a − r₁
        acc2 = 0.0
        for part in range(2):
            if part == 0:
                q0 = fr[0]
                q1 = fr[1]
                q2 = fr[2]
                u0 = fr[3] + cr * q0 - (jac[0, 3] * q0 + jac[0, 4] * q1 + jac[0, 5] * q2)
                u1 = fr[4] + cr * q1 - (jac[1, 3] * q0 + jac[1, 4] * q1 + jac[1, 5] * q2)
                u2 = fr[5] + cr * q2 - (jac[2, 3] * q0 + jac[2, 4] * q1 + jac[2, 5] * q2)
                a0 = S[0, 0] * u0 + S[0, 1] * u1 + S[0, 2] * u2
                a1 = S[1, 0] * u0 + S[1, 1] * u1 + S[1, 2] * u2
                a2 = S[2, 0] * u0 + S[2, 1] * u1 + S[2, 2] * u2
                fr[3] = cr * a0 - q0
                fr[4] = cr * a1 - q1
                fr[5] = cr * a2 - q2
                fr[0] = a0
                fr[1] = a1
                fr[2] = a2
            else:
                # complex system, (real, imaginary) parts written out
                p0 = fc[0]
                p1 = fc[1]
                p2 = fc[2]
                q0 = fi[0]
                q1 = fi[1]
                q2 = fi[2]
                ur0 = fc[3] + (ccr * p0 - cci * q0) - (jac[0, 3] * p0 + jac[0, 4] * p1
                                                       + jac[0, 5] * p2)
                ur1 = fc[4] + (ccr * p1 - cci * q1) - (jac[1, 3] * p0 + jac[1, 4] * p1
                                                       + jac[1, 5] * p2)
                ur2 = fc[5] + (ccr * p2 - cci * q2) - (jac[2, 3] * p0 + jac[2, 4] * p1
                                                       + jac[2, 5] * p2)
                ui0 = fi[3] + (ccr * q0 + cci * p0) - (jac[0, 3] * q0 + jac[0, 4] * q1
                                                       + jac[0, 5] * q2)
                ui1 = fi[4] + (ccr * q1 + cci * p1) - (jac[1, 3] * q0 + jac[1, 4] * q1
                                                       + jac[1, 5] * q2)
                ui2 = fi[5] + (ccr * q2 + cci * p2) - (jac[2, 3] * q0 + jac[2, 4] * q1
                                                       + jac[2, 5] * q2)
                ar0 = (S[3, 0] * ur0 + S[3, 1] * ur1 + S[3, 2] * ur2) - (
                    S[6, 0] * ui0 + S[6, 1] * ui1 + S[6, 2] * ui2)
                ar1 = (S[4, 0] * ur0 + S[4, 1] * ur1 + S[4, 2] * ur2) - (
                    S[7, 0] * ui0 + S[7, 1] * ui1 + S[7, 2] * ui2)
                ar2 = (S[5, 0] * ur0 + S[5, 1] * ur1 + S[5, 2] * ur2) - (
                    S[8, 0] * ui0 + S[8, 1] * ui1 + S[8, 2] * ui2)
                ai0 = (S[3, 0] * ui0 + S[3, 1] * ui1 + S[3, 2] * ui2) + (
                    S[6, 0] * ur0 + S[6, 1] * ur1 + S[6, 2] * ur2)
                ai1 = (S[4, 0] * ui0 + S[4, 1] * ui1 + S[4, 2] * ui2) + (
                    S[7, 0] * ur0 + S[7, 1] * ur1 + S[7, 2] * ur2)
                ai2 = (S[5, 0] * ui0 + S[5, 1] * ui1 + S[5, 2] * ui2) + (
                    S[8, 0] * ur0 + S[8, 1] * ur1 + S[8, 2] * ur2)
                fc[3] = (ccr * ar0 - cci * ai0) - p0
                fc[4] = (ccr * ar1 - cci * ai1) - p1
                fc[5] = (ccr * ar2 - cci * ai2) - p2
                fi[3] = (ccr * ai0 + cci * ar0) - q0
                fi[4] = (ccr * ai1 + cci * ar1) - q1
                fi[5] = (ccr * ai2 + cci * ar2) - q2
                fc[0] = ar0
                fc[1] = ar1
                fc[2] = ar2
                fi[0] = ai0
                fi[1] = ai1
                fi[2] = ai2
        for i in range(6):
            a = fr[i] * inv_scale[i]
            b = fc[i] * inv_scale[i]
            c = fi[i] * inv_scale[i]
            acc2 += a * a + b * b + c * c
        norm = math.sqrt(acc2 / 18.0)
        if norm_old >= 0.0:
            rate = norm / norm_old
        if rate >= 0.0 and (rate >= 1.0 or rate ** (_NEWTON_MAXITER - k) / (1.0 - rate) * norm
                            > tol):
            break
        for i in range(6):
            w0 = W[0, i] + fr[i]
            w1 = W[1, i] + fc[i]
            w2 = W[2, i] + fi[i]
            W[0, i] = w0
            W[1, i] = w1
            W[2, i] = w2
            Z[0, i] = _T00 * w0 + _T01 * w1 + _T02 * w2
            Z[1, i] = _T10 * w0 + _T11 * w1 + _T12 * w2
            Z[2, i] = _T20 * w0 + _T21 * w1
        if norm == 0.0 or (rate >= 0.0 and rate / (1.0 - rate) * norm < tol):
            converged = True
            break
        norm_old = norm
    return converged, iters, rate


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _radau_error3(h, x, y, f0, Z, jac, S, rtol, atol, err):
    """:func:`_radau_error` for 3 links with the closed-form inverse of S(μ_real/h)."""
    cr = _MU_REAL / h
    inv_h = 1.0 / h
    for i in range(6):
        err[i] = f0[i] + (_RE1 * Z[0, i] + _RE2 * Z[1, i] + _RE3 * Z[2, i]) * inv_h
    q0 = err[0]
    q1 = err[1]
    q2 = err[2]
    u0 = err[3] + cr * q0 - (jac[0, 3] * q0 + jac[0, 4] * q1 + jac[0, 5] * q2)
    u1 = err[4] + cr * q1 - (jac[1, 3] * q0 + jac[1, 4] * q1 + jac[1, 5] * q2)
    u2 = err[5] + cr * q2 - (jac[2, 3] * q0 + jac[2, 4] * q1 + jac[2, 5] * q2)
    a0 = S[0, 0] * u0 + S[0, 1] * u1 + S[0, 2] * u2
    a1 = S[1, 0] * u0 + S[1, 1] * u1 + S[1, 2] * u2
    a2 = S[2, 0] * u0 + S[2, 1] * u1 + S[2, 2] * u2
    err[3] = cr * a0 - q0
    err[4] = cr * a1 - q1
    err[5] = cr * a2 - q2
    err[0] = a0
    err[1] = a1
    err[2] = a2
    acc = 0.0
    for i in range(6):
        v = err[i] / (atol + rtol * max(abs(x[i]), abs(y[i])))
        acc += v * v
    return math.sqrt(acc / 6.0)


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _radau_stage_accelerations(t, h, dp, out):
    """(ẍ_d, ÿ_d) at the three collocation nodes of a Radau step into out (6,). [m/s²]"""
    for s in range(3):
        cs = _RC1 if s == 0 else (_RC2 if s == 1 else 1.0)
        ax, ay = platform_acceleration(t + cs * h, dp)
        out[2 * s] = ax
        out[2 * s + 1] = ay



# ---------------------------------------------------------------------------
# One run
# ---------------------------------------------------------------------------


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT, nogil=True)
def _integrate(x0, grid, mp0, E, kd, ld, one_sided, dp, bps, fpar, ipar, samples,
               sample_locked, switch_times, peak, final):
    """Integrate one run.

    If ``samples`` has columns, the samples go to it (2N, T + 1) and whether the
    knee constraint held at each to ``sample_locked`` (T + 1,). Always: the
    peak |θ_i| over the samples goes to ``peak`` (N,), the last sample to
    ``final`` (2N,), and the switch times to ``switch_times`` (capacity
    max_switches + 1). After a fall, the state at the fall closes the series
    (one sample off the grid, as in the reference) unless a grid sample lies
    within 1e-12 s before it.

    Returns a float array of length N_RESULT (indices R_*): status code,
    number of samples, fall kind (link index 0…N−1, N toe, N+1 heel; −1 if
    none), fall time [s] (NaN if none), number of switches, time reached [s],
    accepted and rejected steps, derivative evaluations, time of the last
    sample with some |θ_i| > settle tolerance [s] (NaN if none), whether
    there was one (0/1), whether the final sample is one (0/1), and whether
    the fall sample was appended (0/1).
    """
    n = x0.size // 2
    m = 2 * n
    n3 = n == 3
    T = grid.size
    store = samples.shape[1] > 0
    rtol = fpar[F_RTOL]
    atol = fpar[F_ATOL]
    max_step = fpar[F_MAX_STEP]
    duration = fpar[F_DURATION]
    settle_tol = fpar[F_SETTLE_TOL]
    max_angle = fpar[F_MAX_ANGLE]
    switch_hyst = fpar[F_SWITCH_HYST]
    stop_angle = fpar[F_STOP_ANGLE]
    total_mass = fpar[F_TOTAL_MASS]
    toe = fpar[F_TOE]
    heel = fpar[F_HEEL]
    use_bos = ipar[I_USE_BOS] != 0
    knee_mode = ipar[I_KNEE_MODE]
    max_switches = ipar[I_MAX_SWITCHES]
    locked = ipar[I_LOCKED0] != 0
    rk23 = ipar[I_METHOD] == METHOD_RK23
    radau = ipar[I_METHOD] == METHOD_RADAU
    if rk23:
        expo1 = _BS_EXPO1
        beta = _BS_BETA
        err_order = 2
        last_row = 3
        evals_per_step = 3
    elif radau:
        expo1 = 0.0
        beta = 0.0
        err_order = 3  # as scipy's Radau selects its first step
        last_row = 1
        evals_per_step = 0  # counted as they happen
    else:
        expo1 = _EXPO1
        beta = _BETA
        err_order = 4
        last_row = 6
        evals_per_step = 6

    mp = mp0.copy()
    work = np.empty((n, n + 4))
    active = np.ones(kd.size)
    x = x0.copy()
    ytmp = np.empty(m)
    base = np.empty(9)  # θ, sin θ, cos θ at the step's start (3 links)
    trig = np.empty(6)  # sin θ, cos θ of y_new
    stg = np.empty((7, m))  # stage derivatives; row 0 is f(t, x) (FSAL)
    scratch = np.empty((1, m))
    Q = np.empty((m, 4))
    ys = np.empty(m)
    stage_acc = np.zeros(12)  # (ẍ_d, ÿ_d) at the six stage times
    has_acceleration = dp[0] > 0.0
    n_ev_max = n + 3 + kd.size
    ev_kind = np.empty(n_ev_max, np.int64)
    ev_par = np.empty(n_ev_max, np.int64)
    ev_sgn = np.zeros(n_ev_max)
    ev_dir = np.empty(n_ev_max, np.int64)
    g_old = np.empty(n_ev_max)
    g_new = np.empty(n_ev_max)
    # Radau: stage increments Z, their transform W, stage derivatives, the Jacobian's
    # acceleration rows, the two factored Newton matrices, and the previous step's state
    rm = m if radau else 0
    rn = n if radau else 0
    rZ = np.zeros((3, rm))
    rZ0 = np.zeros((3, rm))
    rW = np.empty((3, rm))
    rF = np.empty((3, rm))
    jac = np.zeros((rn, rm))
    lur = np.empty((rn, rn))
    pivr = np.zeros(rn, np.int64)
    luc = np.empty((rn, rn), np.complex128)
    pivc = np.zeros(rn, np.int64)
    rscale = np.empty(rm)
    rfr = np.empty(rm)
    rfc = np.empty(rm, np.complex128)
    rtmpr = np.empty(rn)
    rtmpc = np.empty(rn, np.complex128)
    rerr = np.empty(rm)
    rxt = np.empty(rm)
    xold = np.empty(rm)
    S3 = np.zeros((9, 3))  # 3 links: closed-form inverses of the reduced Newton matrices
    rfi = np.empty(rm)
    rfc3 = np.empty(rm)
    racc = np.zeros(6)
    prm = _model_tuple3(mp if n3 else np.zeros(34))
    have_sol = False
    current_jac = False
    h_lu = -1.0
    h_old = -1.0
    err_old = -1.0
    h_start = 0.0
    err_rejected = False  # an error-norm rejection in this step (scipy's `rejected`)
    newton_tol = max(10.0 * _EPS / rtol, min(0.03, math.sqrt(rtol)))  # scipy's
    t_prev = 0.0
    h_prev = 1.0

    for i in range(n):
        peak[i] = 0.0
    for i in range(m):
        final[i] = np.nan

    # one-sided pairs act at the start if stretched, or at zero stretch and stretching
    for p in range(kd.size):
        if one_sided[p]:
            s = 0.0
            sd = 0.0
            for j in range(n):
                s += E[p, j] * x[j]
                sd += E[p, j] * x[n + j]
            active[p] = 1.0 if (s > 0.0 or (s == 0.0 and sd >= 0.0)) else 0.0
    _joint_matrices(E, kd, ld, active, mp, n)

    t = 0.0
    status = STATUS_COMPLETED
    fall_kind = -1
    fall_time = np.nan
    n_switches = 0
    n_steps = 0
    n_rejected = 0
    n_evals = 0
    gi = 0  # next output sample
    last_outside = np.nan
    any_outside = False
    final_outside = False
    fall_sample = False
    bi = 0  # next breakpoint
    restart = True
    h = 0.0
    log_errold = _LOG_ERR_FLOOR
    last_rejected = False
    n_ev = 0

    while t < duration:
        if restart:
            # start of a smooth segment (t = 0, or after a switch, as the reference restarts)
            while bi < bps.size and bps[bi] <= t + 1e-12:
                bi += 1
            _deriv(t, x, stg, 0, locked, mp, dp, work)
            n_ev = _build_events(n, one_sided, active, knee_mode, locked, use_bos,
                                 ev_kind, ev_par, ev_sgn, ev_dir)
            for e in range(n_ev):
                g_old[e] = _event_value(ev_kind[e], ev_par[e], ev_sgn[e], t, x, mp, E, fpar,
                                        dp, scratch, work)
            t_stop = bps[bi] if bi < bps.size else duration
            h = _initial_step(t, x, stg, t_stop, max_step, rtol, atol, locked, mp, dp, work,
                              ytmp, scratch, err_order)
            n_evals += 2
            if radau:
                if n3:
                    prm = _model_tuple3(mp)  # the gains change at a switch
                n_evals += _radau_jacobian(t, x, stg[0], jac, n, locked, mp, dp, work, rxt,
                                           scratch)
                current_jac = True
                have_sol = False
                err_rejected = False
                h_lu = -1.0
                h_old = -1.0
                err_old = -1.0
            log_errold = _LOG_ERR_FLOOR
            last_rejected = False
            restart = False
            if n3:
                for i in range(3):
                    base[i] = x[i]
                    base[3 + i] = math.sin(x[i])
                    base[6 + i] = math.cos(x[i])

        t_stop = bps[bi] if bi < bps.size else duration
        if radau and h > max_step:
            h_old = -1.0
            err_old = -1.0
        h = min(h, max_step)
        landing = False
        if t + 1.01 * h >= t_stop:
            h = t_stop - t  # land exactly on the breakpoint (or the end)
            landing = True
        if not (h > 10.0 * _EPS * abs(t)):
            status = STATUS_STEP_TOO_SMALL
            break
        t_new = t_stop if landing else t + h

        if radau:
            if not last_rejected:
                h_start = h
            if h != h_lu:
                if n3:
                    _radau_factor3(h, jac, S3)
                else:
                    _radau_factor(h, jac, lur, pivr, luc, pivc, n)
                h_lu = h
            if n3 and has_acceleration:
                _radau_stage_accelerations(t, h, dp, racc)
            # the first guess: the previous step's collocation polynomial, extrapolated
            for s_ in range(3):
                cs = _RC1 if s_ == 0 else (_RC2 if s_ == 1 else 1.0)
                if have_sol:
                    sg = (t + cs * h - t_prev) / h_prev
                    for i in range(m):
                        rZ0[s_, i] = (xold[i] + sg * (Q[i, 0] + sg * (Q[i, 1] + sg * Q[i, 2]))
                                      - x[i])
                else:
                    for i in range(m):
                        rZ0[s_, i] = 0.0
            for i in range(m):
                rscale[i] = atol + abs(x[i]) * rtol
                if n3:
                    rscale[i] = 1.0 / rscale[i]
            converged = False
            n_iter = 0
            rate = -1.0
            while True:
                for s_ in range(3):
                    for i in range(m):
                        rZ[s_, i] = rZ0[s_, i]
                if n3:
                    converged, n_iter, rate = _radau_newton3(
                        h, x, rZ, rW, rF, rscale, newton_tol, jac, S3, prm, locked, racc, base,
                        rfr, rfi, rfc3)
                else:
                    converged, n_iter, rate = _radau_newton(
                        t, h, x, rZ, rW, rF, rscale, newton_tol, jac, lur, pivr, luc, pivc, n,
                        locked, mp, dp, work, ys, rfr, rfc, rtmpr, rtmpc)
                n_evals += 3 * n_iter
                if converged or current_jac:
                    break
                n_evals += _radau_jacobian(t, x, stg[0], jac, n, locked, mp, dp, work, rxt,
                                           scratch)
                current_jac = True
                if n3:
                    _radau_factor3(h, jac, S3)
                else:
                    _radau_factor(h, jac, lur, pivr, luc, pivc, n)
                h_lu = h
            if not converged:
                h = 0.5 * h
                n_rejected += 1
                last_rejected = True  # a retry of the same step (keeps h_start)
                continue
            for i in range(m):
                ytmp[i] = x[i] + rZ[2, i]
            if n3:
                err_norm = _radau_error3(h, x, ytmp, stg[0], rZ, jac, S3, rtol, atol, rerr)
            else:
                err_norm = _radau_error(h, x, ytmp, stg[0], rZ, jac, lur, pivr, n, rtol, atol,
                                        rerr, rtmpr)
            safety = 0.9 * (2 * _NEWTON_MAXITER + 1) / (2 * _NEWTON_MAXITER + n_iter)
            if err_rejected and err_norm > 1.0:
                # after a rejection, one more smoothing of the estimate (scipy, Hairer)
                for i in range(m):
                    rxt[i] = x[i] + rerr[i]
                _deriv(t, rxt, scratch, 0, locked, mp, dp, work)
                n_evals += 1
                if n3:
                    err_norm = _radau_error3(h, x, ytmp, scratch[0], rZ, jac, S3, rtol, atol,
                                             rerr)
                else:
                    err_norm = _radau_error(h, x, ytmp, scratch[0], rZ, jac, lur, pivr, n,
                                            rtol, atol, rerr, rtmpr)
            if not (err_norm <= 1.0):
                n_rejected += 1
                if err_norm == err_norm:
                    h = h * max(0.2, safety * _radau_predict(h, h_old, err_norm, err_old))
                else:
                    h = 0.2 * h
                last_rejected = True
                err_rejected = True
                continue
            # ---- accepted ----
            n_steps += 1
            recompute_jac = n_iter > 2 and rate > 1e-3
            fac = min(10.0, safety * _radau_predict(h, h_old, err_norm, err_old))
            if not recompute_jac and fac < 1.2:
                fac = 1.0
            if n3:
                if has_acceleration:
                    ax_new, ay_new = platform_acceleration(t_new, dp)
                else:
                    ax_new = 0.0
                    ay_new = 0.0
                fnew, tr = _f3(ytmp[0], ytmp[1], ytmp[2], ytmp[3], ytmp[4], ytmp[5], locked,
                               prm, ax_new, ay_new, base[0], base[1], base[2], base[3],
                               base[4], base[5], base[6], base[7], base[8])
                for i in range(6):
                    stg[1, i] = fnew[i]
                    trig[i] = tr[i]
            else:
                _deriv(t_new, ytmp, stg, 1, locked, mp, dp, work)
            n_evals += 1
            if recompute_jac:
                n_evals += _radau_jacobian(t_new, ytmp, stg[1], jac, n, locked, mp, dp, work,
                                           rxt, scratch)
                current_jac = True
                h_lu = -1.0
            else:
                current_jac = False
            h_old = h_start
            err_old = err_norm
            h_next = h * fac
            last_rejected = False
            err_rejected = False
            for i in range(m):
                z0 = rZ[0, i]
                z1 = rZ[1, i]
                z2 = rZ[2, i]
                for k in range(3):
                    Q[i, k] = (z0 * _RP[0, k] + z1 * _RP[1, k]) + z2 * _RP[2, k]
                Q[i, 3] = 0.0
                xold[i] = x[i]
            have_sol = True
            t_prev = t
            h_prev = h
        else:
            if n3:
                if rk23:
                    if has_acceleration:
                        _bs_stage_accelerations(t, h, t_new, dp, stage_acc)
                    err2 = _bs_step3(h, x, stg, ytmp, locked, mp, stage_acc, base, trig, rtol,
                                     atol)
                else:
                    if has_acceleration:
                        _stage_accelerations(t, h, t_new, dp, stage_acc)
                    err2 = _dp_step3(h, x, stg, ytmp, locked, mp, stage_acc, base, trig, rtol,
                                     atol)
            elif rk23:
                err2 = _bs_stepN(t, t_new, h, x, stg, ytmp, m, locked, mp, dp, work, rtol, atol)
            else:
                err2 = _dp_stepN(t, t_new, h, x, stg, ytmp, m, locked, mp, dp, work, rtol, atol)
            n_evals += evals_per_step
            # err2 is the squared error norm: accept when the norm is <= 1
            if not (err2 <= 1.0):
                # rejected (a NaN error counts as too large)
                n_rejected += 1
                if err2 < 1e300:
                    h = h / min(_FACC1, _exp_approx(0.5 * expo1 * _log_approx(err2)) / _SAFE)
                elif err2 == err2:
                    h = h / _FACC1
                else:
                    h = 0.1 * h
                last_rejected = True
                continue

            # ---- accepted: Hairer's PI controller, fac = err^0.17 / errold^0.04 / 0.9 ----
            n_steps += 1
            log_err = 0.5 * _log_approx(err2) if err2 > 1e-300 else -345.0
            fac = max(_FACC2, min(_FACC1, _exp_approx(expo1 * log_err - beta * log_errold) / _SAFE))
            h_next = h / fac
            if last_rejected:
                h_next = min(h_next, h)
            last_rejected = False
            log_errold = max(log_err, _LOG_ERR_FLOOR)
            if rk23:
                if n3:
                    _bs_dense_coefficients3(Q, stg, h)
                else:
                    _bs_dense_coefficients(Q, stg, h, m)
            elif n3:
                _dense_coefficients3(Q, stg, h)
            else:
                _dense_coefficients(Q, stg, h, m)

        # events that fired in (t, t_new]: the earliest root on the interpolant
        ev_hit = -1
        t_ev = t_new
        for e in range(n_ev):
            # (written out rather than a call: a call with array arguments that is not a
            # straight-line leaf costs atomic reference counting in every step)
            kind = ev_kind[e]
            if kind == EV_LINK:
                gn = max_angle - abs(ytmp[ev_par[e]])
            elif kind == EV_PAIR:
                gn = ev_sgn[e] * switch_hyst
                for j in range(n):
                    gn += E[ev_par[e], j] * ytmp[j]
            elif kind == EV_KNEE_HIT:
                gn = (ytmp[1] - ytmp[0]) - stop_angle - switch_hyst
            elif kind == EV_KNEE_RELEASE:
                gn = _release_value(t_new, ytmp, mp, fpar, dp, scratch, work)
            else:
                xc = 0.0
                for i in range(n):
                    xc += mp[i] * math.sin(ytmp[i])
                xc /= total_mass
                gn = toe - xc if kind == EV_TOE else xc - heel
            g_new[e] = gn
            go = g_old[e]
            if ev_dir[e] > 0:
                fired = go <= 0.0 and gn >= 0.0
            else:
                fired = go >= 0.0 and gn <= 0.0
            if not fired:
                continue
            root = _event_root(kind, ev_par[e], ev_sgn[e], t, t_new, go, gn, x, Q, h,
                               mp, E, fpar, dp, scratch, work, ys)
            if ev_hit < 0 or root < t_ev - 1e-12 * max(1.0, t_ev):
                ev_hit = e
                t_ev = root
            elif root < t_ev:
                t_ev = root  # a tie within 1e-12 s: the earlier-listed event wins

        # output samples in [t, end of this piece], as the reference selects them
        t_end = t_ev if ev_hit >= 0 else t_new
        inclusive = ev_hit >= 0 or t_new >= duration
        # (written out rather than a call, for the reason given above)
        first_gi = gi
        g_end = gi
        while g_end < T and (grid[g_end] < t_end - 1e-12
                             or (inclusive and grid[g_end] <= t_end + 1e-12)):
            g_end += 1
        inv_h = 1.0 / h
        if n3:
            # one pass per sample, the six components written out (the same expression
            # for a stored run and a batch row, so that they agree bit for bit)
            q00 = Q[0, 0]
            q01 = Q[0, 1]
            q02 = Q[0, 2]
            q03 = Q[0, 3]
            q10 = Q[1, 0]
            q11 = Q[1, 1]
            q12 = Q[1, 2]
            q13 = Q[1, 3]
            q20 = Q[2, 0]
            q21 = Q[2, 1]
            q22 = Q[2, 2]
            q23 = Q[2, 3]
            xa = x[0]
            xb = x[1]
            xc = x[2]
            pk0 = peak[0]
            pk1 = peak[1]
            pk2 = peak[2]
            for g in range(gi, g_end):
                sg = (grid[g] - t) * inv_h
                v0 = xa + sg * (q00 + sg * (q01 + sg * (q02 + sg * q03)))
                v1 = xb + sg * (q10 + sg * (q11 + sg * (q12 + sg * q13)))
                v2 = xc + sg * (q20 + sg * (q21 + sg * (q22 + sg * q23)))
                if store:
                    samples[0, g] = v0
                    samples[1, g] = v1
                    samples[2, g] = v2
                    samples[3, g] = x[3] + sg * (Q[3, 0] + sg * (Q[3, 1] + sg * (
                        Q[3, 2] + sg * Q[3, 3])))
                    samples[4, g] = x[4] + sg * (Q[4, 0] + sg * (Q[4, 1] + sg * (
                        Q[4, 2] + sg * Q[4, 3])))
                    samples[5, g] = x[5] + sg * (Q[5, 0] + sg * (Q[5, 1] + sg * (
                        Q[5, 2] + sg * Q[5, 3])))
                    sample_locked[g] = locked
                v0 = abs(v0)
                v1 = abs(v1)
                v2 = abs(v2)
                pk0 = max(pk0, v0)
                pk1 = max(pk1, v1)
                pk2 = max(pk2, v2)
                outside = v0 > settle_tol or v1 > settle_tol or v2 > settle_tol
                if outside:
                    last_outside = grid[g]
                    any_outside = True
                final_outside = outside
            peak[0] = pk0
            peak[1] = pk1
            peak[2] = pk2
        else:
            if store:
                # component by component: contiguous writes that vectorise
                for i in range(m):
                    q0 = Q[i, 0]
                    q1 = Q[i, 1]
                    q2 = Q[i, 2]
                    q3 = Q[i, 3]
                    xi = x[i]
                    row = samples[i]
                    for g in range(gi, g_end):
                        sg = (grid[g] - t) * inv_h
                        row[g] = xi + sg * (q0 + sg * (q1 + sg * (q2 + sg * q3)))
                for g in range(gi, g_end):
                    sample_locked[g] = locked
            for g in range(gi, g_end):
                outside = False
                if store:
                    for i in range(n):
                        v = abs(samples[i, g])
                        if v > peak[i]:
                            peak[i] = v
                        if v > settle_tol:
                            outside = True
                else:
                    sg = (grid[g] - t) * inv_h
                    for i in range(n):
                        v = abs(x[i] + sg * (Q[i, 0] + sg * (Q[i, 1] + sg * (
                            Q[i, 2] + sg * Q[i, 3]))))
                        if v > peak[i]:
                            peak[i] = v
                        if v > settle_tol:
                            outside = True
                if outside:
                    last_outside = grid[g]
                    any_outside = True
                final_outside = outside
        gi = g_end
        if gi > first_gi:
            sg = (grid[gi - 1] - t) * inv_h
            for i in range(m):
                final[i] = x[i] + sg * (Q[i, 0] + sg * (Q[i, 1] + sg * (Q[i, 2] + sg * Q[i, 3])))

        if ev_hit >= 0:
            _dense(x, Q, t, h, t_ev, ys)
            for i in range(m):
                x[i] = ys[i]
            kind = ev_kind[ev_hit]
            t = t_ev
            if kind == EV_LINK or kind == EV_TOE or kind == EV_HEEL:
                status = STATUS_FELL
                fall_time = t_ev
                if gi == 0 or grid[gi - 1] < t_ev - 1e-12:
                    # the state at the fall closes the series (off the sample grid)
                    fall_sample = True
                    outside = False
                    for i in range(n):
                        v = abs(x[i])
                        if v > peak[i]:
                            peak[i] = v
                        if v > settle_tol:
                            outside = True
                    if outside:
                        last_outside = t_ev
                        any_outside = True
                    final_outside = outside
                    for i in range(m):
                        final[i] = x[i]
                        if store:
                            samples[i, gi] = x[i]
                    if store:
                        sample_locked[gi] = locked
                if kind == EV_LINK:
                    fall_kind = ev_par[ev_hit]
                elif kind == EV_TOE:
                    fall_kind = n
                else:
                    fall_kind = n + 1
                break
            if n_switches < switch_times.size:
                switch_times[n_switches] = t_ev
            n_switches += 1
            if n_switches > max_switches:
                status = STATUS_CHATTERING
                break
            if kind == EV_PAIR:
                # the pair engages if its stretch is now growing, goes slack otherwise
                p = ev_par[ev_hit]
                sd = 0.0
                for j in range(n):
                    sd += E[p, j] * x[n + j]
                active[p] = 1.0 if sd >= 0.0 else 0.0
                _joint_matrices(E, kd, ld, active, mp, n)
            elif kind == EV_KNEE_HIT:
                x[1] = x[0] + stop_angle
                om = project_velocity(x[:n], x[n:], mp)
                for i in range(n):
                    x[n + i] = om[i]
                locked = True
            else:
                locked = False
            if not np.all(np.isfinite(x)):
                status = STATUS_NONFINITE
                break
            restart = True
            continue

        finite = True
        for i in range(m):
            if not np.isfinite(ytmp[i]):
                finite = False
        if not finite:
            status = STATUS_NONFINITE
            break
        t = t_new
        for i in range(m):
            x[i] = ytmp[i]
            stg[0, i] = stg[last_row, i]
        for e in range(n_ev):
            g_old[e] = g_new[e]
        if n3:
            if n_steps % _TRIG_REFRESH == 0:
                # fresh libm values now and then keep rounding from building up
                for i in range(3):
                    base[i] = x[i]
                    base[3 + i] = math.sin(x[i])
                    base[6 + i] = math.cos(x[i])
            else:
                for i in range(3):
                    base[i] = x[i]
                    base[3 + i] = trig[i]
                    base[6 + i] = trig[3 + i]
        if landing:
            while bi < bps.size and bps[bi] <= t + 1e-12:
                bi += 1
        h = h_next

    res = np.empty(N_RESULT)
    res[R_STATUS] = status
    res[R_N_SAMPLES] = gi
    res[R_FALL_KIND] = fall_kind
    res[R_FALL_TIME] = fall_time
    res[R_N_SWITCHES] = n_switches
    res[R_T_REACHED] = t
    res[R_N_STEPS] = n_steps
    res[R_N_REJECTED] = n_rejected
    res[R_N_EVALS] = n_evals
    res[R_LAST_OUTSIDE] = last_outside
    res[R_ANY_OUTSIDE] = 1.0 if any_outside else 0.0
    res[R_FINAL_OUTSIDE] = 1.0 if final_outside else 0.0
    res[R_FALL_SAMPLE] = 1.0 if fall_sample else 0.0
    return res


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT, nogil=True)
def run_one(x0, grid, mp0, E, kd, ld, one_sided, dp, bps, fpar, ipar):
    """One run with stored samples.

    Returns (result vector, samples (2N, T + 1), knee locked at each sample
    (T + 1,), switch times); the result vector says how many samples are valid.
    """
    m = x0.size
    samples = np.empty((m, grid.size + 1))
    sample_locked = np.zeros(grid.size + 1, np.bool_)
    switch_times = np.empty(ipar[I_MAX_SWITCHES] + 1)
    peak = np.empty(m // 2)
    final = np.empty(m)
    res = _integrate(x0, grid, mp0, E, kd, ld, one_sided, dp, bps, fpar, ipar, samples,
                     sample_locked, switch_times, peak, final)
    return res, samples, sample_locked, switch_times


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT, nogil=True)
def run_batch_serial(x0_all, which, grid, mp0, E, kd_all, ld_all, one_sided, dp_all, bps, fpar,
                     ipar_all, results, peaks, finals):
    """Runs one after another in the calling thread, without the GIL (outcomes only).

    Run r starts from ``x0_all[which[r]]`` under the disturbance ``dp_all[which[r]]``
    with the integer options ``ipar_all[which[r]]`` (whether the knee starts locked
    depends on the initial state): one row per distinct disturbance scale, a single
    row when nothing is scaled."""
    dummy = np.empty((x0_all.shape[1], 0))
    dummy_locked = np.empty(0, np.bool_)
    switch_times = np.empty(1)
    for r in range(kd_all.shape[0]):
        w = which[r]
        results[r] = _integrate(x0_all[w], grid, mp0, E, kd_all[r], ld_all[r], one_sided,
                                dp_all[w], bps, fpar, ipar_all[w], dummy, dummy_locked,
                                switch_times, peaks[r], finals[r])


@njit(cache=True, parallel=True, error_model="numpy", fastmath=_CONTRACT)
def run_batch_parallel(x0_all, which, grid, mp0, E, kd_all, ld_all, one_sided, dp_all, bps,
                       fpar, ipar_all, results, peaks, finals, chunk):
    """Runs spread over numba's threads, ``chunk`` runs per work item (outcomes only; the
    arguments as for :func:`run_batch_serial`)."""
    M = kd_all.shape[0]
    n_chunks = (M + chunk - 1) // chunk
    for c in prange(n_chunks):
        dummy = np.empty((x0_all.shape[1], 0))
        dummy_locked = np.empty(0, np.bool_)
        switch_times = np.empty(1)
        for r in range(c * chunk, min(M, c * chunk + chunk)):
            w = which[r]
            results[r] = _integrate(x0_all[w], grid, mp0, E, kd_all[r], ld_all[r], one_sided,
                                    dp_all[w], bps, fpar, ipar_all[w], dummy, dummy_locked,
                                    switch_times, peaks[r], finals[r])


# ---------------------------------------------------------------------------
# Derived time series of a stored run
# ---------------------------------------------------------------------------

_INVPIO2 = 6.36619772367581382433e-01
_PIO2_1 = 1.57079632673412561417e+00  # the first 33 bits of π/2
_PIO2_1T = 6.07710050650619224932e-11  # π/2 − _PIO2_1
# fdlibm's kernels of sin and cos on [−π/4, π/4] (k_sin.c, k_cos.c)
_KS1 = -1.66666666666666324348e-01
_KS2 = 8.33333333332248946124e-03
_KS3 = -1.98412698298579493134e-04
_KS4 = 2.75573137070700676789e-06
_KS5 = -2.50507602534068634195e-08
_KS6 = 1.58969099521155010221e-10
_KC1 = 4.16666666666666019037e-02
_KC2 = -1.38888888888741095749e-03
_KC3 = 2.48015872894767294178e-05
_KC4 = -2.75573143513906633035e-07
_KC5 = 2.08757232129817482790e-09
_KC6 = -1.13596475577881948265e-11


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def sincos_array(x, s, c):
    """s, c = sin x, cos x elementwise (to 1 ulp); branch-free so that it vectorises.

    Cody–Waite reduction by π/2 and fdlibm's polynomial kernels; |x| > 1e5 [rad]
    (never a posture) falls back to libm.
    """
    for i in range(x.size):
        v = x[i]
        k = math.floor(v * _INVPIO2 + 0.5)
        r = (v - k * _PIO2_1) - k * _PIO2_1T
        z = r * r
        sp = r + r * z * (_KS1 + z * (_KS2 + z * (_KS3 + z * (_KS4 + z * (_KS5 + z * _KS6)))))
        cp = 1.0 - 0.5 * z + z * z * (_KC1 + z * (_KC2 + z * (_KC3 + z * (_KC4 + z * (
            _KC5 + z * _KC6)))))
        q = int(k) & 3
        swap = (q & 1) == 1
        sv = cp if swap else sp
        cv = sp if swap else cp
        s[i] = -sv if (q & 2) != 0 else sv
        c[i] = -cv if ((q + 1) & 2) != 0 else cv
    for i in range(x.size):
        if not abs(x[i]) <= 1e5:
            s[i] = math.sin(x[i])
            c[i] = math.cos(x[i])


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def derived_fields(samples, count, locked, E, kd, ld, one_sided, crosses, mp0, total_mass,
                   time, dp, vx0, vy0):
    """The derived time series of a result, as posturelab.simulate._assemble computes them.

    ``samples`` (2N, ≥T) holds the states [rad, rad/s] in its first ``count`` = T
    columns and ``locked`` (≥T,) marks samples where the knee constraint held.
    Returns, each with time last (the caller transposes the views):
    pair torques M (T, P) [N·m] (zero while a one-sided pair's stretch is
    negative), joint torques U = −EᵀM (T, N) [N·m], joint moments CᵀM (T, N)
    [N·m], angular accelerations (T, N) [rad/s²] (the model at each sample,
    the knee constraint where it held), centre of gravity (T, 2) [m] and its
    velocity (T, 2) [m/s], ground reaction (T, 2) [N], centre of pressure (T,)
    [m] (NaN where the vertical reaction is not positive), platform
    acceleration (T, 2) [m/s²], velocity (T, 2) [m/s] (trapezoidal, from the
    velocity step (vx0, vy0) [m/s]) and position (T, 2) [m].
    """
    n = samples.shape[0] // 2
    T = count
    theta = np.empty((n, T))
    omega = np.empty((n, T))
    for i in range(n):
        theta[i] = samples[i, :T]
        omega[i] = samples[n + i, :T]
    P = kd.size
    g = mp0[2 * n + 3 * n * n]
    sn = np.empty((n, T))
    cs = np.empty((n, T))
    for i in range(n):
        sincos_array(theta[i], sn[i], cs[i])
    acc = np.zeros((2, T))
    if dp[0] > 0.0:
        for k in range(T):
            ax, ay = platform_acceleration(time[k], dp)
            acc[0, k] = ax
            acc[1, k] = ay
    # pair torques, link torques and joint moments (loops over time innermost: they vectorise)
    M = np.empty((P, T))
    U = np.zeros((n, T))
    mom = np.zeros((n, T))
    stretch = np.empty(T)
    rate = np.empty(T)
    for p in range(P):
        stretch[:] = 0.0
        rate[:] = 0.0
        for j in range(n):
            e = E[p, j]
            if e != 0.0:
                th = theta[j]
                om = omega[j]
                for k in range(T):
                    stretch[k] += e * th[k]
                    rate[k] += e * om[k]
        kp = kd[p]
        lp = ld[p]
        gated = one_sided[p] != 0
        Mp = M[p]
        for k in range(T):
            v = kp * stretch[k] + lp * rate[k]
            Mp[k] = 0.0 if (gated and stretch[k] < 0.0) else v
        for j in range(n):
            e = E[p, j]
            c = crosses[p, j]
            Uj = U[j]
            mj = mom[j]
            for k in range(T):
                Uj[k] -= Mp[k] * e
                mj[k] += Mp[k] * c
    alpha = np.empty((n, T))
    if n == 3:
        c12 = mp0[7]
        c13 = mp0[8]
        c23 = mp0[11]
        a1 = mp0[0]
        a2 = mp0[1]
        a3 = mp0[2]
        j11 = mp0[3]
        j22 = mp0[4]
        j33 = mp0[5]
        for k in range(T):
            s1 = sn[0, k]
            s2 = sn[1, k]
            s3 = sn[2, k]
            cc1 = cs[0, k]
            cc2 = cs[1, k]
            cc3 = cs[2, k]
            q1 = omega[0, k] * omega[0, k]
            q2 = omega[1, k] * omega[1, k]
            q3 = omega[2, k] * omega[2, k]
            n12 = c12 * (s1 * cc2 - cc1 * s2)
            n13 = c13 * (s1 * cc3 - cc1 * s3)
            n23 = c23 * (s2 * cc3 - cc2 * s3)
            ga = g + acc[1, k]
            ax = acc[0, k]
            r1 = U[0, k] - (n12 * q2 + n13 * q3) + a1 * (ga * s1 - ax * cc1)
            r2 = U[1, k] - (n23 * q3 - n12 * q1) + a2 * (ga * s2 - ax * cc2)
            r3 = U[2, k] + (n13 * q1 + n23 * q2) + a3 * (ga * s3 - ax * cc3)
            j12 = c12 * (cc1 * cc2 + s1 * s2)
            j13 = c13 * (cc1 * cc3 + s1 * s3)
            j23 = c23 * (cc2 * cc3 + s2 * s3)
            m11 = j22 * j33 - j23 * j23
            m12 = j13 * j23 - j12 * j33
            m13 = j12 * j23 - j13 * j22
            m22 = j11 * j33 - j13 * j13
            m23 = j12 * j13 - j11 * j23
            m33 = j11 * j22 - j12 * j12
            inv_det = 1.0 / (j11 * m11 + j12 * m12 + j13 * m13)
            b1 = (m11 * r1 + m12 * r2 + m13 * r3) * inv_det
            b2 = (m12 * r1 + m22 * r2 + m23 * r3) * inv_det
            b3 = (m13 * r1 + m23 * r2 + m33 * r3) * inv_det
            y1 = m12 - m11
            y2 = m22 - m12
            y3 = m23 - m13
            if locked[k]:
                lam = (b2 - b1) / (y2 - y1)
                b1 -= y1 * lam
                b2 -= y2 * lam
                b3 -= y3 * lam
            alpha[0, k] = b1
            alpha[1, k] = b2
            alpha[2, k] = b3
    else:
        work = np.empty((n, n + 4))
        x = np.empty(2 * n)
        out = np.empty((1, 2 * n))
        mp = mp0.copy()
        ok = 2 * n + n * n
        for q in range(2 * n * n):
            mp[ok + q] = 0.0  # K = L = 0: the muscle torques come in as U below
        for k in range(T):
            for i in range(n):
                x[i] = theta[i, k]
                x[n + i] = omega[i, k]
            # the free model with U added: solve J α = U + (the rest), as _derivN does
            _derivN_with_torque(time[k], x, out, locked[k], mp, dp, work, U[:, k])
            for i in range(n):
                alpha[i, k] = out[0, n + i]
    # centre of gravity, its velocity and acceleration, ground reaction, centre of pressure
    T2 = (2, T)
    # Σ a s, Σ a c, Σ ω a c, −Σ ω a s, Σ (α a c − a s ω²), Σ (−α a s − a c ω²)
    sums = np.zeros((6, T))
    for i in range(n):
        ai = mp0[i]
        si = sn[i]
        ci = cs[i]
        wi = omega[i]
        al = alpha[i]
        for k in range(T):
            w = wi[k]
            sums[0, k] += ai * si[k]
            sums[1, k] += ai * ci[k]
            sums[2, k] += w * ai * ci[k]
            sums[3, k] -= w * ai * si[k]
            sums[4, k] += al[k] * ai * ci[k] - ai * si[k] * w * w
            sums[5, k] += -al[k] * ai * si[k] - ai * ci[k] * w * w
    cog = np.empty(T2)
    cogv = np.empty(T2)
    ground = np.empty(T2)
    cop = np.empty(T)
    for k in range(T):
        cog[0, k] = sums[0, k] / total_mass
        cog[1, k] = sums[1, k] / total_mass
        cogv[0, k] = sums[2, k] / total_mass
        cogv[1, k] = sums[3, k] / total_mass
        gy = total_mass * (g + acc[1, k] + sums[5, k] / total_mass)
        ground[0, k] = total_mass * (acc[0, k] + sums[4, k] / total_mass)
        ground[1, k] = gy
        cop[k] = mom[0, k] / gy if gy > 0.0 else np.nan
    vel = np.empty(T2)
    pos = np.empty(T2)
    if dp[0] > 0.0:
        # trapezoidal integration, both axes in one pass (independent chains overlap)
        if T > 0:
            vx = vx0
            vy = vy0
            px = 0.0
            py = 0.0
            vel[0, 0] = vx
            vel[1, 0] = vy
            pos[0, 0] = 0.0
            pos[1, 0] = 0.0
            for k in range(1, T):
                dt = time[k] - time[k - 1]
                vxn = vx + 0.5 * (acc[0, k] + acc[0, k - 1]) * dt
                vyn = vy + 0.5 * (acc[1, k] + acc[1, k - 1]) * dt
                px = px + 0.5 * (vxn + vx) * dt
                py = py + 0.5 * (vyn + vy) * dt
                vx = vxn
                vy = vyn
                vel[0, k] = vx
                vel[1, k] = vy
                pos[0, k] = px
                pos[1, k] = py
    else:
        # no acceleration: the velocity stays that of the step, the trapezoids sum to v·t
        t0 = time[0] if T > 0 else 0.0
        for k in range(T):
            vel[0, k] = vx0
            vel[1, k] = vy0
            pos[0, k] = vx0 * (time[k] - t0)
            pos[1, k] = vy0 * (time[k] - t0)
    return M, U, mom, alpha, cog, cogv, ground, cop, acc, vel, pos


@njit(cache=True, error_model="numpy", fastmath=_CONTRACT)
def _derivN_with_torque(t, x, out, locked, mp, dp, work, U):
    """As _derivN (with K = L = 0 in ``mp``) plus the generalised torques U (N,) [N·m]."""
    n = x.size // 2
    oc = 2 * n
    if dp[0] > 0.0:
        ax, ay = platform_acceleration(t, dp)
    else:
        ax = 0.0
        ay = 0.0
    ga = mp[oc + 3 * n * n] + ay
    for i in range(n):
        work[i, n + 2] = math.sin(x[i])
        work[i, n + 3] = math.cos(x[i])
    for i in range(n):
        si = work[i, n + 2]
        ci = work[i, n + 3]
        r = U[i] + mp[i] * (ga * si - ax * ci)
        for j in range(n):
            if j != i:
                sj = work[j, n + 2]
                cj = work[j, n + 3]
                cij = mp[oc + i * n + j]
                r -= cij * (si * cj - ci * sj) * x[n + j] * x[n + j]
                work[i, j] = cij * (ci * cj + si * sj)
            else:
                work[i, j] = mp[n + i]
        work[i, n] = r
        work[i, n + 1] = 0.0
    ncol = 1
    if locked:
        work[0, n + 1] = -1.0
        work[1, n + 1] = 1.0
        ncol = 2
    _solve_into(work, n, ncol)
    if locked:
        lam = (work[1, n] - work[0, n]) / (work[1, n + 1] - work[0, n + 1])
        for i in range(n):
            work[i, n] -= work[i, n + 1] * lam
    for i in range(n):
        out[0, i] = x[n + i]
        out[0, n + i] = work[i, n]
