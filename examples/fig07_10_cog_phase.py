"""Paper Figs. 7–10: centre-of-gravity phase portraits
=====================================================

Horizontal centre-of-gravity velocity [m/s] against position [m].

Fig. 7: backward platform motion, case 1; Fig. 8: forward, case 1 (artificial
antagonist gastrocnemius); Fig. 9: forward, case 2 (no gastrocnemius, falls);
Fig. 10: forward, case 3 (no gastrocnemius, doubled ankle stiffness, recovers
slowly). A typical foot (not in the paper's model) is shaded.

Usage: python examples/fig07_10_cog_phase.py [OUTPUT_DIR]   (default: current directory)
"""

import sys
from pathlib import Path

from posturelab.simulate import FOOT_FROM_LITERATURE

from posturelab.scenarios import builtin_scenario
from posturelab.viz.plots import new_figure, plot_cog_phase, save_figure

PANELS = (
    ("paper-backward-case1", "Fig. 7 — backward, case 1"),
    ("paper-forward-case1", "Fig. 8 — forward, case 1"),
    ("paper-forward-case2", "Fig. 9 — forward, case 2"),
    ("paper-forward-case3", "Fig. 10 — forward, case 3"),
)


def make_figure():
    """The figure (a pyplot-free matplotlib Figure); prints each run's outcome."""
    fig, axes = new_figure(2, 2, figsize=(12.0, 11.0))
    for ax, (name, title) in zip(axes.ravel(), PANELS, strict=True):
        result = builtin_scenario(name).run()
        plot_cog_phase(result, ax, base_of_support=FOOT_FROM_LITERATURE, title=title)
        print(f"{title}: {result.message}")
    return fig


def main(out_dir: Path) -> Path:
    return save_figure(make_figure(), out_dir / "fig07_10_cog_phase.png")


if __name__ == "__main__":
    out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
    fig = make_figure()
    print(save_figure(fig, out_dir / "fig07_10_cog_phase.png"))
