"""How large a backward platform step does each ankle stiffness absorb?
======================================================================

Beyond the paper.

Case 1 of Table I with the ankle stiffness varied from 300 to 2000 N·m/rad
(viscosity 0.25 s × stiffness, as in the paper), standing upright at rest when
the platform is jerked backward at 0.05–3 m/s. A run falls when the centre
of gravity leaves a foot of literature size (``FOOT_FROM_LITERATURE``: heel
−0.063 m, toe +0.188 m from the ankle) or a link passes ±60°. The grid,
40 stiffnesses × 60 speeds = 2,400 runs of 5 s, goes to the compiled
simulator in one batch (``disturbance_scale`` multiplies a 1 m/s step); it
takes a fraction of a second once the simulator is compiled (the first use
after installing compiles it, about a minute).

Writes largest_step_vs_ankle.png: the largest speed recovered and the smallest
that fell, per ankle stiffness [m/s against N·m/rad].

Usage: python examples/largest_step_vs_ankle.py [OUTPUT_DIR]   (default: current directory)
"""

import sys
from pathlib import Path

import numpy as np
from posturelab.platform import VelocityStep
from posturelab.simulate import FOOT_FROM_LITERATURE, FallCriteria

from posturelab.model.body import paper_body
from posturelab.model.muscles import paper_muscles
from posturelab.simulation.compiled import simulate_batch
from posturelab.viz.plots import new_figure, save_figure

ANKLE = np.linspace(300.0, 2000.0, 40)  # [N·m/rad]
SPEED = np.linspace(0.05, 3.0, 60)  # [m/s]


def largest_recovered(ankle: np.ndarray = ANKLE, speed: np.ndarray = SPEED,
                      duration: float = 5.0) -> tuple[np.ndarray, np.ndarray]:
    """(largest speed recovered, smallest speed that fell) per ankle stiffness [m/s];
    NaN where every speed fell / none did."""
    base = np.asarray(paper_muscles("1").stiffnesses, dtype=float)
    stiffness = np.repeat(base[None, :], ankle.size * speed.size, axis=0)
    stiffness[:, 0] = np.repeat(ankle, speed.size)
    scale = np.tile(speed, ankle.size)  # × a 1 m/s backward step
    out = simulate_batch(paper_body(), stiffness, 0.25 * stiffness, VelocityStep.backward(1.0),
                         duration, fall=FallCriteria(base_of_support=FOOT_FROM_LITERATURE),
                         disturbance_scale=scale)
    fell = out.fell.reshape(ankle.size, speed.size)
    recovered = np.array([speed[~f].max() if (~f).any() else np.nan for f in fell])
    first_fall = np.array([speed[f].min() if f.any() else np.nan for f in fell])
    return recovered, first_fall


def make_figure():
    """The figure (a pyplot-free matplotlib Figure)."""
    recovered, first_fall = largest_recovered()
    fig, ax = new_figure(figsize=(7.0, 4.2))
    ax.fill_between(ANKLE, recovered, first_fall, step="mid", alpha=0.25,
                    label="boundary lies here (grid resolution)")
    ax.plot(ANKLE, recovered, drawstyle="steps-mid", label="largest step recovered")
    ax.set_xlabel("ankle stiffness [N·m/rad]")
    ax.set_ylabel("backward platform step [m/s]")
    ax.set_title("Case 1, upright start, literature-sized foot: how large a step is absorbed")
    ax.legend(loc="lower right")
    return fig


def main(out_dir: Path) -> Path:
    return save_figure(make_figure(), out_dir / "largest_step_vs_ankle.png")


if __name__ == "__main__":
    out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
    fig = make_figure()
    print(save_figure(fig, out_dir / "largest_step_vs_ankle.png"))
