"""Delayed linear stability of many parameter sets at once (numpy, stacked).

For M gain sets on one body and pair layout, at one feedback delay τ (one
:class:`~posturelab.linear.system.LinearSystem` of M sets), the rightmost
characteristic root of each set (posturelab.linear.delay states the equation) is found by
the spectral discretisation of :func:`posturelab.linear.delay.rightmost_roots`, stacked
over the sets (one ``numpy.linalg.eigvals`` call on an (M, 2N(n+1), 2N(n+1)) array), then
polished by a few Newton steps on det Δ(s) = 0, stacked too. A set is stable when that
root's real part is below −δ (δ = 1e-9 × max(1, |root|)).

:func:`delay_stability_map` evaluates a grid of two active (delayed) gains at a fixed delay:
the classic D-subdivision figure, whose stable region the tests check against the exact
crossing count of :func:`posturelab.linear.delay.delay_margin`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._validation import float_in_range
from ..errors import ParameterError
from ..model.body import Body
from ..model.muscles import MuscleSet
from .delay import MAX_DELAY_FOR_ROOTS, _chebyshev, negligible_delay
from .system import LinearSystem, linear_system

__all__ = ["batch_rightmost_root", "batch_delay_stable", "DelayStabilityMap",
           "delay_stability_map", "MAX_DELAY_MAP_RESOLUTION"]

#: Largest grid side of :func:`delay_stability_map`: what finishes in reasonable time. The
#: three-link body costs about 1 ms a set on this project's 2-core machine when it is quiet
#: and about 3 ms under load (300 × 300 took 1.2 min on 2026-12-02; 30 × 30 took 3 s under
#: load), so 300 × 300 takes one to five minutes and 1000 × 1000 would take up to an hour.
#: [-]
MAX_DELAY_MAP_RESOLUTION = 300
#: Sets per stacked eigenvalue call (bounds the memory of one call). [-]
_CHUNK = 1024


def batch_rightmost_root(body: Body, muscles: MuscleSet, stiffness, viscosity,
                         active_stiffness=None, active_viscosity=None, delay: float = 0.0, *,
                         nodes: int = 12,
                         progress: Callable[[int, int], None] | None = None,
                         torque_feedback_gain: float = 0.0,
                         torque_feedback_time_constant: float | None = None) -> np.ndarray:
    """The rightmost characteristic root of each of M gain sets at delay ``delay``.

    Parameters
    ----------
    body : Body
    muscles : MuscleSet
        The pair layout (its own gains are not used).
    stiffness, viscosity : array_like, shape (M, P)
        Pair (intrinsic, or without active gains the whole) gains. [N·m/rad], [N·m·s/rad]
    active_stiffness, active_viscosity : array_like, shape (M, P), optional
        Active (delayed) gains; without them the whole feedback is delayed (the rule of
        :func:`posturelab.model.muscles.feedback_gains`). [N·m/rad], [N·m·s/rad]
    delay : float
        τ in [0, MAX_DELAY_FOR_ROOTS]. [s]
    nodes : int
        Chebyshev intervals, 4 … 64. [-]
    progress : callable, optional
        Called as ``progress(done, M)`` on this thread as blocks of sets finish. [-]
    torque_feedback_gain, torque_feedback_time_constant : float
        K_t [-] and τ_t [s] of Peterka 2002's torque feedback (the filter states join the
        first-order form; :func:`posturelab.linear.system.linear_system`). 0: none.

    Returns
    -------
    numpy.ndarray of complex, shape (M,)
        [1/s]
    """
    delay = float_in_range("delay [s]", delay, 0.0, MAX_DELAY_FOR_ROOTS, unit="s")
    if isinstance(nodes, bool) or not isinstance(nodes, int | np.integer) \
            or not 4 <= nodes <= 64:
        raise ParameterError(f"nodes must be an integer in [4, 64], got {nodes!r}")
    system = linear_system(body, muscles, stiffness=stiffness, viscosity=viscosity,
                           active_stiffness=active_stiffness,
                           active_viscosity=active_viscosity, delay=delay, inputs=False,
                           torque_feedback_gain=torque_feedback_gain,
                           torque_feedback_time_constant=torque_feedback_time_constant)
    A0, A1 = system.first_order()
    M, m = A0.shape[0], A0.shape[1]
    roots = np.empty(M, dtype=complex)
    negligible = negligible_delay(A0, A1, delay)
    if delay == 0.0 or bool(np.all(negligible)):
        # no delay, or one negligible for every set (posturelab.linear.delay's notes): the
        # τ = 0 poles, refined at τ
        for lo in range(0, M, _CHUNK):
            lam = np.linalg.eigvals(A0[lo:lo + _CHUNK] + A1[lo:lo + _CHUNK])
            roots[lo:lo + _CHUNK] = lam[np.arange(lam.shape[0]), np.argmax(lam.real, axis=1)]
        return roots if delay == 0.0 else _newton(system, roots)
    _, D = _chebyshev(nodes)
    template = np.kron(D * (2.0 / delay), np.eye(m))
    template[:m, :] = 0.0

    def chunk(lo: int) -> None:
        a0, a1 = A0[lo:lo + _CHUNK], A1[lo:lo + _CHUNK]
        gen = np.broadcast_to(template, (a0.shape[0],) + template.shape).copy()
        gen[:, :m, :m] = a0
        gen[:, :m, -m:] = a1
        lam = np.linalg.eigvals(gen)  # (LAPACK, without the GIL: chunks run in parallel)
        roots[lo:lo + _CHUNK] = lam[np.arange(lam.shape[0]), np.argmax(lam.real, axis=1)]

    starts = range(0, M, _CHUNK)
    if progress is not None:
        progress(0, M)
    if len(starts) > 1:
        from concurrent.futures import ThreadPoolExecutor, as_completed

        with ThreadPoolExecutor(max_workers=min(len(starts), _threads())) as pool:
            futures = {pool.submit(chunk, lo): min(_CHUNK, M - lo) for lo in starts}
            done = 0
            try:
                for future in as_completed(futures):
                    future.result()
                    done += futures[future]
                    if progress is not None:
                        progress(done, M)
            except BaseException:  # Ctrl-C: drop the blocks not started
                for future in futures:
                    future.cancel()
                raise
    else:
        chunk(0)
        if progress is not None:
            progress(M, M)
    if negligible.any():  # sets whose delay is negligible: their τ = 0 poles, refined at τ
        lam = np.linalg.eigvals(A0[negligible] + A1[negligible])
        roots[negligible] = lam[np.arange(lam.shape[0]), np.argmax(lam.real, axis=1)]
    return _newton(system, roots)


def _threads() -> int:
    """CPUs this process may run on. [-]"""
    import os

    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def _newton(system: LinearSystem, s: np.ndarray, steps: int = 8) -> np.ndarray:
    """A few stacked Newton steps s ← s − f/f' on f(s) = det Δ(s) of each set, f' by a
    central difference (a singular Δ does not stop the stack)."""
    def f(z):
        return np.linalg.det(system.characteristic_matrix(z))

    s = s.copy()
    for _ in range(steps):
        h = 1e-6 * np.maximum(1.0, np.abs(s))
        with np.errstate(all="ignore"):
            step = f(s) / ((f(s + h) - f(s - h)) / (2 * h))
        ok = np.isfinite(step) & (np.abs(step) < 0.5 * (1.0 + np.abs(s)))
        s = np.where(ok, s - step, s)  # keep the spectral estimate where Newton wanders off
    return s


def batch_delay_stable(body: Body, muscles: MuscleSet, stiffness, viscosity,
                       active_stiffness=None, active_viscosity=None, delay: float = 0.0, *,
                       nodes: int = 12) -> np.ndarray:
    """Stable flags of M gain sets at delay τ (arguments of :func:`batch_rightmost_root`):
    the rightmost root's real part < −1e-9 · max(1, |root|)."""
    r = batch_rightmost_root(body, muscles, stiffness, viscosity, active_stiffness,
                             active_viscosity, delay, nodes=nodes)
    return r.real < -1e-9 * np.maximum(1.0, np.abs(r))


@dataclass(frozen=True, eq=False)  # (its arrays: a field-wise == would raise)
class DelayStabilityMap:
    """Delayed stability over active stiffness × active viscosity of one pair.

    Attributes
    ----------
    pair : str
        The pair whose active gains vary.
    active_stiffness : numpy.ndarray, shape (R,)
        x values. [N·m/rad]
    active_viscosity : numpy.ndarray, shape (R,)
        y values. [N·m·s/rad]
    delay : float
        τ. [s]
    max_real_part : numpy.ndarray, shape (R, R)
        Real part of the rightmost root, [y, x]. [1/s]
    stable : numpy.ndarray of bool, shape (R, R)
    load_stiffness : float
        The body's mgh. [N·m/rad]
    """

    pair: str
    active_stiffness: np.ndarray
    active_viscosity: np.ndarray
    delay: float
    max_real_part: np.ndarray
    stable: np.ndarray
    load_stiffness: float


def delay_stability_map(body: Body, muscles: MuscleSet, delay: float,
                        stiffness_range: tuple[float, float],
                        viscosity_range: tuple[float, float], resolution: int = 200, *,
                        pair: str | None = None, nodes: int = 12,
                        progress: Callable[[int, int], None] | None = None,
                        torque_feedback_gain: float = 0.0,
                        torque_feedback_time_constant: float | None = None
                        ) -> DelayStabilityMap:
    """Rightmost root over a grid of one pair's active stiffness × active viscosity at a
    fixed delay (the D-subdivision figure); every other gain is ``muscles``' own.

    Parameters
    ----------
    body : Body
    muscles : MuscleSet
        Intrinsic gains, and the other pairs' active gains (none: zero).
    delay : float
        τ. [s]
    stiffness_range, viscosity_range : (float, float)
        (low, high) of the axes, >= 0. [N·m/rad], [N·m·s/rad]
    resolution : int
        Points per axis, 2 … :data:`MAX_DELAY_MAP_RESOLUTION`. [-]
    pair : str, optional
        The pair varied (default: the first, the ankle).
    progress : callable, optional
        Called as ``progress(done, total)`` as sets finish (see
        :func:`batch_rightmost_root`). [-]
    torque_feedback_gain, torque_feedback_time_constant : float
        K_t [-] and τ_t [s] of the torque feedback (:func:`batch_rightmost_root`).
    """
    if isinstance(resolution, bool) or not isinstance(resolution, int | np.integer) \
            or not 2 <= resolution <= MAX_DELAY_MAP_RESOLUTION:
        raise ParameterError(f"resolution must be an integer in [2, "
                             f"{MAX_DELAY_MAP_RESOLUTION}], got {resolution!r}")
    names = muscles.names
    pair = names[0] if pair is None else pair
    if pair not in names:
        raise ParameterError(f"unknown pair {pair!r}; pairs: {', '.join(names)}")
    j = names.index(pair)
    axes = []
    for label, (lo, hi) in (("active stiffness [N·m/rad]", stiffness_range),
                            ("active viscosity [N·m·s/rad]", viscosity_range)):
        lo = float_in_range(f"{label} low", lo, 0.0, 1e7)
        hi = float_in_range(f"{label} high", hi, 0.0, 1e7)
        if not lo < hi:
            raise ParameterError(f"{label} range must have low < high, got {lo:g}:{hi:g}")
        axes.append(np.linspace(lo, hi, resolution))
    kx, vy = np.meshgrid(axes[0], axes[1])
    count = kx.size
    ka = np.tile(muscles.active_stiffnesses, (count, 1))
    va = np.tile(muscles.active_viscosities, (count, 1))
    ka[:, j], va[:, j] = kx.ravel(), vy.ravel()
    k = np.tile(muscles.stiffnesses, (count, 1))
    v = np.tile(muscles.viscosities, (count, 1))
    root = batch_rightmost_root(body, muscles.as_two_sided(), k, v, ka, va, delay, nodes=nodes,
                                progress=progress, torque_feedback_gain=torque_feedback_gain,
                                torque_feedback_time_constant=torque_feedback_time_constant)
    real = root.real.reshape(kx.shape)
    stable = real < -1e-9 * np.maximum(1.0, np.abs(root)).reshape(kx.shape)
    for arr in (real, stable, axes[0], axes[1]):
        arr.setflags(write=False)
    return DelayStabilityMap(pair, axes[0], axes[1], float(delay), real, stable,
                             body.load_stiffness)
