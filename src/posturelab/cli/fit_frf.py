"""``posturelab fit-frf``: fit a controller to frequency response functions."""

from __future__ import annotations

import argparse

from ..errors import ParameterError
from ._common import (
    add_muscle_arguments,
    body_from_args,
    feedback_options_from_args,
    muscles_from_args,
    print_json,
)

DESCRIPTION = """\
Fit the linearised model's FRF to one or several measured FRFs. Each --data is a condition:
a trial CSV (then --stimulus, --response and --cycle-length say how to estimate its FRF, as
posturelab frf does) or the JSON that posturelab frf --json writes. --free NAMES (comma
separated) are shared by the conditions, --per-condition NAMES take one value per condition.
Names: stiffness, viscosity (intrinsic), active_stiffness, active_viscosity (a :PAIR suffix
names a pair other than the first), feedback_delay, proprioceptive_weight. The body and the
starting values come from the options below (as in posturelab simulate); --bounds
NAME=LO:HI,... narrows the defaults (gains 0 … 1e5, delay 0 … 1 s, W 0 … 1).

Objective: the complex error against each band, weighted by its 95 % bound (posturelab.
frequency.fit); a trial's model FRF is averaged over each band's harmonics with the
stimulus's power, as its estimate is (a JSON FRF has no harmonics: the model is taken at the
band frequencies). Prints each parameter with its standard error and 95 % interval, the fit
error (the RMS weighted residual, about 1 when the model explains the data within its
noise), and parameters the data cannot determine; warns when a band's coherence is below 0.5.

Example: posturelab fit-frf --data trial.csv --stimulus tilt --response com_angle \\
             --cycle-length 20 --discard-cycles 1 --controller peterka-2002 \\
             --free active_stiffness,active_viscosity,feedback_delay
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab fit-frf``."""
    p.add_argument("--data", required=True, action="append", metavar="FILE",
                   help="a condition: trial.csv or frf.json (repeat for several).")
    p.add_argument("--stimulus", metavar="COLUMN", help="stimulus column of a trial CSV.")
    p.add_argument("--response", metavar="COLUMN", help="response column of a trial CSV.")
    p.add_argument("--cycle-length", type=float, metavar="SECONDS", help="of a trial CSV [s].")
    p.add_argument("--discard-cycles", type=int, default=0, metavar="N")
    p.add_argument("--input", choices=["tilt", "translation"], default="tilt")
    p.add_argument("--output", default="com_angle", metavar="NAME",
                   help="the model output the response is (default com_angle).")
    p.add_argument("--free", required=True, metavar="NAMES", help="shared parameters.")
    p.add_argument("--per-condition", default="", metavar="NAMES",
                   help="parameters with one value per condition.")
    p.add_argument("--bounds", default="", metavar="NAME=LO:HI,...")
    p.add_argument("--json", action="store_true", help="print one JSON object.")
    p.add_argument("--plot", metavar="BODE.png",
                   help="write a Bode plot of every condition with its fitted model (PNG/SVG/"
                   "PDF).")
    add_muscle_arguments(p)


def _condition(path: str, args: argparse.Namespace):
    import json

    import numpy as np

    from .._files import read_text
    from ..frequency.estimate import FRFEstimate

    if path.lower().endswith(".json"):
        try:
            obj = json.loads(read_text(path, "FRF JSON"))
            f = np.array(obj["frequency"], dtype=float)
            H = np.array([complex(z["re"], z["im"]) for z in obj["frf"]])
            coh = np.array(obj["coherence"], dtype=float)
            gci = np.array([[np.nan if v is None else v for v in pair]
                            for pair in obj["gain_ci95"]], dtype=float)
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise ParameterError(f"--data {path!r} is not an FRF JSON of posturelab frf: "
                                 f"{exc}") from None
        if not (f.size == H.size == coh.size == gci.shape[0]) or not np.all(np.isfinite(H)):
            raise ParameterError(f"--data {path!r}: frequency, frf, coherence and gain_ci95 "
                                 "must have one finite entry per band")
        phase = np.degrees(np.unwrap(np.angle(H)))
        return FRFEstimate(f, H, np.abs(H), phase, coh, gci, np.full(gci.shape, np.nan),
                           np.zeros(f.size, int), (), 0, 0.0, np.zeros(0), np.zeros(0))
    from ..frequency.data import read_series_csv
    from ..frequency.estimate import estimate_frf
    from .frf import response_sign, whole_cycles

    if args.stimulus is None or args.response is None or args.cycle_length is None:
        raise ParameterError("a trial CSV needs --stimulus, --response and --cycle-length")
    stim, resp = args.stimulus.strip().lower(), args.response.strip().lower()
    fs, cols = read_series_csv(path, [stim, resp])
    x, y, _ = whole_cycles(cols[stim], cols[resp], fs, args.cycle_length)
    return estimate_frf(x, y, fs, args.cycle_length, discard_cycles=args.discard_cycles,
                        response_sign=response_sign(stim, resp, "auto"))


def _names(text: str) -> list[str]:
    return [n.strip().lower() for n in str(text).split(",") if n.strip()]


def _bounds(text: str) -> dict:
    out = {}
    for item in _names(text):
        name, _, rng = item.partition("=")
        parts = rng.split(":")
        try:
            lo, hi = float(parts[0]), float(parts[1])
        except (IndexError, ValueError):
            raise ParameterError(f"--bounds must be NAME=LO:HI,..., got {item!r}") from None
        out[name] = (lo, hi)
    return out


def run(args: argparse.Namespace) -> int:
    from ..frequency.fit import fit_frf
    from .frf import check_plot_path

    check_plot_path(args.plot)
    body = body_from_args(args)
    muscles = muscles_from_args(args, body)
    options = feedback_options_from_args(args)
    conditions = [_condition(path, args) for path in args.data]
    fit = fit_frf(body, muscles, conditions, _names(args.free), input=args.input,
                  output=args.output.strip().lower(),
                  feedback_delay=options.get("feedback_delay", 0.0),
                  proprioceptive_weight=options.get("proprioceptive_weight", 1.0),
                  per_condition=_names(args.per_condition), bounds=_bounds(args.bounds))
    if args.plot:
        from pathlib import Path

        from ..viz.plots import plot_bode, save_figure

        labels = [Path(p).name for p in args.data]
        curves = [(f, h, f"fit: {label}") for (f, h), label in zip(fit.curves, labels,
                                                                     strict=True)]
        save_figure(plot_bode(conditions, labels, model=curves), args.plot)
    if args.json:
        print_json(fit.to_dict())
        return 0
    print(f"fitted {len(fit.names)} parameter(s) to {len(conditions)} condition(s); fit error "
          f"{fit.fit_error:.3g} (weighted RMS; about 1 when the model explains the data)")
    for name, e, se, (lo, hi), ok in zip(fit.names, fit.estimates, fit.standard_errors,
                                         fit.confidence_intervals, fit.determined,
                                         strict=True):
        note = "" if ok else "   (not determined by these data)"
        print(f"  {name:<24} {e:10.4g} ± {se:.3g} {fit.unit(name)}   (95 % CI {lo:.4g} … "
              f"{hi:.4g}){note}")
    for w in fit.warnings:
        print(f"warning: {w}")
    if not fit.success:
        print(f"warning: the optimiser did not converge: {fit.message}")
    if args.plot:
        print(f"wrote {args.plot}")
    return 0
