"""Linear analysis with a feedback delay: the characteristic quasi-polynomial, the delay
margin and the rightmost roots.

Linearised about upright with the platform at rest, the chain with intrinsic gains
(K_i, L_i, immediate) and active gains (K_a, L_a, delayed by τ) obeys::

    J0 Θ̈ − g A Θ + K_i Θ + L_i Θ̇ + K_a Θ(t − τ) + L_a Θ̇(t − τ) = 0,

A = diag(a), K_i = Eᵀ diag(k_i) E and so on, the gains split as
:func:`posturelab.model.muscles.feedback_gains` states (a muscle set without active
gains has K_i = L_i = 0: its whole feedback is delayed). Its characteristic matrix is::

    Δ(s) = s² J0 − g A + K_i + s L_i + (K_a + s L_a) e^{−sτ},

(the matrices of the one linear system, :mod:`posturelab.linear.system`; with Peterka 2002's
torque feedback the delayed part is multiplied by g(s) = (τ_t s + 1)/(τ_t s + 1 − K_t) and
the first-order form below carries the filter states, 3N in all), and the roots of
det Δ(s) = 0 are the characteristic roots (infinitely many; finitely
many to the right of any vertical line: the equation is of retarded type).

**Delay margin.** The smallest τ > 0 at which a root reaches the imaginary axis, s = iω.
It is computed exactly, without a frequency grid, by the method of Chen, Gu and Nett
(1995, *Syst. Control Lett.* 26:107–117): in first-order form ẋ = A0 x + A1 x(t − τ),
iω is an eigenvalue of A0 + z A1 with z = e^{−iωτ} on the unit circle only if the
Kronecker sum (A0 + z A1) ⊕ (A0 + z⁻¹ A1) is singular, a quadratic eigenvalue problem in
z of size (2N)². Its unit-circle solutions give the crossing frequencies (the imaginary
eigenvalues of A0 + z A1) and the delays τ = (−arg z + 2πk)/ω; each crossing is then
polished by Newton's method on det Δ(iω, τ) = 0. The crossing direction is the sign of
Re ds/dτ (from the left and right null vectors of Δ).

**Rightmost roots.** The spectral discretisation of the solution operator's generator
(Breda, Maset and Vermiglio 2005, *SIAM J. Sci. Comput.* 27:482–495): the state on
[−τ, 0] is collocated at Chebyshev points; the eigenvalues of the resulting matrix
approximate the rightmost roots with spectral accuracy, and Newton's method on
det Δ(s) = 0 (step 1/tr(Δ⁻¹Δ')) then refines each to rounding. The tests check both
against an independent frequency sweep of |z(ω)| = 1 for the pencil Δ(iω) = M0(ω) + z M1(ω)
and against the closed form of the delayed inverted pendulum.

**A negligible delay.** When τ·ρ ≤ :data:`NEGLIGIBLE_DELAY_PHASE` (ρ = max(1 [1/s], ‖A0‖₂,
‖A1‖₂), the rate scale of the first-order form), the delay shifts the roots near the τ = 0
poles by a relative O(τρ) only, and the roots it adds lie to the left of Re s ≈
−ln(1/(τρ))/τ, far left of them (the equation is of retarded type, so its rightmost
roots are continuous at τ = 0). Such a delay is treated as no delay for the starting
guesses: the τ = 0 poles, refined by Newton's method at the actual τ. The Chebyshev
generator, whose entries grow as nodes²/τ, would lose every root to rounding there (it
did below about 1e-13 s).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .._validation import float_in_range
from ..errors import ParameterError
from ..model.body import Body
from ..model.muscles import MuscleSet
from ..parameters import MAX_FEEDBACK_DELAY
from .analysis import _check_match
from .system import LinearSystem, OneSided, linear_system

__all__ = [
    "DelayedSystem",
    "DelayCrossing",
    "DelayMargin",
    "delayed_system",
    "characteristic_matrix",
    "characteristic_function",
    "delay_margin",
    "rightmost_roots",
    "system_rightmost_roots",
    "MAX_DELAY_FOR_ROOTS",
]

#: Largest delay :func:`rightmost_roots` accepts: the parameter table's feedback delay bound. [s]
MAX_DELAY_FOR_ROOTS = MAX_FEEDBACK_DELAY
#: τ·ρ at or below which a delay is negligible (module notes): the τ = 0 poles are the
#: starting guesses. [-]
NEGLIGIBLE_DELAY_PHASE = 1e-6


def negligible_delay(A0: np.ndarray, A1: np.ndarray, delay: float) -> np.ndarray:
    """Whether ``delay`` is negligible for each first-order form (module notes):
    τ·max(1, ‖A0‖₂, ‖A1‖₂) ≤ :data:`NEGLIGIBLE_DELAY_PHASE` (True at τ = 0).

    Parameters
    ----------
    A0, A1 : numpy.ndarray, shape (..., m, m)
        The first-order form's matrices. [1/s]
    delay : float
        τ. [s]

    Returns
    -------
    numpy.ndarray of bool, shape (...)
    """
    rate = np.maximum(1.0, np.maximum(np.linalg.norm(A0, ord=2, axis=(-2, -1)),
                                      np.linalg.norm(A1, ord=2, axis=(-2, -1))))
    return delay * rate <= NEGLIGIBLE_DELAY_PHASE


#: The linearised delayed chain: one :class:`~posturelab.linear.system.LinearSystem`.
DelayedSystem = LinearSystem


def delayed_system(body: Body, muscles: MuscleSet, one_sided: OneSided = "active", *,
                   torque_feedback_gain: float = 0.0,
                   torque_feedback_time_constant: float | None = None) -> LinearSystem:
    """The linearised delayed chain of one body and muscle set, as a
    :class:`~posturelab.linear.system.LinearSystem` of one set (see the module notes).

    Parameters
    ----------
    body : Body
    muscles : MuscleSet
        Intrinsic and active gains (without active gains, all of the feedback is the
        delayed part).
    one_sided : {"active", "inactive"}
        How a one-sided pair is linearised (:func:`posturelab.analyse`).
    torque_feedback_gain, torque_feedback_time_constant : float
        Peterka 2002's torque feedback (:func:`posturelab.linear.system.linear_system`; K_t
        0: none; τ_t by default the parameter table's). [-], [s]
    """
    _check_match(body, muscles)
    return linear_system(body, muscles, one_sided=one_sided, inputs=False,
                         torque_feedback_gain=torque_feedback_gain,
                         torque_feedback_time_constant=torque_feedback_time_constant)


def characteristic_matrix(system: LinearSystem, s, delay: float) -> np.ndarray:
    """Δ(s) = s² J0 − g A + K_i + s L_i + (K_a + s L_a) e^{−sτ} of a one-set system,
    shape s.shape + (N, N).

    Parameters
    ----------
    s : complex or array_like
        Laplace variable. [1/s]
    delay : float
        τ. [s]
    """
    return system.characteristic_matrix(np.asarray(s, dtype=complex)[None], delay)[0]


def characteristic_function(system: LinearSystem, s, delay: float) -> np.ndarray:
    """det Δ(s), the characteristic quasi-polynomial, at ``s``. [(N·m/rad)^N]"""
    return np.linalg.det(characteristic_matrix(system, s, delay))


def _matrices(system: LinearSystem) -> tuple[np.ndarray, ...]:
    """(J0, S, L_i, K_a, L_a) of a one-set system, each (N, N)."""
    return tuple(x[0] for x in (system.inertia, system.stiffness, system.viscosity,
                                system.delayed_stiffness, system.delayed_viscosity))


def _slope(system: LinearSystem, s: complex, delay: float) -> np.ndarray:
    """dΔ/ds at ``s`` for delay τ (with the torque feedback's factor g(s) and its
    derivative g'(s) = −K_t τ_t/(τ_t s + 1 − K_t)² when the system has one). [N·m·s/rad]"""
    J0, _, Li, Ka, La = _matrices(system)
    delayed = np.exp(-s * delay)
    slope = (La - delay * (Ka + s * La)) * delayed
    if system.has_torque_feedback:
        gain = float(system.torque_feedback_gain[0])
        lag = float(system.torque_feedback_time_constant[0])
        factor = (lag * s + 1.0) / (lag * s + 1.0 - gain)
        slope = slope * factor - (Ka + s * La) * delayed * gain * lag / (lag * s + 1.0 - gain) ** 2
    return 2 * s * J0 + Li + slope


@dataclass(frozen=True)
class DelayCrossing:
    """A delay at which a pair of characteristic roots ±iω sits on the imaginary axis.

    Attributes
    ----------
    delay : float
        τ. [s]
    frequency : float
        ω > 0. [rad/s]
    direction : int
        +1 if the roots cross into the right half-plane as τ grows, −1 if they leave it. [-]
    """

    delay: float
    frequency: float
    direction: int


@dataclass(frozen=True)
class DelayMargin:
    """The delay margin of a linearised chain.

    Attributes
    ----------
    stable_without_delay : bool
        Every root has a negative real part at τ = 0.
    delay_margin : float or None
        The smallest τ at which a root reaches the imaginary axis; ``inf`` if none ever
        does; None if the chain is unstable without delay. [s]
    crossing_frequency : float or None
        ω at that crossing (None if there is none). [rad/s]
    crossings : tuple of DelayCrossing
        Every crossing with τ up to ``max_delay``, by delay. [s], [rad/s]
    """

    stable_without_delay: bool
    delay_margin: float | None
    crossing_frequency: float | None
    crossings: tuple[DelayCrossing, ...]

    @property
    def verdict(self) -> Literal["unstable without delay", "no crossing", "crossing"]:
        """What was found, in words."""
        if not self.stable_without_delay:
            return "unstable without delay"
        return "no crossing" if math.isinf(self.delay_margin) else "crossing"

    def to_dict(self) -> dict:
        """``{"delay_margin": s | None | "infinite", "crossing_frequency": rad/s | None,
        "stable_without_delay": bool}``."""
        margin = self.delay_margin
        return {
            "delay_margin": None if margin is None else ("infinite" if math.isinf(margin)
                                                          else float(margin)),
            "crossing_frequency": (None if self.crossing_frequency is None
                                   else float(self.crossing_frequency)),
            "stable_without_delay": bool(self.stable_without_delay),
        }


def _crossing_candidates(A0: np.ndarray, A1: np.ndarray) -> list[tuple[complex, float]]:
    """(z, ω): unit-circle z and ω > 0 with iω an eigenvalue of A0 + z A1 (Chen–Gu–Nett)."""
    from scipy.linalg import eig

    m = A0.shape[0]
    eye = np.eye(m)
    B0 = np.kron(A0, eye) + np.kron(eye, A0)
    B1 = np.kron(A1, eye)
    B2 = np.kron(eye, A1)
    q = m * m
    # (z² B1 + z B0 + B2) u = 0, linearised: [[0, I], [−B2, −B0]] w = z [[I, 0], [0, B1]] w
    big_a = np.block([[np.zeros((q, q)), np.eye(q)], [-B2, -B0]])
    big_b = np.block([[np.eye(q), np.zeros((q, q))], [np.zeros((q, q)), B1]])
    with np.errstate(all="ignore"):
        zs = eig(big_a, big_b, right=False)
    scale = max(1.0, np.abs(A0).max(), np.abs(A1).max())
    out = []
    for z in zs[np.isfinite(zs)]:
        if abs(abs(z) - 1.0) > 1e-5:
            continue
        z = z / abs(z)
        lam = np.linalg.eigvals(A0 + z * A1)
        for w in lam[np.abs(lam.real) <= 1e-6 * scale]:
            if w.imag > 1e-9 * scale:
                out.append((complex(z), float(w.imag)))
    return out


def _polish(system: LinearSystem, omega: float, delay: float) -> tuple[float, float] | None:
    """Newton on det Δ(iω, τ) = 0 in (ω, τ) from a candidate; None if it does not converge."""
    # a fixed scale: Hadamard's bound on |det Δ| at the candidate
    scale = max(float(np.prod(np.linalg.norm(characteristic_matrix(system, 1j * omega, delay),
                                             axis=1))), 1e-300)

    def f(w: float, t: float) -> np.ndarray:
        v = characteristic_function(system, 1j * w, t) / scale
        return np.array([v.real, v.imag])

    w, t = omega, delay
    for _ in range(50):
        r = f(w, t)
        hw = 1e-7 * max(1.0, abs(w))
        ht = 1e-7 * max(1e-3, abs(t))
        jac = np.column_stack([(f(w + hw, t) - f(w - hw, t)) / (2 * hw),
                               (f(w, t + ht) - f(w, t - ht)) / (2 * ht)])
        try:
            step = np.linalg.solve(jac, -r)
        except np.linalg.LinAlgError:
            return None
        w, t = w + step[0], t + step[1]
        if abs(step[0]) <= 1e-14 * max(1.0, abs(w)) and abs(step[1]) <= 1e-15 * max(1.0, t):
            break
    if not (w > 0 and t > 0) or abs(w - omega) > 1e-3 * max(1.0, omega):
        return None
    return w, t


def _direction(system: LinearSystem, omega: float, delay: float) -> int:
    """sign Re ds/dτ at the root s = iω for delay τ (left and right null vectors of Δ)."""
    s = 1j * omega
    D = characteristic_matrix(system, s, delay)
    u, _, vh = np.linalg.svd(D)
    right, left = vh[-1].conj(), u[:, -1]
    _, _, _, Ka, La = _matrices(system)
    factor = system.torque_feedback_factor(np.array([s]))[0]
    d_tau = -s * (Ka + s * La) * np.exp(-s * delay) * factor
    d_s = _slope(system, s, delay)
    ds_dtau = -(left.conj() @ d_tau @ right) / (left.conj() @ d_s @ right)
    return 1 if ds_dtau.real > 0 else -1


def delay_margin(body: Body, muscles: MuscleSet, *, max_delay: float = 2.0,
                 one_sided: OneSided = "active", torque_feedback_gain: float = 0.0,
                 torque_feedback_time_constant: float | None = None) -> DelayMargin:
    """The delay margin of the chain linearised about upright (see the module notes).

    Parameters
    ----------
    body : Body
    muscles : MuscleSet
        Intrinsic and active gains; without active gains the whole pair feedback is
        delayed.
    max_delay : float
        Crossings are listed up to this delay; the margin itself is found at any delay.
        [s]
    one_sided : {"active", "inactive"}
        How a one-sided pair is linearised.
    torque_feedback_gain, torque_feedback_time_constant : float
        Peterka 2002's torque feedback (K_t 0: none; τ_t by default 17.4 s): its filter
        states join the first-order form (3N states, :meth:`LinearSystem.first_order`) and
        its factor g(s) the delayed part of Δ(s). [-], [s]

    Returns
    -------
    DelayMargin

    Examples
    --------
    The paper's case 1 gains, all of their feedback delayed, lose stability at 2.81 ms, to a
    mode at 88.6 Hz:

    >>> import math
    >>> import posturelab as pl
    >>> dm = pl.delay_margin(pl.paper_body(), pl.paper_muscles("1"))
    >>> round(dm.delay_margin * 1000, 2)  # [ms]
    2.81
    >>> round(dm.crossing_frequency / (2 * math.pi), 1)  # [Hz]
    88.6
    """
    max_delay = float_in_range("max_delay [s]", max_delay, 0.0, 1e3, unit="s")
    system = delayed_system(body, muscles, one_sided, torque_feedback_gain=torque_feedback_gain,
                            torque_feedback_time_constant=torque_feedback_time_constant)
    A0, A1 = (a[0] for a in system.first_order())
    stable0 = bool(np.all(np.linalg.eigvals(A0 + A1).real < 0))
    if not stable0:
        return DelayMargin(False, None, None, ())
    crossings: dict[tuple[float, float], DelayCrossing] = {}
    first: tuple[float, float] | None = None
    for z, omega in _crossing_candidates(A0, A1):
        base = (-np.angle(z)) % (2 * math.pi) / omega
        polished = _polish(system, omega, base if base > 0 else 2 * math.pi / omega)
        if polished is None:
            continue
        w, t0 = polished
        if first is None or t0 < first[1]:
            first = (w, t0)
        period = 2 * math.pi / w
        t = t0
        while t <= max_delay and len(crossings) < 10_000:
            key = (round(w, 6), round(t, 9))
            if key not in crossings:
                crossings[key] = DelayCrossing(float(t), float(w), _direction(system, w, t))
            t += period
    if first is None:
        return DelayMargin(True, math.inf, None, ())
    listed = tuple(sorted(crossings.values(), key=lambda c: c.delay))
    return DelayMargin(True, float(first[1]), float(first[0]), listed)


def _chebyshev(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Chebyshev points x_j = cos(jπ/n) on [−1, 1] and the differentiation matrix
    (Trefethen, *Spectral Methods in MATLAB*, 2000, cheb.m)."""
    x = np.cos(np.pi * np.arange(n + 1) / n)
    c = np.ones(n + 1)
    c[0] = c[-1] = 2.0
    c *= (-1.0) ** np.arange(n + 1)
    dx = x[:, None] - x[None, :]
    D = np.outer(c, 1.0 / c) / (dx + np.eye(n + 1))
    D -= np.diag(D.sum(axis=1))
    return x, D


def rightmost_roots(body: Body, muscles: MuscleSet, delay: float, count: int = 6, *,
                    nodes: int = 40, one_sided: OneSided = "active") -> np.ndarray:
    """The ``count`` rightmost characteristic roots at feedback delay ``delay``.

    Spectral discretisation on ``nodes`` + 1 Chebyshev points, then Newton refinement
    (module notes). With τ = 0 these are the poles of :func:`posturelab.analyse`.

    Parameters
    ----------
    delay : float
        τ, in [0, :data:`MAX_DELAY_FOR_ROOTS`]. [s]
    count : int
        How many roots, 1 … 2N·nodes. [-]
    nodes : int
        Chebyshev intervals, 4 … 200. [-]

    Returns
    -------
    numpy.ndarray of complex, shape (count,)
        Real part descending. [1/s]
    """
    delay = float_in_range("delay [s]", delay, 0.0, MAX_DELAY_FOR_ROOTS, unit="s")
    return system_rightmost_roots(delayed_system(body, muscles, one_sided), delay, count,
                                  nodes=nodes)


def system_rightmost_roots(system: LinearSystem, delay: float, count: int = 6, *,
                           nodes: int = 40) -> np.ndarray:
    """:func:`rightmost_roots` of a one-set :class:`~posturelab.linear.system.LinearSystem`
    at delay τ [s] (its gains split for a positive delay; τ = 0 gives the poles). [1/s]"""
    if isinstance(nodes, bool) or not isinstance(nodes, int | np.integer) \
            or not 4 <= nodes <= 200:
        raise ParameterError(f"nodes must be an integer in [4, 200], got {nodes!r}")
    if system.n_sets != 1:
        raise ParameterError(f"rightmost roots are of one set, the system has {system.n_sets}")
    A0, A1 = (a[0] for a in system.first_order())
    m = A0.shape[0]
    if isinstance(count, bool) or not isinstance(count, int | np.integer) \
            or not 1 <= count <= m * nodes:
        raise ParameterError(f"count must be an integer in [1, {m * nodes}], got {count!r}")
    if bool(negligible_delay(A0, A1, delay)):
        guesses = np.linalg.eigvals(A0 + A1)  # refined at the actual τ below
    else:
        _, D = _chebyshev(nodes)
        D = D * (2.0 / delay)  # θ = τ (x − 1)/2 on [−τ, 0]; x_0 = 1 is θ = 0
        gen = np.kron(D, np.eye(m))
        gen[:m, :] = 0.0
        gen[:m, :m] = A0
        gen[:m, -m:] = A1  # x_N = −1 is θ = −τ
        guesses = np.linalg.eigvals(gen)
    guesses = guesses[np.argsort(-guesses.real)][: max(count + 4, 2 * count)]
    roots = []
    for s in guesses:
        refined = _newton_root(system, complex(s), delay)
        if refined is not None and not any(abs(refined - r) <= 1e-8 * max(1.0, abs(r))
                                           for r in roots):
            roots.append(refined)
    if not roots:
        raise ParameterError(f"no characteristic root converged at delay {delay:g} s "
                             f"(nodes {nodes}); try more nodes")
    roots = np.array(sorted(roots, key=lambda r: (-r.real, -r.imag)))
    return roots[:count]


def _newton_root(system: LinearSystem, s: complex, delay: float) -> complex | None:
    """Newton on det Δ(s) = 0: s ← s − 1/tr(Δ(s)⁻¹ Δ'(s))."""
    for _ in range(60):
        D = characteristic_matrix(system, s, delay)
        dD = _slope(system, s, delay)
        try:
            tr = np.trace(np.linalg.solve(D, dD))
        except np.linalg.LinAlgError:
            return s
        if tr == 0 or not np.isfinite(tr):
            return None
        step = 1.0 / tr
        s = s - step
        if abs(step) <= 1e-14 * max(1.0, abs(s)):
            return s
    return s if abs(step) <= 1e-9 * max(1.0, abs(s)) else None
