"""``posturelab convert``: a lab recording (C3D or CSV) to a posturelab table."""

from __future__ import annotations

import argparse

from ._common import check_writable
from ._flags import add_flag
from ._recording import add_recording_arguments, add_sway_arguments

DESCRIPTION = """\
Turn a lab recording into a table posturelab's commands read: a uniform time column [s],
SI units, and optionally com_angle [rad] (posturelab's sign: leaning forward positive).

A .c3d is read with ezc3d (pip install ezc3d, or posturelab[c3d]): every marker as LABEL_x,
LABEL_y, LABEL_z in m (scaled from POINT:UNITS), every analog channel by its label (its
ANALOG:UNITS unit), each force plate k as fpk_fx, fpk_fy, fpk_fz [N] and its centre of
pressure fpk_copx, fpk_copy, fpk_copz [m], at the marker rate or --rate HZ (analogs
decimated by a zero-phase FIR low-pass). Labels are lower-cased. A CSV needs a time
column. Every column that declares deg, mm, deg/s or mm/s (a header's [deg], a C3D's
ANALOG:UNITS) is written in rad, m, rad/s or m/s; a CSV column in a unit posturelab neither
reads nor converts (e.g. [furlong]) is refused. --angle-columns names angle columns that
declare no unit, --angle-unit deg their unit; --length-unit mm is the unit of a CSV's
marker columns (--markers) that declare none. Either flag where it would do nothing is
refused.

--sway METHOD writes com_angle: segments (ankle, knee, hip, shoulder markers; Winter 2009
Table 4.1), two-marker (hip and shoulder; the knee on the ankle–hip line: posturelab's
reduction of Winter's table, no published validation; forward positions only need
--height), cop (a force plate; the inverted-pendulum low-pass of Caron et al. 1997; needs
--height and --mass). --markers ankle=LABEL,knee=LABEL,... (or --hip-marker LABEL, ...)
names them; --forward and --up the lab axes (default x forward, z up; -x flips). The same
--sway options on frf, fit-frf, cohort, likeness and compare-frf compute com_angle on the
fly, by the same functions.

Example: posturelab convert trial.c3d --out trial.csv --sway segments \\
             --markers ankle=ank,knee=kne,hip=hip,shoulder=sho
         posturelab frf --data trial.csv --stimulus tilt --response com_angle \\
             --cycle-length 20 --discard-cycles 1
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab convert``."""
    p.add_argument("recording", metavar="FILE.c3d|FILE.csv", help="the recording.")
    p.add_argument("--out", required=True, metavar="OUT.csv|OUT.parquet",
                   help="the table to write.")
    add_flag(p, "--sample-rate", "a C3D's marker rate", former=("--rate",), dest="rate",
             default=None)
    p.add_argument("--angle-columns", default="", metavar="COL,...",
                   help="columns that are angles: converted to rad from the unit they "
                   "declare (ANALOG:UNITS, a CSV header's [deg]) or else --angle-unit.")
    add_recording_arguments(p, sway=False)
    add_sway_arguments(p)
    p.set_defaults(angle_unit=None, length_unit=None)  # given where it does nothing: refused


def run(args: argparse.Namespace) -> int:
    from .._files import refuse_input_as_output
    from ..recordings.convert import convert_recording
    from ._recording import marker_mapping, sway_spec

    refuse_input_as_output({"FILE": args.recording}, {"--out": args.out})
    check_writable([args.out], {args.out: (".csv", ".parquet")})
    markers = marker_mapping(args)
    sway_spec(args)  # the --sway options checked before any reading
    rec = convert_recording(
        args.recording, rate=args.rate, resample=args.resample, max_gap=args.max_gap,
        angle_unit=args.angle_unit, length_unit=args.length_unit, time_unit=args.time_unit,
        angle_columns=tuple(c.strip().lower() for c in args.angle_columns.split(",")
                            if c.strip()),
        sway=args.sway, markers=markers, plate=args.plate,
        forward=args.forward.strip().lower(), up=args.up.strip().lower(),
        height=args.height, mass=args.mass, start=args.start)
    rec.write(args.out)
    print(f"{len(rec.columns)} columns, {rec.time.size} samples at {rec.rate:g} Hz "
          f"({rec.time.size / rec.rate:g} s)")
    for note in rec.notes:
        print(f"  {note}")
    print(f"wrote {args.out}")
    return 0
