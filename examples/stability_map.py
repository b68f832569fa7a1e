"""Stability map over two pair stiffnesses
========================================

The paper's three-link biped linearised about upright, over a grid of the ankle and the
gastrocnemius pair stiffnesses [N·m/rad]; every other gain is Table I case 1's, each pair's
viscosity 0.25 s × its stiffness. The colour is the largest real part of the six poles
[1/s] (blue decays, red grows), the stable region is outlined and the Table I cases that
lie in this plane are marked: what ``posturelab stability-map --x stiffness:ankle:0:2000
--y stiffness:gastrocnemius:0:1000`` draws (:func:`posturelab.linear.batch.stability_map`,
the batched numba evaluator; its first use compiles or loads its kernels).

Usage: python examples/stability_map.py [OUTPUT_DIR]   (default: current directory)
"""

import sys
from pathlib import Path

from matplotlib.colors import TwoSlopeNorm

from posturelab.linear.batch import stability_map
from posturelab.viz.plots import new_figure, save_figure

RESOLUTION = 300  # grid points per axis [-]


def compute(resolution: int = RESOLUTION):
    """The map over ankle 0–2000 × gastrocnemius 0–1000 N·m/rad, others from case 1."""
    return stability_map(("stiffness:ankle", 0.0, 2000.0),
                         ("stiffness:gastrocnemius", 0.0, 1000.0), resolution,
                         case="1")


def make_figure(resolution: int = RESOLUTION):
    """The figure (a pyplot-free matplotlib Figure)."""
    smap = compute(resolution)
    grid = smap.grid
    xs, ys = grid.x_values, grid.y_values
    values = smap.max_real_part
    low, high = float(values.min()), float(values.max())
    span = max(abs(low), abs(high), 1e-12)
    norm = (TwoSlopeNorm(vmin=low, vcenter=0.0, vmax=high) if low < 0.0 < high
            else TwoSlopeNorm(vmin=-span, vcenter=0.0, vmax=span))
    fig, ax = new_figure(figsize=(7.5, 5.8))
    image = ax.pcolormesh(xs, ys, values, cmap="RdBu_r", norm=norm, shading="nearest")
    fig.colorbar(image, ax=ax, label="largest real part of the poles [1/s]")
    if smap.stable.any() and not smap.stable.all():
        ax.contour(xs, ys, smap.stable.astype(float), levels=[0.5], colors="k",
                   linewidths=1.5)
    for case, x, y in grid.table_i_points():
        ax.plot(x, y, "o", ms=7, mfc="gold", mec="k", clip_on=False, zorder=5)
        ax.annotate(f"case {case}", (x, y), xytext=(5, 5), textcoords="offset points",
                    fontsize=9)
    ax.set_xlabel(grid.x.label)
    ax.set_ylabel(grid.y.label)
    ax.set_title(f"Linearised stability about upright, others from Table I case "
                 f"{grid.base_case}: {100 * smap.stable_fraction:.1f}% stable (outlined)",
                 fontsize=10)
    print(f"{grid.size:,} parameter sets, {100 * smap.stable_fraction:.1f}% stable; "
          f"largest real part {low:.3g} … {high:.3g} 1/s")
    return fig


def main(out_dir: Path) -> Path:
    return save_figure(make_figure(), out_dir / "stability_map.png")


if __name__ == "__main__":
    out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
    fig = make_figure()
    print(save_figure(fig, out_dir / "stability_map.png"))
