"""``posturelab likeness-reference``: a human-likeness reference from one's own cohort."""

from __future__ import annotations

import argparse

from ._flags import add_data_files

DESCRIPTION = """\
Build a reference for posturelab likeness from a cohort: each --data FILE is one
subject's FRF (frf.json as posturelab frf --json writes it, a table as fit-frf reads, or
a trial CSV with --stimulus, --response, --cycle-length, --response-sign), all over the
same bands. The reference is the mean FRF m, the inverse of the sample covariance Σ of
the real and imaginary parts over the subjects (2B numbers for B bands), and per-band
weights (--weights, default 1 each: the plain Mahalanobis distance, whose square for a
subject of the cohort's population is about χ² with 2B degrees of freedom).

Σ is invertible only with at least 2B + 1 subjects (23 for the 11 bands); fewer are
refused, unless --shrinkage λ in (0, 1] is given: Σ_λ = (1 − λ)Σ + λ·diag(Σ), stated in
the reference ("shrinkage"). Writes JSON (--out, atomically); posturelab likeness
--reference ref.json reads it. A trial is read with posturelab frf's recording options
(--resample, --angle-unit, --time-unit, --start, --drop-partial, --sway, ...); what was
resampled or cut is said on standard error.

Example: posturelab likeness-reference --data s01.json s02.json … s30.json --out ref.json
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab likeness-reference``."""
    from .compare_frf import add_recording_flags, add_trial_arguments

    add_data_files(p, "the cohort: one FRF file (or trial CSV) per subject")
    p.add_argument("--out", required=True, metavar="REF.json",
                   help="the reference to write (JSON).")
    p.add_argument("--weights", default="", metavar="S1,S2,...",
                   help="per-band weights, one per band (default 1 each).")
    p.add_argument("--shrinkage", type=float, default=0.0, metavar="LAMBDA",
                   help="shrink the covariance towards its diagonal by LAMBDA in [0, 1] "
                   "(default 0: none, and a cohort too small to invert is refused).")
    p.add_argument("--name", default="cohort", help="the reference's name (default cohort).")
    add_trial_arguments(p)
    add_recording_flags(p)


def run(args: argparse.Namespace) -> int:
    import json

    from .._files import atomic_write_text, refuse_input_as_output
    from ..frequency.likeness import build_likeness_reference
    from ._common import check_writable, parse_float_list
    from .compare_frf import read_frfs

    refuse_input_as_output({"--data": args.data}, {"--out": args.out})
    from ._recording import refuse_repeated_files

    refuse_repeated_files(args.data)
    check_writable([args.out], {args.out: (".json",)})
    weights = parse_float_list(args.weights, "--weights") if args.weights.strip() else None
    reference = build_likeness_reference(read_frfs(args.data, args), weights=weights,
                                         shrinkage=args.shrinkage, name=args.name)
    atomic_write_text(args.out, json.dumps(reference.to_dict(), indent=1,
                                           ensure_ascii=False) + "\n")
    print(f"wrote {args.out}: reference {reference.name!r} from {reference.subjects} FRFs "
          f"over {reference.mean.size} bands"
          + (f"; covariance shrunk towards its diagonal by λ = {reference.shrinkage:g}"
             if reference.shrinkage else ""))
    return 0
