"""``posturelab frf``: a frequency response function from a measured (or simulated) trial."""

from __future__ import annotations

import argparse
import math

from ..errors import ParameterError
from ._common import FIGURE_SUFFIXES, check_writable, print_json
from ._flags import add_flag, add_flags
from ._recording import (
    add_cycle_trim_argument,
    add_recording_arguments,
    check_sway_response,
    print_reading,
    recording_options,
)

#: Band names ``frf`` and ``frf-model`` both take (frequency.bands.SEQUENCE_BANDS; "peterka"
#: is the historical name of the 80-state bands).
BAND_CHOICES = ["peterka", "posturelab-80", "comtest-80", "peterka-2002-242"]

DESCRIPTION = """\
Estimate the frequency response function (FRF) of one column to another in a CSV trial with a
periodic stimulus (a PRTS), by Peterka's (2002) method: the record is cut into cycles of
--cycle-length s (--discard-cycles leading ones dropped), the DFT cross- and auto-spectra are
averaged over cycles at the stimulus's odd harmonics and then over frequency bands, and the
FRF is G_xy/G_xx, with the coherence and 95 % bounds on gain and phase. A stimulus that does
not repeat every --cycle-length (its cycles differing by more than 25 % of its RMS; a
measured tilt with sensor noise differs by a few %) is refused, naming the period its
autocorrelation shows; so are a response with no variation and a response that is the
stimulus's column.

The file has a header row and a uniform time column, t or time [s] (the sample rate comes
from it); --resample HZ puts an uneven one on a uniform grid (cubic spline; a gap over
--max-gap refused). A header may declare units, e.g. tilt [deg]: a declared deg or mm is
converted to rad or m, another unit refused (time [ms] needs --time-unit ms). Columns that
declare no unit are read in SI (angles in rad, translations in m, time in s) unless
--angle-unit deg / --length-unit mm / --time-unit ms says otherwise (these apply only to
columns without a declared unit). A .c3d
is read directly (columns as posturelab convert names them). --sway METHOD with its markers
(--hip-marker LABEL --shoulder-marker LABEL, ...) computes com_angle from a C3D's or a lab
CSV's markers as posturelab convert --sway does; then --response com_angle, --length-unit
is the markers' unit and the stimulus is read as an angle (a translation stimulus in m).
--bands peterka (default; the historical name, the same as posturelab-80 and comtest-80)
averages the 11 bands of the 80-state protocol (COMTEST's analysis; 20 s: 0.05 … 2.20 Hz; for
another cycle length the same harmonic numbers); --bands peterka-2002-242 the 17 bands
posturelab uses for Peterka 2002's 242-state sequence; --bands harmonics every odd harmonic.

Sign (declared, never guessed from column names): the response is multiplied by
--response-sign before the ratio, and every output states the sign applied. A tilt FRF is
reported so that a body that stays perpendicular to the surface has gain 1 and phase 0.
The default, -1, is posturelab's convention: its files have sway positive leaning forward
and tilt positive toes-up, so a body following a toes-up tilt reads negative sway. Another
lab's recording: if a body following the surface reads sway of the same sign as the tilt
(both in one rotational sense, e.g. both positive toes-up/backward), give --response-sign
+1; if it reads the opposite sign, as posturelab's files do, keep -1. A translation
stimulus: posturelab's model FRF is y/x, so +1. Unsure: a response that follows a slow
stimulus reads near 0 deg in the lowest band; a warning (stderr, and "warnings" in --json)
says when that band's phase lies within 45 deg of +-180 deg with coherence >= 0.8.

--json prints one object: {"frequency": [Hz], "frf": [{"re", "im"}], "gain", "phase_deg",
"coherence", "gain_ci95": [[low, high]], "phase_ci95_deg": [[low, high]],
"harmonic_frequency" and "harmonic_weight" (each band's harmonics [Hz] and their share of
its stimulus power), "frf_se" (standard error of the complex estimate), "dof",
"frf_covariance" (of the bands), "response_sign", "sign_convention", "warnings", and with
--resample "resampling" (what was done), with --start or --drop-partial "trimming" (what
was cut), for a .c3d or --sway "reading_notes"}; an undefined number is null. fit-frf reads it back.
--ci periodic (default) gives bounds exact for a periodic stimulus; --ci otnes-enochson the
form Peterka used (wider).

Dual-stimulus trials (a surface and a visual-scene tilt at once, posturelab.frequency.dual):
--stimulus tilt,visual_tilt (the default when the file has both columns: without --stimulus
the trial's tilt and visual_tilt columns, and com_angle without --response) estimates each
FRF at its own stimulus's harmonics over the common --cycle-length; the two stimuli must not
share a harmonic (a PRTS and one of half its cycle: simulate --tilt prts:0.035 --visual-tilt
prts:0.035:0.125). --json then prints {"tilt": {...}, "visual_tilt": {...}}, one FRF object
each.
--bootstrap N (1 … 100,000) adds bootstrap bands over the stimulus cycles (the cycles
resampled with replacement N times, --seed; posturelab.frequency.bootstrap_frf_bands): per
band 95 % percentile intervals of Re, Im, the gain and the phase, the pointwise circle
about the estimate and the simultaneous circles that hold every band at once ("bootstrap"
in --json: {"re_ci", "im_ci", "gain_ci", "phase_ci_deg": [[low, high]] per band, "radius",
"simultaneous_radius", "level": 0.95, "resamples", "n_cycles", "seed"}); --plot draws the
gain and phase intervals as dashed lines. Few cycles make them narrow (under about 12
cycles, prefer the estimate's own 95 % bounds).

Example: posturelab simulate --controller peterka-2002 --tilt prts:0.035 --duration 120 \\
             --engine compiled --sample-rate 100 --out trial.csv
         posturelab frf --data trial.csv --stimulus tilt --response com_angle \\
             --cycle-length 20 --discard-cycles 1 --plot bode.png
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab frf``."""
    p.add_argument("--data", required=True, metavar="FILE.csv|FILE.c3d", help="the trial.")
    add_flag(p, "--stimulus", ", or two of a dual-stimulus trial (default: the trial's tilt "
             "and visual_tilt columns)", metavar="COLUMN[,COLUMN]")
    add_flag(p, "--response")
    add_flag(p, "--cycle-length", " (20 for the 80-state PRTS)", required=True)
    add_flag(p, "--discard-cycles", "0")
    p.add_argument("--bands", choices=BAND_CHOICES + ["harmonics"], default="peterka",
                   help="frequency bands (default peterka, the historical name of the 11 "
                   "bands of the 80-state protocol (COMTEST), the same as posturelab-80 and "
                   "comtest-80; peterka-2002-242: 17 bands for Peterka 2002's 242-state "
                   "sequence, posturelab's placement; harmonics: every odd harmonic).")
    add_flag(p, "--response-sign", "; see above")
    p.add_argument("--ci", choices=["periodic", "otnes-enochson"], default="periodic",
                   help="form of the 95 %% bounds (default periodic).")
    p.add_argument("--bootstrap", type=int, default=None, metavar="N",
                   help="also bootstrap 95 %% bands over the cycles, N resamples "
                   "(1 … 100,000; see above).")
    add_flag(p, "--seed", "the bootstrap's resampling")
    add_flags(p, "--json")
    add_flag(p, "--plot", "a Bode plot", metavar="BODE.png")
    p.add_argument("--plot-cycles", metavar="CYCLES.png",
                   help="write the stimulus over one cycle and the cycle-averaged response "
                   "(PNG, SVG or PDF, by the suffix).")
    add_recording_arguments(p)
    add_cycle_trim_argument(p)


def _check_bootstrap(args: argparse.Namespace) -> None:
    """--bootstrap in 1 … MAX_RESAMPLES and --seed >= 0, before any work."""
    from ..errors import ParameterError
    from ..frequency.statistics import MAX_RESAMPLES

    if args.bootstrap is not None and not 1 <= args.bootstrap <= MAX_RESAMPLES:
        raise ParameterError(f"--bootstrap must be 1 … {MAX_RESAMPLES:,} resamples, got "
                             f"{args.bootstrap}")
    if args.seed < 0:
        raise ParameterError(f"--seed must be >= 0, got {args.seed}")


def check_plot_path(*paths: str | None) -> None:
    """Each given figure path ends in .png, .svg or .pdf and can be written."""
    given = [p for p in paths if p]
    check_writable(given, {p: FIGURE_SUFFIXES for p in given})


def trial_kinds(stimulus: str, response: str, length_unit: str = "m",
                input: str | None = None) -> dict[str, str]:
    """Which declared unit applies to the stimulus and response columns: the response is an
    angle; the stimulus a length for a translation (``input``, or ``--length-unit mm`` given
    to ``frf``), else an angle."""
    translation = input == "translation" or (input is None and length_unit != "m")
    return {stimulus: "length" if translation else "angle", response: "angle"}


def response_sign(choice: str) -> int:
    """The sign the response is taken with (``--response-sign``, declared)."""
    return -1 if str(choice).strip() == "-1" else 1


def run(args: argparse.Namespace) -> int:
    from .._files import refuse_input_as_output
    from .._validation import float_in_range
    from ..frequency.estimate import estimate_frf, sign_convention, whole_cycles
    from ..recordings.table import read_recording

    refuse_input_as_output({"--data": args.data},
                           {"--plot": args.plot, "--plot-cycles": args.plot_cycles})
    check_plot_path(args.plot, args.plot_cycles)
    float_in_range("--cycle-length [s]", args.cycle_length, 1e-3, 1e5, unit="s")
    _check_bootstrap(args)
    from ..frequency.dual import estimate_frfs, stimulus_columns

    resp = (args.response or "com_angle").strip().lower()
    check_sway_response(args, resp)
    if args.stimulus:
        stimuli = [s.strip().lower() for s in args.stimulus.split(",") if s.strip()]
    elif str(args.data).lower().endswith(".c3d"):
        raise ParameterError("a .c3d trial needs --stimulus COLUMN (its analog channel)")
    else:
        stimuli = stimulus_columns(args.data)
    if not stimuli:
        raise ParameterError(f"--data {args.data!r} has no tilt or visual_tilt column: give "
                             "--stimulus COLUMN")
    if resp in stimuli or len(set(stimuli)) < len(stimuli):
        raise ParameterError(f"--stimulus {args.stimulus or ','.join(stimuli)!r} and --response "
                             f"{resp!r} name the same column twice; an FRF relates two "
                             "different columns")
    kinds = {k: v for s in stimuli
             for k, v in trial_kinds(s, resp, args.length_unit,
                                     "tilt" if args.sway else None).items()}
    rec = read_recording(args.data, [*stimuli, resp], {s: ("rad", "m") for s in stimuli},
                         kinds=kinds, cycle_length=args.cycle_length,
                         **recording_options(args))
    fs, cols = rec.rate, rec.columns
    if not args.json:
        print_reading(rec)
    sign = response_sign(args.response_sign)
    if len(stimuli) > 1:
        if args.plot_cycles or args.bootstrap:
            raise ParameterError(f"{'--plot-cycles' if args.plot_cycles else '--bootstrap'} "
                                 "takes one stimulus; give --stimulus COLUMN")
        x, trimmed = {}, False
        for s in stimuli:
            x[s], y, trimmed = whole_cycles(cols[s], cols[resp], fs, args.cycle_length)
        ests = estimate_frfs(x, y, fs, args.cycle_length, discard_cycles=args.discard_cycles,
                             bands=args.bands, response_sign=sign, ci=args.ci)
        if args.plot:
            from ..viz.plots import plot_bode, save_figure

            save_figure(plot_bode(list(ests.values()),
                                  [f"{'−' if sign < 0 else ''}{resp} / {s}" for s in ests]),
                        args.plot)
        if args.json:
            print_json({**{s: {**e.to_dict(), "sign_convention": sign_convention(sign)}
                           for s, e in ests.items()}, **rec.report_dict()})
            return 0
        for s, e in ests.items():
            _table(e, s, resp, sign, fs, trimmed)
        if args.plot:
            print(f"wrote {args.plot}")
        return 0
    stim = stimuli[0]
    x, y, trimmed = whole_cycles(cols[stim], cols[resp], fs, args.cycle_length)
    est = estimate_frf(x, y, fs, args.cycle_length,
                       discard_cycles=args.discard_cycles, bands=args.bands,
                       response_sign=sign, ci=args.ci)
    label = f"{'−' if sign < 0 else ''}{resp} / {stim} (response × {sign:+d})"
    boot = None
    if args.bootstrap is not None:
        from ..frequency.statistics import bootstrap_frf_bands

        boot = bootstrap_frf_bands(x, y, fs, args.cycle_length,
                                   discard_cycles=args.discard_cycles, bands=args.bands,
                                   response_sign=sign, resamples=args.bootstrap,
                                   seed=args.seed)
    if args.plot:
        from ..viz.plots import plot_bode, save_figure

        save_figure(plot_bode([est], [label], bootstrap=None if boot is None else [boot]),
                    args.plot)
    if args.plot_cycles:
        from ..viz.plots import plot_prts_cycles, save_figure

        def unit(column: str) -> tuple[str, float]:  # angles in degrees, the rest as read
            angle = column in ("tilt", "com_angle") or column.startswith("theta")
            return ("deg", 180 / math.pi) if angle else ("file unit", 1.0)

        save_figure(plot_prts_cycles(est, stimulus_label=stim,
                                     response_label=("−" if sign < 0 else "") + resp,
                                     stimulus_unit=unit(stim), response_unit=unit(resp)),
                    args.plot_cycles)
    if est.warnings:
        import sys

        for warning in est.warnings:
            print(f"warning: {warning}", file=sys.stderr)
    if args.json:
        extra = rec.report_dict()
        if boot is not None:
            extra["bootstrap"] = {k: v for k, v in boot.to_dict().items()
                                  if k not in ("frequency", "frf")}
        print_json({**est.to_dict(), "sign_convention": sign_convention(sign), **extra})
        return 0
    _table(est, stim, resp, sign, fs, trimmed, boot)
    for path in (args.plot, args.plot_cycles):
        if path:
            print(f"wrote {path}")
    return 0


def _table(est, stim: str, resp: str, sign: int, fs: float, trimmed: bool,
           boot=None) -> None:
    """Print one FRF as a table (with its bootstrap intervals, ``boot``), and its warnings."""
    from ..frequency.estimate import sign_convention

    print(f"FRF of {resp} to {stim}, {sign_convention(sign)}: {est.n_cycles} cycles "
          f"of {est.cycle_length:g} s at {fs:g} Hz, {len(est.bands)} bands"
          + (" (the record's end point, one sample past the last cycle, left out)"
             if trimmed else ""))
    print(f"{'f [Hz]':>8} {'gain':>10} {'phase [deg]':>12} {'coherence':>10}  gain 95 %")
    for k in range(est.frequency.size):
        lo, hi = est.gain_ci95[k]
        bound = (f"{lo:.4g} … {hi:.4g}" if math.isfinite(lo) and math.isfinite(hi)
                 else f"undefined (n_d = {est.averages[k]})")
        print(f"{est.frequency[k]:8.3f} {est.gain[k]:10.4g} {est.phase_deg[k]:12.1f} "
              f"{est.coherence[k]:10.3f}  {bound}")
    if boot is not None:
        print(f"bootstrap over {boot.n_cycles} cycles ({boot.resamples} resamples, seed "
              f"{boot.seed}), {100 * boot.level:g} % percentile intervals:")
        print(f"{'f [Hz]':>8} {'gain':>22} {'phase [deg]':>22}")
        for k in range(est.frequency.size):
            (glo, ghi), (plo, phi) = boot.gain_ci[k], boot.phase_ci_deg[k]
            print(f"{est.frequency[k]:8.3f} {f'{glo:.4g} … {ghi:.4g}':>22} "
                  f"{f'{plo:.1f} … {phi:.1f}':>22}")
    low = est.coherence < 0.5
    if low.any():
        print(f"warning: coherence below 0.5 at {int(low.sum())} band(s): those estimates are "
              "noisy")
