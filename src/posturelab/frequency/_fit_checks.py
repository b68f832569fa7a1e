"""Helpers of :func:`posturelab.frequency.fit.fit_frf`: the systematic part of the intervals
under a model mismatch, the stability of a fitted loop, whether the fit describes the data
(its variance accounted for) and the condition groups."""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError
from ..model.body import Body
from ..model.muscles import MuscleSet
from ..parameters import check_value
from ..parameters import unit as parameter_unit


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


#: A fit describes the data when its model accounts for at least this fraction of the FRF's
#: variation (:func:`variance_accounted_for`): a model that leaves most of the measured FRF
#: unexplained describes nothing, however small the noise makes its fit error look (a
#: noise-only response is fitted about as well by any loop; our threshold, not a
#: published one). [-]
MIN_VARIANCE_ACCOUNTED = 0.5


def variance_accounted_for(targets: list, model: list) -> float:
    """VAF = 1 − Σ_b |H_b − Ĥ_b|² / Σ_b |Ĥ_b|² over every band of every condition, H the
    fitted model's band FRF and Ĥ the measured one: the share of the measured FRF's
    variation about zero that the model accounts for (1: all, 0: no better than no
    response; negative: worse). [-]"""
    num = sum(float(np.sum(np.abs(np.asarray(m) - t.frf) ** 2))
              for t, m in zip(targets, model, strict=True))
    den = sum(float(np.sum(np.abs(t.frf) ** 2)) for t in targets)
    return 1.0 - num / den if den > 0 else -np.inf


def group_conditions(groups, count: int) -> list[int]:
    """Each condition's group (default its own), checked: integers 0 … G − 1, each used."""
    if groups is None:
        return list(range(count))
    if isinstance(groups, str) or len(groups) != count or not all(
            isinstance(g, int | np.integer) and not isinstance(g, bool) for g in groups):
        raise ParameterError(f"condition_groups must give an integer group per condition "
                             f"({count}), got {groups!r}"[:200])
    out = [int(g) for g in groups]
    if sorted(set(out)) != list(range(max(out) + 1)):
        raise ParameterError(f"condition_groups must number the groups 0 … G − 1, each "
                             f"used, got {out}")
    return out


def check_bounds(bounds, canonical, fitted: dict) -> dict:
    """``bounds`` as {canonical name: (low, high)}, each for a fitted parameter (``fitted``:
    canonical name -> base name; ``canonical``: given name -> its one spelling) and within
    its range."""
    if bounds is None:
        return {}
    if not isinstance(bounds, dict):
        raise ParameterError(f"bounds must be a dict of name -> (low, high), got {bounds!r}")
    out = {}
    for given, value in bounds.items():
        name = canonical(given)
        if name not in fitted:
            raise ParameterError(f"bounds given for {given!r}, which is not fitted; fitted: "
                                 f"{', '.join(fitted)}")
        if name in out:
            raise ParameterError(f"bounds given twice for {name!r}")
        try:
            lo, hi = (float(v) for v in value)
        except (TypeError, ValueError):
            raise ParameterError(f"bounds of {given} must be (low, high), got {value!r}"
                                 ) from None
        if any(isinstance(v, bool) for v in value):
            raise ParameterError(f"bounds of {given} must be numbers, got {value!r}")
        if not (math.isfinite(lo) and math.isfinite(hi)):
            raise ParameterError(f"bounds of {given} must be finite, got {lo:g}:{hi:g}")
        check_value(name, lo, f"bound {name} LO")  # the parameter table's bounds
        check_value(name, hi, f"bound {name} HI")
        if not lo < hi:
            raise ParameterError(f"bounds of {given} must satisfy low < high "
                                 f"[{parameter_unit(name)}], got {lo:g}:{hi:g}")
        out[name] = (lo, hi)
    return out
