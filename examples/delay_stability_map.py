"""D-subdivision: where a delayed PD controller keeps the inverted pendulum up
=============================================================================

The paper's body as one link (``paper-1link``, mgh = 564 N·m/rad) with the small intrinsic
ankle stiffness and viscosity of a typical identification (5 % and 2 % of mgh) and an active,
neural ankle feedback K_a, L_a delayed by τ = 0.15 s (Peterka 2002). The map is the real part
of the rightmost characteristic root over K_a × L_a (posturelab.linear.delay_batch; 40,000
sets in a few seconds); the stable region is outlined, Peterka's round values
(K_P = 1.35 mgh, K_D = 0.47 mgh·s, the ``peterka-2002`` preset) are marked.

Writes delay_stability_map.png.

Usage: python examples/delay_stability_map.py [OUTPUT_DIR]   (default: current directory)
"""

import sys
from pathlib import Path

import posturelab as pl
from posturelab.linear.delay_batch import delay_stability_map
from posturelab.model.controllers import get_controller
from posturelab.model.muscles import MusclePair, MuscleSet
from posturelab.viz.plots import plot_delay_stability_map, save_figure

DELAY = 0.15  # [s]


def compute(resolution: int = 200):
    """The map over 0–3 mgh × 0–1.2 mgh·s."""
    body = pl.get_body("paper-1link")
    mgh = body.load_stiffness
    base = MuscleSet((MusclePair("ankle", 0, 1, 0.05 * mgh, 0.02 * mgh, active_stiffness=0.0,
                                 active_viscosity=0.0),), 1)
    return delay_stability_map(body, base, DELAY, (0.0, 3 * mgh), (0.0, 1.2 * mgh), resolution)


def make_figure(resolution: int = 200):
    """The figure (a pyplot-free matplotlib Figure), Peterka's controller marked."""
    dmap = compute(resolution)
    preset = get_controller("peterka-2002")
    mgh = dmap.load_stiffness
    return plot_delay_stability_map(dmap, mark=(preset.active_stiffness * mgh,
                                                preset.active_viscosity * mgh, "Peterka 2002"))


def main(out_dir: Path) -> Path:
    return save_figure(make_figure(), out_dir / "delay_stability_map.png")


if __name__ == "__main__":
    out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
    fig = make_figure()
    print(f"wrote {save_figure(fig, out_dir / 'delay_stability_map.png')}")
