"""``posturelab delay-margin``: the delay at which the linearised feedback loses stability."""

from __future__ import annotations

import argparse
import math

from ._common import (
    add_muscle_arguments,
    add_torque_feedback_arguments,
    feedback_given,
    model_from_args,
    print_json,
)
from ._flags import add_flags

DESCRIPTION = """\
The delay margin of the chain linearised about upright: the smallest feedback delay τ at
which a characteristic root of

    det(s² J0 − g A + K_i + s L_i + (K_a + s L_a) e^{−sτ}) = 0

reaches the imaginary axis, and the frequency ω [rad/s] of that crossing. K_i, L_i are the
intrinsic gains (immediate), K_a, L_a the active ones (delayed); without active gains every
pair's whole feedback is delayed. Computed exactly (Chen, Gu and Nett's matrix pencil, each
crossing polished by Newton's method), not by a frequency grid.

--torque-feedback-gain K (and --torque-feedback-time-constant S) adds Peterka 2002's torque
feedback: the delayed part is multiplied by g(s) = (S s + 1)/(S s + 1 − K), the filter's
states join the quasi-polynomial (docs/design.md), and the margin is of that loop ("torque
feedback": {"gain", "time_constant"} in --json).

Prints the margin in s and ms and the crossing frequency; with --feedback-delay also the
rightmost roots at that delay. --json prints one object:
  {"delay_margin": seconds, or null when there is none (then "stable_at_every_delay"
   says why: true, no crossing; false, unstable without delay), "crossing_frequency":
   rad/s or null, "stable_without_delay": true/false, "stable_at_every_delay": true/false,
   "units": {"delay_margin": "s", "crossing_frequency": "rad/s"}}
With one-sided pairs the margin is of the side where they are engaged, and
"unstable_sides" lists each other side on which upright is unstable already without delay
({"engaged", "slack", "rightmost_root_without_delay": {"re", "im"} [1/s],
"unstable_at_every_delay": true when the side's stiffness does not hold the gravitational
load, det(K − g A) < 0, so a real positive root exists at every delay}).

Example: posturelab delay-margin --case 1
         posturelab delay-margin --controller peterka-2002 --json
         posturelab delay-margin --controller peterka-2002 --torque-feedback-gain 0.5
"""


#: The unit of each number of the JSON object. [-]
JSON_UNITS = {"delay_margin": "s", "crossing_frequency": "rad/s"}


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab delay-margin``."""
    add_muscle_arguments(p)
    add_torque_feedback_arguments(p)
    add_flags(p, "--json")


def run(args: argparse.Namespace) -> int:
    from ..linear.delay import delay_margin
    from ..linear.verdict import upright_verdict
    from ..parameters import TORQUE_FEEDBACK_TIME_CONSTANT
    from ._common import torque_feedback_options_from_args

    # the filter is read here, not into the model: the margin needs no feedback delay
    given = torque_feedback_options_from_args(args)
    args.torque_feedback_gain = args.torque_feedback_time_constant = None
    model = model_from_args(args)
    body, muscles = model.body, model.muscles
    delay = model.options.feedback_delay if feedback_given(args) else None
    gain = float(given.get("torque_feedback_gain", 0.0))
    torque_feedback = dict(torque_feedback_gain=gain,
                           torque_feedback_time_constant=float(given.get(
                               "torque_feedback_time_constant", TORQUE_FEEDBACK_TIME_CONSTANT)))
    result = delay_margin(body, muscles, **torque_feedback)
    unstable = (_unstable_sides(body, muscles, torque_feedback)
                if muscles.one_sided_mask.any() else [])
    filtered = ({"torque_feedback": {"gain": gain, "time_constant":
                                     torque_feedback["torque_feedback_time_constant"]}}
                if gain > 0 else {})
    if args.json:
        sides = {"unstable_sides": unstable} if muscles.one_sided_mask.any() else {}
        units = {**JSON_UNITS, "torque_feedback": {"gain": "-", "time_constant": "s"}} \
            if filtered else JSON_UNITS
        print_json({**_json_margin(result), **sides, **filtered, "units": units})
        return 0
    kind = ("intrinsic gains at once, active gains delayed" if muscles.has_active_feedback
            else "every pair's whole feedback delayed")
    if filtered:
        kind += (f"; torque feedback K_t = {gain:g}, τ_t = "
                 f"{torque_feedback['torque_feedback_time_constant']:g} s")
    for side in unstable:
        root = side["rightmost_root_without_delay"]
        when = ("whatever the delay (its stiffness does not hold the gravitational load, "
                "det(K − g A) < 0)" if side["unstable_at_every_delay"]
                else "already without delay")
        print(f"upright is unstable while {' and '.join(side['slack'])} slack, {when}; "
              f"rightmost root {root['re']:.4g}{root['im']:+.4g}j 1/s at τ = 0")
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
        engaged = ", ".join(p.name for p in muscles.pairs if p.one_sided)
        print(f"  (only while {engaged} engaged; upright is the switching point"
              + ("; on the slack side there is no margin: unstable at τ = 0)" if unstable
                 else ")"))
    if delay is not None or muscles.one_sided_mask.any():
        # the one verdict about upright (posturelab poles and simulate give it too)
        verdict = upright_verdict(body, muscles, delay or 0.0, **torque_feedback)
        roots = verdict.side(engaged=True).roots[:4]
        print(f"at τ = {delay or 0.0:g} s: {verdict.describe()}; rightmost roots [1/s]: "
              + ", ".join(f"{z.real:.4g}{z.imag:+.4g}j" for z in roots))
    return 0


def _json_margin(result) -> dict:
    """The margin's JSON fields: a number or null in every numeric field (no "infinite"),
    and "stable_at_every_delay" telling a margin of no crossing from none at all."""
    out = result.to_dict()
    every = bool(result.stable_without_delay and math.isinf(result.delay_margin))
    if every:
        out["delay_margin"] = None
    return {**out, "stable_at_every_delay": every}


def _unstable_sides(body, muscles, torque_feedback: dict) -> list[dict]:
    """The sides of the one-sided pairs' switch, other than all engaged, on which upright is
    unstable without delay; ``unstable_at_every_delay`` when the characteristic function
    det(s I − A0 − A1 e^{−sτ}) of the first-order form is negative at s = 0, where it is
    det(−A0 − A1) whatever τ (without torque feedback of the sign of det(K − g A)): it tends
    to +∞ along the positive real axis, so a real positive root exists at every delay."""
    import numpy as np

    from ..linear.delay import delayed_system
    from ..linear.verdict import _side_muscles, upright_verdict

    found = []
    for side in upright_verdict(body, muscles, 0.0, **torque_feedback).sides[1:]:
        if side.status != "unstable":
            continue
        system = delayed_system(body, _side_muscles(muscles, frozenset(side.engaged)),
                                **torque_feedback)
        static = float(np.linalg.det(-system.state_matrix()[0])) < 0
        z = side.rightmost_root
        found.append({"engaged": list(side.engaged), "slack": list(side.slack),
                      "rightmost_root_without_delay": {"re": float(z.real),
                                                       "im": float(z.imag)},
                      "unstable_at_every_delay": static})
    return found
