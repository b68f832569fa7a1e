"""``reproduce_paper``: regenerate the paper's tables and figures, check its claims, and
render the report.

One call computes Table II (printed beside computed, disagreements flagged
with their erratum), the disturbance-severity vector J⁻¹H (at upright and at
the flexed initial posture), runs the four built-in paper scenarios
(Figs. 3–10) and the real one-sided gastrocnemius in the forward case
(:mod:`.runs`), computes the verdicts and the findings (:mod:`.checks`), draws
Figs. 3–10 (:mod:`.figures`), and writes into a directory:

* ``index.html`` — self-contained (figures embedded as base64 PNG): Table I,
  Table II, J⁻¹H, each figure with the paper's caption, the claim tested, the verdict
  and the numbers behind it, the errata, and findings beyond the paper;
* ``table2.csv`` — one row per printed pole (54): case, column, printed,
  computed_re, computed_im, agrees, erratum;
* ``fig03.png`` … ``fig10.png`` and ``.svg``, and ``beyond1.png/.svg``.

Everything is built in a hidden temporary directory inside the output
directory and then renamed into place file by file, so a failure (or an
interrupt) leaves no half-written file; a directory created by the call is
removed again on failure.
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
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import PostureLabError
from ..model.body import paper_body
from ..model.muscles import PAPER_PAIR_NAMES, STIFFNESS_CASES, TABLE_I_CITATION
from ..simulation.results import atomic_write_bytes, atomic_write_text, new_file_mode
from . import checks as _checks
from . import figures as _figures
from .checks import (
    FIGURE_CAPTIONS,
    PAPER_SETTLING_CLAIM,
    SETTLE_TOLERANCE,
    FigureCheck,
    PaperChecks,
    Table2Check,
    Table2Disagreement,
)
from .printed import ERRATA, SENSITIVITY_PRINTED, TABLE_II_SOURCE, Erratum
from .runs import RUN_STEPS, run_paper

__all__ = [
    "FIGURE_CAPTIONS",
    "FigureCheck",
    "ReproduceReport",
    "reproduce_paper",
    "render_index",
    "table2_csv",
    "ProgressCallback",
    "SETTLE_TOLERANCE",
    "PAPER_SETTLING_CLAIM",
]

#: progress(step, total, message): called before each step of :func:`reproduce_paper`.
ProgressCallback = Callable[[int, int, str], None]

#: Steps :func:`reproduce_paper` reports: Table II, the runs, the figures, the two searches,
#: the writing. [-]
_TOTAL_STEPS = 1 + RUN_STEPS + len(_figures.FIGURE_STEPS) + 2 + 1


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
    table2_disagreements : tuple of Table2Disagreement
        (case, column 1–6, printed, computed [1/s], erratum number or None).
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
    details : PaperChecks or None
        Everything computed, as data (:mod:`posturelab.paper.checks`).
    """

    out_dir: Path
    index_html: Path
    files: tuple[Path, ...]
    table2_total: int
    table2_agree: int
    table2_disagreements: tuple[Table2Disagreement, ...]
    sensitivity_agrees: bool
    checks: tuple[FigureCheck, ...]
    errata: tuple[Erratum, ...]
    findings: tuple[str, ...] = field(default_factory=tuple)
    elapsed: float = 0.0
    details: PaperChecks | None = field(default=None, repr=False, compare=False)

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
# Rendering
# ---------------------------------------------------------------------------


def _fmt_pole(z: complex, digits: int = 2) -> str:
    z = complex(z)
    if abs(z.imag) < 10 ** (-digits - 3):
        return f"{z.real:.{digits}f}"
    return f"{z.real:.{digits}f} {'+' if z.imag >= 0 else '−'} {abs(z.imag):.{digits}f}i"


def _vec(v, digits: int = 3) -> str:
    return "[" + ", ".join(f"{x:.{digits}f}" for x in np.asarray(v, dtype=float)) + "]"


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


def render_index(paper: PaperChecks, images: Mapping[str, bytes],
                 version: str | None = None) -> str:
    """The report page.

    Parameters
    ----------
    paper : PaperChecks
        Everything computed.
    images : mapping of str to bytes
        PNG of each figure, by stem (``"fig03"`` … ``"fig10"``, ``"beyond1"``).
    version : str, optional
        The posturelab version named on the page; the installed one by default.
    """
    if version is None:
        from .. import __version__ as version
    body, rows, checks = paper.body, paper.table2.rows, paper.figures
    sens, sens_flexed = paper.sensitivity.upright, paper.sensitivity.flexed
    flexed, findings = paper.sensitivity.flexed_posture, paper.finding_texts
    t2_total, t2_agree = paper.table2.total, paper.table2.agree

    h: list[str] = []
    a = h.append
    a("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>")
    a("<title>posturelab: reproducing the ankle-strategy paper</title>")
    a(f"<style>{_CSS}</style></head><body>")
    a("<h1>Reproducing “Quantitative Analysis of the Ankle Strategy Under Translational "
      "Platform Disturbance”</h1>")
    a(f"<p>Generated by posturelab {_e(version)}. Every number below is computed by "
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
        e = next(x for x in ERRATA if x.number == n)
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
        note = paper.erratum_notes.get(e.number)
        extra = f" {note}" if note else ""
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


def table2_csv(table2: Table2Check) -> str:
    """``table2.csv``: one row per printed pole (case, column, printed, computed_re,
    computed_im [1/s], agrees, erratum)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["case", "column", "printed", "computed_re", "computed_im", "agrees", "erratum"])
    for row in table2.rows:
        for k, p in enumerate(row.poles, start=1):
            w.writerow([row.case, k, p.printed, f"{p.computed.real:.6f}",
                        f"{p.computed.imag:.6f}", "yes" if p.agrees else "no",
                        "" if p.erratum is None else p.erratum])
    return buf.getvalue()


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
        paper, names = _build(tmp, progress)
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
        table2_total=paper.table2.total, table2_agree=paper.table2.agree,
        table2_disagreements=paper.table2.disagreements,
        sensitivity_agrees=paper.sensitivity.agrees, checks=paper.figures, errata=ERRATA,
        findings=paper.finding_texts, elapsed=time.perf_counter() - t_start, details=paper,
    )


def _build(tmp: Path, progress: ProgressCallback | None) -> tuple[PaperChecks, list[str]]:
    """Compute, draw and write every file into ``tmp``; return what was found and the file
    names."""
    step = 0

    def tick(msg: str) -> None:
        nonlocal step
        step += 1
        if progress is not None:
            progress(step, _TOTAL_STEPS, msg)

    body = paper_body()
    names = [s.name for s in body.segments]

    tick("Table II: poles of the nine Table I cases, printed vs computed")
    table2 = _checks.table2_check(body)
    sensitivity = _checks.sensitivity_check(body)

    runs = run_paper(tick)
    linear = _checks.linear_facts(body)
    figure_checks = _checks.figure_checks(runs, linear, names)

    files: list[str] = []

    def save(image: _figures.FigureImage) -> None:
        atomic_write_bytes(tmp / f"{image.stem}.png", image.png)
        atomic_write_bytes(tmp / f"{image.stem}.svg", image.svg)
        files.extend([f"{image.stem}.png", f"{image.stem}.svg"])

    images = _figures.render_figures(runs, names, tick=tick, done=save)

    findings = [_checks.one_sided_finding(runs, linear), _checks.foot_finding(runs)]
    tick("largest recoverable platform move, with a foot that can tip (beyond the paper)")
    findings.append(_checks.recovery_finding(body, runs.foot))
    tick("neural delay the paper's case 1 gains tolerate (beyond the paper)")
    findings.append(_checks.delay_finding(runs.scenarios["backward"]))

    tick("write table2.csv and index.html")
    paper = PaperChecks(body, table2, sensitivity, figure_checks, tuple(findings),
                        _checks.erratum_notes(runs))
    atomic_write_text(tmp / "table2.csv", table2_csv(table2))
    files.append("table2.csv")
    atomic_write_text(tmp / "index.html",
                      render_index(paper, {k: v.png for k, v in images.items()}))
    files.append("index.html")
    return paper, files
