"""``posturelab frf-model``: the linearised model's frequency response, exact."""

from __future__ import annotations

import argparse

from ..errors import ParameterError
from ._common import (
    add_muscle_arguments,
    body_from_args,
    feedback_options_from_args,
    muscles_from_args,
    parse_float_list,
    print_json,
)

DESCRIPTION = """\
The frequency response function of the model linearised about upright, with the delay as
e^{−sτ} (no Padé approximation), for any body and controller (the options below, as in
posturelab simulate). --input tilt (the surface angle, rad) or translation (the platform
displacement, m); --output com_angle (Σ a_i θ_i / Σ a_i), theta1 … or a joint angle
(ankle_angle, knee_angle, hip_angle). Tilt FRFs use the literature's sign: a body that
follows the surface has gain 1 and phase 0. At --frequencies LIST [Hz] or at the band
frequencies of Peterka's 11 bands (--bands peterka, for --cycle-length s, default 20).

--json prints one object: {"frequency": [Hz], "frf": [{"re", "im"}], "gain", "phase_deg"}.

Example: posturelab frf-model --controller peterka-2002 --bands peterka --json
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab frf-model``."""
    add_muscle_arguments(p)
    p.add_argument("--input", choices=["tilt", "translation"], default="tilt",
                   help="tilt [rad] (default) or platform translation [m].")
    p.add_argument("--output", default="com_angle", metavar="NAME",
                   help="com_angle (default), thetaN or a joint angle (ankle_angle, …).")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--frequencies", metavar="LIST", help="frequencies [Hz], > 0.")
    g.add_argument("--bands", choices=["peterka"], help="Peterka's 11 band frequencies.")
    p.add_argument("--cycle-length", type=float, default=20.0, metavar="SECONDS",
                   help="stimulus cycle for --bands [s] (default 20).")
    p.add_argument("--json", action="store_true", help="print one JSON object.")


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from ..frequency.bands import PETERKA_BAND_HARMONICS, band_frequencies
    from ..frequency.model import model_frf

    body = body_from_args(args)
    muscles = muscles_from_args(args, body)
    options = feedback_options_from_args(args)
    if args.frequencies is not None:
        f = np.array(parse_float_list(args.frequencies, "--frequencies [Hz]"))
        if np.any(f <= 0) or f.size > 100_000:
            raise ParameterError("--frequencies [Hz] must be 1 … 100,000 values > 0")
    else:
        if not (np.isfinite(args.cycle_length) and args.cycle_length > 0):
            raise ParameterError(f"--cycle-length [s] must be > 0, got {args.cycle_length:g}")
        f = band_frequencies(PETERKA_BAND_HARMONICS, args.cycle_length)
    H = model_frf(body, muscles, f, input=args.input, output=args.output.strip().lower(),
                  feedback_delay=options.get("feedback_delay", 0.0),
                  proprioceptive_weight=options.get("proprioceptive_weight", 1.0))
    phase = np.degrees(np.unwrap(np.angle(H)))
    if args.json:
        print_json({"frequency": [float(v) for v in f],
                    "frf": [{"re": float(h.real), "im": float(h.imag)} for h in H],
                    "gain": [float(abs(h)) for h in H],
                    "phase_deg": [float(p) for p in phase]})
        return 0
    unit = "" if args.input == "tilt" else " [rad/m]"
    print(f"model FRF of {args.output} to {args.input}{unit}")
    print(f"{'f [Hz]':>8} {'gain':>10} {'phase [deg]':>12}")
    for fk, h, p in zip(f, H, phase, strict=True):
        print(f"{fk:8.3f} {abs(h):10.4g} {p:12.1f}")
    return 0
