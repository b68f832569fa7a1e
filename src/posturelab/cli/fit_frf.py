"""``posturelab fit-frf``: fit a controller to frequency response functions."""

from __future__ import annotations

import argparse

from ..errors import ParameterError
from ..parameters import MAX_FEEDBACK_DELAY
from ._common import (
    add_muscle_arguments,
    add_torque_feedback_arguments,
    body_from_args,
    feedback_options_from_args,
    muscles_from_args,
    print_json,
    torque_feedback_options_from_args,
)

DESCRIPTION = f"""\
Fit the linearised model's FRF to one or several measured FRFs. Each --data is a condition:
a trial CSV (then --stimulus, --response, --cycle-length and --response-sign say how to
estimate its FRF, as posturelab frf does), the JSON that posturelab frf --json writes, or a
table as JSON: {{"frequency": [Hz], "gain": [...], "phase_deg": [...]}} with optional
"gain_se" and "phase_se_deg" (standard errors of gain [-] and phase [deg], as published
group means give them), or "frf_se" (standard error of the complex value), "dof" and
"coherence". A trial's header may declare units, e.g. com [rad]; posturelab reads SI (time
in s, a tilt in rad, a translation in m) and refuses a column in another unit. --free
NAMES (comma separated) are shared by the conditions, --per-condition NAMES take one value
per condition, NAME#1, NAME#2, … in the order of --data (the output lists the conditions:
"conditions" in --json, each --data path and its kind, trial or table).
Names (the parameter table's, as for sweep --vary and fit --free): stiffness:PAIR,
viscosity:PAIR (intrinsic), active_stiffness:PAIR, active_viscosity:PAIR (:PAIR may be left
out on a body with one pair), feedback_delay, proprioceptive_weight, torque_feedback_gain,
torque_feedback_time_constant (Peterka 2002's torque feedback; starting values from
--torque-feedback-gain and --torque-feedback-time-constant). The body and the
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
a name given twice or a bound for a parameter not fitted is refused.

Example: posturelab fit-frf --data trial.csv --stimulus tilt --response com_angle \\
             --cycle-length 20 --discard-cycles 1 --controller peterka-2002 \\
             --free active_stiffness:ankle,active_viscosity:ankle,feedback_delay
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab fit-frf``."""
    p.add_argument("--data", required=True, action="append", metavar="FILE",
                   help="a condition: trial.csv or frf.json (repeat for several).")
    p.add_argument("--stimulus", metavar="COLUMN", help="stimulus column of a trial CSV.")
    p.add_argument("--response", metavar="COLUMN", help="response column of a trial CSV.")
    p.add_argument("--cycle-length", type=float, metavar="SECONDS", help="of a trial CSV [s].")
    p.add_argument("--discard-cycles", type=int, default=0, metavar="N",
                   help="leading cycles of a trial CSV to drop (the transient; default 0).")
    p.add_argument("--response-sign", choices=["-1", "+1", "1"], default="-1",
                   help="multiply a trial's response by this (default -1: posturelab's tilt "
                   "convention, as posturelab frf).")
    p.add_argument("--input", choices=["tilt", "translation"], default="tilt",
                   help="what the stimulus is: tilt [rad] (default) or platform "
                   "translation [m].")
    p.add_argument("--output", default="com_angle", metavar="NAME",
                   help="the model output the response is (default com_angle).")
    p.add_argument("--free", required=True, metavar="NAMES",
                   help="parameters shared by the conditions, comma separated, from "
                   "stiffness:PAIR, viscosity:PAIR, active_stiffness:PAIR, "
                   "active_viscosity:PAIR, feedback_delay, proprioceptive_weight, "
                   "torque_feedback_gain, torque_feedback_time_constant (e.g. "
                   "active_stiffness:ankle,feedback_delay).")
    p.add_argument("--per-condition", default="", metavar="NAMES",
                   help="parameters with one value per condition (names as --free).")
    p.add_argument("--bounds", default="", metavar="NAME=LO:HI,...",
                   help="bounds of fitted parameters, replacing the defaults (e.g. "
                   "active_stiffness:ankle=0:2000,feedback_delay=0.05:0.3 [N·m/rad], [s]); "
                   "within the table's ranges.")
    p.add_argument("--json", action="store_true", help="print one JSON object.")
    p.add_argument("--plot", metavar="BODE.png",
                   help="write a Bode plot of every condition with its fitted model (PNG/SVG/"
                   "PDF).")
    add_muscle_arguments(p)
    add_torque_feedback_arguments(p)


def _condition(path: str, args: argparse.Namespace):
    if path.lower().endswith(".json"):
        from ..frequency.table import read_frf_json

        return read_frf_json(path, "--data FRF JSON")
    from .._validation import float_in_range
    from ..frequency.data import read_series_csv
    from ..frequency.estimate import estimate_frf, whole_cycles
    from .frf import response_sign

    if args.stimulus is None or args.response is None or args.cycle_length is None:
        raise ParameterError("a trial CSV needs --stimulus, --response and --cycle-length")
    float_in_range("--cycle-length [s]", args.cycle_length, 1e-3, 1e5, unit="s")
    stim, resp = args.stimulus.strip().lower(), args.response.strip().lower()
    fs, cols = read_series_csv(path, [stim, resp],
                               {stim: ("rad",) if args.input == "tilt" else ("m",)})
    x, y, _ = whole_cycles(cols[stim], cols[resp], fs, args.cycle_length)
    return estimate_frf(x, y, fs, args.cycle_length, discard_cycles=args.discard_cycles,
                        response_sign=response_sign(args.response_sign))


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
    from .._files import refuse_input_as_output
    from ..frequency.fit import check_fit_request, fit_frf
    from .frf import check_plot_path

    refuse_input_as_output({"--data": args.data}, {"--plot": args.plot})
    check_plot_path(args.plot)
    body = body_from_args(args)
    muscles = muscles_from_args(args, body)
    options = feedback_options_from_args(args)
    check_fit_request(muscles, _names(args.free), _names(args.per_condition),
                      _bounds(args.bounds))  # the names first, before any data are read
    conditions = [_condition(path, args) for path in args.data]
    fit = fit_frf(body, muscles, conditions, _names(args.free), input=args.input,
                  output=args.output.strip().lower(),
                  feedback_delay=options.get("feedback_delay", 0.0),
                  proprioceptive_weight=options.get("proprioceptive_weight", 1.0),
                  per_condition=_names(args.per_condition), bounds=_bounds(args.bounds),
                  **torque_feedback_options_from_args(args))
    if args.plot:
        from pathlib import Path

        from ..viz.plots import plot_bode, save_figure

        labels = [Path(p).name + ("" if getattr(c, "response_sign", None) is None
                                  else f" (response × {int(c.response_sign):+d})")
                  for p, c in zip(args.data, conditions, strict=True)]
        curves = [(f, h, f"fit: {label}") for (f, h), label in zip(fit.curves, labels,
                                                                     strict=True)]
        save_figure(plot_bode(conditions, labels, model=curves),
                    args.plot)
    signs = sorted({int(c.response_sign) for c in conditions
                    if getattr(c, "response_sign", None) is not None})
    from ..frequency.estimate import FRFEstimate

    sign_warnings = [f"--data {p!r}: {w}" for p, c in zip(args.data, conditions, strict=True)
                     if isinstance(c, FRFEstimate) for w in c.warnings]
    if sign_warnings:
        import sys

        for w in sign_warnings:
            print(f"warning: {w}", file=sys.stderr)
    kinds = [{"data": p, "kind": "trial" if isinstance(c, FRFEstimate) else "table"}
             for p, c in zip(args.data, conditions, strict=True)]
    if args.json:
        out = fit.to_dict()
        print_json({**out, "conditions": kinds, "response_sign": signs,
                    "warnings": sign_warnings + out["warnings"]})
        return 0
    print(f"fitted {len(fit.names)} parameter(s) to {len(conditions)} condition(s); fit error "
          f"{fit.fit_error:.3g} (√(χ²/dof); about 1 when the model explains the data)")
    print("conditions (NAME#k is condition k's value): " + ", ".join(
        f"#{k + 1} {c['data']} ({c['kind']})" for k, c in enumerate(kinds)))
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
    if not fit.success:
        print(f"warning: the optimiser did not converge: {fit.message}")
    if args.plot:
        print(f"wrote {args.plot}")
    return 0
