"""The reproduction report's results as data: Table II, J⁻¹H, the figure verdicts
and the findings beyond the paper (whose data types are in :mod:`.findings`).

Everything here is computed from the model, its linearisation and the runs of
:mod:`.runs`; nothing is drawn or formatted as HTML. Each verdict follows from
the runs through a threshold stated below, never written in advance. The
sentences (``FigureCheck.evidence``, each finding's ``text``) are the report's
words, with their numbers.

The findings beyond the paper that need runs of their own are computed in
:mod:`.beyond`; their names are importable from here too.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..linear.analysis import analyse, disturbance_sensitivity
from ..model.body import Body
from ..model.muscles import paper_muscles
from ..simulation.results import SimulationResult
from .beyond import (
    DELAY_BRACKET,
    FIT_BACK_SEEDS,
    RECOVERY_RAMP_DURATION,
    FRFExperiment,
    delay_finding,
    delayed_run,
    fit_back_errors,
    frf_experiment,
    frf_finding,
    literature_controller_finding,
    ramp_and_hold_run,
    recovery_finding,
    strategy_finding,
    with_delay_margin,
)
from .compare import SensitivityComparison, Table2Row, sensitivity_comparison, table2_comparison
from .findings import (
    FOOT_RUN_LABELS,
    DelayFinding,
    FootExcursion,
    FootFinding,
    OneSidedFinding,
    Outcome,
    RecoveryFinding,
)
from .printed import BACKWARD_INITIAL_STATE, FIGURE_CAPTIONS
from .runs import PaperRuns

__all__ = [
    "SETTLE_TOLERANCE", "PAPER_SETTLING_CLAIM", "ORDER_OF_MAGNITUDE", "IMPULSE_WINDOW",
    "KNEE_STRAIGHT", "LINEAR_R", "ALMOST_IDENTICAL", "RECOVERY_RAMP_DURATION",
    "DELAY_BRACKET", "FIGURE_CAPTIONS",
    "FigureCheck", "Table2Disagreement", "Table2Check", "SensitivityCheck", "LinearFacts",
    "PaperChecks", "Outcome", "FootExcursion", "OneSidedFinding", "FootFinding",
    "RecoveryFinding", "DelayFinding",
    "table2_check", "sensitivity_check", "linear_facts", "figure_checks",
    "check_fig3", "check_fig4", "check_fig5_6", "check_fig7", "check_fig8", "check_fig9",
    "check_fig10", "erratum_notes", "one_sided_finding", "foot_finding",
    "ramp_and_hold_run", "recovery_finding", "delayed_run", "delay_finding",
    "with_delay_margin", "literature_controller_finding", "strategy_finding", "frf_finding",
    "FRFExperiment", "frf_experiment", "fit_back_errors", "FIT_BACK_SEEDS",
]

#: |θ_i| below this counts as back upright (the settling criterion). [rad]
SETTLE_TOLERANCE = 0.01
#: Section V.A: "The postural disturbances, as a consequence, dissipate in less than three
#: seconds." [s]
PAPER_SETTLING_CLAIM = 3.0
#: "Same order of magnitude": the largest peak pair torque within this factor of the smallest. [-]
ORDER_OF_MAGNITUDE = 10.0
#: The initial rate jump drives the pair torques through the viscosity for the first few
#: time constants of the fast poles (−554 and −89 1/s); torques after this are "sustained". [s]
IMPULSE_WINDOW = 0.1
#: A knee counts as straight ("locked") when |θ2 − θ1| is below this. [rad]
KNEE_STRAIGHT = 0.05
#: Angles count as "linearly dependent" when |Pearson r| is above this. [-]
LINEAR_R = 0.95
#: Forward and backward responses count as "almost identical" when the peak |x_c| ratio is
#: within [1/this, this]. [-]
ALMOST_IDENTICAL = 1.25



# ---------------------------------------------------------------------------
# Data
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class FigureCheck:
    """One of the paper's figures: its caption, the claim we test, and the verdict.

    Attributes
    ----------
    number : int
        Figure number in the paper (3–10).
    filename : str
        Stem of the image files, e.g. ``"fig03"``.
    caption : str
        The paper's caption.
    claim : str
        The claim tested, quoted or paraphrased from the text.
    verdict : str
        "supported", "partly supported" or "not supported".
    evidence : str
        The numbers behind the verdict, with units.
    """

    number: int
    filename: str
    caption: str
    claim: str
    verdict: str
    evidence: str


class Table2Disagreement(NamedTuple):
    """A printed Table II pole the linearised model does not reproduce (a tuple, so that it
    unpacks as ``case, column, printed, computed, erratum``).

    Attributes
    ----------
    case : str
        Table I case.
    column : int
        Column of the pole in Table II (1–6).
    printed : str
        The printed pole.
    computed : complex
        The computed pole paired with it. [1/s]
    erratum : int or None
        The erratum explaining it (:data:`posturelab.paper.ERRATA`).
    """

    case: str
    column: int
    printed: str
    computed: complex
    erratum: int | None


@dataclass(frozen=True)
class Table2Check:
    """Table II, printed beside computed.

    Attributes
    ----------
    rows : tuple of Table2Row
        One row per printed case; poles [1/s].
    total, agree : int
        Printed poles, and how many agree to the printed digits. [-]
    disagreements : tuple of Table2Disagreement
        The others, in table order.
    """

    rows: tuple[Table2Row, ...]
    total: int
    agree: int
    disagreements: tuple[Table2Disagreement, ...]

    @property
    def errata(self) -> tuple[int, ...]:
        """Numbers of the errata behind the disagreements, ascending."""
        return tuple(sorted({d.erratum for d in self.disagreements if d.erratum}))


@dataclass(frozen=True, eq=False)
class SensitivityCheck:
    """The disturbance-severity vector J⁻¹H, printed beside computed.

    Attributes
    ----------
    upright : SensitivityComparison
        J(0)⁻¹H(0) printed and computed. [rad/m]
    flexed_posture : numpy.ndarray, shape (3,)
        The initial posture of the simulations. [rad]
    flexed : numpy.ndarray, shape (3,)
        J⁻¹H at ``flexed_posture``. [rad/m]
    """

    upright: SensitivityComparison
    flexed_posture: np.ndarray
    flexed: np.ndarray

    @property
    def agrees(self) -> bool:
        """J(0)⁻¹H(0) agrees with the printed vector to its printed digits."""
        return bool(self.upright.agrees)


@dataclass(frozen=True)
class LinearFacts:
    """Poles of the linearised model that the checks quote.

    Attributes
    ----------
    case2_pole : float
        Largest real part of the case 2 poles (unstable). [1/s]
    case3_slow_pole : float
        Slowest real pole of case 3. [1/s]
    one_sided_acting, one_sided_slack : float
        Largest real part of the case 1 poles with the one-sided gastrocnemius, on its
        acting side (θ2 ≥ 0) and on its slack side (θ2 < 0). [1/s]
    one_sided_verdict : str
        :func:`posturelab.upright_verdict`'s status for it ("depends on the side").
    """

    case2_pole: float
    case3_slow_pole: float
    one_sided_acting: float
    one_sided_slack: float
    one_sided_verdict: str = ""


@dataclass(frozen=True)
class PaperChecks:
    """Everything the report found.

    Attributes
    ----------
    body : Body
        The paper's body (Appendix A).
    table2 : Table2Check
        Table II, printed beside computed. [1/s]
    sensitivity : SensitivityCheck
        J⁻¹H, printed beside computed. [rad/m]
    figures : tuple of FigureCheck
        Figs. 3–10.
    findings : tuple
        Results beyond the paper (:class:`OneSidedFinding`, :class:`FootFinding`,
        :class:`RecoveryFinding`, :class:`DelayFinding`), each with a ``text``.
    erratum_notes : mapping of int to str
        What our runs show about an erratum, by erratum number.
    """

    body: Body
    table2: Table2Check
    sensitivity: SensitivityCheck
    figures: tuple[FigureCheck, ...]
    findings: tuple
    erratum_notes: Mapping[int, str]

    @property
    def finding_texts(self) -> tuple[str, ...]:
        """The findings in words."""
        return tuple(f.text for f in self.findings)


# ---------------------------------------------------------------------------
# Tables and the linearised model
# ---------------------------------------------------------------------------


def table2_check(body: Body) -> Table2Check:
    """Table II printed beside the poles of the linearised ``body`` [1/s]."""
    rows = tuple(table2_comparison(body))
    total = agree = 0
    dis = []
    for row in rows:
        for k, p in enumerate(row.poles, start=1):
            total += 1
            agree += p.agrees
            if not p.agrees:
                dis.append(Table2Disagreement(row.case, k, p.printed, p.computed, p.erratum))
    return Table2Check(rows, total, agree, tuple(dis))


def sensitivity_check(body: Body) -> SensitivityCheck:
    """J⁻¹H [rad/m] at upright (against the print) and at the flexed initial posture."""
    flexed = np.asarray(BACKWARD_INITIAL_STATE[:3])
    return SensitivityCheck(sensitivity_comparison(body), flexed,
                            disturbance_sensitivity(body, flexed))


def linear_facts(body: Body) -> LinearFacts:
    """The poles [1/s] of cases 2, 3 and of case 1 with the one-sided gastrocnemius."""
    case2_pole = float(analyse(body, paper_muscles("2")).max_real_part)
    case3 = analyse(body, paper_muscles("3"))
    slow3 = float(max(p.real for p in case3.poles if abs(p.imag) < 1e-9))
    from ..linear.verdict import upright_verdict
    from .runs import ONE_SIDED_FORM

    verdict = upright_verdict(body, paper_muscles("1", gastrocnemius=ONE_SIDED_FORM))
    return LinearFacts(case2_pole, slow3, float(verdict.side(engaged=True).rightmost_root.real),
                       float(verdict.side(engaged=False).rightmost_root.real),
                       verdict.status)


# ---------------------------------------------------------------------------
# The figure checks, computed from the runs
# ---------------------------------------------------------------------------


def _max_theta_text(result: SimulationResult, names) -> str:
    return ", ".join(f"θ{i + 1} ({names[i]}) {v:.3f}"
                     for i, v in enumerate(result.max_abs_theta)) + " rad"


def check_fig3(r: SimulationResult, names: list[str]) -> FigureCheck:
    """Fig. 3: case 1 recovers from the backward motion within three seconds.

    Parameters
    ----------
    r : SimulationResult
        The backward case 1 run.
    names : list of str
        The link names.
    """
    settle = r.settling_time(SETTLE_TOLERANCE)
    ok = (not r.fell) and settle is not None
    verdict = ("supported" if ok and settle < PAPER_SETTLING_CLAIM
               else "partly supported" if ok else "not supported")
    ev = (f"Case 1 {'falls' if r.fell else 'recovers'}: peak |θ| {_max_theta_text(r, names)}; "
          + (f"every |θ_i| < {SETTLE_TOLERANCE} rad after t = {settle:.2f} s "
             f"({'within' if settle < PAPER_SETTLING_CLAIM else 'beyond'} the paper's "
             f"'less than three seconds', Section V.A); " if settle is not None else
             f"|θ| does not settle below {SETTLE_TOLERANCE} rad by {r.time[-1]:.1f} s; ")
          + f"max |θ| at t = {r.time[-1]:.1f} s is {np.abs(r.theta[-1]).max():.1e} rad.")
    return FigureCheck(3, "fig03", FIGURE_CAPTIONS[3],
                       "Case 1 recovers from the backward platform motion; postural "
                       "disturbances dissipate in less than three seconds (Section V.A).",
                       verdict, ev)


def check_fig4(r: SimulationResult) -> FigureCheck:
    """Fig. 4: the angles depend linearly on one another; the knee locks at the maximum
    forward excursion. ``r`` is the backward case 1 run."""
    th = r.theta
    knee = th[:, 1] - th[:, 0]
    i_max = int(np.argmax(th[:, 0]))
    k_at = float(knee[i_max])
    r12 = float(np.corrcoef(th[:, 0], th[:, 1])[0, 1])
    r13 = float(np.corrcoef(th[:, 0], th[:, 2])[0, 1])
    straight = abs(k_at) < KNEE_STRAIGHT
    linear = min(abs(r12), abs(r13)) > LINEAR_R
    verdict = ("supported" if straight and linear
               else "partly supported" if straight or linear else "not supported")
    j = int(np.argmax(knee))
    ev = (f"Knee angle θ2 − θ1 ranges over [{knee.min():+.3f}, {knee.max():+.3f}] rad (it "
          f"starts at {knee[0]:+.3f}, flexed). At the maximum forward excursion, θ1 = "
          f"{th[i_max, 0]:.3f} rad at t = {r.time[i_max]:.2f} s, the knee angle is {k_at:+.3f} "
          f"rad: {'straight' if straight else 'not straight'} (|θ2 − θ1| < {KNEE_STRAIGHT} rad "
          f"counts as locked). The free model has no knee stop: the knee then over-extends to "
          f"{knee[j]:+.3f} rad at t = {r.time[j]:.2f} s. Correlation with θ1: r(θ1, θ2) = "
          f"{r12:.3f}, r(θ1, θ3) = {r13:.3f} (|r| > {LINEAR_R} counts as linear): θ3 "
          f"{'is' if abs(r13) > LINEAR_R else 'is not'} nearly linear in θ1, θ2 "
          f"{'is' if abs(r12) > LINEAR_R else 'is less so'}.")
    return FigureCheck(4, "fig04", FIGURE_CAPTIONS[4],
                       "The angles depend linearly on one another, and the knee locks "
                       "(straightens) at the point of maximum forward excursion.", verdict, ev)


def _peaks(r: SimulationResult, mask: np.ndarray) -> tuple[np.ndarray, float, str]:
    peaks = np.abs(r.pair_torques[mask]).max(axis=0)
    order = float(peaks.max() / peaks.min()) if peaks.min() > 0 else float("inf")
    text = ", ".join(f"{n} {p:.0f}" for n, p in zip(r.pair_names, peaks, strict=True))
    return peaks, order, text


def check_fig5_6(r: SimulationResult) -> tuple[FigureCheck, FigureCheck]:
    """Figs. 5 and 6: the five pair torques are of the same order of magnitude. ``r`` is the
    backward case 1 run."""
    peaks, order, ptxt = _peaks(r, np.ones(r.time.size, dtype=bool))
    _, order_late, ltxt = _peaks(r, r.time >= IMPULSE_WINDOW)
    same, same_late = order < ORDER_OF_MAGNITUDE, order_late < ORDER_OF_MAGNITUDE
    verdict = ("supported" if same and same_late
               else "partly supported" if same or same_late else "not supported")
    ev = (f"Peak |M| per pair [N·m]: {ptxt}; largest/smallest = {order:.1f} "
          f"({'the same' if same else 'not the same'} order of magnitude: within a factor "
          f"{ORDER_OF_MAGNITUDE:g} counts). These peaks are set at t = 0 by the viscosity "
          f"acting on the jump of the rates. After the first {IMPULSE_WINDOW:g} s the peaks "
          f"are {ltxt}; largest/smallest = {order_late:.1f} "
          f"({'the same' if same_late else 'not the same'} order of magnitude).")
    claim = "All five muscular pair activities seem to be of the same order of magnitude."
    iq = r.pair_names.index("quadriceps")
    t_pk = float(r.time[int(np.argmax(np.abs(r.pair_torques[:, iq])))])
    ev6 = (ev + f" The quadriceps pair peaks at |M| = {peaks[iq]:.0f} N·m at t = {t_pk:.2f} s.")
    return (FigureCheck(5, "fig05", FIGURE_CAPTIONS[5], claim, verdict, ev),
            FigureCheck(6, "fig06", FIGURE_CAPTIONS[6], claim, verdict, ev6))


def check_fig7(r: SimulationResult) -> FigureCheck:
    """Fig. 7: the forward sway of the centre of gravity spirals back to upright. ``r`` is
    the backward case 1 run."""
    x = r.cog_position[:, 0]
    v = r.cog_velocity[:, 0]
    i = int(np.argmax(x))
    back = abs(x[-1]) < 0.005 and abs(v[-1]) < 0.005 and not r.fell
    forward = x[i] > 0 and v[0] > 0
    verdict = "supported" if back and forward else "not supported"
    ev = (f"The CoG starts at x_c = {x[0]:+.3f} m moving forward at ẋ_c = {v[0]:+.3f} m/s, "
          f"peaks at x_c = {x[i]:+.3f} m (forward) at t = {r.time[i]:.2f} s, and ends at "
          f"x_c = {x[-1]:+.4f} m, ẋ_c = {v[-1]:+.4f} m/s at t = {r.time[-1]:.1f} s "
          f"({'back at upright' if back else 'not back at upright'}).")
    return FigureCheck(7, "fig07", FIGURE_CAPTIONS[7],
                       "A backward platform motion gives a forward sway of the centre of "
                       "gravity that spirals back to upright.", verdict, ev)


def check_fig8(fwd: SimulationResult, back: SimulationResult) -> FigureCheck:
    """Fig. 8: with the gastrocnemius, the forward response (``fwd``, forward case 1) is
    almost identical to the backward one (``back``) and recovers."""
    pf = float(np.abs(fwd.cog_position[:, 0]).max())
    pb = float(np.abs(back.cog_position[:, 0]).max())
    ratio = pf / pb
    sf, sb = fwd.settling_time(SETTLE_TOLERANCE), back.settling_time(SETTLE_TOLERANCE)
    recovers = not fwd.fell and sf is not None
    similar = 1 / ALMOST_IDENTICAL <= ratio <= ALMOST_IDENTICAL
    verdict = ("supported" if recovers and similar
               else "partly supported" if recovers else "not supported")
    ev = (f"Case 1 with the two-sided gastrocnemius {'falls' if fwd.fell else 'recovers'}: "
          f"peak |x_c| = {pf:.3f} m backward vs {pb:.3f} m forward in the backward run "
          f"(ratio {ratio:.2f}; within [{1 / ALMOST_IDENTICAL:.2f}, {ALMOST_IDENTICAL:.2f}] "
          f"counts as almost identical); |θ| < {SETTLE_TOLERANCE} rad after "
          + (f"{sf:.2f} s" if sf is not None else "— (never)")
          + (f" vs {sb:.2f} s backward" if sb is not None else "")
          + ". The paper does not print the forward initial state: we use the backward posture "
          "[0.1, −0.1, 0.1] rad with the rates negated, so the two runs are not exact mirror "
          "images.")
    return FigureCheck(8, "fig08", FIGURE_CAPTIONS[8],
                       "With the gastrocnemius pair (K5) included, the forward response is "
                       "almost identical to the backward one and recovers.", verdict, ev)


def check_fig9(r: SimulationResult, pole: float) -> FigureCheck:
    """Fig. 9: without the gastrocnemius (case 2, run ``r``) the biped falls; ``pole`` is the
    largest real part of the linearised case 2 [1/s]."""
    verdict = "supported" if r.fell else "not supported"
    ev = ((f"Case 2 falls at t = {r.fall_time:.3f} s ({r.fall_reason}); x_c reaches "
           f"{r.cog_position[-1, 0]:+.3f} m. " if r.fell else
           f"Case 2 does not fall within {r.time[-1]:.1f} s. ")
          + f"The linearised case 2 has an unstable pole at +{pole:.3f} 1/s (Table II: +1.17).")
    return FigureCheck(9, "fig09", FIGURE_CAPTIONS[9],
                       "Without the gastrocnemius (case 2) the biped is unstable and falls.",
                       verdict, ev)


def check_fig10(r3: SimulationResult, long3: SimulationResult, r1: SimulationResult,
                slow_pole: float) -> FigureCheck:
    """Fig. 10: case 3 (``r3``, continued in ``long3``) recovers, more slowly than case 1
    (``r1``); ``slow_pole`` is its slowest real pole [1/s]."""
    d3 = float(np.abs(r3.theta[-1]).max())
    d1 = float(np.abs(r1.theta[-1]).max())
    s_long = long3.settling_time(SETTLE_TOLERANCE)
    recovering = not r3.fell and not long3.fell and s_long is not None
    slower = d3 > d1
    verdict = ("supported" if recovering and slower
               else "partly supported" if (not r3.fell and slower) else "not supported")
    tau = -1.0 / slow_pole if slow_pole < 0 else float("inf")
    ev = (f"At t = {r3.time[-1]:.0f} s the largest |θ_i| is {d3:.3f} rad for case 3 against "
          f"{d1:.1e} rad for case 1 (Fig. 8): case 3 {'is' if slower else 'is not'} slower. "
          + (f"Continued to {long3.time[-1]:.0f} s, case 3 settles (|θ| < {SETTLE_TOLERANCE} "
             f"rad) after {s_long:.1f} s. " if s_long is not None else
             f"Continued to {long3.time[-1]:.0f} s, case 3 does not settle. ")
          + f"Its slowest pole is {slow_pole:.3f} 1/s (time constant {tau:.1f} s), not the "
          "printed −0.90 (erratum 1), which explains the slow recovery.")
    return FigureCheck(10, "fig10", FIGURE_CAPTIONS[10],
                       "With no gastrocnemius but doubled ankle stiffness (case 3) the biped "
                       "recovers, but more slowly.", verdict, ev)


def figure_checks(runs: PaperRuns, linear: LinearFacts,
                  names: list[str]) -> tuple[FigureCheck, ...]:
    """The verdicts of Figs. 3–10, from the runs and the linearised model.

    Parameters
    ----------
    runs : PaperRuns
    linear : LinearFacts
        Poles of the linearised model. [1/s]
    names : list of str
        The link names.
    """
    b = runs.backward
    c5, c6 = check_fig5_6(b)
    return (check_fig3(b, names), check_fig4(b), c5, c6, check_fig7(b),
            check_fig8(runs.forward1, b), check_fig9(runs.forward2, linear.case2_pole),
            check_fig10(runs.forward3, runs.forward3_long, runs.forward1,
                        linear.case3_slow_pole))


def erratum_notes(runs: PaperRuns) -> dict[int, str]:
    """What our runs show about the errata, by erratum number (erratum 4: which case falls)."""
    f2, f3, long3 = runs.forward2, runs.forward3, runs.forward3_long
    note4 = ("Our runs: case 2 (Fig. 9) "
             + (f"falls at t = {f2.fall_time:.3f} s" if f2.fell else "does not fall")
             + "; case 3 (Fig. 10) "
             + ("falls" if f3.fell else
                f"does not fall and settles after "
                f"{long3.settling_time(SETTLE_TOLERANCE) or float('nan'):.1f} s")
             + ".")
    return {4: note4}


# ---------------------------------------------------------------------------
# Findings beyond the paper
# ---------------------------------------------------------------------------


def one_sided_finding(runs: PaperRuns, linear: LinearFacts) -> OneSidedFinding:
    """The forward case 1 run with the real, one-sided gastrocnemius against case 2."""
    return OneSidedFinding(float(runs.one_sided.theta[:, 1].max()), Outcome.of(runs.one_sided),
                           Outcome.of(runs.forward2), linear.one_sided_acting,
                           linear.one_sided_slack, linear.case2_pole,
                           linear.one_sided_verdict)


def foot_finding(runs: PaperRuns) -> FootFinding:
    """The centre-of-gravity excursions of the paper's runs over ``runs.foot``."""
    paper = runs.paper
    return FootFinding(
        runs.foot,
        tuple((label, FootExcursion.of(paper[key], runs.foot))
              for key, label in FOOT_RUN_LABELS.items()),
        Outcome.of(runs.backward_with_foot), Outcome.of(runs.forward1_with_foot))
