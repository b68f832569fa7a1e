"""``posturelab likeness``: the human-likeness distance of an FRF to a reference."""

from __future__ import annotations

import argparse

#: The shipped references (frequency.likeness.LIKENESS_PRESETS; here so that --help loads
#: no numerical module; a test compares them).
PRESET_NAMES = ("comtest-eyes-closed",)

DESCRIPTION = """\
Score an FRF by its distance to a human reference, as the Eurobench COMTEST protocol does:
D = sqrt(d·S·Σ⁻¹·S·dᵀ), d = [Re H − Re m, Im H − Im m] over the bands, m the reference's
mean FRF, Σ⁻¹ its inverse covariance of the real and imaginary parts, S its per-band
weights. --data is the FRF: the JSON posturelab frf --json writes (or a table fit-frf
reads), or a trial CSV (then --stimulus, --response, --cycle-length, --response-sign as
for posturelab frf). --reference is a preset, or a file: a reference JSON written by
posturelab likeness-reference, or one's own copy of COMTEST's PRTSinfo.m.

Presets: comtest-eyes-closed, COMTEST's eyes-closed tilt reference (m, Σ⁻¹ and weights
from github.com/VittorioFreiburg/COMTEST, ANALYSIS/OCTAVE/src/PRTSinfo.m, commit 541da31;
GPL-3.0-or-later, shipped under that licence: posturelab/data/likeness/README.md), over
the 11 bands of the 80-state PRTS (0.05 … 2.20 Hz).
Sign and scale: COMTEST's FRF is the recorded sway over an ideal PRTS of unit peak-to-peak,
following the surface reading a phase near 0, as posturelab's tilt FRF (response sign -1)
does; so a posturelab FRF H is scored as A·H with --scale A, the tilt's peak-to-peak
amplitude in the unit of COMTEST's recorded sway (PRTSinfo.m does not state that unit or
the reference's amplitude; posturelab does not choose A: default 1).

--json prints one object: {"score", "reference", "scale", "difference" (per band, {"re",
"im"}: A·H − m), "frequency" [Hz], "source", "sign_convention", and for a resampled or
cut trial "resampling", "trimming"}. A trial is read with posturelab frf's recording
options (--resample, --angle-unit, --time-unit, --start, --drop-partial, --sway, ...).

Example: posturelab frf --data trial.csv --stimulus tilt --response com_angle \\
             --cycle-length 20 --discard-cycles 1 --json > frf.json
         posturelab likeness --data frf.json --reference comtest-eyes-closed --json
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab likeness``."""
    from ._flags import add_flags
    from .compare_frf import add_recording_flags, add_trial_arguments

    p.add_argument("--data", required=True, metavar="FILE",
                   help="the FRF: frf.json (posturelab frf --json) or a trial CSV.")
    p.add_argument("--reference", required=True, metavar="NAME|FILE",
                   help=f"a preset ({', '.join(PRESET_NAMES)}) or a reference file "
                   "(likeness-reference's JSON, or COMTEST's PRTSinfo.m).")
    p.add_argument("--scale", type=float, default=1.0, metavar="A",
                   help="multiply the FRF by A before scoring (for comtest-eyes-closed: the "
                   "tilt's peak-to-peak amplitude in the unit of the recorded sway; "
                   "default 1).")
    add_trial_arguments(p)
    add_recording_flags(p)
    add_flags(p, "--json")


def run(args: argparse.Namespace) -> int:
    from ..frequency.likeness import likeness, likeness_reference
    from ._common import print_json
    from .compare_frf import read_frfs

    reference = likeness_reference(args.reference)  # (an unknown name before any reading)
    readings: dict | None = {} if args.json else None
    (frf,) = read_frfs([args.data], args, readings)
    result = likeness(frf, reference, scale=args.scale)
    if args.json:
        said = next(iter((readings or {}).values()), None)
        print_json({**result.to_dict(), **(said.report_dict() if said else {}),
                    "frequency": [float(f) for f in reference.frequency],
                    "source": reference.source, "sign_convention": reference.sign_convention})
        return 0
    print(f"likeness score D = {result.score:.4g} to {reference.name} (FRF × {args.scale:g})")
    print(f"reference: {reference.source}")
    if reference.sign_convention:
        print(f"sign and scale: {reference.sign_convention}")
    print(f"{'f [Hz]':>8} {'A·H − m (re)':>14} {'(im)':>10}")
    for f, d in zip(reference.frequency, result.difference, strict=True):
        print(f"{f:8.3f} {d.real:14.4g} {d.imag:10.4g}")
    return 0
