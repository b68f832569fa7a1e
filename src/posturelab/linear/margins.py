"""Delay margins of many parameter sets at once: a closed form for one link, the delay
pencil for N links.

Each set's :class:`~posturelab.linear.system.LinearSystem` has the characteristic matrix
Δ(s) = A(s) + B(s) e^{−sτ}, A(s) = s² J0 + s L_i + S, B(s) = K_a + s L_a (real
matrices). Its delay margin is the smallest τ > 0 at which a root reaches the imaginary
axis, s = iω (the same quantity as :func:`posturelab.linear.delay.delay_margin`, which
finds it by the Chen–Gu–Nett pencil of the first-order form, one set at a time).

**Crossing frequencies.** At a crossing, A(iω) v = −z B(iω) v with z = e^{−iωτ} on the unit
circle; conjugating (the matrices are real, and z̄ = 1/z) gives B(−iω) w = −z A(−iω) w
with w = v̄. So v ⊗ w is a null vector of::

    Δ₀(s) = A(s) ⊗ A(−s) − B(s) ⊗ B(−s) = E(s²) + s O(s²),

E(λ) = λ² J⊗J + λ (J⊗S + S⊗J − L_i⊗L_i + L_a⊗L_a) + S⊗S − K_a⊗K_a and
O(λ) = λ (L_i⊗J − J⊗L_i) + L_i⊗S − S⊗L_i + K_a⊗L_a − L_a⊗K_a. E commutes with the swap
Π(x ⊗ y) = y ⊗ x and O anticommutes with it, so in an orthonormal basis of the symmetric
and antisymmetric tensors (sizes N(N+1)/2 and N(N−1)/2) Δ₀ is [[E_ss, s O_sa], [s O_as,
E_aa]]; scaling the second block row by s and column by 1/s leaves the quadratic
eigenvalue problem in λ = s² = −ω²::

    T(λ) = [[E_ss(λ), O_sa(λ)], [λ O_as(λ), E_aa(λ)]],

of size N², whose leading coefficient is block triangular with the invertible diagonal
blocks of J⊗J. Its companion form (2N² × 2N², real: 18 × 18 for three links) gives every
candidate ω at once; the stacked eigenvalue calls run on all sets together. For each
real negative λ the eigenvalues z of the N × N pencil A(iω) + z B(iω) on the unit circle
give the delays τ = (−arg z mod 2π)/ω, and the smallest over all candidates is the
margin.

**One link.** Δ₀ is a scalar quadratic in u = ω²: J² u² + (L_i² − L_a² − 2 J S) u + S² −
K_a² = 0 (the delayed inverted pendulum's |A(iω)| = |B(iω)|), solved in closed form.

**Torque feedback** (Peterka 2002; :mod:`.system`): the delayed part is B(s) g(s) with
g(s) = n(s)/d(s), n(s) = τ_t s + 1, d(s) = τ_t s + 1 − K_t. Multiplied by d(s)^N, which
does not vanish at s = iω, ω > 0, det Δ(s) is the quasi-polynomial det(Â(s) + B̂(s)
e^{−sτ}) with Â = d A (cubic) and B̂ = n B (quadratic): the characteristic function of the
3N-state first-order form with the filter states, of retarded type still. Everything above
holds with Â, B̂: as d(s) d(−s) = (1 − K_t)² − τ_t² λ and n(s) n(−s) = 1 − τ_t² λ are real
polynomials in λ, E = d d̄ E_A − n n̄ E_B and O = d d̄ O_A − n n̄ O_B (E_A, O_A the even and
odd parts of A(s) ⊗ A(−s), E_B, O_B those of B(s) ⊗ B(−s)) keep their symmetry, and T(λ)
is cubic, its leading coefficient −τ_t² times the one above (block triangular, invertible):
a companion form of size 3N². For one link the crossing condition |Â(iω)| = |B̂(iω)| is the
cubic in u = ω²::

    ((1 − K_t)² + τ_t² u) ((S − J u)² + L_i² u) − (1 + τ_t² u) (K_a² + L_a² u) = 0.

A set unstable without delay has no margin (NaN); a stable set that no delay destabilises
has an infinite one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.body import Body
from ..model.muscles import MuscleSet
from .delay_batch import _threads
from .system import BodyArrays, LinearSystem, OneSided, linear_system

__all__ = ["BatchDelayMargin", "batch_delay_margin", "delay_margins"]

#: A candidate z is on the unit circle when ||z| − 1| is at most this. [-]
_UNIT_CIRCLE = 1e-6
#: A candidate λ = −ω² is real when |Im λ| is at most this times |λ|. [-]
_REAL = 1e-4
#: Sets per stacked eigenvalue call (a block of the thread pool). [-]
_CHUNK = 1024


@dataclass(frozen=True)
class BatchDelayMargin:
    """The delay margins of M parameter sets.

    Attributes
    ----------
    delay_margin : numpy.ndarray, shape (M,)
        The smallest τ at which a root reaches the imaginary axis; ``inf`` if none ever
        does; NaN if the set is unstable without delay. [s]
    crossing_frequency : numpy.ndarray, shape (M,)
        ω of that crossing; NaN when there is none. [rad/s]
    stable_without_delay : numpy.ndarray of bool, shape (M,)
        Every root has a negative real part at τ = 0.
    """

    delay_margin: np.ndarray
    crossing_frequency: np.ndarray
    stable_without_delay: np.ndarray

    #: The unit of each array.
    units = {"delay_margin": "s", "crossing_frequency": "rad/s", "stable_without_delay": "-"}

    def __post_init__(self) -> None:
        for name in ("delay_margin", "crossing_frequency", "stable_without_delay"):
            getattr(self, name).setflags(write=False)

    def __len__(self) -> int:
        return int(self.delay_margin.shape[0])

    def to_dict(self) -> dict:
        """Plain-Python lists (a margin as s, ``"infinite"`` or None; a frequency as rad/s or
        None) and ``units``."""
        def margin(v: float):
            return None if math.isnan(v) else ("infinite" if math.isinf(v) else float(v))

        return {"delay_margin": [margin(v) for v in self.delay_margin],
                "crossing_frequency": [None if math.isnan(v) else float(v)
                                       for v in self.crossing_frequency],
                "stable_without_delay": [bool(v) for v in self.stable_without_delay],
                "units": dict(self.units)}


def batch_delay_margin(body: Body | BodyArrays, muscles: MuscleSet, *, stiffness=None,
                       viscosity=None, viscosity_ratio=None, active_stiffness=None,
                       active_viscosity=None, one_sided: OneSided = "active",
                       torque_feedback_gain=0.0, torque_feedback_time_constant=None
                       ) -> BatchDelayMargin:
    """The delay margins of M parameter sets (module notes).

    Parameters
    ----------
    body : Body or BodyArrays
    muscles : MuscleSet
        The pairs; without gain arrays also their gains (one set).
    stiffness, viscosity, viscosity_ratio, active_stiffness, active_viscosity
        As in :func:`posturelab.linear.system.linear_system`: shape (M, P) [N·m/rad],
        [N·m·s/rad]; the ratio [s]. Without active gains the whole pair feedback is
        delayed.
    one_sided : {"active", "inactive"}
        How a one-sided pair is linearised at upright.
    torque_feedback_gain, torque_feedback_time_constant : float or array_like, shape (M,)
        Peterka 2002's torque feedback (K_t 0: none; τ_t by default 17.4 s; module
        notes). [-], [s]

    Returns
    -------
    BatchDelayMargin

    Examples
    --------
    The paper's case 1 gains, all of their feedback delayed (as :func:`delay_margin`):

    >>> import numpy as np
    >>> import posturelab as pl
    >>> k = np.array([pl.paper_muscles("1").stiffnesses, pl.paper_muscles("3").stiffnesses])
    >>> out = pl.linear.batch_delay_margin(pl.paper_body(), pl.paper_muscles("1"),
    ...                                    stiffness=k, viscosity_ratio=0.25)
    >>> [round(float(v) * 1000, 2) for v in out.delay_margin]  # [ms]
    [2.81, 2.71]
    """
    return delay_margins(linear_system(body, muscles, stiffness=stiffness,
                                       viscosity=viscosity, viscosity_ratio=viscosity_ratio,
                                       active_stiffness=active_stiffness,
                                       active_viscosity=active_viscosity,
                                       one_sided=one_sided, inputs=False,
                                       torque_feedback_gain=torque_feedback_gain,
                                       torque_feedback_time_constant=(
                                           torque_feedback_time_constant)))


def delay_margins(system: LinearSystem) -> BatchDelayMargin:
    """The delay margin of every set of ``system`` (module notes): the closed form for one
    link, the delay pencil otherwise (blocks of sets on a thread pool; LAPACK runs
    without the GIL)."""
    m = system.n_sets
    margin = np.full(m, np.nan)
    frequency = np.full(m, np.nan)
    stable = _stable_without_delay(system)
    index = np.flatnonzero(stable)

    def block(lo: int) -> None:
        part = index[lo:lo + _CHUNK]
        sub = system[part]
        mats = (sub.inertia, sub.stiffness, sub.viscosity, sub.delayed_stiffness,
                sub.delayed_viscosity)
        gain, lag = _filter(sub, part.size)
        if system.n_links == 1:
            tau, omega = _one_link(*(np.broadcast_to(x, (part.size, 1, 1))[:, 0, 0]
                                     for x in mats), gain, lag)
        else:
            tau, omega = _pencil(part.size, *mats, gain, lag)
        margin[part], frequency[part] = tau, omega

    starts = range(0, index.size, _CHUNK)
    if system.n_links == 1 or len(starts) < 2:
        for lo in starts:
            block(lo)
    else:
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(max_workers=min(len(starts), _threads())) as pool:
            for _ in pool.map(block, starts):
                pass
    return BatchDelayMargin(margin, frequency, stable)


def _filter(system: LinearSystem, m: int) -> tuple[np.ndarray | None, np.ndarray | None]:
    """(K_t, τ_t) of the torque feedback, each (M,), or (None, None) without it. [-], [s]"""
    if not system.has_torque_feedback:
        return None, None
    return (np.broadcast_to(system.torque_feedback_gain, (m,)),
            np.broadcast_to(system.torque_feedback_time_constant, (m,)))


def _stable_without_delay(system: LinearSystem) -> np.ndarray:
    """Every root with a negative real part at τ = 0 (the eigenvalues of the state matrix;
    for one link without torque feedback the Routh conditions L > 0, K − g a > 0)."""
    if system.n_links == 1 and not system.has_torque_feedback:
        _, damp, load = system.without_delay()
        return np.broadcast_to((damp[:, 0, 0] > 0) & (load[:, 0, 0] > 0),
                               (system.n_sets,)).copy()
    out = np.empty(system.n_sets, dtype=bool)
    for lo in range(0, system.n_sets, _CHUNK):
        ev = np.linalg.eigvals(system[lo:lo + _CHUNK].state_matrix())
        out[lo:lo + _CHUNK] = np.all(ev.real < 0, axis=-1)
    return out


def _delays(z: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """τ = (−arg z mod 2π)/ω > 0 (a full period where arg z = 0). [s]"""
    tau = np.mod(-np.angle(z), 2 * math.pi) / omega
    return np.where(tau > 0, tau, 2 * math.pi / omega)


def _one_link(J, S, L, K, La, gain=None, lag=None) -> tuple[np.ndarray, np.ndarray]:
    """The margin and crossing frequency of one-link sets: the positive roots u = ω² of
    J² u² + (L² − La² − 2 J S) u + S² − K² = 0, τ from z = −A(iω)/B(iω); with torque
    feedback (K_t ``gain``, τ_t ``lag``, each (M,)) the positive roots of the cubic
    (c0 + c1 u)((S − J u)² + L² u) − (1 + c1 u)(K² + La² u) = 0, c0 = (1 − K_t)²,
    c1 = τ_t² (module notes), and z = −d(iω) A(iω)/(n(iω) B(iω)). [s], [rad/s]"""
    if gain is not None:
        return _one_link_filtered(J, S, L, K, La, gain, lag)
    a = J * J
    b = L * L - La * La - 2 * J * S
    c = (S - K) * (S + K)
    disc = b * b - 4 * a * c
    root = np.sqrt(np.maximum(disc, 0.0))
    q = -0.5 * (b + np.where(b >= 0, root, -root))
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.stack([q / a, np.where(q != 0, c / q, -1.0)])       # (2, M)
        ok = (disc >= 0) & (u > 0)
        omega = np.sqrt(np.where(ok, u, 1.0))
        s = 1j * omega
        z = -(J * s * s + L * s + S) / (K + La * s)
        tau = np.where(ok & np.isfinite(z), _delays(z, omega), np.inf)
    return _first(tau, omega)


def _first(tau: np.ndarray, omega: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The smallest delay over the candidates (axis 0) and its frequency. [s], [rad/s]"""
    best = np.argmin(tau, axis=0)
    cols = np.arange(tau.shape[1])
    margin = tau[best, cols]
    return margin, np.where(np.isfinite(margin), omega[best, cols], np.nan)


def _one_link_filtered(J, S, L, K, La, gain, lag) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_one_link` with torque feedback: the cubic's roots (the eigenvalues of its
    companion matrix, all sets at once). [s], [rad/s]"""
    c0 = (1.0 - gain) ** 2
    c1 = lag * lag
    cubic = np.stack([c1 * J * J,
                      c0 * J * J + c1 * (L * L - 2 * J * S) - c1 * La * La,
                      c0 * (L * L - 2 * J * S) + c1 * S * S - La * La - c1 * K * K,
                      c0 * S * S - K * K], axis=-1)                      # (M, 4), u³ first
    companion = np.zeros((J.size, 3, 3))
    companion[:, 0, :] = -cubic[:, 1:] / cubic[:, :1]
    companion[:, 1, 0] = companion[:, 2, 1] = 1.0
    u = np.linalg.eigvals(companion).T                                   # (3, M)
    with np.errstate(divide="ignore", invalid="ignore"):
        ok = (np.abs(u.imag) <= _REAL * np.abs(u)) & (u.real > 0)
        omega = np.sqrt(np.where(ok, u.real, 1.0))
        s = 1j * omega
        z = -((lag * s + 1.0 - gain) * (J * s * s + L * s + S)
              / ((lag * s + 1.0) * (K + La * s)))
        tau = np.where(ok & np.isfinite(z), _delays(z, omega), np.inf)
    return _first(tau, omega)


def _tensor_basis(n: int) -> tuple[np.ndarray, int]:
    """Q (N², N²), orthonormal: the symmetric tensors first, then the antisymmetric ones;
    and the count of symmetric ones N(N+1)/2."""
    sym, alt = [], []
    for i in range(n):
        for j in range(i, n):
            v = np.zeros((n, n))
            if i == j:
                v[i, i] = 1.0
                sym.append(v.ravel())
                continue
            v[i, j] = v[j, i] = math.sqrt(0.5)
            sym.append(v.ravel())
            w = np.zeros((n, n))
            w[i, j], w[j, i] = math.sqrt(0.5), -math.sqrt(0.5)
            alt.append(w.ravel())
    return np.array(sym + alt).T, len(sym)


def _kron(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """x ⊗ y of stacked square matrices, (M, N², N²)."""
    n = x.shape[-1]
    out = np.einsum("...ij,...kl->...ikjl", x, y)
    return out.reshape(out.shape[:-4] + (n * n, n * n))


def _polymul(p: list, q: list) -> list:
    """The coefficients (constant first) of the product of two polynomials whose
    coefficients are arrays that broadcast."""
    out = [0.0] * (len(p) + len(q) - 1)
    for i, a in enumerate(p):
        for j, b in enumerate(q):
            out[i + j] = out[i + j] + a * b
    return out


def _pencil(m: int, J, S, L, K, La, gain=None, lag=None) -> tuple[np.ndarray, np.ndarray]:
    """The margin and crossing frequency of ``m`` N-link sets by the delay pencil (module
    notes); each matrix argument (M or 1, N, N); ``gain``, ``lag`` the torque feedback's
    K_t [-] and τ_t [s], each (M,), or None. [s], [rad/s]"""
    n = S.shape[-1]
    J, S, L, K, La = (np.broadcast_to(x, (m, n, n)) if x.shape[0] != 1 else x
                      for x in (J, S, L, K, La))
    q, ns = _tensor_basis(n)
    size = n * n

    def project(x):
        return q.T @ x @ q

    # A(s) ⊗ A(−s) = E_A(λ) + s O_A(λ) and B(s) ⊗ B(−s) = E_B(λ) + s O_B(λ), λ = s²
    even_a = [project(_kron(S, S)), project(_kron(J, S) + _kron(S, J) - _kron(L, L)),
              project(_kron(J, J))]
    even_b = [project(_kron(K, K)), -project(_kron(La, La))]
    odd_a = [project(_kron(L, S) - _kron(S, L)), project(_kron(L, J) - _kron(J, L))]
    odd_b = [project(_kron(La, K) - _kron(K, La))]
    if gain is None:
        ones = [np.ones((1, 1, 1))]
        p_d = p_n = ones
    else:  # d(s) d(−s) = (1 − K_t)² − τ_t² λ,  n(s) n(−s) = 1 − τ_t² λ
        c = (lag * lag)[:, None, None]
        p_d = [((1.0 - gain) ** 2)[:, None, None], -c]
        p_n = [np.ones((1, 1, 1)), -c]
    even = [x - y for x, y in zip(_polymul(p_d, even_a),
                                  _polymul(p_n, even_b) + [0.0] * len(p_d), strict=False)]
    odd = [x - y for x, y in zip(_polymul(p_d, odd_a),
                                 _polymul(p_n, odd_b) + [0.0] * len(p_d), strict=False)]
    degree = len(even) - 1
    # T_k = [[E_k,ss, O_k,sa], [O_{k−1},as, E_k,aa]] (E's off-diagonal and O's diagonal
    # blocks are 0); T_degree is block triangular with invertible diagonal blocks
    coefficients = []
    for k in range(degree + 1):
        t = np.array(np.broadcast_to(even[k], (m, size, size)))
        t[:, :ns, ns:] = odd[k][..., :ns, ns:] if k < len(odd) else 0.0
        t[:, ns:, :ns] = odd[k - 1][..., ns:, :ns] if 0 < k <= len(odd) else 0.0
        coefficients.append(t)
    companion = np.zeros((m, degree * size, degree * size))
    companion[:, :-size, size:] = np.eye((degree - 1) * size)
    companion[:, -size:, :] = -np.linalg.solve(coefficients[-1],
                                               np.concatenate(coefficients[:-1], axis=-1))
    lam = np.linalg.eigvals(companion)                  # (M, 2N²), 3N² with the filter
    real = (lam.real < 0) & (np.abs(lam.imag) <= _REAL * np.abs(lam))
    sets, which = np.nonzero(real)
    margin = np.full(m, np.inf)
    frequency = np.full(m, np.nan)
    if sets.size == 0:
        return margin, frequency
    omega = np.sqrt(-lam.real[sets, which])                              # (C,)
    s = (1j * omega)[:, None, None]
    def rows(x):
        return x[0] if x.shape[0] == 1 else x[sets]

    a = s * s * rows(J) + s * rows(L) + rows(S)
    b = rows(K) + s * rows(La)
    if gain is not None:  # Â = d(s) A(s), B̂ = n(s) B(s)
        lag_c, gain_c = lag[sets][:, None, None], gain[sets][:, None, None]
        a = a * (lag_c * s + 1.0 - gain_c)
        b = b * (lag_c * s + 1.0)
    # A + z B singular ⇔ z = −1/μ, μ an eigenvalue of A⁻¹B (A(iω) is regular there)
    try:
        mu = np.linalg.eigvals(np.linalg.solve(a, b))                    # (C, N)
    except np.linalg.LinAlgError:
        mu = np.array([_pencil_mu(x, y) for x, y in zip(a, b, strict=True)])
    with np.errstate(divide="ignore", invalid="ignore"):
        z = -1.0 / mu
        on_circle = np.abs(np.abs(z) - 1.0) <= _UNIT_CIRCLE
        tau = np.where(on_circle, _delays(z, omega[:, None]), np.inf).min(axis=1)
    order = np.lexsort((tau, sets))
    first = order[np.r_[True, sets[order][1:] != sets[order][:-1]]]
    margin[sets[first]] = tau[first]
    found = np.isfinite(tau[first])
    frequency[sets[first][found]] = omega[first][found]
    return margin, frequency


def _pencil_mu(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """μ with A + (−1/μ) B singular for a singular A too (the generalised eigenvalues of
    (B, A), infinite where B is singular)."""
    from scipy.linalg import eigvals

    with np.errstate(all="ignore"):
        return eigvals(b, a)
