"""``posturelab compare``: overlay saved runs in one figure and tabulate them."""

from __future__ import annotations

import argparse

from ._common import FIGURE_SUFFIXES, check_writable, print_json
from ._flags import add_flag, add_flags

DESCRIPTION = """\
Read runs written by posturelab simulate --out (columns t, theta1..N, omega1..N), print for
each its samples, end time, largest |θ_i| [rad] and final state, and with --plot draw one
panel per link angle with every run overlaid (one colour and one legend entry per run;
--rates for the angular rates). --labels names the runs (comma separated; default the file
names). Then each later run against the first: the largest |Δθ_i| [rad] over the time both
cover (the later run interpolated at the first run's samples), the difference of the
peaks |θ_i| [rad] and of the end times [s]. --json prints one object: "runs" (one object
per run) and "differences" (one per later run, with its "units").

Example: posturelab compare case1.csv case3.csv --labels "case 1,case 3" --plot cmp.png
"""


#: Units of the numbers of one entry of "differences". [-]
DIFFERENCE_UNITS = {"common_time": "s", "max_abs_theta_difference": "rad",
                    "peak_difference": "rad", "end_time_difference": "s"}


def run_difference(first, other) -> dict:
    """How run ``other`` differs from run ``first`` (each (t [s], θ [rad], θ̇ [rad/s]) as
    read by :func:`posturelab.simulation.results.read_run_csv`): the largest |Δθ_i| [rad]
    over the time both cover (``other`` linearly interpolated at ``first``'s samples), the
    difference of the peaks |θ_i| [rad] and of the end times [s]; None with a note when
    the runs have different numbers of links or no time in common."""
    import numpy as np

    (t0, th0, _), (t1, th1, _) = first, other
    out = {"common_time": None, "max_abs_theta_difference": None, "peak_difference": None,
           "end_time_difference": float(t1[-1] - t0[-1]), "units": DIFFERENCE_UNITS}
    if th0.shape[1] != th1.shape[1]:
        return out | {"note": f"{th1.shape[1]} links against {th0.shape[1]}: not compared"}
    lo, hi = max(t0[0], t1[0]), min(t0[-1], t1[-1])
    inside = (t0 >= lo) & (t0 <= hi)
    if not inside.any():
        return out | {"note": "no time in common: not compared"}
    moved = np.column_stack([np.interp(t0[inside], t1, th1[:, i])
                             for i in range(th1.shape[1])])
    return out | {
        "common_time": [float(lo), float(hi)],
        "max_abs_theta_difference": [float(v) for v in
                                     np.abs(moved - th0[inside]).max(axis=0)],
        "peak_difference": [float(v) for v in
                            np.abs(th1).max(axis=0) - np.abs(th0).max(axis=0)]}


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab compare``."""
    p.add_argument("runs", nargs="+", metavar="RUN.csv", help="runs saved by simulate --out.")
    p.add_argument("--labels", metavar="A,B,...", help="one label per run.")
    add_flag(p, "--plot", "the overlay")
    p.add_argument("--rates", action="store_true", help="plot the rates, not the angles.")
    add_flags(p, "--json")


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    import numpy as np

    from .._files import refuse_input_as_output
    from ..errors import ParameterError
    from ..simulation.results import read_run_csv

    refuse_input_as_output({"run": args.runs}, {"--plot": args.plot})  # ("the input run")
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
    diffs = [run_difference(runs[0], run) | {"label": label, "against": labels[0]}
             for label, run in zip(labels[1:], runs[1:], strict=True)]
    if args.json:
        print_json({"runs": rows, "differences": diffs})
        return 0
    for r in rows:
        peaks = ", ".join(f"{v:.4f}" for v in r["max_abs_theta"])
        print(f"{r['label']}: {r['samples']} samples to {r['end_time']:g} s; peak |θ| [rad] "
              f"{peaks}")
    for d in diffs:
        if d["max_abs_theta_difference"] is None:
            print(f"{d['label']} − {d['against']}: {d['note']}")
            continue
        lo, hi = d["common_time"]
        print(f"{d['label']} − {d['against']}: max |Δθ| [rad] "
              + ", ".join(f"{v:.4f}" for v in d["max_abs_theta_difference"])
              + f" over t = {lo:g}–{hi:g} s; Δpeak |θ| [rad] "
              + ", ".join(f"{v:+.4f}" for v in d["peak_difference"])
              + f"; Δend time {d['end_time_difference']:+g} s")
    if args.plot:
        print(f"wrote {args.plot}")
    return 0
