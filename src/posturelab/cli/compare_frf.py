"""``posturelab compare-frf``: two groups of FRFs compared band by band and as a whole."""

from __future__ import annotations

import argparse

from ._common import add_trial_arguments  # (likeness and likeness-reference import it here)
from ._flags import add_flag, add_flags

DESCRIPTION = """\
Compare two groups of FRFs (patients and controls, eyes open and closed, two amplitudes):
each --a and --b FILE is one subject's FRF, a trial CSV (then --stimulus, --response,
--cycle-length and --response-sign say how to estimate it, as posturelab frf does) or the
JSON that posturelab frf --json writes (or a gain-and-phase table, as fit-frf reads),
all over the same bands.

Per band: the difference of the group means, Δ = mean(A) − mean(B), with percentile
intervals (--level, default 95 %) of its real and imaginary parts from an unpaired
bootstrap (subjects resampled within each group, --resamples times).
Globally: a permutation test (the group labels shuffled --permutations times, seeded by
--seed; every split when there are no more) of T = Σ over bands of the two-sample
Hotelling T² of [Re H, Im H] with each band's pooled 2×2 covariance: each band weighed by
its own scatter, real and imaginary parts jointly, valid from 2 subjects per group;
p = (1 + #{T* >= T}) / (1 + permutations). posturelab.frequency.statistics states why
this statistic and its sources (Lippi 2025, arXiv:2505.23778 and 2504.20588).
Which bands differ: each band's own Hotelling T² tested by the same permutations (its
p-value, valid at any group size); a band is marked * when p <= 1 − --level. The bootstrap
intervals are descriptive only: with 2–3 subjects per group they are far too narrow. With
few subjects no band can be marked (2 + 2: the smallest p is 1/3; "smallest_band_p").

--json prints one object: {"p_value", "statistic", "statistic_name", "permutations",
"exact", "n_a", "n_b", "level", "resamples", "seed", "bands": [{"frequency" [Hz],
"mean_a", "mean_b", "difference" ({"re", "im"}), "re_ci", "im_ci", "excludes_zero",
"p_value", "differs"}], "smallest_band_p",
"a", "b" (the files), and "recordings" (per trial file: "resampling", "trimming") when a
recording was resampled or cut}. The recording options (--resample, --angle-unit,
--time-unit, --start, --drop-partial, --sway, ...) are those of posturelab frf.

Example: posturelab compare-frf --a ec1.json ec2.json ec3.json --b eo1.json eo2.json \\
             eo3.json --seed 1 --json
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab compare-frf``."""
    p.add_argument("--a", required=True, nargs="+", metavar="FILE",
                   help="group A: trial CSVs or FRF JSON files, one per subject.")
    p.add_argument("--b", required=True, nargs="+", metavar="FILE",
                   help="group B, as --a.")
    add_flag(p, "--seed", "the permutations and the bootstrap")
    p.add_argument("--permutations", type=int, default=10_000, metavar="N",
                   help="permutations of the global test, 1 … 1,000,000 (default 10,000; "
                   "frequency.statistics.MAX_PERMUTATIONS).")
    p.add_argument("--resamples", type=int, default=2000, metavar="N",
                   help="bootstrap resamples of the per-band intervals, 1 … 100,000 "
                   "(default 2000).")
    p.add_argument("--level", type=float, default=0.95, metavar="P",
                   help="coverage of the per-band intervals (default 0.95).")
    add_trial_arguments(p)
    add_recording_flags(p)
    add_flags(p, "--json")


def add_recording_flags(p: argparse.ArgumentParser) -> None:
    """How a trial recording among the inputs is read (the options ``frf`` takes)."""
    from ._recording import add_cycle_trim_argument, add_recording_arguments

    add_recording_arguments(p)
    add_cycle_trim_argument(p)


def read_frfs(paths: list[str], args: argparse.Namespace,
              readings: dict | None = None) -> list:
    """Each file's FRF, read as ``posturelab fit-frf`` reads a condition (a trial CSV or an
    FRF JSON); FRFs that state different response signs are refused. What reading each
    trial did goes in ``readings`` (path → Recording) when given, else on standard error."""
    from ._recording import print_reading
    from .fit_frf import _condition

    said: dict = {} if readings is None else readings
    frfs = [_condition(path, args, said) for path in paths]
    if readings is None:
        for path, rec in said.items():
            print_reading(rec, path)
    one_sign(paths, frfs)
    return frfs


def one_sign(paths: list[str], frfs: list) -> None:
    """Refuse FRFs that state different response signs (in one line, naming the files)."""
    from ..errors import ParameterError

    stated = [(p, int(f.response_sign)) for p, f in zip(paths, frfs, strict=True)
              if getattr(f, "response_sign", None) is not None]
    if len({s for _, s in stated}) > 1:
        raise ParameterError(("the FRFs were taken with different response signs ("
                              + ", ".join(f"{p!r}: {s:+d}" for p, s in stated))[:250]
                             + "); compare FRFs of one sign convention")


def run(args: argparse.Namespace) -> int:
    from ..frequency.statistics import compare_frf_groups
    from ._common import print_json
    from ._recording import refuse_repeated_files

    refuse_repeated_files(list(args.a) + list(args.b), "--a/--b")
    readings: dict | None = {} if args.json else None
    a, b = read_frfs(args.a, args, readings), read_frfs(args.b, args, readings)
    one_sign(args.a + args.b, a + b)
    result = compare_frf_groups(a, b,
                                permutations=args.permutations, resamples=args.resamples,
                                level=args.level, seed=args.seed)
    if args.json:
        recordings = [{"data": p, **r.report_dict()} for p, r in (readings or {}).items()
                      if r.report_dict()]
        print_json({**result.to_dict(), "a": list(args.a), "b": list(args.b),
                    **({"recordings": recordings} if recordings else {})})
        return 0
    how = ("every split" if result.exact else f"{result.permutations:,} permutations, seed "
           f"{result.seed}")
    print(f"group A: {result.n_a} FRFs, group B: {result.n_b} FRFs, {result.frequency.size} "
          "bands")
    print(f"global test: T = {result.statistic:.4g} ({result.statistic_name}); "
          f"p = {result.p_value:.4g} ({how})")
    pct = f"{100 * result.level:g} %"
    print(f"{'f [Hz]':>8} {'Δ re':>10} {'Δ im':>10}  re {pct:<22} im {pct}")
    for k in range(result.difference.size):
        d = result.difference[k]
        (rlo, rhi), (ilo, ihi) = result.re_ci[k], result.im_ci[k]
        mark = f"  p = {result.band_p_values[k]:.3g}" + ("  *" if result.band_differs[k]
                                                          else "")
        print(f"{result.frequency[k]:8.3f} {d.real:10.4g} {d.imag:10.4g}  "
              f"{rlo:.4g} … {rhi:.4g}".ljust(58) + f"{ilo:.4g} … {ihi:.4g}{mark}")
    print(f"(p: the band's own permutation test; * p <= {1 - result.level:.3g}, uncorrected "
          "for the number of bands: the global p is the test; the intervals are descriptive, "
          "too narrow for small groups)")
    if result.smallest_band_p > 1 - result.level:
        print(f"(with {result.n_a} + {result.n_b} subjects the smallest attainable band p is "
              f"{result.smallest_band_p:.3g}: no band can be marked)")
    return 0
