"""Nonlinear simulation of the chain under muscle-pair feedback and platform motion.

:func:`simulate` integrates eq. 1 with scipy's adaptive Runge–Kutta
integrators (DOP853 by default) and returns a frozen
:class:`~posturelab.results.SimulationResult`.

Switches are located as events, never as an ``if`` inside the right-hand
side that the integrator could step over: the integration runs in segments
within which the model is smooth, and a segment ends

* at every corner (breakpoint) of the platform profile;
* where a one-sided pair's stretch crosses zero (the real gastrocnemius
  engages or goes slack as θ2 crosses 0);
* where the knee reaches its hyper-extension stop, or the stop lets go;
* where a fall criterion fires (then the run stops and reports it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from .._validation import finite_array, float_in_range, positive_float
from ..errors import ParameterError
from ..model.body import Body
from ..model.dynamics import (
    gravity_vector,
    mass_matrix,
    platform_vector,
    velocity_terms,
)
from ..model.kinematics import centre_of_gravity, centre_of_gravity_velocity
from ..model.muscles import MuscleSet
from ..model.platform import Disturbance, NoDisturbance
from .results import DerivedSeries, SimulationResult

__all__ = [
    "BaseOfSupport",
    "FallCriteria",
    "KneeModel",
    "simulate",
    "initial_state_for",
    "FOOT_FROM_LITERATURE",
    "base_of_support_for_height",
]

KneeMode = Literal["free", "locked", "stop"]

#: A one-sided pair switches when its stretch passes 0 by this much, and the knee stop engages
#: this far past its angle: a hysteresis far below any physical resolution that stops a pair
#: or knee resting exactly at its switch point from switching back and forth. [rad]
_SWITCH_HYSTERESIS = 1e-12
#: The knee stop lets go when the free knee acceleration pulls away by more than this. [rad/s²]
_RELEASE_HYSTERESIS = 1e-9

#: Winter (2009), Biomechanics and Motor Control of Human Movement, 4th ed., Fig. 4.1 / Table 4.1:
#: foot length = 0.152 × body height. [-]
FOOT_LENGTH_FRACTION_OF_HEIGHT = 0.152
#: Fraction of the foot length behind the ankle joint (heel side). Our assumption (the ankle
#: joint sits about a quarter of the foot length in front of the heel); configurable. [-]
HEEL_FRACTION_OF_FOOT = 0.25


@dataclass(frozen=True)
class BaseOfSupport:
    """Heel and toe positions relative to the ankle, along x.

    Parameters
    ----------
    heel : float
        Heel position, negative (behind the ankle). [m]
    toe : float
        Toe position, positive (in front of the ankle). [m]
    source : str
        Where the numbers come from.
    """

    heel: float
    toe: float
    source: str = "user"

    def __post_init__(self) -> None:
        heel = float_in_range("base of support heel [m]", self.heel, -1.0, 0.0,
                              include_high=False)
        toe = float_in_range("base of support toe [m]", self.toe, 0.0, 1.0, include_low=False)
        object.__setattr__(self, "heel", heel)
        object.__setattr__(self, "toe", toe)


def base_of_support_for_height(height: float) -> BaseOfSupport:
    """Heel and toe of a foot scaled to body height.

    Foot length 0.152 H (Winter 2009, Table 4.1 / Fig. 4.1, after Drillis and
    Contini); the ankle joint a quarter of the foot length in front of the
    heel (our assumption, stated in :data:`HEEL_FRACTION_OF_FOOT`).

    Parameters
    ----------
    height : float
        Body height H. [m]
    """
    h = float_in_range("height [m]", height, 0.5, 2.5, unit="m")
    foot = FOOT_LENGTH_FRACTION_OF_HEIGHT * h
    return BaseOfSupport(
        -HEEL_FRACTION_OF_FOOT * foot, (1 - HEEL_FRACTION_OF_FOOT) * foot,
        source=f"foot length 0.152 H (Winter 2009) for H = {h:g} m; ankle at 25 % of the foot",
    )


#: A foot for the paper's body, whose link lengths match a stature of about 1.65 m
#: (Winter's leg 0.246 H and thigh 0.245 H give 1.63 m and 1.68 m): heel −0.063 m, toe +0.188 m.
FOOT_FROM_LITERATURE = base_of_support_for_height(1.65)


@dataclass(frozen=True)
class FallCriteria:
    """When a run counts as a fall.

    Parameters
    ----------
    max_link_angle : float
        A fall when any |θ_i| exceeds this. [rad] (default π/3, 60°)
    base_of_support : BaseOfSupport or None
        If given, a fall also when the centre of gravity's horizontal
        projection leaves [heel, toe] (the foot would tip). None (default)
        is the paper's model: the foot never tips.
    centre_of_pressure : bool
        With a base of support, also a fall when the centre of pressure under
        the (massless) foot leaves [heel, toe]: the ankle moment exceeds what
        the ground can react and the foot starts to tip, even while the
        centre of gravity is still above the foot.
    """

    max_link_angle: float = math.pi / 3
    base_of_support: BaseOfSupport | None = None
    centre_of_pressure: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "max_link_angle", float_in_range(
            "max_link_angle [rad]", self.max_link_angle, 0.0, math.pi, include_low=False))
        if self.centre_of_pressure and self.base_of_support is None:
            raise ParameterError("centre_of_pressure needs a base_of_support (heel and toe)")


@dataclass(frozen=True)
class KneeModel:
    """How the knee behaves.

    Parameters
    ----------
    mode : {"free", "locked", "stop"}
        ``free``: the paper's unconstrained model. ``locked``: θ2 − θ1 stays at
        its initial value (θ1 = θ2 for an extended knee; two degrees of freedom
        for three links), as the paper assumes when the knee is extended.
        ``stop``: a hyper-extension stop; when θ2 − θ1 reaches ``stop_angle``
        the knee locks (a plastic impact) and it lets go when the muscles and
        gravity would flex it again.
    stop_angle : float
        Knee angle θ2 − θ1 at the hyper-extension stop (mode ``stop``). [rad]
    """

    mode: KneeMode = "free"
    stop_angle: float = 0.0

    def __post_init__(self) -> None:
        if self.mode not in ("free", "locked", "stop"):
            raise ParameterError(f"knee mode must be 'free', 'locked' or 'stop', got {self.mode!r}")
        object.__setattr__(self, "stop_angle",
                           float_in_range("knee stop_angle [rad]", self.stop_angle, -0.5, 0.5))


# ---------------------------------------------------------------------------
# Model pieces in one mode (fixed active pairs, fixed constraint)
# ---------------------------------------------------------------------------


def joint_crossing_matrix(muscles: MuscleSet) -> np.ndarray:
    """C (P, N): C[p, j] = 1 when pair p crosses joint j (0 = ankle, 1 = knee, …). [-]

    Joint j lies between link j (0 = the foot) and link j + 1; the net muscle
    moment at the joints is τ = Cᵀ M.
    """
    crosses = np.zeros((len(muscles.pairs), muscles.n_links))
    for r, p in enumerate(muscles.pairs):
        crosses[r, p.lo:p.hi] = 1.0
    return crosses


def moments_to_link_torques(moments: np.ndarray) -> np.ndarray:
    """Generalised torques on the link angles from joint moments: U_i = −τ_i + τ_{i+1}. [N·m]

    Equal to −EᵀM when τ = CᵀM (see :func:`joint_crossing_matrix`).
    """
    moments = np.asarray(moments, dtype=float)
    above = np.concatenate([moments[..., 1:], np.zeros(moments.shape[:-1] + (1,))], axis=-1)
    return above - moments


class _History:
    """The state at past times: a constant before t = 0, then the dense outputs of the
    integrated segments (the method of steps for the delayed feedback)."""

    def __init__(self, before: np.ndarray):
        self.before = np.asarray(before, dtype=float).copy()
        self.starts: list[float] = []
        self.ends: list[float] = []
        self.pieces: list = []

    def add(self, t0: float, t1: float, sol) -> None:
        if t1 > t0:
            self.starts.append(t0)
            self.ends.append(t1)
            self.pieces.append(sol)

    def __call__(self, t: float) -> np.ndarray:
        if t < 0.0 or not self.pieces:
            return self.before
        import bisect

        k = max(bisect.bisect_right(self.starts, t) - 1, 0)
        return self.pieces[k](min(t, self.ends[k]))


@dataclass
class _Model:
    body: Body
    muscles: MuscleSet
    disturbance: Disturbance
    knee_row: np.ndarray | None  # C (N,) for the knee constraint, or None
    limits: np.ndarray | None = None  # (N,) largest |joint moment| [N·m], inf where none
    delay: float = 0.0  # neural delay of the muscle feedback [s]
    history: _History | None = None
    E: np.ndarray = field(init=False)
    crossing: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        self.E = self.muscles.selection_matrix
        self.crossing = joint_crossing_matrix(self.muscles)

    def feedback_state(self, t: float, x: np.ndarray) -> np.ndarray:
        """The state the muscles respond to: x(t − delay) (x itself without delay)."""
        if self.delay <= 0.0:
            return x
        return self.history(t - self.delay)

    def raw_moments_at(self, t, x, active):
        """Unsaturated joint moments τ = Cᵀ M from the fed-back state. [N·m]"""
        n = self.body.n_links
        xf = self.feedback_state(t, x)
        return self.raw_moments(xf[:n], xf[n:], active)

    def raw_moments(self, theta, omega, active):
        """Unsaturated joint moments τ = Cᵀ M. [N·m]"""
        M = (self.muscles.stiffnesses * (self.E @ theta)
             + self.muscles.viscosities * (self.E @ omega)) * active
        return M @ self.crossing

    def torques(self, theta, omega, active, saturation=None):
        if self.limits is None:
            M = (self.muscles.stiffnesses * (self.E @ theta)
                 + self.muscles.viscosities * (self.E @ omega)) * active
            return None, -(self.E.T @ M)
        tau = self.raw_moments(theta, omega, active)
        if saturation is not None:
            bound = np.where(np.isfinite(self.limits), self.limits, 0.0)
            tau = np.where(saturation != 0, saturation * bound, tau)
        return tau, moments_to_link_torques(tau)

    def free_acceleration(self, t, x, active, saturation=None):
        n = self.body.n_links
        theta, omega = x[:n], x[n:]
        xf = self.feedback_state(t, x)
        _, U = self.torques(xf[:n], xf[n:], active, saturation)
        a = self.disturbance.acceleration(t)
        rhs = (U - velocity_terms(self.body, theta, omega)
               + (self.body.gravity + a[1]) * gravity_vector(self.body, theta)
               - a[0] * platform_vector(self.body, theta))
        J = mass_matrix(self.body, theta)
        return J, np.linalg.solve(J, rhs)

    def acceleration(self, t, x, active, locked, saturation=None):
        J, acc = self.free_acceleration(t, x, active, saturation)
        if locked:
            C = self.knee_row
            JiC = np.linalg.solve(J, C)
            acc = acc - JiC * (C @ acc) / (C @ JiC)
        return acc

    def project_velocity(self, theta, omega):
        """Plastic impact onto the knee constraint: momentum-consistent projection."""
        C = self.knee_row
        J = mass_matrix(self.body, theta)
        JiC = np.linalg.solve(J, C)
        return omega - JiC * (C @ omega) / (C @ JiC)

    def centre_of_pressure(self, t, x, active, locked, saturation=None):
        """x_p = τ_ankle / F_y under the massless foot, relative to the ankle. [m]"""
        n = self.body.n_links
        theta, omega = x[:n], x[n:]
        acc = self.acceleration(t, x, active, locked, saturation)
        xf = self.feedback_state(t, x)
        if self.limits is None:
            M = (self.muscles.stiffnesses * (self.E @ xf[:n])
                 + self.muscles.viscosities * (self.E @ xf[n:])) * active
            tau0 = M @ self.crossing[:, 0]
        else:
            tau0 = self.torques(xf[:n], xf[n:], active, saturation)[0][0]
        a = self.body.gravity_coefficients
        ay = self.disturbance.acceleration(t)[1]
        fy = (self.body.total_mass * (self.body.gravity + ay)
              - acc @ (a * np.sin(theta)) - (a * np.cos(theta)) @ omega**2)
        return tau0 / fy


def initial_state_for(
    body: Body,
    disturbance: Disturbance,
    initial_state: np.ndarray | None = None,
    rates_from: Literal["upright", "posture"] = "upright",
) -> np.ndarray:
    """Initial state after the disturbance's velocity step at t = 0.

    The step changes the rates by ΔΘ̇ = J⁻¹(−H Δẋ_d + G Δẏ_d), with J, H, G
    evaluated at upright (the paper's choice, ``rates_from="upright"``) or at
    the initial posture (``"posture"``, exact; erratum 5).

    Parameters
    ----------
    initial_state : array_like, shape (2N,), optional
        ``[Θ, Θ̇]`` before the step; upright at rest by default. [rad], [rad/s]
    """
    n = body.n_links
    x0 = (np.zeros(2 * n) if initial_state is None
          else finite_array("initial_state [rad, rad/s]", initial_state, (2 * n,)).copy())
    dv = disturbance.velocity_change
    if dv != (0.0, 0.0):
        if rates_from not in ("upright", "posture"):
            raise ParameterError(
                f"rates_from must be 'upright' or 'posture', got {rates_from!r}"
            )
        ref = np.zeros(n) if rates_from == "upright" else x0[:n]
        J = mass_matrix(body, ref)
        gen = -platform_vector(body, ref) * dv[0] + gravity_vector(body, ref) * dv[1]
        x0[n:] += np.linalg.solve(J, gen)
    return x0


def simulate(
    body: Body,
    muscles: MuscleSet,
    disturbance: Disturbance | None = None,
    duration: float = 5.0,
    *,
    initial_state: np.ndarray | None = None,
    rates_from: Literal["upright", "posture"] = "upright",
    knee: KneeModel | None = None,
    fall: FallCriteria | None = None,
    torque_limits: np.ndarray | None = None,
    feedback_delay: float = 0.0,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    sample_rate: float = 1000.0,
    method: str = "DOP853",
    max_switches: int = 10_000,
    description: str = "",
) -> SimulationResult:
    """Simulate the nonlinear chain.

    Parameters
    ----------
    body : Body
        The chain.
    muscles : MuscleSet
        Muscle pairs (one-sided pairs switch exactly where their stretch crosses 0).
    disturbance : Disturbance, optional
        Platform motion; none by default.
    duration : float
        Simulated time. [s]
    initial_state : array_like, shape (2N,), optional
        ``[Θ, Θ̇]`` before any velocity step; upright at rest by default. [rad], [rad/s]
    rates_from : {"upright", "posture"}
        Where J⁻¹H is evaluated for a velocity step (see :func:`initial_state_for`).
    knee : KneeModel, optional
        Free (default), locked, or with a hyper-extension stop. Needs N >= 2.
    fall : FallCriteria, optional
        Fall criteria; default: any |θ_i| > π/3, no foot limit (the paper's model).
    torque_limits : array_like, shape (N,), optional
        Largest net muscle moment at the ankle, knee, hip, … (the sum of the
        pairs crossing each joint); ``inf`` for no limit. A joint saturates and
        lets go at events, never inside the right-hand side. [N·m]
    feedback_delay : float
        Neural delay τ of the muscle feedback: pair torques respond to the
        state at t − τ (before t = 0, to the state before any velocity step).
        Integrated by the method of steps, in pieces no longer than τ. [s]
    rtol, atol : float
        Integrator tolerances (relative [-], absolute [rad, rad/s]).
    sample_rate : float
        Output samples per second. [Hz]
    method : str
        A scipy ``solve_ivp`` method: "DOP853" (default), "RK45", "Radau", …
    max_switches : int
        Guard against chattering: more switches than this fail the run.
    description : str
        Words stored in the result.

    Returns
    -------
    SimulationResult
        A fall is reported in ``fell``/``fall_time``/``status`` and the
        state at the fall is the last sample (off the regular grid); a failed
        integration in ``status == "failed"`` with a ``message``.
    """
    from scipy.integrate import solve_ivp

    disturbance = NoDisturbance() if disturbance is None else disturbance
    knee = KneeModel() if knee is None else knee
    fall = FallCriteria() if fall is None else fall
    if muscles.n_links != body.n_links:
        raise ParameterError(
            f"muscle set is for {muscles.n_links} links but the body has {body.n_links}"
        )
    duration = positive_float("duration [s]", duration)
    rtol = float_in_range("rtol", rtol, 1e-14, 1e-1)
    atol = float_in_range("atol", atol, 1e-16, 1e-1)
    sample_rate = float_in_range("sample_rate [Hz]", sample_rate, 1.0, 1e6, unit="Hz")
    n = body.n_links
    if knee.mode != "free" and n < 2:
        raise ParameterError("knee mode 'locked' or 'stop' needs a body with at least 2 links")

    delay = float_in_range("feedback_delay [s]", feedback_delay, 0.0, 1.0, unit="s")
    before = (np.zeros(2 * n) if initial_state is None
              else finite_array("initial_state [rad, rad/s]", initial_state, (2 * n,)))
    x = initial_state_for(body, disturbance, initial_state, rates_from)
    knee_row = None
    if knee.mode != "free":
        knee_row = np.zeros(n)
        knee_row[0], knee_row[1] = -1.0, 1.0
    limits = None
    if torque_limits is not None:
        limits = np.asarray(torque_limits, dtype=float)
        if limits.shape != (n,) or np.any(np.isnan(limits)) or np.any(limits <= 0):
            raise ParameterError(
                f"torque_limits [N·m] must be {n} numbers > 0 (inf for none), got "
                f"{np.asarray(torque_limits).tolist()}"
            )
        if np.all(np.isinf(limits)):
            limits = None
    history = _History(before) if delay > 0 else None
    model = _Model(body, muscles, disturbance, knee_row, limits, delay, history)

    locked = knee.mode == "locked"
    if knee.mode == "locked":
        x[n:] = model.project_velocity(x[:n], x[n:])
    if knee.mode == "stop":
        kappa = x[1] - x[0]
        if kappa > knee.stop_angle + 1e-12:
            raise ParameterError(
                f"initial knee angle θ2 − θ1 = {kappa:g} rad is beyond the hyper-extension "
                f"stop ({knee.stop_angle:g} rad)"
            )
        if abs(kappa - knee.stop_angle) <= 1e-12 and (x[n + 1] - x[n]) >= 0:
            locked = True
            x[n:] = model.project_velocity(x[:n], x[n:])

    E = muscles.selection_matrix
    one_sided = np.nonzero(muscles.one_sided_mask)[0]

    def active_from(state: np.ndarray) -> np.ndarray:
        act = np.ones(len(muscles.pairs))
        for p in one_sided:
            s = E[p] @ state[:n]
            sd = E[p] @ state[n:]
            act[p] = 1.0 if (s > 0 or (s == 0 and sd >= 0)) else 0.0
        return act

    active = active_from(model.feedback_state(0.0, x))
    limited = [] if limits is None else [j for j in range(n) if np.isfinite(limits[j])]
    saturation = np.zeros(n)
    if limited:
        tau0 = model.raw_moments_at(0.0, x, active)
        for j in limited:
            if abs(tau0[j]) > limits[j]:
                saturation[j] = np.sign(tau0[j])
    locked_flags: list[np.ndarray] = []
    grid = np.arange(0.0, duration + 0.5 / sample_rate, 1.0 / sample_rate)
    grid = grid[grid <= duration + 1e-12]
    stops = sorted({b for b in disturbance.breakpoints if 0.0 < b < duration} | {duration}
                   | {k * delay for k in (1, 2, 3) if 0.0 < k * delay < duration})
    max_step = min(disturbance.max_step, duration)
    if math.isfinite(disturbance.max_step) and len(disturbance.breakpoints) > 2000:
        stops = [duration]  # a long measured profile: step capped at its sample spacing instead

    times: list[np.ndarray] = []
    states: list[np.ndarray] = []
    t = 0.0
    status, message = "completed", f"ran to {duration:g} s"
    fell, fall_time, fall_reason = False, None, None
    switch_times: list[float] = []
    lim = fall.max_link_angle
    bos = fall.base_of_support
    a_coef = body.gravity_coefficients
    mtot = body.total_mass

    initial_fall = _outside_at_start(model, fall, x, active, locked,
                                     saturation.copy() if limited else None)
    if initial_fall is not None:
        times.append(np.array([0.0]))
        states.append(x[None, :])
        locked_flags.append(np.array([locked]))
        fell, fall_time, fall_reason = True, 0.0, initial_fall
        status, message = "fell", f"fell at t = 0 s: {initial_fall}"
        t = duration  # nothing to integrate

    while t < duration:
        t_end = next(s for s in stops if s > t + 1e-12) if any(s > t + 1e-12 for s in stops) \
            else duration
        if delay > 0:
            t_end = min(t_end, t + delay)  # the method of steps: the past is already known

        sat = saturation.copy() if limited else None

        def rhs(tt, xx, _active=active, _locked=locked, _sat=sat):
            return np.concatenate([xx[n:], model.acceleration(tt, xx, _active, _locked, _sat)])

        events, kinds = [], []
        for i in range(n):
            def ev(tt, xx, _i=i):
                return lim - abs(xx[_i])
            ev.terminal, ev.direction = True, -1
            events.append(ev)
            kinds.append(("fall", f"link {i + 1} angle passed ±{lim:.3g} rad"))
        if bos is not None:
            def ev_toe(tt, xx):
                return bos.toe - (a_coef @ np.sin(xx[:n])) / mtot
            def ev_heel(tt, xx):
                return (a_coef @ np.sin(xx[:n])) / mtot - bos.heel
            for ev, what in ((ev_toe, f"toe ({bos.toe:.3f} m)"),
                             (ev_heel, f"heel ({bos.heel:.3f} m)")):
                ev.terminal, ev.direction = True, -1
                events.append(ev)
                kinds.append(("fall", f"centre of gravity passed the {what}"))
            if fall.centre_of_pressure:
                def ev_cop_toe(tt, xx, _a=active, _l=locked, _s=sat):
                    return bos.toe - model.centre_of_pressure(tt, xx, _a, _l, _s)
                def ev_cop_heel(tt, xx, _a=active, _l=locked, _s=sat):
                    return model.centre_of_pressure(tt, xx, _a, _l, _s) - bos.heel
                for ev, what in ((ev_cop_toe, f"toe ({bos.toe:.3f} m)"),
                                 (ev_cop_heel, f"heel ({bos.heel:.3f} m)")):
                    ev.terminal, ev.direction = True, -1
                    events.append(ev)
                    kinds.append(("fall", f"centre of pressure passed the {what}: the foot tips"))
        for j in limited:
            # a free joint saturates when |τ| reaches its limit; a saturated one lets go when
            # the unsaturated moment comes back inside (hysteresis as for the one-sided pairs)
            if saturation[j] == 0:
                for side in (1.0, -1.0):
                    def ev_sat(tt, xx, _j=j, _side=side, _a=active):
                        tau = model.raw_moments_at(tt, xx, _a)[_j]
                        return _side * tau - limits[_j] - _SWITCH_HYSTERESIS
                    ev_sat.terminal, ev_sat.direction = True, 1
                    events.append(ev_sat)
                    kinds.append(("saturate", (j, side)))
            else:
                def ev_unsat(tt, xx, _j=j, _side=saturation[j], _a=active):
                    tau = model.raw_moments_at(tt, xx, _a)[_j]
                    return _side * tau - limits[_j] + _SWITCH_HYSTERESIS
                ev_unsat.terminal, ev_unsat.direction = True, -1
                events.append(ev_unsat)
                kinds.append(("saturate", (j, 0.0)))
        for p in one_sided:
            # An acting pair waits for its stretch to fall below 0, a slack one to rise above.
            # The tiny hysteresis keeps a pair resting at zero stretch from re-firing.
            sign = 1.0 if active[p] else -1.0
            def ev_p(tt, xx, _p=p, _s=sign):
                return E[_p] @ model.feedback_state(tt, xx)[:n] + _s * _SWITCH_HYSTERESIS
            ev_p.terminal, ev_p.direction = True, (-1 if active[p] else 1)
            events.append(ev_p)
            kinds.append(("pair", int(p)))
        if knee.mode == "stop":
            if not locked:
                def ev_knee(tt, xx):
                    return (xx[1] - xx[0]) - knee.stop_angle - _SWITCH_HYSTERESIS
                ev_knee.terminal, ev_knee.direction = True, 1
                events.append(ev_knee)
                kinds.append(("knee-hit", None))
            else:
                def ev_release(tt, xx, _active=active, _sat=sat):
                    _, acc = model.free_acceleration(tt, xx, _active, _sat)
                    return acc[1] - acc[0] + _RELEASE_HYSTERESIS
                ev_release.terminal, ev_release.direction = True, -1
                events.append(ev_release)
                kinds.append(("knee-release", None))

        try:
            sol = solve_ivp(rhs, (t, t_end), x, method=method, rtol=rtol, atol=atol,
                            dense_output=True, events=events, max_step=max_step)
        except (ValueError, np.linalg.LinAlgError, FloatingPointError) as exc:
            status, message = "failed", f"integrator error at t = {t:.6g} s: {exc}"
            break
        seg_end = float(sol.t[-1])
        if history is not None:
            history.add(t, seg_end, sol.sol)
        last_segment = sol.status == 0 and t_end >= duration
        sel = (grid >= t - 1e-12) & ((grid <= seg_end + 1e-12) if last_segment or sol.status == 1
                                      else (grid < seg_end - 1e-12))
        if sel.any():
            times.append(grid[sel])
            states.append(sol.sol(grid[sel]).T)
            locked_flags.append(np.full(int(sel.sum()), locked))
            grid = grid[~sel | (grid > seg_end + 1e-12)]
            grid = grid[grid > seg_end - 1e-12] if sol.status == 1 else grid
        if sol.status == -1:
            status, message = "failed", f"integrator failed at t = {seg_end:.6g} s: {sol.message}"
            break
        x = sol.y[:, -1].copy()
        if not np.all(np.isfinite(x)):
            status, message = "failed", f"state diverged (non-finite) at t = {seg_end:.6g} s"
            break
        if sol.status == 1:
            fired = [k for k, te in enumerate(sol.t_events) if len(te) and
                     abs(te[-1] - seg_end) <= 1e-12 * max(1.0, seg_end)]
            if not fired:
                fired = [k for k, te in enumerate(sol.t_events) if len(te)]
            kind, info = kinds[fired[0]]
            x = sol.y_events[fired[0]][-1].copy()
            t = seg_end
            if kind == "fall":
                # the state at the fall itself closes the series (it is off the sample grid)
                if not times or times[-1][-1] < seg_end - 1e-12:
                    times.append(np.array([seg_end]))
                    states.append(x[None, :])
                    locked_flags.append(np.array([locked]))
                fell, fall_time, fall_reason = True, seg_end, info
                status = "fell"
                message = f"fell at t = {seg_end:.4f} s: {info}"
                break
            switch_times.append(seg_end)
            if len(switch_times) > max_switches:
                status = "failed"
                message = f"more than {max_switches} switches by t = {seg_end:.6g} s (chattering)"
                break
            if kind == "pair":
                # the pair engages if its stretch is now growing, goes slack otherwise
                sd = E[info] @ model.feedback_state(seg_end, x)[n:]
                active = active.copy()
                active[info] = 1.0 if sd >= 0 else 0.0
            elif kind == "knee-hit":
                x[1] = x[0] + knee.stop_angle
                x[n:] = model.project_velocity(x[:n], x[n:])
                locked = True
            elif kind == "knee-release":
                locked = False
            elif kind == "saturate":
                joint, side = info
                saturation = saturation.copy()
                saturation[joint] = side
            continue
        t = t_end

    feedback = None
    if history is not None and times:
        feedback = np.array([history(tk - delay) for tk in np.concatenate(times)])
    return _assemble(body, muscles, disturbance, times, states, status, message, fell,
                     fall_time, fall_reason, switch_times, description,
                     locked=np.concatenate(locked_flags) if locked_flags else None,
                     knee_row=knee_row, torque_limits=limits, feedback_states=feedback)


def _outside_at_start(model, fall, x, active, locked, saturation) -> str | None:
    """A fall criterion already violated at t = 0 (events only see crossings)."""
    n = model.body.n_links
    over = np.nonzero(np.abs(x[:n]) > fall.max_link_angle)[0]
    if over.size:
        return f"link {over[0] + 1} angle beyond ±{fall.max_link_angle:.3g} rad at the start"
    bos = fall.base_of_support
    if bos is None:
        return None
    xc = model.body.gravity_coefficients @ np.sin(x[:n]) / model.body.total_mass
    if not bos.heel <= xc <= bos.toe:
        return f"centre of gravity ({xc:.3f} m) outside the foot at the start"
    if fall.centre_of_pressure:
        xp = model.centre_of_pressure(0.0, x, active, locked, saturation)
        if not bos.heel <= xp <= bos.toe:
            return (f"centre of pressure ({xp:.3f} m) outside the foot at the start: "
                    "the foot tips")
    return None


def _assemble(body, muscles, disturbance, times, states, status, message, fell, fall_time,
              fall_reason, switch_times, description, *, locked=None, knee_row=None,
              torque_limits=None, feedback_states=None) -> SimulationResult:
    """Derived series of a run: torques, accelerations, ground reaction, CoG, platform.

    ``locked`` (T,) marks samples where the knee constraint held (its row
    ``knee_row``); ``torque_limits`` (N,) saturates the joint moments [N·m];
    ``feedback_states`` (T, 2N) is what the muscles responded to (delayed feedback).
    """
    n = body.n_links
    if times:
        time = np.concatenate(times)
        state = np.concatenate(states, axis=0)
    else:  # pragma: no cover - the first sample is always produced
        time = np.zeros(0)
        state = np.zeros((0, 2 * n))
    theta, omega = state[:, :n], state[:, n:]
    from ..model.muscles import pair_torques as _pair_torques

    fb = state if feedback_states is None else np.asarray(feedback_states)
    M = _pair_torques(muscles, fb[:, :n], fb[:, n:])
    moments = M @ joint_crossing_matrix(muscles)
    if torque_limits is not None:
        moments = np.clip(moments, -torque_limits, torque_limits)
        U = moments_to_link_torques(moments)
    else:
        U = -M @ muscles.selection_matrix
    acc = disturbance.acceleration(time)
    rhs = (U - velocity_terms(body, theta, omega)
           + (body.gravity + acc[:, 1:2]) * gravity_vector(body, theta)
           - acc[:, 0:1] * platform_vector(body, theta))
    J = mass_matrix(body, theta)
    alpha = np.linalg.solve(J, rhs[..., None])[..., 0] if time.size else np.zeros((0, n))
    if locked is not None and knee_row is not None and np.any(locked):
        JiC = np.linalg.solve(J[locked], np.broadcast_to(knee_row, (int(locked.sum()), n))[
            ..., None])[..., 0]
        alpha[locked] -= JiC * ((alpha[locked] @ knee_row) / (JiC @ knee_row))[:, None]
    a_coef = body.gravity_coefficients
    s, c = np.sin(theta), np.cos(theta)
    cog_acc_x = (np.sum(alpha * a_coef * c, axis=1)
                 - np.sum(a_coef * s * omega**2, axis=1)) / body.total_mass
    cog_acc_y = (-np.sum(alpha * a_coef * s, axis=1)
                 - np.sum(a_coef * c * omega**2, axis=1)) / body.total_mass
    ground = body.total_mass * np.column_stack(
        [acc[:, 0] + cog_acc_x, body.gravity + acc[:, 1] + cog_acc_y])
    with np.errstate(divide="ignore", invalid="ignore"):
        cop = np.where(ground[:, 1] > 0, moments[:, 0] / ground[:, 1], np.nan)
    vel = np.zeros_like(acc)
    pos = np.zeros_like(acc)
    if time.size > 1:
        dt = np.diff(time)[:, None]
        vel[1:] = np.cumsum(0.5 * (acc[1:] + acc[:-1]) * dt, axis=0)
        vel += np.array(disturbance.velocity_change)
        pos[1:] = np.cumsum(0.5 * (vel[1:] + vel[:-1]) * dt, axis=0)
    elif time.size == 1:
        vel[:] = disturbance.velocity_change
    for arr in (time, theta, omega, alpha):
        arr.setflags(write=False)
    derived = DerivedSeries(
        pair_torques=M, joint_torques=U, joint_moments=moments,
        cog_position=centre_of_gravity(body, theta),
        cog_velocity=centre_of_gravity_velocity(body, theta, omega),
        platform_acceleration=acc, platform_velocity=vel, platform_position=pos,
        angular_acceleration=alpha, ground_reaction=ground, centre_of_pressure=cop,
    )
    return SimulationResult(
        time=time, theta=theta, omega=omega,
        pair_names=tuple(muscles.names), status=status, message=message, fell=fell,
        fall_time=fall_time, fall_reason=fall_reason, switch_times=tuple(switch_times),
        description=description or disturbance.describe(), derived=derived,
    )
