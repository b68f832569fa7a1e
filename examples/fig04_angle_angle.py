"""Paper Fig. 4: thigh and torso angles against the leg angle
============================================================

θ2 and θ3 against θ1 [rad] in the backward platform motion (case 1).

The dashed diagonal θ = θ1 is a straight knee for θ2: the paper reads the figure
as "the knee gets locked at the point of maximum excursion forward".

Usage: python examples/fig04_angle_angle.py [OUTPUT_DIR]   (default: current directory)
"""

import sys
from pathlib import Path

import numpy as np

from posturelab.scenarios import builtin_scenario
from posturelab.viz.plots import new_figure, plot_angle_angle, save_figure


def make_figure():
    """The figure (a pyplot-free matplotlib Figure); prints the knee angle at the peak."""
    scenario = builtin_scenario("paper-backward-case1")
    result = scenario.run()
    fig, ax = new_figure(figsize=(7.0, 5.5))
    plot_angle_angle(result, ax, link_names=[s.name for s in scenario.body.segments])
    i = int(np.argmax(result.theta[:, 0]))
    knee = result.theta[i, 1] - result.theta[i, 0]
    print(f"knee angle θ2 − θ1 at the maximum forward excursion: {knee:+.3f} rad")
    fig.suptitle("Fig. 4 — backward platform motion, case 1")
    return fig


def main(out_dir: Path) -> Path:
    return save_figure(make_figure(), out_dir / "fig04_angle_angle.png")


if __name__ == "__main__":
    out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
    fig = make_figure()
    print(save_figure(fig, out_dir / "fig04_angle_angle.png"))
