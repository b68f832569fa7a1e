"""``posturelab design``: the standard errors a PRTS tilt experiment will give, before it."""

from __future__ import annotations

import argparse

from ..errors import ParameterError
from ._common import (
    add_muscle_arguments,
    model_from_args,
    parse_float_list,
    print_json,
)
from ._flags import MODEL_OUTPUTS, add_flag, add_flags, add_options

DESCRIPTION = """\
Predict, before the experiment, the standard error of each --free parameter that a fit of
the model FRF (posturelab fit-frf) to a PRTS tilt experiment will give, for a subject whose
parameters are those the body and controller options below state: the Fisher
information of the exact model FRF (the delay as e^{−sτ}) under the stated noise, 2 Re(Dᴴ
V⁻¹ D) with D = ∂H/∂θ over the bands (central differences) and V the covariance of the
estimated band FRFs: white --sensor-noise RAD on the recorded angle, and --motor-noise
SIGMA[,SIGMA...] N·m per joint (optionally low-passed at --motor-noise-cutoff HZ) through the
closed loop, for --cycles N analysed cycles (plus --discard-cycles, default 1) of --tilt
prts:AMPLITUDE_RAD[:STATE_DURATION_S][:SEQUENCE] recorded at --sample-rate HZ
(posturelab.frequency.design states the derivation and its sources;
posturelab.frequency.design_search the search). The errors fall as
1/(amplitude × √cycles) under the linear model.

--optimise searches the state duration (--state-durations LO:HI s, default 0.1:0.5), the
amplitude (--amplitudes LO:HI rad peak to peak, default 0.005:0.07) and the cycles (as many
as fit) on a --grid of values per range (default 9, at most 41) for the smallest Σ (se/|θ|)²
over --targets (default: every --free parameter) within --budget SECONDS of recording,
discarded cycles included. --optimise chooses the cycles and the PRTS amplitude and state
duration itself: it refuses --cycles and --tilt (bound the search with --amplitudes and
--state-durations instead). Under the linear model the largest amplitude always wins; a real
subject reweights with amplitude (Peterka 2002), which the prediction does not know.

--json prints one object: {"parameters": {NAME: {"value", "standard_error",
"relative_error", "unit"}}, "design": {...}, "bands": {"frequency", "frf_se"}} and, with
--optimise, "optimised": {"objective", "targets", "budget", "searched", "by_state_duration"}.

Example: posturelab design --controller peterka-2002 --tilt prts:0.035 --cycles 5 \\
             --free active_stiffness,active_viscosity,feedback_delay --sensor-noise 0.002 --json
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab design``."""
    add_muscle_arguments(p)
    add_flag(p, "--tilt", "prts:AMPLITUDE_RAD[:STATE_DURATION_S][:SEQUENCE] (default "
             "prts:0.035: posturelab-80, 0.25 s states, 20 s cycle).")
    add_flag(p, "--visual-tilt", "; the PRTS then moves the visual scene instead of the "
             "surface (--free may name visual_weight)")
    add_flag(p, "--cycles")  # (None: 5; refused with --optimise, which chooses them)
    add_flag(p, "--discard-cycles", "1; run before the analysed ones, they count in the "
             "duration", former=("--discard",), dest="discard", default=1)
    p.add_argument("--free", required=True, metavar="NAMES",
                   help="the parameters the fit estimates, comma separated (names as "
                   "fit-frf --free: stiffness:PAIR, viscosity:PAIR, active_stiffness:PAIR, "
                   "active_viscosity:PAIR, feedback_delay, proprioceptive_weight).")
    add_flag(p, "--sensor-noise", default=0.0)
    add_flags(p, "--motor-noise", "--motor-noise-cutoff")
    add_flag(p, "--sample-rate", "100", default=100.0)
    add_flag(p, "--output", MODEL_OUTPUTS)
    search = p.add_argument_group("searching the design (--optimise)")
    search.add_argument("--optimise", action="store_true",
                        help="search state duration, amplitude and cycles within --budget.")
    search.add_argument("--budget", type=float, default=None, metavar="SECONDS",
                        help="total recording time for --optimise [s].")
    add_options(search, {
        "--targets": ("NAMES", "the parameters whose errors --optimise minimises (default: "
                      "all --free)."),
        "--amplitudes": ("LO:HI", "peak-to-peak amplitudes --optimise searches [rad] "
                         "(default 0.005:0.07)."),
        "--state-durations": ("LO:HI", "state durations --optimise searches [s] (default "
                              "0.1:0.5)."),
    }, default=None)
    search.add_argument("--grid", type=int, default=9, metavar="N",
                        help="values per range for --optimise (2 … 41, default 9).")
    add_flags(p, "--json")
    p.set_defaults(seed=None)


def _names(text: str) -> list[str]:
    return [n.strip().lower() for n in str(text).split(",") if n.strip()]


def _pair(text: str | None, option: str, default):
    """LO:HI of ``option``, checked against the search's range (the option named)."""
    from ..frequency.design_search import _range

    if text is None:
        return default
    unit = "[rad]" if option == "--amplitudes" else "[s]"
    values = parse_float_list(text.replace(":", ","), f"{option} LO:HI {unit}", 2)
    low, high = ((1e-4, 0.5) if option == "--amplitudes" else (0.01, 10.0))
    return _range(f"{option} LO:HI {unit}", values, low, high)


def _check_numbers(args: argparse.Namespace) -> None:
    """The numbers given, each named by its option."""
    from .._validation import float_in_range
    from ..frequency.design import MAX_CYCLES
    from ..frequency.design_search import MAX_GRID

    float_in_range("--sensor-noise [rad]", args.sensor_noise, 0.0, 1.0, unit="rad")
    float_in_range("--sample-rate [Hz]", args.sample_rate, 1.0, 1e5, unit="Hz")
    for option, value, least, most in (("--cycles", 5 if args.cycles is None else args.cycles,
                                        2, MAX_CYCLES),
                                       ("--discard-cycles", args.discard, 0, MAX_CYCLES),
                                       ("--grid", args.grid, 2, MAX_GRID)):
        if not least <= value <= most:
            raise ParameterError(f"{option} must be an integer in [{least}, {most}], got "
                                 f"{value}")
    if args.budget is not None:
        float_in_range("--budget [s]", args.budget, 1e-3, 86_400.0, unit="s")


def run(args: argparse.Namespace) -> int:
    from ..frequency.design import predict_errors
    from ..frequency.design_search import (
        AMPLITUDE_RANGE,
        STATE_DURATION_RANGE,
        optimise_design,
    )
    from ._common import naming_option, parse_tilt
    from .simulate import motor_noise_from_args

    model = model_from_args(args)
    body, muscles, options = model.body, model.muscles, model.options
    if args.tilt is not None and args.visual_tilt is not None:
        raise ParameterError("give --tilt or --visual-tilt, not both (a dual-stimulus design "
                             "is not predicted)")
    scene = args.visual_tilt is not None
    with naming_option("--visual-tilt" if scene else "--tilt"):
        tilt = parse_tilt(args.visual_tilt if scene else args.tilt or "prts:0.035")
    with naming_option("--motor-noise"):
        noise = motor_noise_from_args(args, body.n_links)
    free = _names(args.free)
    _check_numbers(args)
    common = dict(discard=args.discard, sensor_noise=args.sensor_noise, motor_noise=noise,
                  sample_rate=args.sample_rate, output=args.output.strip().lower(),
                  feedback_delay=options.feedback_delay,
                  proprioceptive_weight=options.proprioceptive_weight,
                  input="visual-tilt" if scene else "tilt", visual_weight=options.visual_weight)
    if args.optimise:
        if args.budget is None:
            raise ParameterError("--optimise needs --budget SECONDS")
        if args.cycles is not None:
            raise ParameterError("--cycles cannot be given with --optimise: the search chooses "
                                 "the cycles (as many as --budget holds); drop --cycles, or "
                                 "drop --optimise to predict that design")
        if args.tilt is not None or args.visual_tilt is not None:
            flag = "--tilt" if args.tilt is not None else "--visual-tilt"
            raise ParameterError(f"{flag} cannot be given with --optimise: the search chooses "
                                 "the amplitude and state duration; bound them with "
                                 "--amplitudes LO:HI and --state-durations LO:HI instead")
        result = optimise_design(
            body, muscles, free, budget=args.budget,
            targets=None if args.targets is None else _names(args.targets), tilt=tilt,
            amplitude_range=_pair(args.amplitudes, "--amplitudes", AMPLITUDE_RANGE),
            state_duration_range=_pair(args.state_durations, "--state-durations",
                                       STATE_DURATION_RANGE), grid=args.grid, **common)
        prediction, out = result.best, result.to_dict()
    else:
        for flag in ("budget", "targets", "amplitudes", "state_durations"):
            if getattr(args, flag) is not None:
                raise ParameterError(f"--{flag.replace('_', '-')} needs --optimise")
        prediction = predict_errors(body, muscles, free, tilt=tilt,
                                    cycles=5 if args.cycles is None else args.cycles,
                                    **common)
        out = prediction.to_dict()
    if args.json:
        print_json(out)
        return 0
    p = prediction
    head = "optimised design" if args.optimise else "design"
    head += " (visual scene)" if scene else ""
    print(f"{head}: PRTS {p.amplitude:.4g} rad peak to peak, {p.state_duration:g} s states "
          f"({p.cycle_length:g} s cycle), {p.cycles} cycles + {p.discard} discarded = "
          f"{p.duration:g} s; sensor noise {p.sensor_noise:g} rad; motor noise: {p.motor_noise}")
    for name, row in out["parameters"].items():
        se = row["standard_error"]
        text = ("not determined by this experiment" if se is None else
                f"± {se:.3g} {row['unit']}" + ("" if row["relative_error"] is None else
                                                f"   ({100 * row['relative_error']:.3g} %)"))
        print(f"  {name:<24} {row['value']:10.4g}   {text}")
    if args.optimise:
        print(f"objective Σ (se/|θ|)² over {', '.join(result.targets)}: {result.objective:.3g} "
              f"({result.searched['designs']} designs compared)")
    return 0
