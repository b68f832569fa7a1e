"""``posturelab frf-model``: the linearised model's frequency response, exact."""

from __future__ import annotations

import argparse

from ..errors import ParameterError
from . import UsageError
from ._common import (
    add_muscle_arguments,
    add_torque_feedback_arguments,
    model_from_args,
    parse_float_list,
    print_json,
)
from ._flags import MODEL_OUTPUTS, add_flag, add_flags
from .frf import BAND_CHOICES

DESCRIPTION = """\
The frequency response function of the model linearised about upright, with the delay as
e^{−sτ} (no Padé approximation), for any body and controller (the options below, as in
posturelab simulate). --input tilt (the surface angle, rad), translation (the platform
displacement, m) or visual-tilt (the visual scene's angle, rad, positive toes-up like the
surface; it acts through the active feedback only, weighted by --visual-weight W_v: for one
link (W_v C)/(J s² − mgh + K_i + L_i s + C), C = (K_a + L_a s) e^{−sτ}; Peterka 2002);
--output com_angle (Σ a_i θ_i / Σ a_i), theta1 … or a joint angle
(ankle_angle, knee_angle, hip_angle). Tilt FRFs use the literature's sign: a body that
follows the surface has gain 1 and phase 0. At --frequencies LIST [Hz] or at the band
frequencies of the 11 bands of the 80-state protocol (COMTEST; --bands peterka, the
historical name, or posturelab-80 or comtest-80, for --cycle-length s,
default 20) or of a named sequence's bands (--bands peterka-2002-242: 17 bands of the 242-state
sequence, cycle 60.5 s by default; posturelab.frequency.bands.SEQUENCE_BANDS).

--torque-feedback-gain K and --torque-feedback-time-constant S add Peterka 2002's torque
feedback: the active torque fed back positively through K/(S s + 1) (docs/design.md).

A loop unstable about upright at its delay has no measurable FRF (a periodic-stimulus
experiment on it would fall): frf-model refuses it (exit 2, the rightmost root named).

--json prints one object: {"frequency": [Hz], "frf": [{"re", "im"}], "gain", "phase_deg",
"sign_convention"}.

Example: posturelab frf-model --controller peterka-2002 --bands peterka --json
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab frf-model``."""
    add_muscle_arguments(p)
    add_torque_feedback_arguments(p)
    p.add_argument("--input", choices=["tilt", "translation", "visual-tilt"], default="tilt",
                   help="tilt [rad] (default), platform translation [m] or visual-tilt "
                   "[rad].")
    add_flag(p, "--output", MODEL_OUTPUTS)
    g = p.add_mutually_exclusive_group()
    g.add_argument("--frequencies", metavar="LIST", help="frequencies [Hz], > 0.")
    g.add_argument("--bands", choices=BAND_CHOICES,
                   help="the band frequencies of the 80-state protocol (COMTEST; peterka, "
                   "its historical name, posturelab-80 and comtest-80: the same 11 bands) or "
                   "of Peterka 2002's 242-state sequence (17 bands).")
    add_flag(p, "--cycle-length", " of --bands (default 20; 60.5 for peterka-2002-242)")
    add_flags(p, "--json")


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from .._validation import float_in_range
    from ..frequency.bands import PETERKA_BAND_HARMONICS, SEQUENCE_BANDS, band_frequencies
    from ..frequency.model import model_frf

    model = model_from_args(args)
    body, muscles, options = model.body, model.muscles, model.options
    if args.input == "visual-tilt" and options.visual_weight == 0:
        raise UsageError("frf-model: --input visual-tilt with visual_weight 0: the scene has "
                         "no effect (gain 0, no phase); give --visual-weight W_v > 0")
    torque_feedback = dict(torque_feedback_gain=options.torque_feedback_gain,
                           torque_feedback_time_constant=options.torque_feedback_time_constant)
    if args.frequencies is not None:
        f = np.array(parse_float_list(args.frequencies, "--frequencies [Hz]"))
        if f.size > 100_000:
            raise ParameterError(f"--frequencies [Hz] must be 1 … 100,000 values, got "
                                 f"{f.size:,}")
        bad = f[(f <= 0) | (f > 1e4)]
        if bad.size:
            raise ParameterError(f"--frequencies [Hz] must be values in (0, 1e4] Hz, got "
                                 f"{bad[0]:g}")
    else:
        bands = SEQUENCE_BANDS.get(args.bands, PETERKA_BAND_HARMONICS)
        cycle = args.cycle_length
        if cycle is None:
            cycle = 60.5 if args.bands == "peterka-2002-242" else 20.0
        float_in_range("--cycle-length [s]", cycle, 1e-3, 1e5, unit="s")
        f = band_frequencies(bands, cycle)
    from ..linear.verdict import upright_verdict

    verdict = upright_verdict(body, muscles, options.feedback_delay, **torque_feedback)
    if not verdict.side(engaged=True).status == "stable":
        raise ParameterError(f"the loop is {verdict.describe()}: its FRF is not measurable "
                             "(a periodic-stimulus experiment would fall); change the gains, "
                             "--feedback-delay or the torque feedback")
    H = model_frf(body, muscles, f, input=args.input, output=args.output.strip().lower(),
                  feedback_delay=options.feedback_delay,
                  proprioceptive_weight=options.proprioceptive_weight,
                  visual_weight=options.visual_weight, **torque_feedback)
    phase = np.degrees(np.unwrap(np.angle(H)))
    phase[np.abs(H) == 0] = np.nan  # a zero response has no phase (null, "—")
    sign = ("−y/α (the literature's tilt sign: a body that follows the surface reads gain 1, "
            "phase 0)" if args.input == "tilt" else "−y/v (a body that follows the visual "
            "scene reads gain 1, phase 0)" if args.input == "visual-tilt"
            else "y/x (as the output is, per metre)")
    if args.json:
        print_json({"frequency": [float(v) for v in f],
                    "frf": [{"re": float(h.real), "im": float(h.imag)} for h in H],
                    "gain": [float(abs(h)) for h in H],
                    "phase_deg": [float(p) for p in phase], "sign_convention": sign})
        return 0
    unit = " [rad/m]" if args.input == "translation" else ""
    print(f"model FRF of {args.output} to {args.input}{unit}, {sign}")
    print(f"{'f [Hz]':>8} {'gain':>10} {'phase [deg]':>12}")
    for fk, h, p in zip(f, H, phase, strict=True):
        print(f"{fk:8.3f} {abs(h):10.4g} " + (f"{p:12.1f}" if p == p else f"{'—':>12}"))
    return 0
