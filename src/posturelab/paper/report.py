"""``reproduce_paper``: regenerate the paper's tables and figures, check its claims, and
render the report.

One call computes Table II (printed beside computed, disagreements flagged
with their erratum), the disturbance-severity vector J⁻¹H (at upright and at
the flexed initial posture), runs the four built-in paper scenarios
(Figs. 3–10) and the real one-sided gastrocnemius in the forward case
(:mod:`.runs`), computes the verdicts and the findings (:mod:`posturelab.paper.checks`), draws
Figs. 3–10 (:mod:`.figures`), and writes into a directory:

* ``index.html`` — self-contained (figures embedded as base64 PNG), rendered
  from the Jinja2 template ``templates/report.html.j2``: Table I, Table II,
  J⁻¹H, each figure with the paper's caption, the claim tested, the verdict
  and the numbers behind it, the errata, and findings beyond the paper;
* ``table2.csv`` — one row per printed pole (54): case, column, printed,
  computed_re, computed_im, agrees, erratum;
* ``fig03.png`` … ``fig10.png`` and ``.svg``, and ``beyond1``, ``frf`` (tilt FRFs) and
  ``prts`` (the PRTS cycle averages) ``.png/.svg``.

Everything is built in a hidden temporary directory inside the output
directory and then renamed into place file by file, so a failure (or an
interrupt) leaves no half-written file; a directory created by the call is
removed again on failure.
"""

from __future__ import annotations

import base64
import csv
import io
import os
import shutil
import signal
import tempfile
import threading
import time
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..errors import PostureLabError
from ..model.body import paper_body
from ..model.muscles import PAPER_PAIR_NAMES, STIFFNESS_CASES, TABLE_I_CITATION
from ..simulation.results import atomic_write_bytes, atomic_write_text, new_file_mode
from . import checks as _checks
from . import figures as _figures
from .beyond_ankle import beyond_ankle_finding
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

#: The report page's template, in ``templates/`` beside this module.
TEMPLATE = "report.html.j2"

#: Steps :func:`reproduce_paper` reports: Table II, the runs, the figures, the five searches,
#: the writing. [-]
_TOTAL_STEPS = 1 + RUN_STEPS + len(_figures.FIGURE_STEPS) + 5 + 1


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


def _num(x: float, digits: int) -> str:
    return f"{x:.{digits}f}"


def _verdict_class(v: str) -> str:
    return ("v-supported" if v == "supported" else "v-partly" if v.startswith("partly")
            else "v-not")


def _b64(data: bytes) -> str:
    return base64.b64encode(data).decode("ascii")


@lru_cache(maxsize=1)
def _environment():
    import jinja2

    env = jinja2.Environment(
        loader=jinja2.PackageLoader("posturelab.paper", "templates"),
        autoescape=True, undefined=jinja2.StrictUndefined,
        trim_blocks=True, lstrip_blocks=True,
    )
    env.filters.update(num=_num, pole=lambda z: _fmt_pole(z, 3), vec=_vec,
                       verdict_class=_verdict_class, b64=_b64)
    return env


def render_index(paper: PaperChecks, images: Mapping[str, bytes],
                 version: str | None = None) -> str:
    """The report page, rendered from :data:`TEMPLATE` with autoescape on.

    Parameters
    ----------
    paper : PaperChecks
        Everything computed.
    images : mapping of str to bytes
        PNG of each figure, by stem (``"fig03"`` … ``"fig10"``, ``"beyond1"``, ``"frf"``,
        ``"prts"``).
    version : str, optional
        The posturelab version named on the page; the installed one by default.

    Returns
    -------
    str
        The HTML page.
    """
    if version is None:
        from .. import __version__ as version
    return _environment().get_template(TEMPLATE).render(
        version=version, body=paper.body, table2=paper.table2, sensitivity=paper.sensitivity,
        figures=paper.figures, findings=paper.finding_texts, erratum_notes=paper.erratum_notes,
        errata=ERRATA, errata_by_number={e.number: e for e in ERRATA},
        pair_names=PAPER_PAIR_NAMES, stiffness_cases=STIFFNESS_CASES,
        table1_citation=TABLE_I_CITATION, table2_source=TABLE_II_SOURCE,
        sensitivity_printed=SENSITIVITY_PRINTED, images=images,
    )


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


@contextmanager
def _terminate_raises() -> Iterator[None]:
    """While inside, SIGTERM raises ``SystemExit(143)`` instead of ending the process at once,
    so that the temporary files are removed; only in the main thread, and only where
    SIGTERM still has its default action."""
    if threading.current_thread() is not threading.main_thread() or \
            signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL:
        yield
        return

    def terminate(signum, frame):
        raise SystemExit(128 + signum)

    signal.signal(signal.SIGTERM, terminate)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)


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

    Notes
    -----
    An interrupt (KeyboardInterrupt, or SIGTERM, which raises ``SystemExit(143)``
    while the call runs in the main thread) also leaves nothing behind.
    """
    with _terminate_raises():
        return _reproduce(Path(out_dir), progress)


def _reproduce(out: Path, progress: ProgressCallback | None) -> ReproduceReport:
    t_start = time.perf_counter()
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
    backward = runs.scenarios["backward"]
    findings.append(_checks.with_delay_margin(_checks.delay_finding(backward), backward))
    tick("a delayed controller from the literature, and the hip strategy (beyond the paper)")
    findings.append(_checks.literature_controller_finding(runs.foot))
    findings.append(_checks.strategy_finding(body, runs.foot))
    tick("the hip strategy under a multi-joint controller, and the step threshold by age "
         "(beyond the paper)")
    findings.append(beyond_ankle_finding(body))
    tick("frequency responses to tilt, and a simulated PRTS experiment fitted (beyond the paper)")
    findings.append(_checks.frf_finding())

    tick("write table2.csv and index.html")
    paper = PaperChecks(body, table2, sensitivity, figure_checks, tuple(findings),
                        _checks.erratum_notes(runs))
    atomic_write_text(tmp / "table2.csv", table2_csv(table2))
    files.append("table2.csv")
    atomic_write_text(tmp / "index.html",
                      render_index(paper, {k: v.png for k, v in images.items()}))
    files.append("index.html")
    return paper, files
