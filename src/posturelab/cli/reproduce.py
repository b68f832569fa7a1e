"""``posturelab reproduce``: regenerate the paper's tables and figures as an HTML report."""

from __future__ import annotations

import argparse
import sys

DESCRIPTION = """\
Regenerate the ankle-strategy paper into DIR: Table II (printed beside computed,
disagreements flagged with their erratum), the disturbance-severity vector J⁻¹H,
Figs. 3–10 from the built-in paper scenarios, each with the paper's caption and
whether our run supports it (with numbers), the errata, and findings beyond the
paper (the real one-sided gastrocnemius; the centre of gravity against a typical
foot).

Writes DIR/index.html (self-contained), DIR/table2.csv, DIR/fig03.png … fig10.png
and .svg. DIR is created if missing; files are built in a temporary directory and
renamed into place, so a failure leaves nothing half-written. Progress goes to
standard error; the path of index.html and a one-paragraph summary to standard
output.
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab reproduce``."""
    p.add_argument("--out", required=True, metavar="DIR",
                   help="output directory (created if missing; must not be a file).")
    p.add_argument("--quiet", action="store_true", help="no progress lines on standard error.")


def run(args: argparse.Namespace) -> int:
    from .._progress import Progress
    from ..paper.report import reproduce_paper

    bar = None if args.quiet else Progress(label="reproduce", unit="steps", every_step=True)

    def progress(step: int, total: int, message: str) -> None:
        bar(step - 1, total, message)  # (called before step ``step`` starts)

    try:
        report = reproduce_paper(args.out, progress=None if bar is None else progress)
        if bar is not None:
            bar(bar.total or 0, bar.total or 0, "done")
    finally:
        if bar is not None:
            bar.close()
    if not args.quiet:
        print(f"done in {report.elapsed:.1f} s", file=sys.stderr)
    print(report.index_html)
    print(report.summary())
    return 0
