"""``posturelab sensitivity``: the disturbance-severity vector J(Θ)⁻¹H(Θ)."""

from __future__ import annotations

import argparse
import math

from ..errors import ParameterError
from ._common import parse_float_list, print_json
from ._flags import add_flags

DESCRIPTION = """\
J(Θ)⁻¹H(Θ) [rad/m] for the paper's three-link body: the change of each link's rate
[rad/s] per unit change of platform velocity [m/s] (ΔΘ̇ = −J⁻¹H Δẋ_d), evaluated at
posture Θ (default upright; each |θ_i| ≤ π/2, a link at most horizontal). The paper
prints [2.5580, -0.0654, 0.0027] at upright.
"""

#: Largest link angle of a posture, either way: a link at most horizontal. [rad]
MAX_POSTURE_ANGLE = math.pi / 2


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab sensitivity``."""
    p.add_argument("--posture", metavar="T1,T2,T3", default="0,0,0",
                   help="link angles θ1,θ2,θ3 [rad] from the vertical, forward positive, each "
                   "within ±π/2 (default 0,0,0).")
    add_flags(p, "--json")


def run(args: argparse.Namespace) -> int:
    from ..linear.analysis import disturbance_sensitivity
    from ..model.body import paper_body

    body = paper_body()
    posture = parse_float_list(args.posture, "--posture [rad]", body.n_links)
    for i, theta in enumerate(posture, 1):
        if not abs(theta) <= MAX_POSTURE_ANGLE:
            raise ParameterError(f"--posture θ{i} must be in [-π/2, π/2] rad (a link at most "
                                 f"horizontal), got {theta:g}")
    value = disturbance_sensitivity(body, posture)
    if args.json:
        print_json({"posture": posture, "sensitivity": [float(v) for v in value]})
        return 0
    print(f"posture [rad]: {', '.join(f'{x:g}' for x in posture)}")
    print("J⁻¹H [rad/m] (link rate change per platform velocity change):")
    for i, v in enumerate(value, 1):
        print(f"  link {i}: {v:+.4f}")
    ratios = [f"{abs(value[0]) / abs(v):.0f}" if v != 0 else "inf" for v in value[1:]]
    print("ankle-to-higher-link ratios: " + ", ".join(ratios))
    return 0
