"""``posturelab convert``: a lab recording (C3D or CSV) to a posturelab table."""

from __future__ import annotations

import argparse

from ._common import check_writable
from ._recording import add_recording_arguments

DESCRIPTION = """\
Turn a lab recording into a table posturelab's commands read: a uniform time column [s],
SI units, and optionally com_angle [rad] (posturelab's sign: leaning forward positive).

A .c3d is read with ezc3d (pip install ezc3d, or posturelab[c3d]): every marker as LABEL_x,
LABEL_y, LABEL_z in m (scaled from POINT:UNITS), every analog channel by its label (its
ANALOG:UNITS unit), each force plate k as fpk_fx, fpk_fy, fpk_fz [N] and its centre of
pressure fpk_copx, fpk_copy, fpk_copz [m], at the marker rate or --rate HZ (analogs
decimated by a zero-phase FIR low-pass). Labels are lower-cased. A CSV needs a time
column. --angle-columns names the angle columns, converted to rad from the unit they
declare (or --angle-unit); --length-unit is the unit of a CSV's marker columns (--markers).

--sway METHOD writes com_angle: segments (ankle, knee, hip, shoulder markers; Winter 2009
Table 4.1), two-marker (hip and shoulder; the knee on the ankle–hip line; forward
positions only need --height), cop (a force plate; the inverted-pendulum low-pass of Caron
et al. 1997; needs --height and --mass). --markers ankle=LABEL,knee=LABEL,... names them;
--forward and --up the lab axes (default x forward, z up; -x flips).

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
    p.add_argument("--rate", type=float, metavar="HZ",
                   help="C3D: the table's sample rate (default the marker rate).")
    p.add_argument("--angle-columns", default="", metavar="COL,...",
                   help="columns that are angles: converted to rad from the unit they "
                   "declare (ANALOG:UNITS, a CSV header's [deg]) or else --angle-unit.")
    p.add_argument("--sway", choices=["segments", "two-marker", "cop"],
                   help="write com_angle by this method (see above).")
    p.add_argument("--markers", default="", metavar="LANDMARK=LABEL,...",
                   help="ankle=, knee=, hip=, shoulder= marker labels (or CSV columns).")
    p.add_argument("--plate", type=int, default=1, metavar="K",
                   help="the force plate --sway cop uses (default 1).")
    p.add_argument("--forward", default="x", metavar="AXIS",
                   help="the lab axis pointing forward: x, y, z, -x, -y, -z (default x).")
    p.add_argument("--up", default="z", metavar="AXIS", help="the lab axis pointing up "
                   "(default z).")
    p.add_argument("--height", type=float, metavar="M", help="the subject's height [m].")
    p.add_argument("--mass", type=float, metavar="KG", help="the subject's mass [kg].")
    add_recording_arguments(p)


def _mapping(text: str) -> dict[str, str]:
    from ..errors import ParameterError

    out = {}
    for item in [i.strip() for i in text.split(",") if i.strip()]:
        key, eq, value = item.partition("=")
        if not eq or not value.strip():
            raise ParameterError(f"--markers must be LANDMARK=LABEL,..., got {item!r}")
        out[key.strip().lower()] = value.strip()
    return out


def run(args: argparse.Namespace) -> int:
    from .._files import refuse_input_as_output
    from ..recordings.convert import convert_recording

    refuse_input_as_output({"FILE": args.recording}, {"--out": args.out})
    check_writable([args.out], {args.out: (".csv", ".parquet")})
    rec = convert_recording(
        args.recording, rate=args.rate, resample=args.resample, max_gap=args.max_gap,
        angle_unit=args.angle_unit, length_unit=args.length_unit,
        angle_columns=tuple(c.strip().lower() for c in args.angle_columns.split(",")
                            if c.strip()),
        sway=args.sway, markers=_mapping(args.markers), plate=args.plate,
        forward=args.forward.strip().lower(), up=args.up.strip().lower(),
        height=args.height, mass=args.mass, start=args.start)
    rec.write(args.out)
    print(f"{len(rec.columns)} columns, {rec.time.size} samples at {rec.rate:g} Hz "
          f"({rec.time[-1] - rec.time[0]:g} s)")
    for note in rec.notes:
        print(f"  {note}")
    print(f"wrote {args.out}")
    return 0
