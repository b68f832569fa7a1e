"""``reproduce_paper``: regenerate the paper's tables and figures, and check its claims.

One call computes Table II (printed beside computed, disagreements flagged
with their erratum), the disturbance-severity vector J⁻¹H (at upright and at
the flexed initial posture), runs the four built-in paper scenarios
(Figs. 3–10) and the real one-sided gastrocnemius in the forward case, draws
Figs. 3–10, and writes into a directory:

* ``index.html`` — self-contained (figures embedded as base64 PNG): Table I,
  Table II, J⁻¹H, each figure with the paper's caption, the claim tested,
  the verdict and the numbers behind it, the errata, and findings beyond the
  paper;
* ``table2.csv`` — one row per printed pole (54): case, column, printed,
  computed_re, computed_im, agrees, erratum;
* ``fig03.png`` … ``fig10.png`` and ``.svg``, and ``beyond1.png/.svg``.

Everything is built in a hidden temporary directory inside the output
directory and then renamed into place file by file, so a failure leaves no
half-written file; a directory created by the call is removed again on
failure.

Verdicts are computed from the runs with stated thresholds, never written
in advance.
"""

from __future__ import annotations

import base64
import csv
import html
import io
import os
import shutil
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import PostureLabError
from ..linear.analysis import analyse, analyse_both_sides, disturbance_sensitivity
from ..model.body import Body, paper_body
from ..model.muscles import PAPER_PAIR_NAMES, STIFFNESS_CASES, TABLE_I_CITATION, paper_muscles
from ..simulation.reference import FOOT_FROM_LITERATURE, BaseOfSupport, FallCriteria
from ..simulation.results import (
    SimulationResult,
    atomic_write_bytes,
    atomic_write_text,
    new_file_mode,
)
from .compare import Table2Row, erratum, sensitivity_comparison, table2_comparison
from .printed import (
    BACKWARD_INITIAL_STATE,
    ERRATA,
    SENSITIVITY_PRINTED,
    TABLE_II_SOURCE,
    Erratum,
)

__all__ = [
    "FIGURE_CAPTIONS",
    "FigureCheck",
    "ReproduceReport",
    "reproduce_paper",
    "ProgressCallback",
    "SETTLE_TOLERANCE",
    "PAPER_SETTLING_CLAIM",
]

#: progress(step, total, message): called before each step of :func:`reproduce_paper`.
ProgressCallback = Callable[[int, int, str], None]

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
#: Duration of the continued Fig. 10 run (case 3), to see whether it settles at all. [s]
CASE3_LONG_DURATION = 60.0
#: Figure resolution. [dots/inch]
DPI = 110

#: The paper's figure captions (Section V), transcribed from paper/ankle-strategy-paper.txt.
FIGURE_CAPTIONS: dict[int, str] = {
    3: "The trajectories of motion: the three angles and the three angular velocities as "
       "functions of time in a backward platform motion.",
    4: "The spatial trajectories of motion: the angles θ2 and θ3 as functions of θ1 in a "
       "backward platform motion - a forward subject sway. All angles seem to linearly depend "
       "on one another, and the knee gets locked at the point of maximum excursion forward.",
    5: "The torque activity at the three joints and the gastrocnemius as functions of time - "
       "all torques are in Newton-meters",
    6: "The quadriceps two-jointed muscle activity as a function of time",
    7: "The phase plane portrait of the horizontal motion of the center of gravity - velocity "
       "versus position - in a backward platform motion, i.e., in a forward sway.",
    8: "The phase plane portrait of the horizontal motion of the center of gravity - velocity "
       "versus position in forward platform disturbance. Artificial antagonistic "
       "gastrocnemius is assumed. In reality, the tibialis anterior would compensate for the "
       "artificial gastrocnemius muscle introduced here, because the knees are locked and θ1 "
       "and θ2 are equal.",
    9: "The phase plane portrait of the horizontal motion of the center of gravity - velocity "
       "versus position - in forward platform disturbance. The system is unstable, and fall "
       "is inevitable. It is possible that a much larger tibialis anterior force would have "
       "prevented the fall.",
    10: "The phase plane portrait of the horizontal motion of the center of gravity - velocity "
        "versus position in forward platform disturbance with no gastrocnemius, but larger "
        "ankle stiffness. The system is recovering from the disturbance but more slowly. A "
        "larger tibialis anterior - soleus force pair would implement this case.",
}

_SCENARIOS = {
    "backward": ("paper-backward-case1", "Figs. 3–7"),
    "forward1": ("paper-forward-case1", "Fig. 8"),
    "forward2": ("paper-forward-case2", "Fig. 9"),
    "forward3": ("paper-forward-case3", "Fig. 10"),
}


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


@dataclass(frozen=True)
class ReproduceReport:
    """What :func:`reproduce_paper` wrote and found.

    Attributes
    ----------
    out_dir : Path
        The output directory.
    index_html : Path
        The report page.
    files : tuple of Path
        Every file written.
    table2_total, table2_agree : int
        Printed Table II poles, and how many we reproduce within the printed digits.
    table2_disagreements : tuple of (str, int, str, complex, int or None)
        (case, column 1–6, printed, computed [1/s], erratum number).
    sensitivity_agrees : bool
        J(0)⁻¹H(0) agrees with the printed vector to its printed digits.
    checks : tuple of FigureCheck
        Figs. 3–10.
    errata : tuple of Erratum
        The errata list (posturelab.paper.ERRATA).
    findings : tuple of str
        Results beyond the paper, in words with numbers.
    elapsed : float
        Wall time of the call. [s]
    """

    out_dir: Path
    index_html: Path
    files: tuple[Path, ...]
    table2_total: int
    table2_agree: int
    table2_disagreements: tuple
    sensitivity_agrees: bool
    checks: tuple[FigureCheck, ...]
    errata: tuple[Erratum, ...]
    findings: tuple[str, ...] = field(default_factory=tuple)
    elapsed: float = 0.0

    def summary(self) -> str:
        """One paragraph: Table II agreement, the figure verdicts and the errata found."""
        dis = "; ".join(
            f"case {c} column {k}: printed {p}, computed {_fmt_pole(v, 3)}"
            + (f" (erratum {e})" if e else "")
            for c, k, p, v, e in self.table2_disagreements
        )
        verdicts = ", ".join(f"Fig. {c.number} {c.verdict}" for c in self.checks)
        errs = "; ".join(f"[{e.number}] {e.where}" for e in self.errata)
        return (
            f"Table II: {self.table2_agree} of {self.table2_total} printed poles agree with the "
            f"linearised model to the printed digits"
            + (f"; disagreements: {dis}." if dis else ".")
            + f" J(0)⁻¹H(0) {'agrees' if self.sensitivity_agrees else 'DISAGREES'} with the "
            f"printed [{', '.join(SENSITIVITY_PRINTED)}]. Figures: {verdicts}."
            f" Errata ({len(self.errata)}, details in the report): {errs}."
        )


# ---------------------------------------------------------------------------
# Small helpers
# ---------------------------------------------------------------------------


def _fmt_pole(z: complex, digits: int = 2) -> str:
    z = complex(z)
    if abs(z.imag) < 10 ** (-digits - 3):
        return f"{z.real:.{digits}f}"
    return f"{z.real:.{digits}f} {'+' if z.imag >= 0 else '−'} {abs(z.imag):.{digits}f}i"


def _vec(v, digits: int = 3) -> str:
    return "[" + ", ".join(f"{x:.{digits}f}" for x in np.asarray(v, dtype=float)) + "]"


def _first_time(result: SimulationResult, mask: np.ndarray) -> float | None:
    hits = np.nonzero(mask)[0]
    return None if hits.size == 0 else float(result.time[hits[0]])


def _max_theta_text(result: SimulationResult, names) -> str:
    return ", ".join(f"θ{i + 1} ({names[i]}) {v:.3f}"
                     for i, v in enumerate(result.max_abs_theta)) + " rad"


def _foot_excursion(result: SimulationResult, foot: BaseOfSupport) -> dict:
    x = result.cog_position[:, 0]
    beyond_toe = x > foot.toe
    behind_heel = x < foot.heel
    outside = beyond_toe | behind_heel
    dt = float(np.mean(np.diff(result.time))) if result.time.size > 1 else 0.0
    return {
        "min": float(x.min()), "max": float(x.max()),
        "t_out": _first_time(result, outside),
        "time_out": float(outside.sum() * dt),
        "side": ("toe" if beyond_toe.any() and (not behind_heel.any() or
                                                np.argmax(beyond_toe) < np.argmax(behind_heel))
                 else ("heel" if behind_heel.any() else None)),
    }


def _m(x: float) -> str:
    """A signed length with 3 decimals, without a negative zero. [m]"""
    text = f"{x:+.3f}"
    return "0.000" if text in ("-0.000", "+0.000") else text


def _outcome(r: SimulationResult) -> str:
    if r.fell:
        return f"falls at t = {r.fall_time:.3f} s"
    return f"does not fall within {r.time[-1]:.1f} s"


def _figure_bytes(fig) -> tuple[bytes, bytes]:
    from ..viz.plots import figure_bytes

    return figure_bytes(fig, "png", DPI), figure_bytes(fig, "svg", DPI)


# ---------------------------------------------------------------------------
# The checks, computed from the runs
# ---------------------------------------------------------------------------


def _check_fig3(r: SimulationResult, names) -> FigureCheck:
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


def _check_fig4(r: SimulationResult) -> FigureCheck:
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


def _check_fig56(r: SimulationResult) -> tuple[FigureCheck, FigureCheck]:
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


def _check_fig7(r: SimulationResult) -> FigureCheck:
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


def _check_fig8(fwd: SimulationResult, back: SimulationResult) -> FigureCheck:
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


def _check_fig9(r: SimulationResult, pole: float) -> FigureCheck:
    verdict = "supported" if r.fell else "not supported"
    ev = ((f"Case 2 falls at t = {r.fall_time:.3f} s ({r.fall_reason}); x_c reaches "
           f"{r.cog_position[-1, 0]:+.3f} m. " if r.fell else
           f"Case 2 does not fall within {r.time[-1]:.1f} s. ")
          + f"The linearised case 2 has an unstable pole at +{pole:.3f} 1/s (Table II: +1.17).")
    return FigureCheck(9, "fig09", FIGURE_CAPTIONS[9],
                       "Without the gastrocnemius (case 2) the biped is unstable and falls.",
                       verdict, ev)


def _check_fig10(r3: SimulationResult, long3: SimulationResult, r1: SimulationResult,
                 slow_pole: float) -> FigureCheck:
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


# ---------------------------------------------------------------------------
# Output directory handling
# ---------------------------------------------------------------------------


def _prepare_out_dir(out_dir: Path) -> list[Path]:
    """Create ``out_dir`` if missing; return the directories created (deepest last)."""
    if out_dir.exists() and not out_dir.is_dir():
        raise PostureLabError(f"output {str(out_dir)!r} exists and is not a directory")
    created: list[Path] = []
    missing = []
    p = out_dir
    while not p.exists():
        missing.append(p)
        if p.parent == p:
            break
        p = p.parent
    if p.exists() and not p.is_dir():
        raise PostureLabError(f"cannot create {str(out_dir)!r}: {str(p)!r} is not a directory")
    for d in reversed(missing):
        try:
            d.mkdir()
        except OSError as exc:
            _remove_dirs(created)
            raise PostureLabError(
                f"cannot create {str(out_dir)!r}: {exc.strerror or exc}") from None
        created.append(d)
    return created


def _remove_dirs(created: list[Path]) -> None:
    for d in reversed(created):
        try:
            d.rmdir()
        except OSError:
            pass


# ---------------------------------------------------------------------------
# The report
# ---------------------------------------------------------------------------


def reproduce_paper(out_dir: str | Path, progress: ProgressCallback | None = None) -> \
        ReproduceReport:
    """Regenerate the paper's Table II, J⁻¹H and Figs. 3–10 into ``out_dir``.

    Parameters
    ----------
    out_dir : str or Path
        Output directory; created (with parents) if missing. Existing files of
        the same names are replaced.
    progress : callable(step, total, message), optional
        Called before each step (the CLI prints ``[step/total] message``).

    Returns
    -------
    ReproduceReport
        Paths written, Table II agreement, figure verdicts, errata, findings.

    Raises
    ------
    PostureLabError
        ``out_dir`` is a file, or cannot be created or written; nothing is
        left behind.
    """
    t_start = time.perf_counter()
    out = Path(out_dir)
    created = _prepare_out_dir(out)
    try:
        tmp = Path(tempfile.mkdtemp(prefix=".posturelab-reproduce-", dir=out))
    except OSError as exc:
        _remove_dirs(created)
        raise PostureLabError(f"cannot write to {str(out)!r}: {exc.strerror or exc}") from None
    try:
        report, names = _build(tmp, progress)
        mode = new_file_mode()
        moved = []
        for name in names:
            os.chmod(tmp / name, mode)  # temporary files are 0600; give the usual umask mode
            os.replace(tmp / name, out / name)
            moved.append(out / name)
    except OSError as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        _remove_dirs(created)
        raise PostureLabError(f"cannot write to {str(out)!r}: {exc.strerror or exc}") from None
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        _remove_dirs(created)
        raise
    shutil.rmtree(tmp, ignore_errors=True)
    return ReproduceReport(
        out_dir=out, index_html=out / "index.html", files=tuple(moved),
        table2_total=report["t2_total"], table2_agree=report["t2_agree"],
        table2_disagreements=report["t2_dis"], sensitivity_agrees=report["sens_ok"],
        checks=report["checks"], errata=ERRATA, findings=report["findings"],
        elapsed=time.perf_counter() - t_start,
    )


def _build(tmp: Path, progress: ProgressCallback | None) -> tuple[dict, list[str]]:
    from ..scenarios import builtin_scenario
    from ..viz.plots import (
        new_figure,
        plot_angle_angle,
        plot_cog_phase,
        plot_pair_torques,
        plot_time_histories,
    )

    total = 19
    step = 0

    def tick(msg: str) -> None:
        nonlocal step
        step += 1
        if progress is not None:
            progress(step, total, msg)

    body = paper_body()
    names = [s.name for s in body.segments]
    foot = FOOT_FROM_LITERATURE

    # -- Tables -------------------------------------------------------------
    tick("Table II: poles of the nine Table I cases, printed vs computed")
    rows = table2_comparison(body)
    sens = sensitivity_comparison(body)
    flexed = np.asarray(BACKWARD_INITIAL_STATE[:3])
    sens_flexed = disturbance_sensitivity(body, flexed)

    # -- Simulations --------------------------------------------------------
    runs: dict[str, SimulationResult] = {}
    scen = {}
    for key, (sname, figs) in _SCENARIOS.items():
        tick(f"simulate {sname} ({figs})")
        scen[key] = builtin_scenario(sname)
        runs[key] = scen[key].run()
    tick(f"simulate paper-forward-case3 continued to {CASE3_LONG_DURATION:g} s")
    long3 = scen["forward3"].run(duration=CASE3_LONG_DURATION, sample_rate=100.0)
    tick("simulate forward case 1 with the real one-sided gastrocnemius (beyond the paper)")
    one_sided_muscles = paper_muscles("1", gastrocnemius="one-sided")
    onesided = scen["forward1"].run(muscles=one_sided_muscles)
    # the same runs with posturelab's own base-of-support fall check (an independent path to
    # the foot finding below: events in the integrator instead of post-processing)
    with_foot = {k: scen[k].run(fall=FallCriteria(scen[k].fall.max_link_angle, foot))
                 for k in ("backward", "forward1")}

    case2_pole = float(analyse(body, paper_muscles("2")).max_real_part)
    case3 = analyse(body, paper_muscles("3"))
    slow3 = float(max(p.real for p in case3.poles if abs(p.imag) < 1e-9))
    act, slack = analyse_both_sides(body, one_sided_muscles)

    # -- Checks -------------------------------------------------------------
    b, f1, f2, f3 = runs["backward"], runs["forward1"], runs["forward2"], runs["forward3"]
    c5, c6 = _check_fig56(b)
    checks = [_check_fig3(b, names), _check_fig4(b), c5, c6, _check_fig7(b),
              _check_fig8(f1, b), _check_fig9(f2, case2_pole),
              _check_fig10(f3, long3, f1, slow3)]

    # -- Figures ------------------------------------------------------------
    images: dict[str, bytes] = {}
    files: list[str] = []

    def save(stem: str, fig) -> None:
        png, svg = _figure_bytes(fig)
        atomic_write_bytes(tmp / f"{stem}.png", png)
        atomic_write_bytes(tmp / f"{stem}.svg", svg)
        images[stem] = png
        files.extend([f"{stem}.png", f"{stem}.svg"])

    foot_label = (f"typical foot, heel {foot.heel:+.3f} m to toe {foot.toe:+.3f} m "
                  "(not in the paper's model)")

    tick("Fig. 3: angles and rates against time (backward, case 1)")
    fig, axes = new_figure(2, 1, figsize=(7.5, 6.0), sharex=True)
    plot_time_histories(b, axes, link_names=names,
                        title="Link angles (absolute from vertical, forward positive)")
    axes[0].xaxis.label.set_visible(False)
    settle = b.settling_time(SETTLE_TOLERANCE)
    if settle is not None:
        for ax in axes:
            ax.axvline(settle, color="0.3", ls="-.", lw=1.0,
                       label=f"all |θ| < {SETTLE_TOLERANCE} rad from t = {settle:.2f} s")
        axes[0].legend(fontsize="small", loc="upper right")
    fig.suptitle("Fig. 3 — backward platform motion (1 m/s step), case 1")
    save("fig03", fig)

    tick("Fig. 4: θ2 and θ3 against θ1")
    fig, ax = new_figure(figsize=(7.0, 5.5))
    plot_angle_angle(b, ax, link_names=names)
    i_max = int(np.argmax(b.theta[:, 0]))
    knee_at = b.theta[i_max, 1] - b.theta[i_max, 0]
    ax.annotate(f"max forward excursion (t = {b.time[i_max]:.2f} s):\n"
                f"knee θ2 − θ1 = {knee_at:+.3f} rad",
                (b.theta[i_max, 0], b.theta[i_max, 1]), xytext=(0.6, 0.2),
                textcoords="axes fraction", fontsize="small",
                arrowprops={"arrowstyle": "->", "color": "0.3"})
    fig.suptitle("Fig. 4 — backward platform motion, case 1: forward sway")
    save("fig04", fig)

    tick("Fig. 5: torques of the ankle, knee, hip and gastrocnemius pairs")
    fig, ax = new_figure(figsize=(7.5, 4.8))
    plot_pair_torques(b, ("ankle", "knee", "hip", "gastrocnemius"), ax,
                      title="Torques of the three single-joint pairs and the gastrocnemius")
    fig.suptitle("Fig. 5 — backward platform motion, case 1")
    save("fig05", fig)

    tick("Fig. 6: torque of the quadriceps (two-joint) pair")
    fig, ax = new_figure(figsize=(7.5, 4.2))
    plot_pair_torques(b, ("quadriceps",), ax,
                      title="Torque of the two-joint quadriceps–hamstring pair")
    fig.suptitle("Fig. 6 — backward platform motion, case 1")
    save("fig06", fig)

    phase = [
        (7, b, "Fig. 7 — backward platform motion, case 1: forward sway"),
        (8, f1, "Fig. 8 — forward platform motion, case 1, artificial antagonist gastrocnemius"),
        (9, f2, "Fig. 9 — forward platform motion, case 2 (no gastrocnemius): falls"),
        (10, f3, "Fig. 10 — forward platform motion, case 3 (no gastrocnemius, 2× ankle)"),
    ]
    for num, run, head in phase:
        tick(f"Fig. {num}: centre-of-gravity phase plane")
        fig, ax = new_figure(figsize=(7.0, 6.2))
        if num == 10:
            ax.plot(long3.cog_position[:, 0], long3.cog_velocity[:, 0], color="0.6", lw=1.0,
                    ls="--", label=f"same run continued to {long3.time[-1]:.0f} s "
                    "(beyond the paper)", zorder=1)
        plot_cog_phase(run, ax, base_of_support=foot, foot_label=foot_label,
                       label=f"centre of gravity, 0–{run.time[-1]:.2f} s")
        fig.suptitle(head)
        save(f"fig{num:02d}", fig)

    tick("Beyond the paper: the real one-sided gastrocnemius in the forward case 1")
    fig, ax = new_figure(figsize=(7.0, 6.8))
    plot_cog_phase(f1, ax, base_of_support=foot, foot_label=foot_label,
                   label="two-sided gastrocnemius (the paper's artificial antagonist)",
                   color="#1f77b4")
    plot_cog_phase(onesided, ax, label="one-sided gastrocnemius (acts only while θ2 ≥ 0)",
                   color="#d62728")
    fig.suptitle("Forward platform motion, case 1: artificial vs real gastrocnemius")
    save("beyond1", fig)

    # -- Findings beyond the paper ----------------------------------------------
    ex = {k: _foot_excursion(r, foot) for k, r in runs.items()}
    findings = []
    theta2_max = float(onesided.theta[:, 1].max())
    engaged = theta2_max >= 0.0
    findings.append(
        "The real gastrocnemius pulls one way only (it acts while θ2 ≥ 0). In the forward case 1 "
        "run with it, "
        + (f"θ2 reaches {theta2_max:+.3f} rad, so the pair acts at times, "
           if engaged else
           f"θ2 stays negative (max θ2 = {theta2_max:+.3f} rad), so the pair never acts, ")
        + f"and the biped {_outcome(onesided)}; case 2 {_outcome(f2)}. Linearised on its "
        f"slack side (θ2 < 0), case 1 has the poles of case 2 (largest real part "
        f"{slack.max_real_part:+.3f} 1/s against {case2_pole:+.3f} 1/s; on the acting side "
        f"{act.max_real_part:+.3f} 1/s). On the slack side case 1 is case 2: the paper's Fig. 8 "
        "recovers only because of the artificial antagonist."
    )
    parts = []
    for key, label in (("backward", "backward, case 1 (Figs. 3–7)"),
                       ("forward1", "forward, case 1 (Fig. 8)"),
                       ("forward2", "forward, case 2 (Fig. 9)"),
                       ("forward3", "forward, case 3 (Fig. 10)")):
        e = ex[key]
        ratio = (f"{e['max'] / foot.toe:.2f} × the toe's distance in front of the ankle"
                 if e["max"] / foot.toe >= e["min"] / foot.heel else
                 f"{e['min'] / foot.heel:.2f} × the heel's distance behind it")
        txt = f"{label}: x_c from {_m(e['min'])} to {_m(e['max'])} m ({ratio})"
        if e["t_out"] is not None:
            txt += (f"; it leaves the foot past the {e['side']} at t = {e['t_out']:.2f} s "
                    f"and is outside for {e['time_out']:.2f} s in total")
        else:
            txt += "; it stays over the foot"
        parts.append(txt)
    def _stops(r: SimulationResult) -> str:
        if r.fell:
            return f"stops at t = {r.fall_time:.2f} s ({r.fall_reason})"
        return "does not stop"

    n_out = sum(e["t_out"] is not None for e in ex.values())
    checks_txt = (f"the backward run {_stops(with_foot['backward'])}; the forward case 1 run "
                  f"{_stops(with_foot['forward1'])}")
    findings.append(
        f"How far the centre of gravity travels, against a typical foot (heel {_m(foot.heel)} m, "
        f"toe {_m(foot.toe)} m from the ankle: foot length 0.152 H for H = 1.65 m, Winter 2009; "
        "ankle at a quarter of the foot from the heel): " + "; ".join(parts) + ". The paper's "
        "foot cannot tip. With a real foot, the static criterion (the centre of gravity's "
        "ground projection must stay between heel and toe) fails in "
        + (f"all {n_out}" if n_out == len(ex) else f"{n_out} of {len(ex)}")
        + " of these runs"
        + (": a 1 m/s platform step is beyond the ankle strategy alone; a step or a hip "
           "strategy would be needed" if n_out == len(ex) else "")
        + ". Rerun with posturelab's base-of-support fall check "
        f"(FallCriteria(base_of_support=FOOT_FROM_LITERATURE)), {checks_txt}.")

    tick("largest recoverable platform move, with a foot that can tip (beyond the paper)")
    findings.append(_recovery_finding(body, foot))
    tick("neural delay the paper's case 1 gains tolerate (beyond the paper)")
    findings.append(_delay_finding(scen["backward"]))

    # -- Table II CSV ---------------------------------------------------------
    tick("write table2.csv and index.html")
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["case", "column", "printed", "computed_re", "computed_im", "agrees", "erratum"])
    t2_total = t2_agree = 0
    dis = []
    for row in rows:
        for k, p in enumerate(row.poles, start=1):
            t2_total += 1
            t2_agree += p.agrees
            w.writerow([row.case, k, p.printed, f"{p.computed.real:.6f}",
                        f"{p.computed.imag:.6f}", "yes" if p.agrees else "no",
                        "" if p.erratum is None else p.erratum])
            if not p.agrees:
                dis.append((row.case, k, p.printed, p.computed, p.erratum))
    atomic_write_text(tmp / "table2.csv", buf.getvalue())
    files.append("table2.csv")

    page = _html(body, rows, sens, sens_flexed, flexed, checks, images, findings,
                 t2_total, t2_agree, f2, f3, long3)
    atomic_write_text(tmp / "index.html", page)
    files.append("index.html")
    return ({"t2_total": t2_total, "t2_agree": t2_agree, "t2_dis": tuple(dis),
             "sens_ok": bool(sens.agrees), "checks": tuple(checks),
             "findings": tuple(findings)}, files)


#: Ramp-and-hold duration for the recovery finding. [s]
RECOVERY_RAMP_DURATION = 0.5
#: Bracket of neural delays searched for case 1. [s]
DELAY_BRACKET = (0.002, 0.03)


def _recovery_finding(body: Body, foot: BaseOfSupport) -> str:
    """Largest backward ramp-and-hold case 1 recovers from, by the CoP and the CoG criteria."""
    from ..model.muscles import paper_muscles
    from ..model.platform import RampAndHold
    from ..simulation.reference import FallCriteria, simulate
    from ..studies.recovery import largest_recoverable

    muscles = paper_muscles("1")

    def runner(cop: bool):
        fall = FallCriteria(base_of_support=foot, centre_of_pressure=cop)
        return lambda d: simulate(body, muscles, RampAndHold(-d, RECOVERY_RAMP_DURATION), 4.0,
                                  fall=fall, sample_rate=50.0)

    by_cop = largest_recoverable(runner(True), 0.01, 1.0, tolerance=1e-3)
    by_cog = largest_recoverable(runner(False), 0.01, 1.0, tolerance=1e-3)
    return (
        "Largest recoverable perturbation (posturelab.recovery.largest_recoverable): case 1, "
        f"the platform moved backward and held over {RECOVERY_RAMP_DURATION:g} s, the typical "
        f"foot above. The foot tips (centre of pressure past the toe) beyond a "
        f"{by_cop.estimate * 100:.1f} cm move; the centre of gravity leaves the foot only beyond "
        f"{by_cog.estimate * 100:.1f} cm. The static criterion overestimates what the ankle "
        f"strategy absorbs by a factor {by_cog.estimate / by_cop.estimate:.1f}."
    )


def _delay_finding(backward) -> str:
    """Largest neural delay of the muscle feedback case 1 survives, by bisection."""
    lo, hi = DELAY_BRACKET
    sc = backward.replace(duration=1.5, sample_rate=100.0)
    if sc.run(feedback_delay=lo).fell or not sc.run(feedback_delay=hi).fell:
        return "Neural delay: the bracket of delays searched did not bracket a fall."
    while hi - lo > 1e-3:
        mid = 0.5 * (lo + hi)
        if sc.run(feedback_delay=mid).fell:
            hi = mid
        else:
            lo = mid
    return (
        "Neural delay (feedback_delay): with every muscle pair responding to the state "
        f"delayed by τ, the backward case 1 run survives τ = {lo * 1000:.0f} ms but falls at "
        f"τ = {hi * 1000:.0f} ms. The paper itself cites 70–120 ms onsets for the muscle "
        "responses to a platform perturbation (Section III.A), so its gains, whose fast modes "
        "(poles near −554 and −89 1/s) come from large viscosity acting on light links, can "
        "only be read as instantaneous, intrinsic (muscle) impedance, not as reflexes."
    )


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;max-width:1000px;
margin:2em auto;padding:0 1em;line-height:1.45;color:#222}
h1{font-size:1.6em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:2em}
table{border-collapse:collapse;margin:1em 0;font-size:.92em}
th,td{border:1px solid #bbb;padding:.25em .5em;text-align:right}
th{background:#f0f0f0}td.l,th.l{text-align:left}
td.bad{background:#ffd6d6;font-weight:bold}td.unst{color:#b00000}
.cell small{color:#555;display:block}
figure{margin:1.5em 0;padding:1em;border:1px solid #ddd;border-radius:6px}
figure img{max-width:100%;height:auto}
figcaption{font-size:.95em}
.caption{font-style:italic;color:#333}
.v-supported{color:#116611;font-weight:bold}.v-partly{color:#aa6600;font-weight:bold}
.v-not{color:#b00000;font-weight:bold}
.note{background:#f7f7f7;border-left:4px solid #999;padding:.5em 1em}
code{background:#f3f3f3;padding:0 .2em}
"""


def _e(text) -> str:
    return html.escape(str(text), quote=True)


def _verdict_class(v: str) -> str:
    return ("v-supported" if v == "supported" else "v-partly" if v.startswith("partly")
            else "v-not")


def _html(body: Body, rows: list[Table2Row], sens, sens_flexed, flexed, checks,
          images, findings, t2_total, t2_agree, f2, f3, long3) -> str:
    from .. import __version__

    h: list[str] = []
    a = h.append
    a("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>")
    a("<title>posturelab: reproducing the ankle-strategy paper</title>")
    a(f"<style>{_CSS}</style></head><body>")
    a("<h1>Reproducing “Quantitative Analysis of the Ankle Strategy Under Translational "
      "Platform Disturbance”</h1>")
    a(f"<p>Generated by posturelab {_e(__version__)}. Every number below is computed by "
      "posturelab and shown beside what the paper prints; a disagreement is flagged, never "
      "silently corrected. Conventions: SI units; link angles θ absolute from the vertical, "
      "positive leaning forward; link 1 leg, 2 thigh, 3 torso; x forward, y up; a backward "
      "platform motion makes the body sway forward.</p>")
    n_dis = t2_total - t2_agree
    a("<p class='note'>Summary: "
      f"{t2_agree} of {t2_total} Table II poles agree with the linearised model to the printed "
      f"digits ({n_dis} disagree, each explained by an erratum). J(0)⁻¹H(0) "
      f"{'agrees' if sens.agrees else 'disagrees'}. Figures: "
      + ", ".join(f"Fig. {c.number} <span class='{_verdict_class(c.verdict)}'>"
                  f"{_e(c.verdict)}</span>" for c in checks)
      + f". {len(ERRATA)} errata are listed below.</p>")

    # Body
    a("<h2>Body (Appendix A)</h2><table><tr><th class='l'>link</th><th>mass m [kg]</th>"
      "<th>length l [m]</th><th>CoM distance k [m]</th><th>inertia I [kg·m²]</th></tr>")
    for s in body.segments:
        a(f"<tr><td class='l'>{_e(s.name)}</td><td>{s.mass:.2f}</td><td>{s.length:.3f}</td>"
          f"<td>{s.com_distance:.2f}</td><td>{s.inertia:.2f}</td></tr>")
    a(f"</table><p>Total mass {body.total_mass:.2f} kg; centre of gravity {body.com_height:.3f} "
      f"m above the ankle when upright; load stiffness mgh = g Σa<sub>i</sub> = "
      f"{body.load_stiffness:.1f} N·m/rad.</p>")

    # Table I
    load = body.load_stiffness
    a(f"<h2>Table I — muscle synergies (stiffness K [N·m/rad])</h2><p>{_e(TABLE_I_CITATION)}. "
      "Viscosity L = 0.25 s × K. The last column gives the ankle stiffness as a fraction of "
      "mgh, as the postural-control literature reports it (erratum 6).</p>")
    a("<table><tr><th class='l'>case</th>" + "".join(f"<th>{_e(n)}</th>"
                                                    for n in PAPER_PAIR_NAMES)
      + "<th>ankle K / mgh [-]</th></tr>")
    for case, ks in STIFFNESS_CASES.items():
        a(f"<tr><td class='l'>{_e(case)}</td>" + "".join(f"<td>{k:.0f}</td>" for k in ks)
          + f"<td>{ks[0] / load:.2f}</td></tr>")
    a("</table>")

    # Table II
    a(f"<h2>Table II — poles of the linearised system [1/s]</h2><p>{_e(TABLE_II_SOURCE)}. "
      "Each cell: the printed pole, and below it the computed pole paired with it. A cell is "
      "<span style='background:#ffd6d6'>highlighted</span> when the two differ by more than "
      "half a unit of the last printed digit; [n] is the erratum. Also in "
      "<a href='table2.csv'>table2.csv</a>.</p>")
    a("<table><tr><th class='l'>case</th>" + "".join(f"<th>pole {k}</th>" for k in range(1, 7))
      + "<th>stable</th></tr>")
    for row in rows:
        cells = []
        for p in row.poles:
            cls = "" if p.agrees else " bad"
            unst = " unst" if p.computed.real > 0 else ""
            tag = f" [{p.erratum}]" if (p.erratum and not p.agrees) else ""
            cells.append(f"<td class='cell{cls}{unst}'>{_e(p.printed.replace('j', 'i'))}{_e(tag)}"
                         f"<small>{_e(_fmt_pole(p.computed, 3))}</small></td>")
        a(f"<tr><td class='l'>{_e(row.case)}</td>{''.join(cells)}"
          f"<td>{'yes' if row.stable else '<b>no</b>'}</td></tr>")
    a("</table>")
    for n in sorted({p.erratum for r in rows for p in r.poles if p.erratum and not p.agrees}):
        e = erratum(n)
        a(f"<p class='note'>[{n}] {_e(e.where)}: printed {_e(e.printed)}, computed "
          f"{_e(e.derived)}. {_e(e.explanation)}</p>")

    # J^-1 H
    a("<h2>Disturbance severity J⁻¹H [rad/m]</h2><p>A platform velocity step Δẋ<sub>d</sub> "
      "changes the link rates by −J⁻¹H Δẋ<sub>d</sub>. The paper prints J(0)⁻¹H(0) and uses it "
      "as the initial rates although the initial posture is flexed (erratum 5).</p>")
    a("<table><tr><th class='l'></th><th>link 1</th><th>link 2</th><th>link 3</th></tr>")
    a("<tr><td class='l'>printed (upright)</td>" + "".join(f"<td>{_e(s)}</td>"
                                                          for s in SENSITIVITY_PRINTED) + "</tr>")
    a("<tr><td class='l'>computed, upright Θ = 0</td>" + "".join(
        f"<td{'' if sens.agrees else ' class=bad'}>{v:.4f}</td>" for v in sens.computed)
      + "</tr>")
    a(f"<tr><td class='l'>computed, flexed Θ = {_e(_vec(flexed, 1))} rad</td>"
      + "".join(f"<td class='bad'>{v:.3f}</td>" for v in sens_flexed) + "</tr></table>")
    a(f"<p>At upright the computed vector {'agrees' if sens.agrees else 'disagrees'} with the "
      "printed one to its printed digits. At the flexed posture of the simulations it is "
      f"{_e(_vec(sens_flexed))}: the knee and hip rates even change sign. posturelab reproduces "
      "the paper's choice (<code>rates_from = \"upright\"</code>) and offers the exact one "
      "(<code>\"posture\"</code>).</p>")

    # Figures
    a("<h2>Figures 3–10</h2><p>The runs are the built-in scenarios "
      "<code>paper-backward-case1</code> (Figs. 3–7), <code>paper-forward-case1</code> "
      "(Fig. 8), <code>paper-forward-case2</code> (Fig. 9) and <code>paper-forward-case3</code> "
      "(Fig. 10): a 1 m/s platform velocity step (the paper's 'unit impulse'), initial posture "
      "[0.1, −0.1, 0.1] rad, rates from J(0)⁻¹H(0), knee free, the paper's foot (which cannot "
      "tip). The paper does not print the forward initial state; we take the backward one with "
      "the rates negated. Figs. 7–10 also shade a typical foot, which is not in the paper's "
      "model (see the findings below). Each figure is also available as PNG and SVG.</p>")
    for c in checks:
        png = base64.b64encode(images[c.filename]).decode("ascii")
        a(f"<figure id='{c.filename}'><img alt='Fig. {c.number}' "
          f"src='data:image/png;base64,{png}'>")
        a(f"<figcaption><p class='caption'>Paper, Fig. {c.number}: “{_e(c.caption)}”</p>")
        a(f"<p><b>Claim tested:</b> {_e(c.claim)}<br><b>Our run:</b> "
          f"<span class='{_verdict_class(c.verdict)}'>{_e(c.verdict)}</span>. {_e(c.evidence)}"
          f"</p><p><a href='{c.filename}.png'>PNG</a> · <a href='{c.filename}.svg'>SVG</a>"
          "</p></figcaption></figure>")

    # Errata
    a("<h2>Errata</h2><p>Places where the printed paper disagrees with a derivation or with "
      "itself (posturelab.paper.ERRATA).</p><ol>")
    for e in ERRATA:
        extra = ""
        if e.number == 4:
            extra = (" Our runs: case 2 (Fig. 9) "
                     + (f"falls at t = {f2.fall_time:.3f} s" if f2.fell else "does not fall")
                     + "; case 3 (Fig. 10) "
                     + ("falls" if f3.fell else
                        f"does not fall and settles after "
                        f"{long3.settling_time(SETTLE_TOLERANCE) or float('nan'):.1f} s")
                     + ".")
        a(f"<li value='{e.number}'><b>{_e(e.where)}</b>: printed <code>{_e(e.printed)}</code>; "
          f"should read <code>{_e(e.derived)}</code>. {_e(e.explanation)}{_e(extra)}</li>")
    a("</ol>")

    # Beyond
    a("<h2>Beyond the paper</h2>")
    png = base64.b64encode(images["beyond1"]).decode("ascii")
    a(f"<figure id='beyond1'><img alt='one-sided gastrocnemius' "
      f"src='data:image/png;base64,{png}'><figcaption><p>{_e(findings[0])}</p>"
      "<p><a href='beyond1.png'>PNG</a> · <a href='beyond1.svg'>SVG</a></p>"
      "</figcaption></figure>")
    for f in findings[1:]:
        a(f"<p>{_e(f)}</p>")
    a("</body></html>")
    return "\n".join(h)
