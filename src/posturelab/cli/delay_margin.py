"""``posturelab delay-margin``: the delay at which the linearised feedback loses stability."""

from __future__ import annotations

import argparse
import math

from ._common import add_muscle_arguments, body_from_args, muscles_from_args, print_json

DESCRIPTION = """\
The delay margin of the chain linearised about upright: the smallest feedback delay τ at
which a characteristic root of

    det(s² J0 − g A + K_i + s L_i + (K_a + s L_a) e^{−sτ}) = 0

reaches the imaginary axis, and the frequency ω [rad/s] of that crossing. K_i, L_i are the
intrinsic gains (immediate), K_a, L_a the active ones (delayed); without active gains every
pair's whole feedback is delayed. Computed exactly (Chen, Gu and Nett's matrix pencil, each
crossing polished by Newton's method), not by a frequency grid.

Prints the margin in s and ms and the crossing frequency; with --feedback-delay also the
rightmost roots at that delay. --json prints one object:
  {"delay_margin": seconds, or null if unstable without delay, or "infinite" if no crossing,
   "crossing_frequency": rad/s or null, "stable_without_delay": true/false,
   "units": {"delay_margin": "s", "crossing_frequency": "rad/s"}}

Example: posturelab delay-margin --case 1
         posturelab delay-margin --controller peterka-2002 --json
"""


#: The unit of each number of the JSON object. [-]
JSON_UNITS = {"delay_margin": "s", "crossing_frequency": "rad/s"}


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab delay-margin``."""
    add_muscle_arguments(p)
    p.add_argument("--json", action="store_true", help="print one JSON object instead of text.")


def run(args: argparse.Namespace) -> int:
    from ..linear.delay import delay_margin
    from ..linear.verdict import upright_verdict
    from ._common import feedback_options_from_args

    body = body_from_args(args)
    muscles = muscles_from_args(args, body)
    delay = feedback_options_from_args(args).get("feedback_delay")
    result = delay_margin(body, muscles)
    if args.json:
        print_json({**result.to_dict(), "units": JSON_UNITS})
        return 0
    kind = ("intrinsic gains at once, active gains delayed" if muscles.has_active_feedback
            else "every pair's whole feedback delayed")
    print(f"delay margin ({kind}):")
    if not result.stable_without_delay:
        print("  unstable without delay: no delay margin")
    elif math.isinf(result.delay_margin):
        print("  no crossing: stable at every delay")
    else:
        w = result.crossing_frequency
        print(f"  τ = {result.delay_margin:.6g} s ({result.delay_margin * 1000:.4g} ms), a root "
              f"crosses at ω = {w:.6g} rad/s ({w / (2 * math.pi):.4g} Hz)")
    if muscles.one_sided_mask.any():
        print("  (of the side where the one-sided pairs are engaged; upright is their "
              "switching point)")
    if delay is not None or muscles.one_sided_mask.any():
        # the one verdict about upright (posturelab poles and simulate give it too)
        verdict = upright_verdict(body, muscles, delay or 0.0)
        roots = verdict.side(engaged=True).roots[:4]
        print(f"at τ = {delay or 0.0:g} s: {verdict.describe()}; rightmost roots [1/s]: "
              + ", ".join(f"{z.real:.4g}{z.imag:+.4g}j" for z in roots))
    return 0
