"""The options that say how a recording is read (``frf``, ``fit-frf``, ``cohort``, ``fit``,
``convert``): resampling, declared units."""

from __future__ import annotations

import argparse


def add_recording_arguments(p: argparse.ArgumentParser) -> None:
    """--resample, --max-gap, --angle-unit, --length-unit."""
    g = p.add_argument_group("reading a recording (CSV or .c3d)")
    g.add_argument("--resample", type=float, metavar="HZ",
                   help="put an uneven time column (or short runs of missing samples) onto a "
                   "uniform grid at HZ by a cubic spline; a gap longer than --max-gap is "
                   "refused (default: a non-uniform time column is refused).")
    g.add_argument("--max-gap", type=float, metavar="SECONDS",
                   help="with --resample: the longest gap accepted [s] (default 3 median "
                   "steps of the time column).")
    g.add_argument("--angle-unit", choices=["rad", "deg"], default="rad",
                   help="the unit of angle columns without a unit in their header "
                   "(default rad; deg is converted).")
    g.add_argument("--length-unit", choices=["m", "mm"], default="m",
                   help="the unit of length columns without a unit in their header "
                   "(default m; mm is converted).")
    g.add_argument("--start", type=float, metavar="SECONDS",
                   help="drop the samples before this time (where the stimulus's first "
                   "cycle starts) [s].")


def add_cycle_trim_argument(p: argparse.ArgumentParser) -> None:
    """--drop-partial (for the commands that cut a trial into stimulus cycles)."""
    p.add_argument("--drop-partial", action="store_true",
                   help="drop a partial cycle at the end of the recording (said on "
                   "standard error; default: a recording must hold whole cycles).")


def recording_options(args: argparse.Namespace) -> dict:
    """:func:`posturelab.recordings.table.read_series`'s reading options."""
    given = {"resample": None, "max_gap": None, "angle_unit": "rad", "length_unit": "m",
             "start": None}  # a command without these options reads as before
    out = {k: getattr(args, k, default) for k, default in given.items()}
    if getattr(args, "drop_partial", False):
        out["drop_partial"] = True
    return out


def print_resampling(report) -> None:
    """Say what the resampling did (on standard error, so --json stays one object)."""
    if report is not None:
        import sys

        print(f"note: {report.text()}", file=sys.stderr)
