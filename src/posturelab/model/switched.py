"""The switched model of a run, stated once: the right-hand side with its inputs, each event's
value and what a switch does, the start activity and start moments.

Two kinds of function live here.

* **Formulas** (``*_formula`` and the event values of :data:`EVENT_VALUES`): scalar
  expressions written once over a math namespace ``xp`` (numpy by default). The reference
  engine evaluates them on numpy arrays; the code generator of the compiled engine
  (``posturelab.simulation.compiled._codegen``, a development tool) evaluates the same
  functions on sympy symbols and prints them as C. ``xp`` needs ``sin``, ``cos``, ``abs``,
  ``minimum``, ``maximum``, ``not_equal`` and ``where(condition, a, b)``.
* **The model over arrays** (:func:`model_response`, :func:`raw_moments`,
  :func:`event_value`, …): the numpy right-hand side and event functions of one
  :class:`SwitchedModel`, built from the formulas and the equation of motion of
  :mod:`.dynamics`; the reference engine integrates them.

Symbols (as in :mod:`.events`): τ_j net muscle moment at joint j [N·m], M_p torque of pair
p [N·m], s_p and ṡ_p its stretch [rad] and stretch rate [rad/s] on the state the muscles
respond to, α the support-surface tilt [rad], h the depth of the tilt axis below the
ankle [m].
"""

from __future__ import annotations

import inspect
from dataclasses import dataclass

import numpy as np

from . import events as ev
from .body import Body
from .dynamics import angular_acceleration, constrained_acceleration, constrained_velocity
from .feedback import feedback_pair_torques, moments_to_link_torques, muscle_set_gains
from .gains import DELAYED_STIFFNESS, DELAYED_VISCOSITY, IMMEDIATE_STIFFNESS, IMMEDIATE_VISCOSITY
from .joint_feedback import joint_feedback_moments
from .kinematics import centre_of_pressure, ground_reaction
from .muscles import MuscleSet
from .noise import TorqueSeries, torque_at
from .options import FallCriteria, KneeModel
from .platform import Disturbance
from .tilt import Tilt, axis_acceleration_formula

__all__ = ["SwitchedModel", "EVENT_VALUES", "EVENT_QUANTITIES", "pair_torque_formula",
           "pull_value_formula", "saturated_moment_formula", "tilt_pair_torque_formula",
           "torque_feedback_rate_formula", "delayed_pair_torques", "torque_feedback_rate",
           "model_response", "raw_moments", "saturated_moments", "platform_acceleration",
           "tilt_pair_torques", "ankle_moment_and_load", "centre_of_pressure_at",
           "event_value", "pair_gains", "pair_activity_after", "saturation_after",
           "knee_impact", "apply_switch", "start_activity", "start_moments",
           "start_saturation", "start_centre_of_pressure"]


# ---------------------------------------------------------------------------
# Formulas (numpy or sympy through ``xp``)
# ---------------------------------------------------------------------------


def pair_torque_formula(stiffness, viscosity, stretch, stretch_rate):
    """M = k s + l ṡ of one pair. [N·m]"""
    return stiffness * stretch + viscosity * stretch_rate


def pull_value_formula(torque, stiffness, stretch, xp=np):
    """min(M, k s) (k replaced by 1 N·m/rad for a pair without stiffness): positive once a
    slack pull-only pair is stretched and its torque pulls. [N·m]"""
    return xp.minimum(torque, xp.where(stiffness > 0, stiffness, 1.0) * stretch)


def saturated_moment_formula(moment, saturation, limit, xp=np):
    """A joint's moment with its saturation applied: ±limit while saturated (saturation
    ±1), the moment itself while free (saturation 0). [N·m]"""
    return xp.where(xp.not_equal(saturation, 0), saturation * limit, moment)


def tilt_pair_torque_formula(gain_angle, gain_rate, gain_delayed_angle, gain_delayed_rate,
                             angle, rate, delayed_angle, delayed_rate):
    """A pair's torque from the tilt: g₀ α(t) + g₁ α̇(t) + g₂ α(t − τ) + g₃ α̇(t − τ). [N·m]"""
    return (gain_angle * angle + gain_rate * rate) + (gain_delayed_angle * delayed_angle
                                                      + gain_delayed_rate * delayed_rate)


def torque_feedback_rate_formula(filter_state, active_torque, gain, time_constant):
    """Ẏ = (K_t A − Y)/τ_t of one pair's torque feedback filter (Peterka 2002; docs/design.md,
    "Torque feedback"): Y [N·m] the filter state, A = P + Y the pair's active torque (P its
    delayed PD part), K_t [-], τ_t [s]. [N·m/s]"""
    return (gain * active_torque - filter_state) / time_constant


# The event values (the physical part g of each event function; the offset of
# posturelab.model.events is added to it). Each is a function of named quantities; the
# engines compute the quantities a kind names (EVENT_QUANTITIES).

def _link_angle(max_link_angle, link_angle, xp=np):
    return max_link_angle - xp.abs(link_angle)


def _cog_toe(toe, cog_x, xp=np):
    return toe - cog_x


def _cog_heel(heel, cog_x, xp=np):
    return cog_x - heel


def _cop_toe(toe, vertical_reaction, ankle_moment, xp=np):
    return toe * vertical_reaction - ankle_moment


def _cop_heel(heel, vertical_reaction, ankle_moment, xp=np):
    return ankle_moment - heel * vertical_reaction


def _saturation(side, moment, limit, xp=np):
    return side * moment - limit


def _stretch(stretch, xp=np):
    return stretch


def _pushes(pair_stiffness, pair_viscosity, stretch, stretch_rate, xp=np):
    return pair_torque_formula(pair_stiffness, pair_viscosity, stretch, stretch_rate)


def _pulls(pair_stiffness, pair_viscosity, stretch, stretch_rate, xp=np):
    torque = pair_torque_formula(pair_stiffness, pair_viscosity, stretch, stretch_rate)
    return pull_value_formula(torque, pair_stiffness, stretch, xp)


def _knee_hits_stop(knee_angle, stop_angle, xp=np):
    return knee_angle - stop_angle


def _knee_leaves_stop(free_knee_acceleration, xp=np):
    return free_knee_acceleration


#: The physical part of each event kind's function (the table of :mod:`.events` adds its
#: offset), as a function of named quantities:
#:
#: link_angle θ_i, cog_x x_c, ankle_moment τ_ankle and vertical_reaction F_y (with the
#: segment's switches), moment τ_j before saturation, stretch s_p and stretch_rate ṡ_p of the
#: fed-back state, pair_stiffness and pair_viscosity (immediate plus delayed gains),
#: knee_angle θ2 − θ1, free_knee_acceleration θ̈2 − θ̈1 with the knee free; and the options
#: max_link_angle, toe, heel, side, limit, stop_angle.
EVENT_VALUES = {
    ev.LINK_ANGLE: _link_angle, ev.COG_TOE: _cog_toe, ev.COG_HEEL: _cog_heel,
    ev.COP_TOE: _cop_toe, ev.COP_HEEL: _cop_heel, ev.SATURATES: _saturation,
    ev.LETS_GO: _saturation, ev.PAIR_SLACKENS: _stretch, ev.PAIR_ENGAGES: _stretch,
    ev.KNEE_HITS_STOP: _knee_hits_stop, ev.KNEE_LEAVES_STOP: _knee_leaves_stop,
    ev.PAIR_PUSHES: _pushes, ev.PAIR_PULLS: _pulls,
}
#: The quantities each event kind's value needs, in its arguments' order.
EVENT_QUANTITIES = {kind: tuple(name for name in inspect.signature(f).parameters if name != "xp")
                    for kind, f in EVENT_VALUES.items()}


# ---------------------------------------------------------------------------
# The model of a run over arrays (numpy)
# ---------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class SwitchedModel:
    """The validated parameters the switched model of a run needs (no integration options).

    Attributes
    ----------
    body : Body
    muscles : MuscleSet
    gains : numpy.ndarray, shape (4, P)
        Pair gains by when they act (rows named in :mod:`.gains`).
        [N·m/rad], [N·m·s/rad], [N·m/rad], [N·m·s/rad]
    disturbance : Disturbance
    torque_limits : numpy.ndarray, shape (N,), or None
        ``inf`` where a joint has none. [N·m]
    feedback_delay : float
        τ. [s]
    tilt, visual_tilt : Tilt or None
        The surface's α(t) and the visual scene's v(t). [rad]
    tilt_gains, visual_gains : numpy.ndarray, shape (4, P), or None
        Gains on α(t), α̇(t), α(t − τ), α̇(t − τ), and on v (:mod:`.visual`). [N·m/rad], …
    tilt_axis_depth : float  (the tilt axis's depth below the ankle [m])
    motor_torque : TorqueSeries or None
        Motor noise added to each joint's moment before the limits. [N·m]
    knee_row : numpy.ndarray, shape (N,), or None  (the row C of the knee constraint)
    knee : KneeModel
    fall : FallCriteria
    torque_feedback_gain : float
        K_t of the torque feedback (0: none; :func:`torque_feedback_rate_formula`). [-]
    torque_feedback_time_constant : float
        τ_t. [s]
    joint_gains : numpy.ndarray, shape (4, N, N), or None
        A joint-space controller's moment gains (:mod:`.joint_feedback`). [N·m/rad, N·m·s/rad]
    """

    body: Body
    muscles: MuscleSet
    gains: np.ndarray
    disturbance: Disturbance
    torque_limits: np.ndarray | None = None
    feedback_delay: float = 0.0
    tilt: Tilt | None = None
    tilt_gains: np.ndarray | None = None
    tilt_axis_depth: float = 0.0
    motor_torque: TorqueSeries | None = None
    knee_row: np.ndarray | None = None
    knee: KneeModel = KneeModel()
    fall: FallCriteria = FallCriteria()
    torque_feedback_gain: float = 0.0
    torque_feedback_time_constant: float = 17.4
    joint_gains: np.ndarray | None = None
    visual_tilt: Tilt | None = None
    visual_gains: np.ndarray | None = None

    def stimuli(self) -> list[tuple[Tilt, np.ndarray]]:
        """The (profile, pair gains (4, P)) of the surface and the visual tilts present."""
        both = ((self.tilt, self.tilt_gains), (self.visual_tilt, self.visual_gains))
        return [(p, g) for p, g in both if p is not None]

    @property
    def n_links(self) -> int:
        """N. [-]"""
        return self.body.n_links

    @property
    def n_filter_states(self) -> int:
        """Torque feedback filter states appended to [Θ, Θ̇]: one per pair with torque
        feedback, else 0. [-]"""
        return len(self.muscles.pairs) if self.torque_feedback_gain > 0 else 0


def platform_acceleration(model: SwitchedModel, t) -> np.ndarray:
    """The ankle's acceleration (ẍ_d, ÿ_d) at ``t``, shape t.shape + (2,): the disturbance's,
    plus that of a tilt about an axis below the ankle (:func:`axis_acceleration_formula`).
    [m/s²]"""
    a = model.disturbance.acceleration(t)
    if model.tilt is not None and model.tilt_axis_depth > 0:
        angle, rate, accel = model.tilt.kinematics(t)
        a = a + np.stack(axis_acceleration_formula(model.tilt_axis_depth, angle, rate, accel),
                         axis=-1)
    return a


def tilt_pair_torques(tilt: Tilt, tilt_gains: np.ndarray, delay: float, t) -> np.ndarray:
    """Pair torques from the tilt at times ``t`` (any shape), shape t.shape + (P,)
    (:func:`tilt_pair_torque_formula`, with ``tilt_gains`` g (..., 4, P)). [N·m]"""
    t = np.asarray(t, dtype=float)
    a, ad = tilt.angle_and_rate(t)
    a, ad = a[..., None], ad[..., None]
    k, v = tilt_gains[..., IMMEDIATE_STIFFNESS, :], tilt_gains[..., IMMEDIATE_VISCOSITY, :]
    if delay > 0:
        a_d, ad_d = tilt.angle_and_rate(t - delay)
        return tilt_pair_torque_formula(k, v, tilt_gains[..., DELAYED_STIFFNESS, :],
                                        tilt_gains[..., DELAYED_VISCOSITY, :], a, ad,
                                        a_d[..., None], ad_d[..., None])
    return k * a + v * ad


def delayed_pair_torques(model: SwitchedModel, t: float, feedback: np.ndarray,
                         active: np.ndarray) -> np.ndarray:
    """P: each pair's delayed (active) torque at ``t`` [s], the delayed gains on
    ``feedback`` (x(t − τ)) and the tilts' delayed parts, what the torque feedback filters
    (:func:`torque_feedback_rate_formula`). [N·m]"""
    g = model.gains
    E = model.muscles.selection_matrix
    n = model.n_links
    P = (g[DELAYED_STIFFNESS] * (E @ feedback[:n]) + g[DELAYED_VISCOSITY] * (E @ feedback[n:]))
    P = P * np.asarray(active, dtype=float)
    for profile, gains in model.stimuli() if model.feedback_delay > 0 else ():
        a_d, ad_d = profile.angle_and_rate(np.asarray(t - model.feedback_delay, float))
        P = P + (gains[DELAYED_STIFFNESS] * a_d + gains[DELAYED_VISCOSITY] * ad_d)
    return P


def torque_feedback_rate(model: SwitchedModel, t: float, feedback: np.ndarray,
                         active: np.ndarray, filter_state: np.ndarray) -> np.ndarray:
    """Ẏ of the pairs' torque feedback filters at ``t`` [s]
    (:func:`torque_feedback_rate_formula` with A = P + Y, the filter's part acting with its
    pair). [N·m/s]"""
    act = np.asarray(active, dtype=float)
    A = delayed_pair_torques(model, t, feedback, active) + act * filter_state
    return torque_feedback_rate_formula(filter_state, A, model.torque_feedback_gain,
                                        model.torque_feedback_time_constant)


def raw_moments(model: SwitchedModel, t: float, x: np.ndarray, feedback: np.ndarray,
                active: np.ndarray, filter_state: np.ndarray | None = None) -> np.ndarray:
    """Unsaturated net muscle moment per joint at ``t`` [s]: the immediate part on the state
    ``x``, the delayed part on ``feedback`` (x(t − τ)), the tilt's part, the torque feedback
    filters' ``filter_state`` (P,), the joint-space controller's and the motor noise. [N·m]"""
    M = feedback_pair_torques(model.muscles, model.gains, x, feedback, active)
    for profile, gains in model.stimuli():  # the surface's and the visual scene's tilts
        M = M + tilt_pair_torques(profile, gains, model.feedback_delay, t)
    if filter_state is not None and model.n_filter_states:
        M = M + np.asarray(active, dtype=float) * filter_state
    tau = M @ model.muscles.crossing_matrix
    if model.joint_gains is not None:
        tau = tau + joint_feedback_moments(model.joint_gains, x, feedback)
    if model.motor_torque is not None:
        tau = tau + torque_at(model.motor_torque, t)
    return tau


def saturated_moments(moments: np.ndarray, saturation: np.ndarray | None,
                      limits: np.ndarray | None) -> np.ndarray:
    """Moments (..., N) with the joints' saturation (..., N) applied
    (:func:`saturated_moment_formula`; a joint without a limit never saturates). [N·m]"""
    if saturation is None or limits is None:
        return moments
    bound = np.where(np.isfinite(limits), limits, 0.0)
    return saturated_moment_formula(moments, saturation, bound)


def _acceleration(model: SwitchedModel, x: np.ndarray, tau: np.ndarray, a: np.ndarray,
                  locked: bool) -> np.ndarray:
    n = model.n_links
    acc = angular_acceleration(model.body, x[..., :n], x[..., n:], moments_to_link_torques(tau),
                               a[..., 0], a[..., 1])
    if locked:
        acc = constrained_acceleration(model.body, x[:n], acc, model.knee_row)
    return acc


def model_response(model: SwitchedModel, t: float, x: np.ndarray, feedback: np.ndarray,
                   active: np.ndarray, locked: bool, saturation: np.ndarray | None,
                   filter_state: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The model at one state with the run's switches applied.

    Parameters
    ----------
    t : float
        Time. [s]
    x : numpy.ndarray, shape (2N,)
        The state. [rad], [rad/s]
    feedback : numpy.ndarray, shape (2N,)
        The state the delayed part of the feedback responds to, x(t − τ) (x itself
        without a delay). [rad], [rad/s]
    active : numpy.ndarray, shape (P,)
        Which pairs act. [-]
    locked : bool
        The knee constraint holds.
    saturation : numpy.ndarray, shape (N,), or None
        ±1 for a saturated joint (its moment is ±limit), 0 for a free one. [-]
    filter_state : numpy.ndarray, shape (P,), or None
        The torque feedback filters' states Y (:func:`torque_feedback_rate`). [N·m]

    Returns
    -------
    moments : numpy.ndarray, shape (N,)
        Net muscle moment per joint, after saturation. [N·m]
    acceleration : numpy.ndarray, shape (N,)
        Θ̈ (on the knee constraint if locked). [rad/s²]
    """
    tau = saturated_moments(raw_moments(model, t, x, feedback, active, filter_state),
                            saturation, model.torque_limits)
    return tau, _acceleration(model, x, tau, platform_acceleration(model, t), locked)


def ankle_moment_and_load(model: SwitchedModel, t: float, x: np.ndarray, feedback: np.ndarray,
                          active, locked, saturation, filter_state=None
                          ) -> tuple[float, float]:
    """The net muscle moment at the ankle τ_ankle [N·m] and the vertical ground reaction F_y
    [N] at one state: x_p = τ_ankle / F_y. The centre-of-pressure events use them in moment
    form (:mod:`.events`), continuous where F_y passes 0."""
    n = model.n_links
    tau, acc = model_response(model, t, x, feedback, active, locked, saturation, filter_state)
    fy = ground_reaction(model.body, x[:n], x[n:], acc, platform_acceleration(model, t))[1]
    return float(tau[0]), float(fy)


def centre_of_pressure_at(model: SwitchedModel, t: float, x: np.ndarray, feedback: np.ndarray,
                          active, locked, saturation) -> float:
    """Centre of pressure x_p at one state, relative to the ankle (NaN when the foot is not
    pressed on the platform, F_y <= 0). [m]"""
    return float(centre_of_pressure(*ankle_moment_and_load(model, t, x, feedback, active,
                                                           locked, saturation)))


def pair_gains(model: SwitchedModel, j: int) -> tuple[float, float]:
    """Pair j's stiffness and viscosity, immediate and delayed parts summed (one-sided
    pairs are wholly immediate or wholly delayed). [N·m/rad], [N·m·s/rad]"""
    g = model.gains
    return (float(g[IMMEDIATE_STIFFNESS, j] + g[DELAYED_STIFFNESS, j]),
            float(g[IMMEDIATE_VISCOSITY, j] + g[DELAYED_VISCOSITY, j]))


def event_value(model: SwitchedModel, kind: int, j: int, side: float, t: float, x: np.ndarray,
                feedback: np.ndarray, active: np.ndarray, locked: bool,
                saturation: np.ndarray | None, filter_state: np.ndarray | None = None
                ) -> float:
    """The event function g(t, x) of event ``kind`` (index ``j``, side ``side``) with the
    segment's switches: :data:`EVENT_VALUES` on the quantities it names, plus the kind's
    offset (:data:`.events.EVENT_OFFSET`); ``filter_state`` the torque feedback filters'
    (:func:`raw_moments`)."""
    n = model.n_links
    body, fall = model.body, model.fall
    bos = fall.base_of_support
    E = model.muscles.selection_matrix

    def quantity(name: str):
        if name == "link_angle":
            return x[j]
        if name == "cog_x":
            return (body.gravity_coefficients @ np.sin(x[:n])) / body.total_mass
        if name == "stretch":
            return E[j] @ feedback[:n]
        if name == "stretch_rate":
            return E[j] @ feedback[n:]
        if name == "pair_stiffness":
            return pair_gains(model, j)[0]
        if name == "pair_viscosity":
            return pair_gains(model, j)[1]
        if name == "moment":
            return raw_moments(model, t, x, feedback, active, filter_state)[j]
        if name == "knee_angle":
            return x[1] - x[0]
        if name == "free_knee_acceleration":
            acc = model_response(model, t, x, feedback, active, False, saturation,
                                 filter_state)[1]
            return acc[1] - acc[0]
        return {"max_link_angle": fall.max_link_angle, "side": side,
                "toe": bos.toe if bos is not None else 0.0,
                "heel": bos.heel if bos is not None else 0.0,
                "limit": model.torque_limits[j] if model.torque_limits is not None else 0.0,
                "stop_angle": model.knee.stop_angle}[name]

    names = EVENT_QUANTITIES[kind]
    values = {}
    if "ankle_moment" in names:
        values["ankle_moment"], values["vertical_reaction"] = ankle_moment_and_load(
            model, t, x, feedback, active, locked, saturation, filter_state)
    for name in names:
        if name not in values:
            values[name] = quantity(name)
    return float(EVENT_VALUES[kind](**values)) + float(ev.EVENT_OFFSET[kind])


# ---------------------------------------------------------------------------
# What a switch does
# ---------------------------------------------------------------------------


#: What each switch changes, stated once for both engines (the C of ``pl_apply_switch`` is
#: generated from it): "active" (pair j, :func:`pair_activity_after`), "saturation" (joint j,
#: :func:`saturation_after`), "knee impact" (:func:`knee_impact`, the knee locks) or
#: "knee free" (the knee lets go). Falls change nothing.
SWITCH_EFFECTS = {
    ev.PAIR_SLACKENS: "active", ev.PAIR_ENGAGES: "active",
    ev.PAIR_PUSHES: "active", ev.PAIR_PULLS: "active",
    ev.SATURATES: "saturation", ev.LETS_GO: "saturation",
    ev.KNEE_HITS_STOP: "knee impact", ev.KNEE_LEAVES_STOP: "knee free",
}


def _where(condition, if_true, if_false):
    return if_true if condition else if_false


def pair_activity_after(kind: int, stretch_rate, where=_where):
    """Whether a pair acts after its event ``kind`` fired: after a stretch event if its
    (fed-back) stretch is growing, ``stretch_rate`` [rad/s] >= 0; slack after PAIR_PUSHES;
    acting after PAIR_PULLS (stretched, and pulling). ``where(condition, a, b)`` chooses
    (the generator passes a symbolic one). [-]"""
    if kind == ev.PAIR_PUSHES:
        return 0.0
    if kind == ev.PAIR_PULLS:
        return 1.0
    return where(stretch_rate >= 0, 1.0, 0.0)


def saturation_after(kind: int, side):
    """A joint's saturation after SATURATES (its side, ±1) or LETS_GO (0). [-]"""
    return side if kind == ev.SATURATES else 0.0


def knee_angle_at_stop(shank_angle, stop_angle):
    """Link 2's angle when the knee reaches its stop, from link 1's. [rad]"""
    return shank_angle + stop_angle


def knee_impact(body: Body, x: np.ndarray, stop_angle: float, knee_row: np.ndarray
                ) -> np.ndarray:
    """The state after the knee reaches its stop: the knee angle at the stop
    (:func:`knee_angle_at_stop`), the rates after a plastic impact onto the constraint
    (:func:`.dynamics.constrained_velocity`). [rad], [rad/s]"""
    n = body.n_links
    x = np.array(x, dtype=float)
    x[1] = knee_angle_at_stop(x[0], stop_angle)
    x[n:] = constrained_velocity(body, x[:n], x[n:], knee_row)
    return x


def apply_switch(model: SwitchedModel, kind: int, j: int, side: float, x: np.ndarray,
                 feedback: np.ndarray, active: np.ndarray, saturation: np.ndarray,
                 locked: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """What switch ``kind`` (index ``j``, side ``side``) does at state ``x`` (2N,), the muscles
    responding to ``feedback`` (2N,): the new (state, active, saturation, locked), new arrays
    where they change (:data:`SWITCH_EFFECTS`). A stretch event sets pair j's activity
    (:func:`pair_activity_after`), the knee stop locks the knee after a plastic impact
    (:func:`knee_impact`) or lets it go, a joint saturates or lets go
    (:func:`saturation_after`). [rad, rad/s], [-], [-]"""
    effect = SWITCH_EFFECTS.get(kind)
    if effect == "active":
        n = model.n_links
        active = active.copy()
        active[j] = pair_activity_after(kind, model.muscles.selection_matrix[j] @ feedback[n:])
    elif effect == "knee impact":
        x, locked = knee_impact(model.body, x, model.knee.stop_angle, model.knee_row), True
    elif effect == "knee free":
        locked = False
    elif effect == "saturation":
        saturation = saturation.copy()
        saturation[j] = saturation_after(kind, side)
    return x, active, saturation, locked


# ---------------------------------------------------------------------------
# The start of a run (for runs that may differ in their gains: leading axes)
# ---------------------------------------------------------------------------


def start_activity(muscles: MuscleSet, state: np.ndarray, gains: np.ndarray | None = None
                   ) -> np.ndarray:
    """Which pairs act at the start: one-sided pairs if stretched, or at zero stretch and
    stretching, in the state the muscles respond to, ``state`` (..., 2N); a pull-only pair
    also only if its torque k s + l ṡ is >= 0, with the run's ``gains`` (..., 4, P) (the
    muscles' own by default; :func:`.muscles.feedback_gains`). Returns (..., P)."""
    n = muscles.n_links
    E = muscles.selection_matrix
    state = np.asarray(state, dtype=float)
    s, sd = state[..., :n] @ E.T, state[..., n:] @ E.T
    act = np.where(muscles.one_sided_mask, (s > 0) | ((s == 0) & (sd >= 0)), True)
    pull = muscles.pull_only_mask
    if pull.any():
        g = muscle_set_gains(muscles, 0.0) if gains is None else np.asarray(gains, float)
        torque = pair_torque_formula(g[..., IMMEDIATE_STIFFNESS, :] + g[..., DELAYED_STIFFNESS, :],
                                     g[..., IMMEDIATE_VISCOSITY, :] + g[..., DELAYED_VISCOSITY, :],
                                     s, sd)
        act = act & np.where(pull, torque >= 0, True)
    return act.astype(float)


def start_moments(muscles: MuscleSet, state: np.ndarray, before: np.ndarray,
                  active: np.ndarray, gains: np.ndarray) -> np.ndarray:
    """Unsaturated joint moments at t = 0, τ = Cᵀ M, for gains that may differ per run:
    the immediate part on ``state`` (..., 2N), the delayed part on ``before`` (..., 2N),
    ``active`` (..., P), ``gains`` (..., 4, P) (:func:`.muscles.feedback_pair_torques`).
    Returns (..., N). [N·m]"""
    return feedback_pair_torques(muscles, gains, state, before, active) @ muscles.crossing_matrix


def start_saturation(moments: np.ndarray, limits: np.ndarray | None) -> np.ndarray:
    """±1 for each joint whose moment starts beyond its limit, else 0 (shape of moments)."""
    moments = np.asarray(moments, dtype=float)
    sat = np.zeros(moments.shape)
    if limits is not None:
        limits = np.broadcast_to(np.asarray(limits, dtype=float), moments.shape)
        over = np.isfinite(limits) & (np.abs(moments) > limits)
        sat[over] = np.sign(moments[over])
    return sat


def start_centre_of_pressure(model: SwitchedModel, x0: np.ndarray, locked0: bool,
                             moments: np.ndarray, limits, saturation) -> np.ndarray:
    """Centre of pressure at t = 0 from the state ``x0`` (2N,) for runs that differ in their
    moments (..., N) [N·m], limits (..., N) [N·m] and saturation (..., N): x_p (...). [m]"""
    n = model.n_links
    tau = np.asarray(moments, dtype=float)
    if limits is not None:
        bound = np.where(np.isfinite(limits), limits, 0.0)
        tau = saturated_moment_formula(tau, saturation, bound)
    a = platform_acceleration(model, 0.0)
    theta = np.broadcast_to(x0[:n], tau.shape)
    omega = np.broadcast_to(x0[n:], tau.shape)
    acc = angular_acceleration(model.body, theta, omega, moments_to_link_torques(tau), a[0],
                               a[1])
    if locked0:
        acc = np.apply_along_axis(
            lambda row: constrained_acceleration(model.body, x0[:n], row, model.knee_row),
            -1, acc)
    fy = ground_reaction(model.body, theta, omega, acc,
                         np.broadcast_to(a, tau.shape[:-1] + (2,)))[..., 1]
    return centre_of_pressure(tau[..., 0], fy)
