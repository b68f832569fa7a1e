"""Ankle or hip strategy as the platform moves further?
=====================================================

The paper proposes that people switch from the ankle to the hip strategy when the ankle
torque is limited (its Section VII). posturelab measures the strategy of a run by its
**hip fraction** (:mod:`posturelab.studies.strategy`, after Creath et al. 2005): the share
of the anti-phase leg–trunk mode b = (u − w)/2 in the motion, u and w the leg and trunk
angles [rad] less their starting values; 0 for a body that sways as one pendulum, 1 for
pure counter-rotation about the hip.

Here the paper's body with the case 1 impedance stands upright on a literature-sized foot
and the platform moves backward by 2–30 cm in a 0.5 s ramp and hold, with the net ankle
moment free or limited to 60 N·m (:func:`posturelab.studies.strategy.hip_fraction_study`,
compiled engine). Top: the hip fraction against the displacement [m]; crosses are runs
that fell. Bottom: leg and trunk angles [rad] of a small and of the largest limited run
that did not fall. Impedance alone does **not** switch strategy: without the limit the
response is linear and the hip fraction does not depend on the size; with the limit the
hip fraction only falls as the body tips over the ankle as one pendulum, and beyond a
point it falls. A hip strategy needs active hip control, which this model does not have.

Usage: python examples/strategy_switch.py [OUTPUT_DIR]   (default: current directory)
"""

import sys
from pathlib import Path

import numpy as np

import posturelab as pl
from posturelab.studies.strategy import hip_fraction_study
from posturelab.viz.plots import new_figure, save_figure

SIZES = np.linspace(0.02, 0.30, 29)  # backward displacements [m]
LIMIT = 60.0  # ankle torque limit [N·m]
RAMP = 0.5  # [s]
DURATION = 3.0  # [s]


def make_figure():
    """The figure (a pyplot-free matplotlib Figure)."""
    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    fall = pl.FallCriteria(base_of_support=pl.FOOT_FROM_LITERATURE)
    free = hip_fraction_study(body, muscles, SIZES, ankle_torque_limit=1e6, fall=fall,
                              ramp_duration=RAMP, duration=DURATION)
    limited = hip_fraction_study(body, muscles, SIZES, ankle_torque_limit=LIMIT, fall=fall,
                                 ramp_duration=RAMP, duration=DURATION)
    fig, (ax, ax_t) = new_figure(2, 1, figsize=(7.5, 7.5))
    for study, label, colour in ((free, "ankle moment free", "#1f77b4"),
                                 (limited, f"ankle moment ≤ {LIMIT:g} N·m", "#d62728")):
        ok = ~study.fell
        ax.plot(study.displacement[ok], study.hip_fraction[ok], "o-", ms=4, color=colour,
                label=label)
        if study.fell.any():
            ax.plot(study.displacement[~ok], study.hip_fraction[~ok], "x", color=colour,
                    label=f"{label}: fell")
    ax.set_xlabel("backward platform displacement [m]")
    ax.set_ylabel("hip fraction [-]")
    ax.set_ylim(bottom=0.0)
    ax.legend(fontsize=8)
    ax.set_title("Case 1 impedance, 0.5 s ramp and hold, literature-sized foot", fontsize=10)

    kept = limited.displacement[~limited.fell]
    limits = np.full(body.n_links, np.inf)
    limits[0] = LIMIT
    for size, style in ((SIZES[1], "-"), (kept.max(), "--")):
        run = pl.simulate(body, muscles, pl.RampAndHold(-float(size), RAMP), DURATION,
                          torque_limits=limits, fall=fall, engine="compiled")
        ax_t.plot(run.time, run.theta[:, 0], style, color="#2ca02c",
                  label=f"leg θ1, {size * 100:.0f} cm (hip fraction {run.hip_fraction:.3f})")
        ax_t.plot(run.time, run.theta[:, -1], style, color="#9467bd",
                  label=f"trunk θ3, {size * 100:.0f} cm")
    ax_t.set_xlabel("time t [s]")
    ax_t.set_ylabel("link angle [rad]")
    ax_t.legend(fontsize=8)
    ax_t.set_title(f"Ankle moment ≤ {LIMIT:g} N·m: leg and trunk lean together", fontsize=10)
    first_fall = limited.displacement[limited.fell]
    print(f"hip fraction, free: {free.hip_fraction.min():.4f} … {free.hip_fraction.max():.4f}; "
          f"limited, kept upright: at most {limited.hip_fraction[~limited.fell].max():.4f}; "
          f"limited runs fall from {first_fall.min() * 100:.0f} cm")
    return fig


def main(out_dir: Path) -> Path:
    return save_figure(make_figure(), out_dir / "strategy_switch.png")


if __name__ == "__main__":
    out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
    fig = make_figure()
    print(save_figure(fig, out_dir / "strategy_switch.png"))
