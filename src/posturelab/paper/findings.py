"""The findings beyond the paper, as data: each finding holds its numbers and says
itself in words (``text``), as the reproduction report prints it.

The findings are computed in :mod:`posturelab.paper.checks`; this module only holds them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.controllers import ControllerPreset
from ..model.options import BaseOfSupport
from ..simulation.results import SimulationResult

__all__ = ["Outcome", "FootExcursion", "OneSidedFinding", "FOOT_RUN_LABELS", "FootFinding",
           "RecoveryFinding", "DelayFinding", "LiteratureControllerFinding", "StrategyFinding",
           "HUMAN_RECOVERY_CITATION", "HUMAN_RECOVERY_YOUNG", "HUMAN_RECOVERY_OLDER",
           "HUMAN_RECOVERY_PROTOCOL",
           "FRFFinding"]

#: Largest backward platform displacement recovered without stepping (PMC6338353): young
#: adults (20–30 years, n = 5) and community-dwelling older adults (70–80, n = 6), mean and
#: standard deviation. [m]
HUMAN_RECOVERY_YOUNG = (0.162, 0.026)
HUMAN_RECOVERY_OLDER = (0.118, 0.021)
HUMAN_RECOVERY_CITATION = (
    "Maximal backward support-surface displacement recovered without stepping: 16.2 ± 2.6 cm "
    "(young, 20–30 years) and 11.8 ± 2.1 cm (older, 70–80 years); PMC6338353"
)
#: What posturelab knows of that study's platform motion: its displacement, velocity and
#: acceleration profile were not found (posturelab's search tool reached neither the paper's
#: text nor a summary of its protocol), so no model run can use the same profile, and the
#: comparison below is stated as not like for like.
HUMAN_RECOVERY_PROTOCOL: str | None = None


@dataclass(frozen=True)
class Outcome:
    """How a run ended.

    Attributes
    ----------
    fell : bool
        Whether it fell.
    fall_time : float or None
        Time of the fall. [s]
    fall_reason : str or None
        Why it fell.
    duration : float
        Last time simulated. [s]
    """

    fell: bool
    fall_time: float | None
    fall_reason: str | None
    duration: float

    @classmethod
    def of(cls, r: SimulationResult) -> Outcome:
        """The outcome of ``r``."""
        return cls(bool(r.fell), r.fall_time, r.fall_reason, float(r.time[-1]))

    @property
    def text(self) -> str:
        """"falls at t = … s" or "does not fall within … s"."""
        if self.fell:
            return f"falls at t = {self.fall_time:.3f} s"
        return f"does not fall within {self.duration:.1f} s"

    @property
    def stops_text(self) -> str:
        """"stops at t = … s (reason)" or "does not stop"."""
        if self.fell:
            return f"stops at t = {self.fall_time:.2f} s ({self.fall_reason})"
        return "does not stop"


@dataclass(frozen=True)
class FootExcursion:
    """How far the centre of gravity travels over (and off) a foot.

    Attributes
    ----------
    min, max : float
        Extremes of x_c, forward positive, from the ankle. [m]
    t_out : float or None
        First time x_c is past the heel or the toe. [s]
    time_out : float
        Total time past the heel or the toe. [s]
    side : str or None
        "toe" or "heel": where it leaves the foot first.
    """

    min: float
    max: float
    t_out: float | None
    time_out: float
    side: str | None

    @classmethod
    def of(cls, result: SimulationResult, foot: BaseOfSupport) -> FootExcursion:
        """The excursion of ``result`` over ``foot``."""
        x = result.cog_position[:, 0]
        beyond_toe = x > foot.toe
        behind_heel = x < foot.heel
        outside = beyond_toe | behind_heel
        dt = float(np.mean(np.diff(result.time))) if result.time.size > 1 else 0.0
        hits = np.nonzero(outside)[0]
        side = ("toe" if beyond_toe.any() and (not behind_heel.any() or
                                               np.argmax(beyond_toe) < np.argmax(behind_heel))
                else ("heel" if behind_heel.any() else None))
        return cls(float(x.min()), float(x.max()),
                   None if hits.size == 0 else float(result.time[hits[0]]),
                   float(outside.sum() * dt), side)


def _m(x: float) -> str:
    """A signed length with 3 decimals, without a negative zero. [m]"""
    text = f"{x:+.3f}"
    return "0.000" if text in ("-0.000", "+0.000") else text


@dataclass(frozen=True)
class OneSidedFinding:
    """The real, one-sided gastrocnemius in the forward case 1 (beyond the paper).

    Attributes
    ----------
    theta2_max : float
        Largest θ2 of the run. [rad]
    one_sided, case2 : Outcome
        The run with the one-sided gastrocnemius, and the case 2 run (Fig. 9).
    acting, slack : float
        Largest real part of the linearised case 1 with the one-sided gastrocnemius, on its
        acting side (θ2 ≥ 0) and on its slack side (θ2 < 0). [1/s]
    case2_pole : float
        Largest real part of the linearised case 2. [1/s]
    verdict : str
        :func:`posturelab.upright_verdict`'s status about upright ("depends on the side":
        upright is the pair's switching point and its sides disagree).
    """

    theta2_max: float
    one_sided: Outcome
    case2: Outcome
    acting: float
    slack: float
    case2_pole: float
    verdict: str = ""

    @property
    def text(self) -> str:
        """The finding in words, with its numbers."""
        return (
            "The real gastrocnemius pulls one way only: the paper's one-sided pair "
            "(--gastrocnemius one-sided) acts only while θ2 ≥ 0. In the forward case 1 run "
            "with it, "
            + (f"θ2 reaches {self.theta2_max:+.3f} rad, so the pair acts at times, "
               if self.theta2_max >= 0.0 else
               f"θ2 stays negative (max θ2 = {self.theta2_max:+.3f} rad), so the pair never "
               "acts, ")
            + f"and the biped {self.one_sided.text}; case 2 {self.case2.text}. Linearised on "
            f"its slack side (θ2 < 0), case 1 has the poles of case 2 (largest real part "
            f"{self.slack:+.3f} 1/s against {self.case2_pole:+.3f} 1/s; on the acting "
            f"side {self.acting:+.3f} 1/s). On the slack side case 1 is case 2: the "
            "paper's Fig. 8 recovers only because of the artificial antagonist."
            + (" Upright is the pair's switching point, so the linear verdict about it is "
               f"'{self.verdict}' (stable while engaged, unstable while slack), not stable."
               if self.verdict == "depends on the side" else "")
        )


#: The runs of the foot finding: key of :meth:`PaperRuns.paper` -> label.
FOOT_RUN_LABELS: dict[str, str] = {
    "backward": "backward, case 1 (Figs. 3–7)",
    "forward1": "forward, case 1 (Fig. 8)",
    "forward2": "forward, case 2 (Fig. 9)",
    "forward3": "forward, case 3 (Fig. 10)",
}


@dataclass(frozen=True)
class FootFinding:
    """The paper's runs against a typical foot that can tip (beyond the paper).

    Attributes
    ----------
    foot : BaseOfSupport
        Heel and toe, from the ankle. [m]
    excursions : tuple of (str, FootExcursion)
        Label of each run and its centre-of-gravity excursion. [m]
    backward, forward1 : Outcome
        The backward and forward case 1 runs with the base-of-support fall check.
    """

    foot: BaseOfSupport
    excursions: tuple[tuple[str, FootExcursion], ...]
    backward: Outcome
    forward1: Outcome

    @property
    def text(self) -> str:
        """The finding in words, with its numbers."""
        foot = self.foot
        parts = []
        for label, e in self.excursions:
            ratio = (f"{e.max / foot.toe:.2f} × the toe's distance in front of the ankle"
                     if e.max / foot.toe >= e.min / foot.heel else
                     f"{e.min / foot.heel:.2f} × the heel's distance behind it")
            txt = f"{label}: x_c from {_m(e.min)} to {_m(e.max)} m ({ratio})"
            if e.t_out is not None:
                txt += (f"; it leaves the foot past the {e.side} at t = {e.t_out:.2f} s "
                        f"and is outside for {e.time_out:.2f} s in total")
            else:
                txt += "; it stays over the foot"
            parts.append(txt)
        n = len(self.excursions)
        n_out = sum(e.t_out is not None for _, e in self.excursions)
        checks_txt = (f"the backward run {self.backward.stops_text}; the forward case 1 run "
                      f"{self.forward1.stops_text}")
        return (
            f"How far the centre of gravity travels, against a typical foot (heel "
            f"{_m(foot.heel)} m, toe {_m(foot.toe)} m from the ankle: foot length 0.152 H for "
            "H = 1.65 m, Winter 2009; ankle at a quarter of the foot from the heel): "
            + "; ".join(parts) + ". The paper's foot cannot tip. With a real foot, the static "
            "criterion (the centre of gravity's ground projection must stay between heel and "
            "toe) fails in "
            + (f"all {n_out}" if n_out == n else f"{n_out} of {n}")
            + " of these runs"
            + (": a 1 m/s platform step is beyond the ankle strategy alone; a step or a hip "
               "strategy would be needed" if n_out == n else "")
            + ". Rerun with posturelab's base-of-support fall check "
            f"(FallCriteria(base_of_support=FOOT_FROM_LITERATURE)), {checks_txt}."
        )


@dataclass(frozen=True)
class RecoveryFinding:
    """The largest backward ramp-and-hold case 1 recovers from (beyond the paper).

    Attributes
    ----------
    ramp_duration : float
        Duration of the ramp. [s]
    by_cop : float
        Largest recoverable move when the foot tips (centre of pressure past the toe). [m]
    by_cog : float
        Largest recoverable move when only the centre of gravity must stay over the foot. [m]
    """

    ramp_duration: float
    by_cop: float
    by_cog: float

    @property
    def text(self) -> str:
        """The finding in words, with its numbers."""
        return (
            "Largest recoverable perturbation "
            "(posturelab.studies.recovery.largest_recoverable): case "
            f"1, the platform moved backward and held over {self.ramp_duration:g} s, the "
            f"typical foot above. The foot tips (centre of pressure past the toe) beyond a "
            f"{self.by_cop * 100:.1f} cm move; the centre of gravity leaves the foot only "
            f"beyond {self.by_cog * 100:.1f} cm. The static criterion overestimates what the "
            f"ankle strategy absorbs by a factor {self.by_cog / self.by_cop:.1f}."
        )


@dataclass(frozen=True)
class DelayFinding:
    """What a neural delay of the whole muscle feedback does to case 1 (beyond the paper).

    Attributes
    ----------
    survives : float or None
        Largest delay at which the nonlinear backward run does not fall; None when the
        bracket did not bracket a fall. [s]
    falls : float or None
        Smallest delay found to fall. [s]
    margin : float or None
        Delay margin of the linearised model (:func:`posturelab.delay_margin`); None if not
        computed. [s]
    crossing_frequency : float or None
        Frequency of the mode that crosses at the margin. [rad/s]
    oscillation : float or None
        At τ = ``survives``: the largest swing of the knee angle about its mean over the
        last 0.5 s of the run, where a stable run would have settled. [rad]
    """

    survives: float | None
    falls: float | None
    margin: float | None = None
    crossing_frequency: float | None = None
    oscillation: float | None = None

    @property
    def text(self) -> str:
        """The finding in words, with its numbers."""
        if self.survives is None or self.falls is None:
            return "Neural delay: the bracket of delays searched did not bracket a fall."
        lead = "Neural delay (feedback_delay): with every muscle pair responding to the state " \
               "delayed by τ, "
        if self.margin is not None and self.crossing_frequency is not None:
            lead += (
                f"the linearised case 1 loses stability at τ = {self.margin * 1000:.2f} ms "
                f"(its delay margin), to a mode at {self.crossing_frequency / (2 * math.pi):.1f}"
                " Hz. Above the margin the nonlinear run does not settle, yet it does not fall "
                "at once: the backward case 1 run "
            )
        else:
            lead += "the backward case 1 run "
        text = (f"{lead}survives τ = {self.survives * 1000:.0f} ms but falls at "
                f"τ = {self.falls * 1000:.0f} ms.")
        if self.oscillation is not None:
            text += (f" At {self.survives * 1000:.0f} ms it is not upright but oscillating: the "
                     f"knee angle still swings by {self.oscillation:.3g} rad in the run's last "
                     "0.5 s. Not falling within a run is not stability.")
        return text + (
            " The paper itself cites 70–120 ms onsets for the muscle responses to a platform "
            "perturbation (Section III.A), so its gains, whose fast modes (poles near −554 and "
            "−89 1/s) come from large viscosity acting on light links, can only be read as "
            "instantaneous, intrinsic (muscle) impedance, not as reflexes."
        )


@dataclass(frozen=True)
class LiteratureControllerFinding(RecoveryFinding):
    """A published delayed controller on the paper's body (as one link): its delay margin
    and the largest backward translation it recovers (the numbers of
    :class:`RecoveryFinding`: ``by_cop`` is the bound compared with people; ``by_cog``, the
    centre of pressure allowed past the toe, a foot that cannot tip, is not), against the
    human range.

    Attributes
    ----------
    preset : ControllerPreset
        The controller (:mod:`posturelab.model.controllers`): its name (``controller``),
        ``citation``, ``feedback_delay`` τ [s] and the ``provenance`` of its numbers, in
        words, read through the finding.
    delay_margin : float
        Of the linearised model. [s]
    """

    preset: ControllerPreset
    delay_margin: float

    @property
    def controller(self) -> str:
        """The preset's name."""
        return self.preset.name

    @property
    def citation(self) -> str:
        """The preset's citation."""
        return self.preset.citation

    @property
    def feedback_delay(self) -> float:
        """The preset's τ. [s]"""
        return self.preset.feedback_delay

    @property
    def provenance(self) -> str:
        """Where each of the preset's numbers comes from, in words."""
        return self.preset.provenance_text()

    @property
    def text(self) -> str:
        """The finding in words, with its numbers."""
        young, older = HUMAN_RECOVERY_YOUNG, HUMAN_RECOVERY_OLDER
        if HUMAN_RECOVERY_PROTOCOL is None:
            protocol = (
                "That study's platform protocol (its displacement, velocity and acceleration "
                "profile) is not known to posturelab, so the model's profile above is "
                "posturelab's choice and the two are not comparable like for like: a "
                "different speed or acceleration moves the model's bound. The model's "
                f"{self.by_cop * 100:.1f} cm against people's "
                f"{young[0] * 100:.1f} cm says only that this linear ankle controller, "
                "with its foot flat until it tips, recovers "
                + ("less" if self.by_cop < young[0] else "as much or more")
                + " under this profile.")
        else:  # pragma: no cover - filled in when the protocol is known
            protocol = f"The model ran that study's profile: {HUMAN_RECOVERY_PROTOCOL}."
        return (
            f"A delayed controller from the literature ({self.controller}: {self.citation}) on "
            "the paper's body lumped into one link (paper-1link): intrinsic ankle impedance "
            f"none, neural feedback delayed by τ = {self.feedback_delay * 1000:.0f} ms. Its "
            f"delay margin is {self.delay_margin * 1000:.0f} ms, so τ leaves "
            f"{(self.delay_margin - self.feedback_delay) * 1000:.0f} ms to spare. On a "
            f"backward ramp-and-hold of the platform over {self.ramp_duration:g} s (one sine "
            "cycle of acceleration, peak speed twice the mean) with the typical foot, it "
            f"recovers up to {self.by_cop * 100:.1f} cm before the centre of pressure leaves "
            "the foot (the foot tips): the bound consistent with a foot that can tip, and the "
            "one to set beside people's. (A centre-of-gravity criterion alone, which lets the "
            f"centre of pressure pass the toe, would allow {self.by_cog * 100:.1f} cm; no "
            f"foot allows that.) People recover {young[0] * 100:.1f} ± {young[1] * 100:.1f} cm "
            f"(young) and {older[0] * 100:.1f} ± {older[1] * 100:.1f} cm (older) without "
            f"stepping (PMC6338353). {protocol}"
            + (f" The preset's numbers: {self.provenance}" if self.provenance else "")
        )


@dataclass(frozen=True)
class StrategyFinding:
    """Whether limiting the ankle torque switches the paper's model to the hip strategy.

    Attributes
    ----------
    ankle_torque_limit : float
        [N·m]
    linear_hip_fraction : float
        Hip fraction of the small, unlimited runs (independent of size there). [-]
    largest_hip_fraction : float
        Largest hip fraction of a limited run that did not fall. [-]
    first_fall : float or None
        Smallest displacement at which the limited run fell. [m]
    ramp_duration : float
        [s]
    """

    ankle_torque_limit: float
    linear_hip_fraction: float
    largest_hip_fraction: float
    first_fall: float | None
    ramp_duration: float

    @property
    def text(self) -> str:
        """The finding in words, with its numbers."""
        fall = ("" if self.first_fall is None else
                f"; beyond {self.first_fall * 100:.0f} cm it falls, toppling as one pendulum")
        return (
            "Ankle to hip strategy (posturelab.studies.strategy, after Creath et al. 2005: the "
            "hip fraction is the share of the anti-phase leg–trunk mode in the motion). The "
            "paper proposes the hip strategy for when the ankle torque is limited. With its "
            "case 1 impedance and the net ankle moment limited to "
            f"{self.ankle_torque_limit:g} N·m, backward ramp-and-holds of growing size (over "
            f"{self.ramp_duration:g} s, the typical foot) keep a hip fraction of at most "
            f"{self.largest_hip_fraction:.3f}, against {self.linear_hip_fraction:.3f} for the "
            f"small unlimited runs{fall}. Impedance alone does not switch strategy: the hip "
            "pairs only resist the trunk's motion. A hip strategy, which people show at the "
            "faster backward translations (Runge et al. 1999), needs active hip control."
        )


@dataclass(frozen=True)
class FRFFinding:
    """The independent-channel model's tilt FRF beside the paper's instantaneous model, and a
    simulated PRTS experiment recovered by the fit.

    Attributes
    ----------
    frequency : tuple of float
        Band frequencies shown. [Hz]
    paper_gain, paper_phase : tuple of float
        Tilt FRF of the paper's case 1 (three links, W = 1). [-], [deg]
    delayed_gain, delayed_phase : tuple of float
        Tilt FRF of the ``peterka-2002`` preset on ``paper-1link``. [-], [deg]
    true, fitted, standard_error : tuple of float
        K_P [N·m/rad], K_D [N·m·s/rad], τ [s] of the simulated experiment and their fit.
    cycles : int
        PRTS cycles used (20 s each, one more discarded). [-]
    noise : float
        Standard deviation of the white sensor noise added to the sway. [rad]
    fit_error : float
        Weighted RMS residual of the shown fit. [-]
    seeds : int
        Noise realisations of the fit-back spread. [-]
    median_error, max_error : tuple of float
        Median and largest |fitted/true − 1| over them, K_P, K_D, τ. [%]
    """

    frequency: tuple
    paper_gain: tuple
    paper_phase: tuple
    delayed_gain: tuple
    delayed_phase: tuple
    true: tuple
    fitted: tuple
    standard_error: tuple
    cycles: int
    noise: float
    fit_error: float = float("nan")
    seeds: int = 0
    median_error: tuple = ()
    max_error: tuple = ()

    @property
    def text(self) -> str:
        """The finding in words, with its numbers."""
        def row(gain, phase):
            return ", ".join(f"{g:.2f} ({p:.0f}°)" for g, p in zip(gain, phase, strict=True))

        freqs = ", ".join(f"{f:g}" for f in self.frequency)
        names = ("K_P", "K_D", "τ")
        units = ("N·m/rad", "N·m·s/rad", "s")
        fit = "; ".join(f"{n} {f:.4g} ± {s:.2g} {u} (true {t:.4g})" for n, f, s, u, t in zip(
            names, self.fitted, self.standard_error, units, self.true, strict=True))
        paper = row(self.paper_gain, self.paper_phase)
        spread = ("" if not self.seeds else
                  f"over {self.seeds} seeds of the sensor noise (the same run) the median "
                  "(largest) error is " + ", ".join(
                      f"{n} {m:.2f} % ({x:.2f} %)" for n, m, x in zip(
                          names, self.median_error, self.max_error, strict=True)) + ".")
        delayed = row(self.delayed_gain, self.delayed_phase)
        return (
            "Frequency response to surface tilt (posturelab.frequency; a body that follows the "
            f"surface has gain 1, phase 0). At {freqs} Hz the paper's case 1, whose impedance "
            f"acts at once and relative to the foot, has gain (phase) {paper}; the "
            "independent-channel controller of Peterka 2002 (peterka-2002, 150 ms delay) on "
            f"the same body as one link has {delayed}. Both over-follow the surface at low "
            "frequency (a stiffness relative to the foot only a little above mgh), but only the "
            "delayed controller's phase keeps falling past −180° with frequency, the shape "
            "people's FRFs have; the paper's instantaneous impedance stays near −90°. A "
            "simulated PRTS "
            f"experiment with it ({self.cycles} cycles of posturelab's 80-state sequence, "
            f"{self.noise * 1000:.1f} mrad of white sensor noise on the sway, seeded) gives, "
            f"fitted to its 11-band FRF: {fit}; fit error {self.fit_error:.2g} (the weighted "
            f"RMS residual). That is one seed; {spread} The few-SE offsets of K_P are the "
            "sway's small nonlinearity at this amplitude, which the linear FRF leaves out "
            "(noise-free, it is 0.04 % at 0.035 rad and vanishes at 0.0035 rad), a bias that "
            "noise-based intervals do not include."
        )
