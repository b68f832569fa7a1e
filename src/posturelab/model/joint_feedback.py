"""Joint-space feedback: a controller that acts on the joint moments from the whole state.

A muscle pair's gains act on its own stretch (a row of E), so the pairs cannot state a general
full-state gain matrix. A :class:`JointFeedback` adds, at every joint j, the moment

    τ_ctrl(t) = −F_θ Θ(t − τ) − F_ω Θ̇(t − τ)

(F_θ [N·m/rad] and F_ω [N·m·s/rad] are N × N, τ the run's feedback delay; with τ = 0 it acts on
the state itself) to the pairs' moments before the joints saturate at their torque limits, so a
limit bounds the controller's moment too. Signs are those of the joint moments of
:mod:`.feedback` (an ankle moment τ_1 > 0 pulls a forward-leaning body back), so for the
ankle F_θ[0, 0] < 0. The matrices come from a design on the linear system
(:func:`posturelab.linear.lqr.lqr_joint_feedback`); this module only states the term.

The moment is linear in the state, so the engines carry it as joint-space gain matrices in the
rows of :mod:`.gains` (:func:`joint_gain_rows`), added to the pairs' T_K = Cᵀ diag(k) E
(:func:`joint_moment_gain_formula`, which the compiled engine's ``pl_moment_gains`` is
generated from).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import finite_array
from ..errors import ParameterError
from .gains import DELAYED_STIFFNESS, DELAYED_VISCOSITY, IMMEDIATE_STIFFNESS, IMMEDIATE_VISCOSITY

__all__ = ["JointFeedback", "joint_gain_rows", "joint_moment_gain_formula",
           "joint_feedback_moments",
           "MAX_JOINT_GAIN"]

#: Largest |entry| of F_θ or F_ω accepted (a thousand times a standing adult's m g h). [N·m/rad]
MAX_JOINT_GAIN = 1e6


def joint_moment_gain_formula(pair_gain, joint_gain):
    """One entry of the moment gain matrix of a run: the pairs' (Cᵀ diag(k) E)_jk plus the
    joint-space controller's (−F)_jk. [N·m/rad] or [N·m·s/rad]"""
    return pair_gain + joint_gain


def _matrix(name: str, value, n: int | None) -> tuple[tuple[float, ...], ...]:
    arr = finite_array(name, value)
    if arr.ndim != 2 or arr.shape[0] != arr.shape[1] or (n is not None and arr.shape[0] != n):
        raise ParameterError(f"{name} must be a square matrix (N × N), got shape {arr.shape}")
    if np.abs(arr).max(initial=0.0) > MAX_JOINT_GAIN:
        raise ParameterError(f"{name} must have entries within ±{MAX_JOINT_GAIN:g}, got "
                             f"{np.abs(arr).max():g}")
    return tuple(tuple(float(v) for v in row) for row in arr)


@dataclass(frozen=True)
class JointFeedback:
    """A joint-space full-state feedback τ_ctrl = −s (F_θ Θ(t − τ) + F_ω Θ̇(t − τ)).

    Attributes
    ----------
    stiffness : tuple of tuple of float, (N, N)
        F_θ: joint moment per link angle. [N·m/rad]
    viscosity : tuple of tuple of float, (N, N)
        F_ω: joint moment per link angular rate. [N·m·s/rad]
    scale : float
        s, a factor on both matrices (1: as designed; the quantity ``joint_feedback_scale``
        sweeps and fits it). [-]
    source : str
        How the matrices were made (the design and its weights).
    """

    stiffness: tuple
    viscosity: tuple
    scale: float = 1.0
    source: str = ""

    def __post_init__(self) -> None:
        k = _matrix("joint feedback stiffness F_θ [N·m/rad]", self.stiffness, None)
        v = _matrix("joint feedback viscosity F_ω [N·m·s/rad]", self.viscosity, len(k))
        from ..parameters import check_value

        object.__setattr__(self, "stiffness", k)
        object.__setattr__(self, "viscosity", v)
        object.__setattr__(self, "scale", check_value("joint_feedback_scale", self.scale))
        if not isinstance(self.source, str):
            raise ParameterError(f"source must be a string, got {self.source!r:.60}")

    @property
    def n_links(self) -> int:
        """N. [-]"""
        return len(self.stiffness)

    def matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """(s F_θ, s F_ω), shape (N, N) each. [N·m/rad], [N·m·s/rad]"""
        return (self.scale * np.array(self.stiffness, dtype=float),
                self.scale * np.array(self.viscosity, dtype=float))

    def scaled(self, scale: float) -> JointFeedback:
        """The same design with the factor s = ``scale`` [-]."""
        return JointFeedback(self.stiffness, self.viscosity, scale, self.source)


def joint_gain_rows(feedback: JointFeedback | None, n_links: int, delay: float) -> np.ndarray:
    """The controller as moment gain matrices by when they act, shape (4, N, N), rows named in
    :mod:`.gains`: −s F_θ and −s F_ω in the delayed rows for a positive ``delay`` τ [s], in the
    immediate rows for τ = 0; zeros without a controller. [N·m/rad], [N·m·s/rad]"""
    out = np.zeros((4, n_links, n_links))
    if feedback is None:
        return out
    if feedback.n_links != n_links:
        raise ParameterError(f"the joint feedback is for {feedback.n_links} links but the body "
                             f"has {n_links}")
    k, v = feedback.matrices()
    rows = (DELAYED_STIFFNESS, DELAYED_VISCOSITY) if delay > 0 else (IMMEDIATE_STIFFNESS,
                                                                     IMMEDIATE_VISCOSITY)
    out[rows[0]], out[rows[1]] = -k, -v
    return out


def joint_feedback_moments(rows: np.ndarray, state: np.ndarray, feedback: np.ndarray
                           ) -> np.ndarray:
    """The controller's joint moments from its gain rows (4, N, N) (:func:`joint_gain_rows`):
    the immediate rows on ``state`` (..., 2N), the delayed rows on ``feedback`` (..., 2N),
    x(t − τ). Returns (..., N). [N·m]"""
    n = rows.shape[-1]
    state, feedback = np.asarray(state, dtype=float), np.asarray(feedback, dtype=float)
    return (state[..., :n] @ rows[IMMEDIATE_STIFFNESS].T
            + state[..., n:] @ rows[IMMEDIATE_VISCOSITY].T
            + feedback[..., :n] @ rows[DELAYED_STIFFNESS].T
            + feedback[..., n:] @ rows[DELAYED_VISCOSITY].T)
