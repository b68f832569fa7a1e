"""Paper Fig. 3: link angles and rates after a backward platform step
====================================================================

The three link angles [rad] and rates [rad/s] against time [s].

Backward platform motion (a 1 m/s backward velocity step), case 1 of Table I,
initial posture [0.1, -0.1, 0.1] rad (the built-in scenario paper-backward-case1).

Usage: python examples/fig03_time_histories.py [OUTPUT_DIR]   (default: current directory)
"""

import sys
from pathlib import Path

from posturelab.scenarios import builtin_scenario
from posturelab.viz.plots import new_figure, plot_time_histories, save_figure


def make_figure():
    """The figure (a pyplot-free matplotlib Figure)."""
    scenario = builtin_scenario("paper-backward-case1")
    result = scenario.run()
    fig, axes = new_figure(2, 1, figsize=(7.5, 6.0), sharex=True)
    plot_time_histories(result, axes, link_names=[s.name for s in scenario.body.segments])
    fig.suptitle("Fig. 3 — backward platform motion, case 1")
    return fig


def main(out_dir: Path) -> Path:
    return save_figure(make_figure(), out_dir / "fig03_time_histories.png")


if __name__ == "__main__":
    out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
    fig = make_figure()
    print(save_figure(fig, out_dir / "fig03_time_histories.png"))
