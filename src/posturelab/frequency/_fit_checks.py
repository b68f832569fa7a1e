"""Helpers of :func:`posturelab.frequency.fit.fit_frf`: the systematic part of the intervals
under a model mismatch, and the stability of a fitted loop."""

from __future__ import annotations

import numpy as np

from ..model.body import Body
from ..model.muscles import MuscleSet


def loop_verdict(body: Body, muscles: MuscleSet, gains: np.ndarray, active: bool,
                  values: dict):
    """The upright verdict of one condition's loop: ``gains`` the rows (stiffness
    [N·m/rad], viscosity [N·m·s/rad], active stiffness, active viscosity) per pair, ``values``
    the scalars (delay [s], torque feedback)."""
    from dataclasses import replace

    from ..linear.verdict import upright_verdict

    pairs = tuple(replace(pair, stiffness=float(gains[0, i]), viscosity=float(gains[1, i]),
                          active_stiffness=float(gains[2, i]) if active else None,
                          active_viscosity=float(gains[3, i]) if active else None)
                  for i, pair in enumerate(muscles.pairs))
    gain = values["torque_feedback_gain"]
    return upright_verdict(body, MuscleSet(pairs, muscles.n_links), values["feedback_delay"],
                           torque_feedback_gain=gain,
                           torque_feedback_time_constant=(values["torque_feedback_time_constant"]
                                                          if gain else None))


def systematic_bound(J: np.ndarray, targets: list, delta: float, seen: np.ndarray
                      ) -> np.ndarray:
    """β_k = δ Σ_b |∂p_k/∂e_b| |Ĥ_b|: the most a model error of at most δ|Ĥ_b| at every band,
    in any direction, moves each parameter (linearised: ∂p/∂u = −(JᵀJ)⁻¹Jᵀ, u the
    standardised residuals, ∂u/∂e_b from a small real and imaginary step at band b)."""
    P = np.linalg.solve(J.T @ J, J.T)  # (K, m)
    out = np.zeros(J.shape[1])
    offset = 0
    for t in targets:
        base = t.standardised(t.frf, delta).ravel()
        size = base.size
        for b in range(t.frf.size):
            h = 1e-6 * max(abs(t.frf[b]), 1e-300)
            g = []
            for step in (h, 1j * h):
                moved = t.frf.copy()
                moved[b] += step
                du = np.zeros(J.shape[0])
                du[offset:offset + size] = (t.standardised(moved, delta).ravel() - base) / h
                g.append(P @ du)
            out += delta * abs(t.frf[b]) * np.hypot(g[0], g[1])
        offset += size
    return out
