"""Which strategy a run uses: the ankle (in-phase) and hip (anti-phase) modes of leg and trunk.

Definition (after Creath et al. 2005, *Neurosci. Lett.* 377:75–80, who found in-phase and
anti-phase coordination of the leg and trunk angles co-existing in quiet and perturbed
stance): with u(t) and w(t) the leg angle θ_1 and the trunk angle θ_N [rad] less their
values at the start,

    ankle mode  a(t) = (u + w)/2     (leg and trunk lean together)
    hip mode    b(t) = (u − w)/2     (they counter-rotate about the hip)

so that u = a + b and w = a − b. The **hip fraction** of a run is Σ b² / (Σ a² + Σ b²) over
its samples (equally spaced in time): 0 for a body that sways as one rigid pendulum, 1 for
pure counter-rotation, and 0 when nothing moves. Creath et al. measured the modes by the
relative phase of leg and trunk over frequency; the hip fraction is our time-domain share of
the anti-phase mode, defined for any run and any N >= 2 (NaN for a one-link body, which has
only the ankle mode). Knee motion (θ_2 of the three-link body) is not part of it.

:func:`hip_fraction_study` asks the paper's question of its Section VII ("the knee and hip
strategies when the ankle torque is limited"): with an ankle torque limit, how the hip
fraction grows with the size of a backward platform translation (a ramp-and-hold of given
displacement), on the compiled engine.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import finite_array, float_in_range
from ..errors import ParameterError
from ..model.kinematics import hip_fraction, strategy_modes  # (defined with the kinematics)

__all__ = ["strategy_modes", "hip_fraction", "HipFractionStudy", "hip_fraction_study",
           "CREATH_2005_CITATION", "RUNGE_1999_CITATION", "MAX_STUDY_RUNS"]

CREATH_2005_CITATION = (
    "Creath R, Kiemel T, Horak F, Peterka R, Jeka J (2005) A unified view of quiet and "
    "perturbed stance: simultaneous co-existing excitable modes. Neurosci Lett 377:75–80"
)
RUNGE_1999_CITATION = (
    "Runge CF, Shupert CL, Horak FB, Zajac FE (1999) Ankle and hip postural strategies "
    "defined by joint torques. Gait Posture 10:161–170 (backward translations of a flat "
    "surface: hip torques join the ankle's at the faster translations)"
)
#: Most runs :func:`hip_fraction_study` accepts. [-]
MAX_STUDY_RUNS = 10_000


@dataclass(frozen=True)
class HipFractionStudy:
    """Hip fraction against the size of a backward translation, with an ankle torque limit.

    Attributes
    ----------
    displacement : numpy.ndarray, shape (K,)
        Backward platform displacement of each run (ramp and hold). [m]
    hip_fraction : numpy.ndarray, shape (K,)
        [-]
    fell : numpy.ndarray of bool, shape (K,)
    peak_ankle_moment : numpy.ndarray, shape (K,)
        Largest |net ankle moment| of the run (at most the limit). [N·m]
    ankle_torque_limit : float
        [N·m]
    ramp_duration : float
        Time of the ramp. [s]
    """

    displacement: np.ndarray
    hip_fraction: np.ndarray
    fell: np.ndarray
    peak_ankle_moment: np.ndarray
    ankle_torque_limit: float
    ramp_duration: float

    def first_above(self, level: float) -> float | None:
        """The smallest displacement of a run that did not fall whose hip fraction exceeds
        ``level`` [-]; None if none does. [m]"""
        ok = (~self.fell) & (self.hip_fraction > level)
        return float(self.displacement[ok][0]) if ok.any() else None


def hip_fraction_study(body, muscles, displacements, *, ankle_torque_limit: float,
                       ramp_duration: float = 0.5, duration: float = 3.0, fall=None,
                       **run_options) -> HipFractionStudy:
    """Run a backward ramp-and-hold of each displacement with the ankle moment limited to
    ``ankle_torque_limit`` and measure each run's hip fraction (compiled engine).

    Parameters
    ----------
    body : Body
        N >= 2 links.
    muscles : MuscleSet
    displacements : array_like, shape (K,)
        Backward displacements, > 0, at most :data:`MAX_STUDY_RUNS` of them. [m]
    ankle_torque_limit : float
        Largest net ankle moment, > 0. [N·m]
    ramp_duration : float
        [s]
    duration : float
        Simulated time of each run. [s]
    fall : FallCriteria, optional
    **run_options
        Passed to :func:`posturelab.simulate` (``initial_state``, ``knee``,
        ``feedback_delay``, …).
    """
    from ..model.platform import RampAndHold
    from ..simulation.engines import simulate

    if body.n_links < 2:
        raise ParameterError("the hip fraction needs a body with at least 2 links")
    d = finite_array("displacements [m]", displacements, (None,))
    if d.size == 0 or d.size > MAX_STUDY_RUNS or np.any(d <= 0):
        raise ParameterError(f"displacements [m] must be 1 … {MAX_STUDY_RUNS:,} values > 0")
    limit = float_in_range("ankle_torque_limit [N·m]", ankle_torque_limit, 1e-6, 1e6)
    limits = np.full(body.n_links, np.inf)
    limits[0] = limit
    fractions, fell, peaks = [], [], []
    for x in d:
        r = simulate(body, muscles, RampAndHold(-float(x), ramp_duration), duration,
                     torque_limits=limits, fall=fall, engine="compiled", **run_options)
        fractions.append(hip_fraction(r.theta))
        fell.append(r.fell)
        peaks.append(float(np.abs(r.joint_moments[:, 0]).max()))
    return HipFractionStudy(d, np.array(fractions), np.array(fell), np.array(peaks), limit,
                            float(ramp_duration))
