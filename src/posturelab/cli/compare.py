"""``posturelab compare``: overlay saved runs in one figure and tabulate them."""

from __future__ import annotations

import argparse

from ._common import FIGURE_SUFFIXES, check_writable, print_json

DESCRIPTION = """\
Read runs written by posturelab simulate --out (columns t, theta1..N, omega1..N), print for
each its samples, end time, largest |θ_i| [rad] and final state, and with --plot draw one
panel per link angle with every run overlaid (one colour and one legend entry per run;
--rates for the angular rates). --labels names the runs (comma separated; default the file
names). --json prints one object per run.

Example: posturelab compare case1.csv case3.csv --labels "case 1,case 3" --plot cmp.png
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab compare``."""
    p.add_argument("runs", nargs="+", metavar="RUN.csv", help="runs saved by simulate --out.")
    p.add_argument("--labels", metavar="A,B,...", help="one label per run.")
    p.add_argument("--plot", metavar="FILE.png", help="write the overlay (PNG/SVG/PDF).")
    p.add_argument("--rates", action="store_true", help="plot the rates, not the angles.")
    p.add_argument("--json", action="store_true", help="print one JSON object.")


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    import numpy as np

    from ..errors import ParameterError
    from ..simulation.results import read_run_csv

    if args.plot:
        check_writable([args.plot], {args.plot: FIGURE_SUFFIXES})
    labels = ([s.strip() for s in args.labels.split(",")] if args.labels
              else [Path(p).name for p in args.runs])
    if len(labels) != len(args.runs):
        raise ParameterError(f"--labels needs one label per run: {len(args.runs)} runs, "
                             f"{len(labels)} labels")
    runs = [read_run_csv(p) for p in args.runs]
    rows = [{"label": label, "file": path, "samples": int(t.size), "end_time": float(t[-1]),
             "max_abs_theta": [float(v) for v in np.abs(th).max(axis=0)],
             "final_state": [float(v) for v in np.concatenate([th[-1], om[-1]])]}
            for label, path, (t, th, om) in zip(labels, args.runs, runs, strict=True)]
    if args.plot:
        from ..viz.plots import plot_compare, save_figure

        save_figure(plot_compare(runs, labels, rates=args.rates), args.plot)
    if args.json:
        print_json({"runs": rows})
        return 0
    for r in rows:
        peaks = ", ".join(f"{v:.4f}" for v in r["max_abs_theta"])
        print(f"{r['label']}: {r['samples']} samples to {r['end_time']:g} s; peak |θ| [rad] "
              f"{peaks}")
    if args.plot:
        print(f"wrote {args.plot}")
    return 0
