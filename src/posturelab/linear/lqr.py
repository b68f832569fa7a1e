"""A joint-space full-state controller designed on the linear system: the linear-quadratic
regulator (LQR) of the chain about upright, and what its delayed closed loop does.

Design. From :func:`posturelab.linear.system.linear_system` (the body and the muscles' own
gains, with the delay set to zero, :meth:`LinearSystem.without_delay`), the chain about upright
is ẋ = A x + B τ with x = [Θ, Θ̇], τ the joint moments (ankle, knee, hip, …)::

    A = [[0, I], [−J0⁻¹ S, −J0⁻¹ L]],   B = [[0], [J0⁻¹ D]]

(D the link torques per joint moment, :func:`~posturelab.linear.system.link_torque_matrix`).
The regulator τ = −F x minimises ∫ (xᵀ Q x + τᵀ R τ) dt, F = R⁻¹ Bᵀ P with P the stabilising
solution of the continuous algebraic Riccati equation (``scipy.linalg.solve_continuous_are``),
as in Kuo's optimal-control model of standing balance (Kuo 1995, IEEE Trans Biomed Eng
42:87–101) and the delayed full-state feedback that Park, Horak & Kuo (2004, Exp Brain Res
154:417–427, doi:10.1007/s00221-003-1674-3) fitted to the joint responses to support
translations.

The weights follow Bryson's rule (Bryson & Ho 1975, *Applied Optimal Control*): each is one
over the square of the largest value one is willing to accept, Q = diag(1/θ_max², …,
1/ω_max², …) and R = diag(1/τ_max,j²). The ankle's τ_max is what the foot can carry (the centre
of pressure at the toe: m g x_toe), far below what the hip and knee may produce, so ankle torque
is the expensive one (Kuo 1995's point that the foot, not muscle strength, limits the ankle).

Delay. The design ignores the feedback delay (the regulator of the undelayed chain, applied to
the state τ earlier); :func:`closed_loop_check` says whether the delayed closed loop is stable
at the run's delay and how much delay it tolerates (the delay margin of the same
:class:`~posturelab.linear.system.LinearSystem`, :func:`posturelab.linear.margins.delay_margins`).
A predictor would remove the delay from the loop; posturelab states the simpler design and
checks its margin instead.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import finite_array
from ..errors import ParameterError
from ..model.body import Body
from ..model.joint_feedback import JointFeedback
from ..model.muscles import MuscleSet
from .system import LinearSystem, linear_system, link_torque_matrix, sorted_poles

__all__ = ["lqr_gain", "lqr_joint_feedback", "LQRCheck", "closed_loop_check",
           "design_matrices", "knee_basis", "on_knee", "MultiJointController",
           "multijoint_controller",
           "bryson_weights"]


def knee_basis(n: int, knee: str) -> np.ndarray:
    """T with Θ = T q: the identity for a free knee; with the knee locked (θ1 = θ2, its angle
    upright), the shank and thigh move as one leg, q = (θ_leg, θ3, …), shape (N, N − 1). [-]"""
    if knee == "free":
        return np.eye(n)
    if knee != "locked" or n < 3:
        raise ParameterError(f"the design's knee must be 'free' or 'locked' (N >= 3), got "
                             f"{knee!r} for N = {n}")
    T = np.zeros((n, n - 1))
    T[0, 0] = T[1, 0] = 1.0
    T[2:, 1:] = np.eye(n - 2)
    return T


def on_knee(system: LinearSystem, knee: str) -> LinearSystem:
    """``system`` in the coordinates q of :func:`knee_basis` (Θ = T q, each matrix M → Tᵀ M T;
    the tilt input left out): the chain with its knee locked, or ``system`` itself for a free
    knee."""
    if knee == "free":
        return system
    T = knee_basis(system.n_links, knee)

    def reduce(m):
        return np.einsum("ji,mjk,kl->mil", T, m, T)

    # the torque feedback's filter acts joint by joint with one scalar gain and lag, so its
    # states project like the moments (Tᵀ Y) and the reduced system keeps gain and lag
    visual = None if system.visual_input is None else system.visual_input @ T
    return LinearSystem(reduce(system.inertia), reduce(system.stiffness),
                        reduce(system.viscosity), reduce(system.delayed_stiffness),
                        reduce(system.delayed_viscosity), system.delay, None,
                        system.translation_input @ T,
                        torque_feedback_gain=system.torque_feedback_gain,
                        torque_feedback_time_constant=system.torque_feedback_time_constant,
                        visual_input=visual)


def _inputs(n: int, knee: str) -> np.ndarray:
    """The joints the design drives: all, or all but the knee when it is locked."""
    return np.arange(n) if knee == "free" else np.array([j for j in range(n) if j != 1])


def design_matrices(system: LinearSystem, knee: str = "free"
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(A, B, T) of the first set of ``system`` without its delay (module notes), in the
    coordinates q of :func:`knee_basis` (Θ = T q): the state [q, q̇] [rad, rad/s] driven by
    the moments of the joints the design drives [N·m] (the knee's left out when locked)."""
    J, L, S = (np.broadcast_to(m, (system.n_sets,) + m.shape[1:])[0]
               for m in system.without_delay())
    n = system.n_links
    T = knee_basis(n, knee)
    r = T.shape[1]
    Jr = T.T @ J @ T
    Jinv = np.linalg.inv(Jr)
    A = np.block([[np.zeros((r, r)), np.eye(r)], [-Jinv @ (T.T @ S @ T),
                                                  -Jinv @ (T.T @ L @ T)]])
    B = np.vstack([np.zeros((r, len(_inputs(n, knee)))),
                   Jinv @ T.T @ link_torque_matrix(n)[:, _inputs(n, knee)]])
    return A, B, T


def lqr_gain(A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray) -> np.ndarray:
    """F = R⁻¹ Bᵀ P of the continuous LQR (P from the algebraic Riccati equation).

    Raises
    ------
    ParameterError
        When no stabilising solution exists (weights not positive, or the pair (A, B) not
        stabilisable).
    """
    from scipy.linalg import solve_continuous_are

    try:
        P = solve_continuous_are(A, B, Q, R)
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise ParameterError(f"the LQR design has no stabilising solution ({exc})") from None
    return np.linalg.solve(R, B.T @ P)


def bryson_weights(n_states: int, angle_limit: float, rate_limit: float, effort_limits
                   ) -> tuple[np.ndarray, np.ndarray]:
    """(Q, R) by Bryson's rule: Q = diag(1/θ_max² × n, 1/ω_max² × n), R = diag(1/τ_max,j²).

    Parameters
    ----------
    n_states : int
        n, the angles of the design's coordinates. [-]
    angle_limit : float
        θ_max. [rad]
    rate_limit : float
        ω_max. [rad/s]
    effort_limits : array_like, shape (K,)
        τ_max of each joint the design drives. [N·m]
    """
    tau = finite_array("effort_limits [N·m]", effort_limits, (None,))
    if not (angle_limit > 0 and rate_limit > 0 and np.all(tau > 0)):
        raise ParameterError("angle_limit [rad], rate_limit [rad/s] and effort_limits [N·m] "
                             "must be > 0")
    q = np.concatenate([np.full(n_states, angle_limit ** -2.0),
                        np.full(n_states, rate_limit ** -2.0)])
    return np.diag(q), np.diag(tau ** -2.0)


def lqr_joint_feedback(body: Body, muscles: MuscleSet, Q, R, source: str = "",
                       knee: str = "free") -> JointFeedback:
    """The LQR of the chain about upright (module notes) as a :class:`JointFeedback`.

    Parameters
    ----------
    body : Body
    muscles : MuscleSet
        The pairs that act beside the controller (their gains without delay enter A).
    Q : array_like, shape (2r, 2r)
        State weight on [q, q̇] (:func:`design_matrices`). [1/rad², 1/(rad/s)²]
    R : array_like, shape (K, K)
        Effort weight on the driven joints' moments. [1/(N·m)²]
    source : str
        Words stored with the design.
    knee : {"free", "locked"}
        Design for a free knee, or for the knee locked (the ankle–hip chain; the knee's row
        of F is zero and a leg gain is split equally between shank and thigh angles, which
        are equal on the constraint).
    """
    system = linear_system(body, muscles, inputs=False)
    A, B, T = design_matrices(system, knee)
    r, k = A.shape[0] // 2, B.shape[1]
    Q = finite_array("Q", Q, (2 * r, 2 * r))
    R = finite_array("R", R, (k, k))
    F = lqr_gain(A, B, Q, R)
    n = body.n_links
    lift = np.linalg.pinv(T)  # q = T⁺ Θ
    full = np.zeros((n, 2 * n))
    rows = _inputs(n, knee)
    full[rows, :n] = F[:, :r] @ lift
    full[rows, n:] = F[:, r:] @ lift
    return JointFeedback(full[:, :n], full[:, n:], 1.0, source)


@dataclass(frozen=True)
class LQRCheck:
    """The designed closed loop, without and with its delay.

    Attributes
    ----------
    design_poles : numpy.ndarray, shape (2N,)
        Eigenvalues of A − B F (the loop as designed, no delay). [1/s]
    poles_without_delay : numpy.ndarray, shape (2N,)
        Poles of the run's linear system at τ = 0 (:meth:`LinearSystem.poles` with the
        controller); equal to ``design_poles``. [1/s]
    delay_margin : float
        The smallest delay at which a root reaches the imaginary axis (inf: none). [s]
    crossing_frequency : float
        ω there (NaN without a crossing). [rad/s]
    delay : float
        The run's delay τ. [s]
    stable_at_delay : bool
        τ below the delay margin.
    """

    design_poles: np.ndarray
    poles_without_delay: np.ndarray
    delay_margin: float
    crossing_frequency: float
    delay: float

    @property
    def stable_at_delay(self) -> bool:
        """Whether the delayed closed loop is stable at the run's delay."""
        return bool(self.delay < self.delay_margin)


def closed_loop_check(body: Body, muscles: MuscleSet, feedback: JointFeedback,
                      delay: float, knee: str = "free") -> LQRCheck:
    """Poles of the designed loop and the delay margin of the delayed one
    (:func:`~posturelab.linear.margins.delay_margins` on the run's linear system with the
    controller, :func:`~posturelab.linear.system.with_joint_feedback`, reduced to the
    coordinates of :func:`knee_basis` when the knee is locked)."""
    from .margins import delay_margins

    base = linear_system(body, muscles, inputs=False)
    A, B, T = design_matrices(base, knee)
    Fth, Fom = feedback.matrices()
    rows = _inputs(body.n_links, knee)
    F = np.hstack([Fth[rows] @ T, Fom[rows] @ T])
    design = sorted_poles(np.linalg.eigvals(A - B @ F))
    system = on_knee(linear_system(body, muscles, inputs=False, joint_feedback=feedback,
                                   delay=float(delay)), knee)
    poles = sorted_poles(np.linalg.eigvals(system.state_matrix()[0]))
    margin = delay_margins(system)
    return LQRCheck(design, poles, float(margin.delay_margin[0]),
                    float(margin.crossing_frequency[0]), float(delay))


@dataclass(frozen=True)
class MultiJointController:
    """A multi-joint controller preset built for one body.

    Attributes
    ----------
    name : str
    muscles : MuscleSet
        The intrinsic pairs acting beside the controller.
    joint_feedback : JointFeedback
    feedback_delay : float
        [s]
    effort_limits : numpy.ndarray, shape (N,)
        τ_max of Bryson's rule per joint. [N·m]
    citation : str
    knee : {"free", "locked"}
        The knee of the design (the runs' knee model).
    """

    name: str
    muscles: MuscleSet
    joint_feedback: JointFeedback
    feedback_delay: float
    effort_limits: np.ndarray
    citation: str
    knee: str = "free"

    def run_options(self) -> dict:
        """``{"feedback_delay": τ [s], "joint_feedback": JointFeedback, "knee": KneeModel}``."""
        from ..model.options import KneeModel

        return {"feedback_delay": self.feedback_delay, "joint_feedback": self.joint_feedback,
                "knee": KneeModel(self.knee)}

    def check(self) -> LQRCheck:
        """:func:`closed_loop_check` at the preset's delay."""
        return closed_loop_check(self._body, self.muscles, self.joint_feedback,
                                 self.feedback_delay, self.knee)


def multijoint_controller(body: Body, name: str = "multijoint-default",
                          scale: float = 1.0) -> MultiJointController:
    """The multi-joint preset ``name`` (:data:`posturelab.model.controllers.MULTIJOINT_CONTROLLERS`)
    designed for ``body``: its intrinsic pairs, the LQR with Bryson's weights, ``scale`` on
    the gains [-]."""
    from ..model.controllers import get_multijoint_controller

    preset = get_multijoint_controller(name)
    muscles = preset.muscles(body)
    knee = preset.knee if body.n_links >= 3 else "free"
    T = knee_basis(body.n_links, knee)
    limits = preset.effort_limits(body)
    Q, R = bryson_weights(T.shape[1], preset.angle_limit, preset.rate_limit,
                          limits[_inputs(body.n_links, knee)])
    r = T.shape[1]
    for j in range(1, r if np.isfinite(preset.joint_angle_limit) else 1):  # q_j − q_{j−1}
        c = np.zeros(2 * r)
        c[j], c[j - 1] = 1.0, -1.0
        Q = Q + np.outer(c, c) / preset.joint_angle_limit ** 2
    feedback = lqr_joint_feedback(body, muscles, Q, R, knee=knee, source=(
        f"{preset.name}: LQR on the undelayed chain, Bryson weights θ_max = "
        f"{preset.angle_limit:g} rad, ω_max = {preset.rate_limit:g} rad/s, τ_max = "
        + ", ".join(f"{v:.0f}" for v in limits) + f" N·m, knee {knee}")).scaled(scale)
    out = MultiJointController(preset.name, muscles, feedback, preset.feedback_delay, limits,
                               preset.citation, knee)
    object.__setattr__(out, "_body", body)
    return out
