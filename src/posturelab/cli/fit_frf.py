"""``posturelab fit-frf``: fit a controller to frequency response functions."""

from __future__ import annotations

import argparse

from ..errors import ParameterError
from ..parameters import MAX_FEEDBACK_DELAY
from ._common import (
    add_muscle_arguments,
    add_torque_feedback_arguments,
    add_trial_arguments,
    model_from_args,
    print_json,
)
from ._flags import MODEL_OUTPUTS, add_data_files, add_flag, add_flags, add_options

DESCRIPTION = f"""\
Fit the linearised model's FRF to one or several measured FRFs. Each --data is a condition:
a trial CSV (then --stimulus, --response, --cycle-length and --response-sign say how to
estimate its FRF, as posturelab frf does), the JSON that posturelab frf --json writes, or a
table as JSON: {{"frequency": [Hz], "gain": [...], "phase_deg": [...]}} with optional
"gain_se" and "phase_se_deg" (standard errors of gain [-] and phase [deg], as published
group means give them), or "frf_se" (standard error of the complex value), "dof" and
"coherence". A trial's header may declare units, e.g. tilt [deg]: deg and mm are converted
to rad and m, another unit refused (time in s). The same file given twice is refused. --free
NAMES (comma separated) are shared by the conditions, --per-condition NAMES take one value
per condition, NAME#1, NAME#2, … in the order of --data (the output lists the conditions:
"conditions" in --json, each --data path and its kind, trial, frf --json or table, and for a trial
resampled or cut its "resampling" and "trimming"; without --json one line each on stderr).
A trial is read with posturelab frf's recording options (--resample, --angle-unit,
--length-unit, --time-unit, --start, --drop-partial, and --sway with its markers to compute
com_angle on the fly; --height and --mass are then the body's).
Names (the parameter table's, as for sweep --vary and fit --free): stiffness:PAIR,
viscosity:PAIR (intrinsic), active_stiffness:PAIR, active_viscosity:PAIR (:PAIR may be left
out on a body with one pair), feedback_delay, proprioceptive_weight, visual_weight,
torque_feedback_gain, torque_feedback_time_constant (Peterka 2002's torque feedback;
starting values from --torque-feedback-gain and --torque-feedback-time-constant).
A dual-stimulus trial (--stimulus tilt,visual_tilt, or a trial CSV with both columns and no
--stimulus; posturelab.frequency.dual), or the JSON posturelab frf --json prints for one,
{{"tilt": {{...}}, "visual_tilt": {{...}}}} (--stimulus picks some), gives two conditions, its
surface-tilt FRF and its visual-scene FRF, each fitted with its own model input: --free
proprioceptive_weight,visual_weight fits W and W_v jointly (Peterka 2002's independent
channels; W + W_v > 1 is reported as a warning). The body and the
starting values come from the options below (as in posturelab simulate); --bounds
NAME=LO:HI,... replaces the defaults (gains 0 … 1e5, delay 0 … {MAX_FEEDBACK_DELAY:g} s,
W 0 … 1, K_t 0 … 3, τ_t 0.5 … 200 s); each must lie within the table's bounds (docs/parameters.md).

Weighting (printed, and "weighting" in --json; posturelab.frequency.fit): every band by
its own precision: a trial's by the variance of its estimate from the scatter of its
cycles (bands that share harmonics correlated), a table's by its standard errors; a table
without them by 1/|H| (then said, and the fit error cannot test the model). A trial's
model FRF is averaged over each band's harmonics with the stimulus's power, as its
estimate is (frf --json carries them, so its JSON fits as its trial does; a table without
them: the model at the band frequencies).
Prints each parameter with its standard error and 95 % interval, the fit error (√(χ²/dof),
about 1 when the model explains the data within their noise), and parameters the data
cannot determine (among them an estimate on its search bound, within 1e-6 of the bounds'
range: "at its search bound LO/HI", "at_bound" in --json); every interval is clipped to the
parameter's accepted range and its search bounds (said when it was); when the fit error
is too large for chance (p < 0.001) it says the model does not describe the data and
widens the intervals by a model error it states;
warns when a band's coherence is below 0.5. Bounds must lie within each parameter's range;
a name given twice or a bound for a parameter not fitted is refused, and so is a fit with no
residual degrees of freedom (as many free parameters as numbers: 2 per band). It prints the
variance accounted for, VAF = 1 − Σ|H − Ĥ|²/Σ|Ĥ|²; the fit is a success ("success" in
--json) only when the optimiser converged, the fitted loop is stable and VAF >= 50 % (the
model describes the data: "describes_data"); otherwise "reason" says why, the estimates
kept and flagged.

Reweighting (posturelab.frequency.reweighting): --compare NAME (e.g. proprioceptive_weight)
fits NAME once per condition and once shared by all, the rest as asked, and tests whether it
differs by a likelihood ratio: ΔS = S_shared − S_per-condition (the whitened residuals' sums
of squares) against χ²(C − 1) for known standard errors, F(C − 1, ν) for ones estimated with
ν degrees of freedom. It prints NAME per condition against the stimulus amplitude (peak to
peak: --amplitudes, else a trial's measured) and vision (--vision open,closed,...), the
shared value and the test ("reweighting" in --json, with "p_value"); --compare-out writes
the table (.json with the test, or .csv), --compare-plot the figure. Peterka (2002) found
the proprioceptive weight falling as the tilt grows. --compare-by vision (with a --vision
label for every condition, both present) tests eyes open against eyes closed instead: NAME
takes one value per vision label (the conditions of a label share it; other
--per-condition parameters also one per label) against one shared, χ²(1) or F(1, ν)
("grouping": "vision" and "vision_groups" in --json).

Example: posturelab fit-frf --data trial.csv --stimulus tilt --response com_angle \\
             --cycle-length 20 --discard-cycles 1 --controller peterka-2002 \\
             --free active_stiffness:ankle,active_viscosity:ankle,feedback_delay
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab fit-frf``."""
    add_data_files(p, "the conditions, one file each: trial.csv or frf.json")
    add_fit_arguments(p, per_condition=True)
    add_flags(p, "--json")
    add_flag(p, "--plot", "a Bode plot of every condition with its fitted model",
             metavar="BODE.png")
    compare = p.add_argument_group("comparing the conditions (--compare)")
    compare.add_argument("--compare", metavar="NAME",
                         help="fit NAME per condition and shared, and test the difference (a "
                         "likelihood-ratio test: \"reweighting\" in --json, with its "
                         "p_value); e.g. proprioceptive_weight.")
    add_options(compare, {  # (each with --compare only)
        "--amplitudes": ("A1,A2,...", "with --compare: each condition's stimulus amplitude, "
                         "peak to peak [rad for a tilt, m for a translation] (default: a "
                         "trial's measured, a table's unknown)."),
        "--vision": ("open|closed,...", "with --compare: each condition's vision, open or "
                     "closed (or - for not given)."),
        "--compare-out": ("TABLE.json|.csv", "with --compare: write the per-condition table "
                          "(and the test, in JSON)."),
        "--compare-plot": ("FIG.png", "with --compare: draw NAME against the stimulus "
                           "amplitude with its intervals (PNG, SVG or PDF, by the suffix)."),
    })
    compare.add_argument("--compare-by", choices=["condition", "vision"], default=None,
                         help="with --compare: one value of NAME per condition (default) or "
                         "per vision label (eyes open against closed; needs --vision).")
    add_muscle_arguments(p)
    add_torque_feedback_arguments(p)


def add_fit_arguments(p: argparse.ArgumentParser, *, per_condition: bool) -> None:
    """How a trial CSV is read and what is fitted (``fit-frf`` and ``cohort`` share them)."""
    add_trial_arguments(p, input_help="what the stimulus is: tilt [rad] (default) or "
                        "platform translation [m].")
    add_flag(p, "--output", MODEL_OUTPUTS)
    p.add_argument("--free", required=True, metavar="NAMES",
                   help="parameters shared by the conditions, comma separated, from "
                   "stiffness:PAIR, viscosity:PAIR, active_stiffness:PAIR, "
                   "active_viscosity:PAIR, feedback_delay, proprioceptive_weight, "
                   "torque_feedback_gain, torque_feedback_time_constant (e.g. "
                   "active_stiffness:ankle,feedback_delay).")
    if per_condition:
        p.add_argument("--per-condition", default="", metavar="NAMES",
                       help="parameters with one value per condition (names as --free).")
    p.add_argument("--bounds", default="", metavar="NAME=LO:HI,...",
                   help="bounds of fitted parameters, replacing the defaults (e.g. "
                   "active_stiffness:ankle=0:2000,feedback_delay=0.05:0.3 [N·m/rad], [s]); "
                   "within the table's ranges.")
    from ._recording import add_cycle_trim_argument, add_recording_arguments

    add_recording_arguments(p, subject=False)  # the body's --height and --mass
    add_cycle_trim_argument(p)


def reader_options(args: argparse.Namespace) -> dict:
    """:func:`posturelab.frequency.cohort.read_frf_file`'s options from the command line."""
    from ._recording import recording_options
    from .frf import response_sign

    return {"stimulus": args.stimulus, "response": args.response,
            "cycle_length": args.cycle_length, "discard_cycles": args.discard_cycles,
            "response_sign": response_sign(args.response_sign), "input": args.input,
            **recording_options(args)}


def _condition(path: str, args: argparse.Namespace, readings: dict | None = None):
    """The one FRF of a --data file (commands that take one condition per file: a
    dual-stimulus trial needs --stimulus COLUMN there); what reading a trial did is put in
    ``readings[path]`` (a :class:`~posturelab.recordings.table.Recording`)."""
    found = _conditions(path, args, readings)
    if len(found) > 1:
        raise ParameterError(f"--data {path!r} is a dual-stimulus trial "
                             f"({', '.join(label for _, _, label in found)}): give "
                             "--stimulus COLUMN")
    return found[0][0]


def _conditions(path: str, args: argparse.Namespace,
                readings: dict | None = None) -> list[tuple]:
    """The conditions of one --data file as (FRF, model input, label): one, or each
    stimulus of a dual-stimulus trial (--stimulus tilt,visual_tilt, or a trial with both
    columns and no --stimulus: posturelab.frequency.dual). What reading a one-stimulus
    trial did is put in ``readings[path]``."""
    from ..frequency.cohort import read_frf_file, read_trial_frf
    from ..frequency.dual import input_of, read_trial_frfs, stimulus_columns
    from ._recording import check_sway_response

    if path.lower().endswith(".json"):
        from ..frequency.table import read_frf_json_stimuli

        tables = read_frf_json_stimuli(path, "--data FRF JSON")
        if None in tables:
            return [(tables[None], args.input, path)]
        if args.stimulus:  # (some of a dual trial's FRFs)
            wanted = [s.strip().lower() for s in args.stimulus.split(",") if s.strip()]
            unknown = [s for s in wanted if s not in tables]
            if unknown:
                raise ParameterError(f"--stimulus {unknown[0]!r} is not in --data {path!r}; "
                                     f"it has {', '.join(tables)}")
            tables = {s: tables[s] for s in wanted}
        return [(t, input_of(s), f"{path} [{s}]") for s, t in tables.items()]
    stimuli = ([s.strip().lower() for s in args.stimulus.split(",") if s.strip()]
               if args.stimulus else stimulus_columns(path))
    if len(stimuli) > 1:
        if args.cycle_length is None:
            raise ParameterError("a trial CSV needs --cycle-length")
        from ._recording import recording_options

        options = reader_options(args)
        _, ests, _ = read_trial_frfs(path, stimuli, args.response or "com_angle",
                                     args.cycle_length, discard_cycles=args.discard_cycles,
                                     response_sign=options["response_sign"],
                                     **recording_options(args))
        return [(e, input_of(s), f"{path} [{s}]") for s, e in ests.items()]
    options = reader_options(args)
    if stimuli and not args.stimulus:  # the trial's one stimulus column
        options["stimulus"] = stimuli[0]
    if options["stimulus"] is not None and options["response"] is None:
        options["response"] = "com_angle"
    source = args.input  # a visual_tilt column is the scene's (a tilt [rad] to the reader)
    if options["stimulus"] is not None and input_of(options["stimulus"]) == "visual-tilt":
        source = "visual-tilt"
    if options["stimulus"] is None:  # (read_frf_file says what a trial needs)
        return [(read_frf_file(path, **options), source, path)]
    check_sway_response(args, options["response"])
    frf, rec = read_trial_frf(path, **options)
    if readings is not None:
        readings[path] = rec
    return [(frf, source, path)]


def _names(text: str) -> list[str]:
    return [n.strip().lower() for n in str(text).split(",") if n.strip()]


def _bounds(text: str) -> dict:
    out = {}
    for item in _names(text):
        name, _, rng = item.partition("=")
        parts = rng.split(":")
        try:
            if len(parts) != 2:
                raise ValueError
            lo, hi = float(parts[0]), float(parts[1])
        except ValueError:
            raise ParameterError(f"--bounds must be NAME=LO:HI,..., got {item!r}") from None
        if name in out:
            raise ParameterError(f"--bounds names {name!r} twice")
        out[name] = (lo, hi)
    return out


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from .._files import refuse_input_as_output
    from ..frequency.fit import check_fit_request, fit_frf
    from .frf import check_plot_path

    refuse_input_as_output({"--data": args.data}, {"--plot": args.plot,
                                                   "--compare-out": args.compare_out,
                                                   "--compare-plot": args.compare_plot})
    check_plot_path(args.plot)
    compare = _compare_request(args)
    model = model_from_args(args)
    body, muscles, options = model.body, model.muscles, model.options
    free, per = _names(args.free), _names(args.per_condition)
    checked = check_fit_request(muscles, free, per, None)  # the names first, before any data
    if compare is not None:
        compare["parameter"] = check_fit_request(muscles, [args.compare])[0][0]
        moved = [n for n in checked[0] + checked[1] if n != compare["parameter"]]
        check_fit_request(muscles, moved, [compare["parameter"]], _bounds(args.bounds))
    else:
        check_fit_request(muscles, free, per, _bounds(args.bounds))
    readings: dict = {}
    from ._recording import refuse_repeated_files

    refuse_repeated_files(args.data)
    found = [c for path in args.data for c in _conditions(path, args, readings)]
    conditions = [c for c, _, _ in found]
    names = [label for _, _, label in found]
    fit_options = dict(input=[source for _, source, _ in found],
                       output=args.output.strip().lower(),
                       feedback_delay=options.feedback_delay,
                       proprioceptive_weight=options.proprioceptive_weight,
                       visual_weight=options.visual_weight,
                       torque_feedback_gain=options.torque_feedback_gain,
                       torque_feedback_time_constant=options.torque_feedback_time_constant,
                       bounds=_bounds(args.bounds))
    comparison = None
    if compare is not None:

        from ..frequency.reweighting import compare_conditions

        compare.pop("out"), compare.pop("plot")
        comparison = compare_conditions(body, muscles, conditions, free, per_condition=per,
                                        labels=[Path(n).name for n in names],
                                        **compare, **fit_options)
        fit = comparison.general
        _write_comparison(comparison, args)
    else:
        fit = fit_frf(body, muscles, conditions, free, per_condition=per, **fit_options)
    if args.plot:
        from ..viz.plots import plot_bode, save_figure

        labels = [Path(p).name + ("" if getattr(c, "response_sign", None) is None
                       else f" (response × {int(c.response_sign):+d})")
                  for p, c in zip(names, conditions, strict=True)]
        curves = [(f, h, f"fit: {label}") for (f, h), label in zip(fit.curves, labels,
                                                                     strict=True)]
        save_figure(plot_bode(conditions, labels, model=curves),
                    args.plot)
    signs = sorted({int(c.response_sign) for c in conditions
                    if getattr(c, "response_sign", None) is not None})
    from ..frequency.estimate import FRFEstimate

    sign_warnings = [f"--data {p!r}: {w}" for p, c in zip(names, conditions, strict=True)
                     if isinstance(c, FRFEstimate) for w in c.warnings]
    if sign_warnings:
        import sys

        for w in sign_warnings:
            print(f"warning: {w}", file=sys.stderr)
    kinds = [{"data": p, "kind": "trial" if isinstance(c, FRFEstimate) else c.kind,
              **(readings[p].report_dict() if p in readings else {})}
             for p, c in zip(names, conditions, strict=True)]
    if any(source != args.input for _, source, _ in found):  # (a visual tilt among them)
        for kind, (_, source, _) in zip(kinds, found, strict=True):
            kind["input"] = source
    if args.json:
        out = fit.to_dict()
        extra = {} if comparison is None else {"reweighting": comparison.to_dict()}
        print_json({**out, "conditions": kinds, "response_sign": signs,
                    "warnings": sign_warnings + out["warnings"], **extra})
        return 0
    from ._recording import print_reading

    for path, rec in readings.items():
        print_reading(rec, path)
    print(f"fitted {len(fit.names)} parameter(s) to {len(conditions)} condition(s); fit error "
          f"{fit.fit_error:.3g} (√(χ²/dof); about 1 when the model explains the data)")
    by_vision = comparison is not None and comparison.grouping == "vision"
    print(("conditions: " if by_vision else "conditions (NAME#k is condition k's value): ")
          + ", ".join(f"#{k + 1} {c['data']} ({c['kind']})" for k, c in enumerate(kinds)))
    if by_vision:
        print("per vision label, NAME#g is label g's value: " + ", ".join(
            f"#{g + 1} eyes {v}" for g, v in enumerate(comparison.groups)))
    print(f"weighting: {fit.weighting_text()}")
    if signs:
        print("response sign applied: " + ", ".join(f"{v:+d}" for v in signs))
    from .._bounds import bound_note

    for name, e, se, (lo, hi), ok, side, clipped, (blo, bhi) in zip(
            fit.names, fit.estimates, fit.standard_errors, fit.confidence_intervals,
            fit.determined, fit.at_bound, fit.clipped, fit.search_bounds, strict=True):
        if side is not None:
            note = f"   ({bound_note(name, side, blo, bhi)}: not determined by these data)"
        else:
            note = "" if ok else "   (not determined by these data)"
        if clipped:
            note += "   (interval clipped to the accepted range and search bounds)"
        if fit.mismatch:
            note += "   (model mismatch: the interval includes the systematic part)"
        print(f"  {name:<24} {e:10.4g} ± {se:.3g} {fit.unit(name)}   (95 % CI {lo:.4g} … "
              f"{hi:.4g}){note}")
    for w in fit.warnings:
        print(f"warning: {w}")
    print(f"variance accounted for: {100 * fit.variance_accounted_for:.4g} % (VAF)")
    if not fit.success:
        print(f"warning: the fit is not a success: {fit.reason}")
    if comparison is not None:
        _print_comparison(comparison)
    for path in (args.plot, args.compare_out, args.compare_plot):
        if path:
            print(f"wrote {path}")
    return 0


def _compare_request(args: argparse.Namespace) -> dict | None:
    """--compare and its options, checked before any work (None without --compare)."""
    given = [o for o, v in (("--amplitudes", args.amplitudes), ("--vision", args.vision),
                            ("--compare-by", args.compare_by),
                            ("--compare-out", args.compare_out),
                            ("--compare-plot", args.compare_plot)) if v]
    if not args.compare:
        if given:
            raise ParameterError(f"{given[0]} needs --compare NAME")
        return None
    if len(args.data) < 2:
        raise ParameterError("--compare needs at least two conditions (--data given once)")
    from .frf import check_plot_path

    check_plot_path(args.compare_plot)
    if args.compare_out:
        from ._common import check_writable

        check_writable([args.compare_out], {args.compare_out: (".json", ".csv")})
    amplitudes = vision = None
    if args.amplitudes:
        items = [a.strip() for a in args.amplitudes.split(",")]
        try:
            amplitudes = [None if a in ("", "-") else float(a) for a in items]
        except ValueError:
            raise ParameterError(f"--amplitudes must be numbers [rad or m] (or -), got "
                                 f"{args.amplitudes!r}"[:200]) from None
        if len(amplitudes) != len(args.data):
            raise ParameterError(f"--amplitudes gives {len(amplitudes)} value(s) for "
                                 f"{len(args.data)} --data")
    if args.vision:
        vision = [None if v.strip() in ("", "-") else v.strip().lower()
                  for v in args.vision.split(",")]
        if len(vision) != len(args.data):
            raise ParameterError(f"--vision gives {len(vision)} label(s) for "
                                 f"{len(args.data)} --data")
    return {"amplitudes": amplitudes, "vision": vision, "out": args.compare_out,
            "plot": args.compare_plot, "by": args.compare_by or "condition"}


def _write_comparison(comparison, args: argparse.Namespace) -> None:
    if args.compare_out:
        comparison.write(args.compare_out)
    if args.compare_plot:
        from ..viz.plots import plot_reweighting, save_figure

        save_figure(plot_reweighting(comparison), args.compare_plot)


def _print_comparison(c) -> None:
    print(f"{c.parameter} per condition [{c.unit}] "
          + ("(its vision label's value; " if c.grouping == "vision" else "(")
          + f"95 % CI; amplitude peak to peak [{c.amplitude_unit}]):")
    for k, (label, a, v, e, (lo, hi)) in enumerate(zip(
            c.labels, c.amplitudes, c.vision, c.estimates, c.confidence_intervals,
            strict=True)):
        seen = "" if v is None else f", eyes {v}"
        print(f"  #{k + 1} {label}: {e:.4g} ({lo:.4g} … {hi:.4g}); amplitude {a:.4g}{seen}")
    if c.grouping == "vision":
        for group in c.to_dict()["vision_groups"]:
            lo, hi = group["ci95"]
            print(f"  eyes {group['vision']} (#{', #'.join(map(str, group['conditions']))}): "
                  f"{group['estimate']:.4g} ({lo:.4g} … {hi:.4g})")
    lo, hi = c.shared_interval
    print(f"  shared: {c.shared_estimate:.4g} ({lo:.4g} … {hi:.4g})")
    verdict = "differs" if c.significant else "no significant difference"
    against = "one per condition" if c.grouping == "condition" else "one per vision label"
    print(f"likelihood-ratio test of one shared {c.parameter} against {against}: "
          f"ΔS = {c.likelihood_ratio:.4g}, statistic {c.statistic:.4g} ~ {c.distribution}, "
          f"p = {c.p_value:.3g} ({verdict} at p < 0.05)")
    for w in c.warnings[:len(c.warnings) - len(c.general.warnings)]:
        print(f"warning: {w}")
