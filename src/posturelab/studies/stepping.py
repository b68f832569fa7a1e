"""When is a step needed? The largest platform translation withstood with the feet in place.

**Criterion** (Hof, Gazendam & Sinke 2005, J Biomech 38:1–8; :mod:`posturelab.model.stepping`).
A run *needs a step* when, at any sample, no centre of pressure on the foot could stop the
centre of mass any more, or when the run falls (a link past 60°, the centre of gravity off the
foot). For the linear inverted pendulum that is the extrapolated centre of mass
ξ = x + v/ω0 (x, v relative to the ankle, ω0 = √(g/l), l the centre of mass's height)
leaving the foot, once the platform's path still to come is counted: ξ + Δ with
Δ(t) = ṗ(t)/ω0 − ∫_t^∞ e^{−ω0 (s − t)} ṗ(s) ds
(:func:`~posturelab.model.stepping.platform_path_offset`, over the platform's whole planned
move, also after a run that falls has stopped; Δ = 0 for a platform at rest or at a constant
velocity, where this is Hof's condition). The subjects compared with were asked not
to step, so what is measured is whether they could stand the whole move, its deceleration
included (``criterion="platform-path"``, the default); ``"platform-velocity"`` judges ξ in the
frame that keeps the platform's current velocity, as if the move never ended (stricter during
the move).

**The foot** is, by default, the population's *functional* base of support (King, Judge &
Wolfson 1994): the share of the foot's length over which the centre of pressure can be held,
measured from the quiet-standing centre of pressure, which the upright model stands on (the
quiet stance's lean is a shift of the operating point: its tonic ankle moment m g l sin(lean)
is not available to the response). Its ends bound the ankle moment each way, m g × toe and
m g × heel (a flat foot cannot press its centre of pressure beyond them; a heel rise or a toe
lift is not modelled), and the XCoM; the body falls (the foot tips) only when its centre of
gravity leaves the whole foot. ``foot="anatomical"`` takes the whole foot from the ankle
(0.152 × height, :func:`posturelab.simulation.base_of_support_for_height`) with the centre of
mass over the ankle. Plantarflexion is also bounded by the strength left after the tonic
moment (:func:`~posturelab.model.stepping.ankle_moment_cap`); the dorsiflexors' own strength is
taken not to bind. ``heel_limit=False`` caps dorsiflexion at the plantarflexion cap instead
(the symmetric cap of posturelab before issue 22), which lets the centre of pressure pass the
heel.

**The feedback delay** enters through the dynamics: for τ after the platform starts only the
intrinsic (undelayed) ankle impedance resists; the neural (active) gains act on the state τ
earlier (:func:`posturelab.simulate`'s ``feedback_delay``). The XCoM is judged along that
delayed trajectory, so what it reaches during the delay counts; the result reports ξ at the
response onset t = τ.

**The body** is a one-link inverted pendulum about the ankle, scaled from height and mass by
Winter's table (:func:`posturelab.model.anthropometry.one_link`). **The threshold** is found as
an experimenter would, by an ascending series (1 cm steps) to the first translation that needs
a step, then bisected to 1 mm against the last one withstood, on the compiled engine.
The protocol and the published figures compared with are in :data:`PROTOCOL` and
:data:`PUBLISHED`; the populations, each number with its source, in
:mod:`posturelab.studies._stepping_presets`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from .._validation import positive_float
from ..errors import ParameterError, PostureLabError, UnknownNameError
from ..parameters import check_value
from ._stepping_presets import (
    POPULATIONS,
    PROTOCOL,
    PUBLISHED,
    PlatformProtocol,
    Population,
    PublishedThreshold,
    get_population,
)

__all__ = ["StepThreshold", "RunVerdict", "step_threshold", "step_verdict", "DIRECTIONS",
           "POPULATIONS", "PROTOCOL", "PUBLISHED", "Population", "PlatformProtocol",
           "PublishedThreshold", "get_population"]

#: Platform directions: "backward" moves the feet back (the body sways forward, toward the
#: toes); "forward" moves them forward (the body sways back, toward the heel).
DIRECTIONS = ("backward", "forward")
#: Foot models of :func:`step_threshold`.
FOOT_MODELS = ("functional", "anatomical")
#: Step criteria of :func:`step_threshold`.
CRITERIA = ("platform-path", "platform-velocity")
#: Output samples per second of each run (the XCoM is judged at these samples). [Hz]
SAMPLE_RATE = 500.0
#: How far the centre of pressure may pass an end of the foot before ``cop_criterion`` counts
#: a step (the cap m g × toe is static; the vertical force varies a little). [m]
COP_TOLERANCE = 0.001


@dataclass(frozen=True)
class RunVerdict:
    """Whether one run needs a step, and why.

    Attributes
    ----------
    needs_step : bool
        True when the XCoM left the foot or the run fell.
    reason : str
        What happened first, in words ("" when no step is needed).
    time : float or None
        When: the first sample with the XCoM off the foot, or the fall. [s]
    minimum_margin : float
        Smallest margin of stability min(toe − ξ, ξ − heel) over the run (negative: off the
        foot). [m]
    """

    needs_step: bool
    reason: str
    time: float | None
    minimum_margin: float


def step_verdict(time, xcom_position, heel: float, toe: float, fell: bool = False,
                 fall_reason: str | None = None, fall_time: float | None = None) -> RunVerdict:
    """Judge one run: the XCoM off the foot at any sample, or a fall, needs a step.

    Parameters
    ----------
    time : array_like, shape (T,)
        Sample times. [s]
    xcom_position : array_like, shape (T,)
        ξ relative to the ankle (:func:`posturelab.model.stepping.xcom`). [m]
    heel, toe : float
        The foot from the ankle. [m]
    fell, fall_reason, fall_time
        The run's fall, if any (its reason in words, its time [s]).

    Examples
    --------
    >>> from posturelab.studies.stepping import step_verdict
    >>> v = step_verdict([0.0, 0.1, 0.2], [0.0, 0.12, 0.21], heel=-0.06, toe=0.2)
    >>> v.needs_step, round(v.minimum_margin, 3), v.time  # [-], [m], [s]
    (True, -0.01, 0.2)
    """
    from ..model.stepping import margin_of_stability

    t = np.asarray(time, dtype=float)
    margin = margin_of_stability(xcom_position, heel, toe)
    minimum = float(np.min(margin)) if margin.size else math.inf
    off = np.flatnonzero(margin < 0.0)
    if off.size and (not fell or fall_time is None or t[off[0]] <= fall_time):
        i = int(off[0])
        xi = float(np.asarray(xcom_position, dtype=float)[i])
        side = f"in front of the toe ({toe:.3f} m)" if xi > toe else \
            f"behind the heel ({heel:.3f} m)"
        return RunVerdict(True, f"the XCoM reached {xi:.3f} m, {-margin[i] * 1000:.1f} mm "
                          f"{side} at t = {t[i]:.3f} s",
                          float(t[i]), minimum)
    if fell:
        return RunVerdict(True, f"fell: {fall_reason}", fall_time, minimum)
    return RunVerdict(False, "", None, minimum)


@dataclass(frozen=True)
class StepThreshold:
    """The largest platform translation withstood without a step, and how it was found.

    Attributes
    ----------
    largest_translation : float
        Largest displacement of the platform after which no step was needed. [m]
    smallest_stepping : float
        Smallest displacement tried that needed one (inf if none up to the protocol's
        largest). [m]
    reason : str
        Why the run at ``smallest_stepping`` needed a step.
    population, direction : str
    height, mass : float
        The subject. [m], [kg]
    move_duration : float
        Time of each platform move (ramp-and-hold). [s]
    peak_velocity, peak_acceleration : float
        Of the platform move at ``largest_translation``: 2D/T, 2πD/T². [m/s], [m/s²]
    feedback_delay : float
        τ. [s]
    ankle_strength : float
        Plantarflexion strength of both ankles. [N·m]
    ankle_moment_cap : float
        The plantarflexion cap used, min(strength − stance_moment, m g × toe). [N·m]
    dorsiflexion_cap : float
        The dorsiflexion cap used (its magnitude): m g × |heel|, or ``ankle_moment_cap``
        with ``heel_limit=False``. [N·m]
    heel, toe : float
        The foot's ends used (from the quiet-standing centre of pressure for the functional
        foot, from the ankle for the anatomical one). [m]
    foot, criterion : str
        The foot model and the step criterion (see :func:`step_threshold`).
    stance_moment : float
        The tonic plantarflexion moment of the quiet stance, not available to the response
        (0 for the anatomical foot). [N·m]
    com_height : float
        l, the centre of mass above the ankle. [m]
    omega0 : float
        √(g/l). [1/s]
    minimum_margin : float
        Smallest margin of stability in the run at ``largest_translation``. [m]
    xcom_at_response_onset : float
        ξ at t = τ (when the neural response starts) in that run, from the ankle. [m]
    cop_overrun : float
        How far the centre of pressure went beyond the foot (either end) in that run, 0 if
        it stayed on it: with the foot's caps only by the vertical force's departure from
        m g (millimetres); with ``heel_limit=False`` the dorsiflexors may pull it behind the
        heel, where a real foot's toes would lift. [m]
    n_simulations : int
        Runs made. [-]
    published_mean, published_sd : float or None
        The published threshold for this population and direction, if any. [m]
    published_source : str
        Its citation ("" if none).
    largest_searched : float
        The search's ceiling when no run needed a step (``reached_search_limit``), else inf.
        [m]
    """

    largest_translation: float
    smallest_stepping: float
    reason: str
    population: str
    direction: str
    height: float
    mass: float
    move_duration: float
    peak_velocity: float
    peak_acceleration: float
    feedback_delay: float
    ankle_strength: float
    ankle_moment_cap: float
    dorsiflexion_cap: float
    heel: float
    toe: float
    foot: str
    criterion: str
    stance_moment: float
    com_height: float
    omega0: float
    minimum_margin: float
    xcom_at_response_onset: float
    cop_overrun: float
    n_simulations: int
    published_mean: float | None
    published_sd: float | None
    published_source: str
    largest_searched: float = math.inf

    @property
    def reached_search_limit(self) -> bool:
        """True when no run up to ``largest_searched`` needed a step: ``largest_translation``
        is then the search's ceiling, not a threshold."""
        return math.isinf(self.smallest_stepping)

    @property
    def within_two_sd(self) -> bool | None:
        """True when ``largest_translation`` is within two published standard deviations of
        the published mean (None without a published figure, or when the search reached its
        ceiling without a step: no threshold to compare)."""
        if (self.published_mean is None or self.published_sd is None
                or self.reached_search_limit):
            return None
        return abs(self.largest_translation - self.published_mean) <= 2 * self.published_sd

    def to_dict(self) -> dict:
        """The fields (SI units, as documented), ``reached_search_limit`` and
        ``within_two_sd``; inf as None; ``largest_translation`` None when the search reached
        its ceiling (``largest_searched``) without a step."""
        out = {k: (None if isinstance(v, float) and math.isinf(v) else v)
               for k, v in asdict(self).items()}
        out["reached_search_limit"] = self.reached_search_limit
        if self.reached_search_limit:
            out["largest_translation"] = None
        out["within_two_sd"] = self.within_two_sd
        return out


#: Units of the fields of :class:`StepThreshold` (for printing).
UNITS = {"largest_translation": "m", "smallest_stepping": "m", "height": "m", "mass": "kg",
         "move_duration": "s", "peak_velocity": "m/s", "peak_acceleration": "m/s²",
         "feedback_delay": "s", "ankle_strength": "N·m", "ankle_moment_cap": "N·m",
         "dorsiflexion_cap": "N·m",
         "heel": "m", "toe": "m", "stance_moment": "N·m", "com_height": "m", "omega0": "1/s",
         "minimum_margin": "m",
         "xcom_at_response_onset": "m", "cop_overrun": "m", "published_mean": "m",
         "published_sd": "m", "largest_searched": "m"}


def step_threshold(height: float, mass: float, population: str | Population = "young",
                   direction: str = "backward", *, protocol: PlatformProtocol = PROTOCOL,
                   feedback_delay: float | None = None, ankle_strength: float | None = None,
                   cop_criterion: bool = False, heel_limit: bool = True,
                   foot: str = "functional", criterion: str = "platform-path",
                   engine: str = "compiled") -> StepThreshold:
    """The largest platform translation a subject withstands without stepping.

    Parameters
    ----------
    height, mass : float
        The subject. [m] (0.5–2.5), [kg] (10–300)
    population : str or Population
        ``"young"`` or ``"older"`` (:data:`POPULATIONS`), or a :class:`Population`.
    direction : {"backward", "forward"}
        Which way the platform moves.
    protocol : PlatformProtocol
        The platform moves and the search (:data:`PROTOCOL`).
    feedback_delay : float, optional
        τ in place of the population's. [s]
    ankle_strength : float, optional
        Plantarflexion strength of both ankles in place of the population's. [N·m]
    cop_criterion : bool
        Also count a step when the centre of pressure leaves the foot by more than
        :data:`COP_TOLERANCE` (the heel would rise or the toes lift): stricter than Hof's
        criterion, and a check on the moment caps (see ``cop_overrun``).
    heel_limit : bool
        Cap dorsiflexion at m g × |heel| (default), or, False, at the plantarflexion cap
        (the same both ways, as before issue 22). [-]
    foot : {"functional", "anatomical"}
        ``"functional"`` (default): the population's functional base of support (King et
        al. 1994), measured from the quiet-standing centre of pressure, which the upright
        model stands on; its ends bound the ankle moment and the XCoM, and the tonic moment
        of the population's stance lean is not available to the response. ``"anatomical"``:
        the whole foot from the ankle (0.152 × height, the ankle at a quarter of it), the
        upright body's centre of mass over the ankle.
    criterion : {"platform-path", "platform-velocity"}
        ``"platform-path"`` (default): a step is needed when no centre of pressure on the
        foot can stop the centre of mass given how the platform goes on to move (ξ + Δ off
        the foot, :func:`posturelab.model.stepping.platform_path_offset`): the subject
        tries not to step, as in the study compared with. ``"platform-velocity"``: ξ judged
        in the frame moving with the platform's current velocity, as if it would never stop
        (stricter during the move).
    engine : {"compiled", "reference"}
        The simulator.

    Returns
    -------
    StepThreshold

    Raises
    ------
    ParameterError
        A bad height, mass, direction, delay or strength (naming the field and its range).
    UnknownNameError
        An unknown population (listing the known ones).
    """
    from ..model.anthropometry import body_from_anthropometry, one_link
    from ..model.limits import foot_moment_limits
    from ..model.options import BaseOfSupport, FallCriteria, base_of_support_for_height
    from ..model.stepping import (
        ankle_moment_cap,
        pendulum_frequency,
        platform_path_offset,
        xcom,
    )
    from ..simulation.engines import simulate

    for flag, value in (("cop_criterion", cop_criterion), ("heel_limit", heel_limit)):
        if not isinstance(value, bool | np.bool_):
            raise ParameterError(f"{flag} must be True or False, got {value!r:.40}")
    h = check_value("height", height)
    m = check_value("mass", mass)
    if direction not in DIRECTIONS:
        raise UnknownNameError(f"unknown direction {direction!r}; known: "
                               f"{', '.join(DIRECTIONS)}")
    pop = population if isinstance(population, Population) else get_population(population)
    delay = pop.feedback_delay if feedback_delay is None else check_value(
        "feedback_delay", feedback_delay)
    strength = pop.ankle_strength if ankle_strength is None else positive_float(
        "ankle_strength [N·m]", ankle_strength)
    if foot not in FOOT_MODELS:
        raise UnknownNameError(f"unknown foot {foot!r}; known: {', '.join(FOOT_MODELS)}")
    if criterion not in CRITERIA:
        raise UnknownNameError(f"unknown criterion {criterion!r}; known: "
                               f"{', '.join(CRITERIA)}")
    body = one_link(body_from_anthropometry(h, m))
    weight = body.total_mass * body.gravity
    com_height = float(body.gravity_coefficients.sum() / body.total_mass)
    omega0 = float(pendulum_frequency(com_height, body.gravity))
    whole = base_of_support_for_height(h)
    if foot == "functional":
        foot_bos = BaseOfSupport(*pop.functional_foot(h), source=(
            f"the functional base of support of the {pop.name} (King et al. 1994) from the "
            "quiet-standing centre of pressure"))
        tonic = weight * com_height * math.sin(pop.stance_lean)
        # the body falls (the foot tips) when its centre of gravity leaves the whole foot,
        # seen from the quiet-standing centre of pressure the model stands on
        lean = com_height * math.sin(pop.stance_lean)
        tipping = BaseOfSupport(whole.heel - lean, whole.toe - lean, source=whole.source)
    else:
        foot_bos, tonic, tipping = whole, 0.0, whole
    if strength <= tonic:
        whose = ("ankle_strength" if ankle_strength is not None
                 else f"the {pop.name} population's ankle strength")
        raise ParameterError(f"{whose}, {strength:g} N·m, must exceed the {tonic:.0f} N·m this "
                             f"subject's quiet stance already uses (m g l sin "
                             f"{math.degrees(pop.stance_lean):.2f}°); give a larger "
                             "--ankle-strength")
    cap = ankle_moment_cap(strength - tonic, weight, foot_bos.toe)
    heel_cap = (foot_moment_limits(weight, foot_bos.heel, foot_bos.toe)[0] if heel_limit
                else -cap)
    muscles = pop.muscles(body)
    _check_upright_stable(body, muscles, delay)
    sign = -1.0 if direction == "backward" else 1.0
    count = 0
    duration = protocol.move_duration + protocol.settle_time
    # Δ from the platform's whole planned path (a run that falls stops early; its last
    # velocity is not how the platform goes on)
    plan_time = np.arange(int(round(duration * SAMPLE_RATE)) + 1) / SAMPLE_RATE

    def path_offset(size: float, time):
        from scipy.integrate import cumulative_trapezoid

        move = protocol.disturbance(sign * size)
        velocity = cumulative_trapezoid(move.acceleration(plan_time)[:, 0], plan_time,
                                        initial=0.0)
        return np.interp(time, plan_time, platform_path_offset(plan_time, velocity, omega0))

    def trial(size: float):
        nonlocal count
        count += 1
        run = simulate(body, muscles, protocol.disturbance(sign * size), duration=duration,
                          feedback_delay=delay, proprioceptive_weight=pop.proprioceptive_weight,
                          torque_limits=((heel_cap, cap),),
                          fall=FallCriteria(base_of_support=tipping),
                          sample_rate=SAMPLE_RATE, engine=engine)
        if run.status == "failed":
            raise PostureLabError(f"the run at a {size:g} m translation failed: {run.message}")
        xi = xcom(run.cog_position[:, 0], run.cog_velocity[:, 0], omega0)
        if criterion == "platform-path":
            xi = xi + path_offset(size, run.time)
        verdict = step_verdict(run.time, xi, foot_bos.heel, foot_bos.toe, run.fell,
                               run.fall_reason, run.fall_time)
        if cop_criterion and not verdict.needs_step:
            cop = run.centre_of_pressure
            off = np.flatnonzero((cop > foot_bos.toe + COP_TOLERANCE)
                                 | (cop < foot_bos.heel - COP_TOLERANCE))
            if off.size:
                i = int(off[0])
                verdict = RunVerdict(True, f"the centre of pressure reached {cop[i]:.3f} m, off "
                                     f"the foot, at t = {run.time[i]:.3f} s",
                                     float(run.time[i]), verdict.minimum_margin)
        return run, xi, verdict

    low, high, reason = 0.0, math.inf, ""
    size = protocol.increment
    while size <= protocol.largest + 1e-12:  # the ascending series
        verdict = trial(size)[2]
        if verdict.needs_step:
            high, reason = size, verdict.reason
            break
        low, size = size, size + protocol.increment
    while high - low > protocol.tolerance and math.isfinite(high):  # bisection
        mid = 0.5 * (low + high)
        verdict = trial(mid)[2]
        if verdict.needs_step:
            high, reason = mid, verdict.reason
        else:
            low = mid
    if low > 0.0:
        run, xi, verdict = trial(low)
        onset = float(np.interp(delay, run.time, xi))
        margin = verdict.minimum_margin
        cop = run.centre_of_pressure
        overrun = float(max(0.0, np.nanmax(cop) - foot_bos.toe,
                            foot_bos.heel - np.nanmin(cop)))
    else:
        onset, margin, overrun = 0.0, min(foot_bos.toe, -foot_bos.heel), 0.0
    published = PUBLISHED.get((pop.name, direction))
    duration = protocol.move_duration
    return StepThreshold(
        largest_translation=low, smallest_stepping=high, reason=reason,
        population=pop.name, direction=direction, height=h, mass=m,
        move_duration=duration, peak_velocity=2 * low / duration,
        peak_acceleration=2 * math.pi * low / duration**2, feedback_delay=delay,
        ankle_strength=strength, ankle_moment_cap=cap, dorsiflexion_cap=-heel_cap,
        heel=foot_bos.heel, toe=foot_bos.toe, foot=foot, criterion=criterion,
        stance_moment=tonic,
        com_height=com_height, omega0=omega0, minimum_margin=margin,
        xcom_at_response_onset=onset, cop_overrun=overrun, n_simulations=count,
        published_mean=None if published is None else published.mean,
        published_sd=None if published is None else published.sd,
        published_source="" if published is None else published.source,
        largest_searched=low if math.isinf(high) else math.inf,
    )


def _check_upright_stable(body, muscles, delay: float) -> None:
    """Refuse (ParameterError) a subject whose upright loop is unstable at ``delay`` [s]: it
    topples with no platform move, so no translation threshold exists."""
    from ..linear.delay import delay_margin
    from ..linear.verdict import upright_verdict

    if upright_verdict(body, muscles, delay).stable:
        return
    dm = delay_margin(body, muscles)
    margin = ("unstable without delay" if dm.delay_margin is None
              else f"delay margin {dm.delay_margin:.3g} s")
    raise ParameterError(f"upright is unstable at feedback_delay {delay:g} s ({margin}): it "
                         "topples without a platform move, so there is no threshold; give a "
                         "smaller --feedback-delay")

