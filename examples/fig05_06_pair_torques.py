"""Paper Figs. 5 and 6: muscle-pair torques
==========================================

Muscle-pair torques [N·m] against time [s] (backward platform motion, case 1).

Fig. 5: the ankle, knee and hip pairs and the gastrocnemius; Fig. 6: the
two-joint quadriceps pair alone. Writes both panels into one PNG.

Usage: python examples/fig05_06_pair_torques.py [OUTPUT_DIR]   (default: current directory)
"""

import sys
from pathlib import Path

import numpy as np

from posturelab.scenarios import builtin_scenario
from posturelab.viz.plots import new_figure, plot_pair_torques, save_figure


def make_figure():
    """The figure (a pyplot-free matplotlib Figure); prints each pair's peak torque."""
    result = builtin_scenario("paper-backward-case1").run()
    fig, (ax5, ax6) = new_figure(2, 1, figsize=(7.5, 7.5), sharex=True)
    plot_pair_torques(result, ("ankle", "knee", "hip", "gastrocnemius"), ax5,
                      title="Fig. 5 — the three single-joint pairs and the gastrocnemius")
    plot_pair_torques(result, ("quadriceps",), ax6, title="Fig. 6 — the quadriceps pair")
    peaks = np.abs(result.pair_torques).max(axis=0)
    for name, peak in zip(result.pair_names, peaks, strict=True):
        print(f"peak |M| {name:<14} {peak:7.1f} N·m")
    return fig


def main(out_dir: Path) -> Path:
    return save_figure(make_figure(), out_dir / "fig05_06_pair_torques.png")


if __name__ == "__main__":
    out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
    fig = make_figure()
    print(save_figure(fig, out_dir / "fig05_06_pair_torques.png"))
