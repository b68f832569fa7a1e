"""Delay margin over the active gains of a one-link controller
=============================================================

How long a feedback delay τ [s] an inverted pendulum tolerates, over its active (neural,
delayed) ankle stiffness K_a and viscosity L_a. The body is the paper's as one link
(``paper-1link``, mgh = 564 N·m/rad), with the intrinsic gains of Peterka's model (the
``peterka-2002`` preset: none) so that the whole feedback is delayed. At each grid
point :func:`posturelab.delay_margin` finds the smallest delay at which a characteristic
root reaches the imaginary axis, exactly (Chen, Gu and Nett's matrix pencil), as
``posturelab delay-margin --controller peterka-2002`` does for one set. White: unstable
without any delay (K_a below mgh). Peterka's round values (K_P = 1.35 mgh,
K_D = 0.47 mgh·s, margin 0.265 s against his τ = 0.15 s) are marked, with the contour
of that τ.

Usage: python examples/delay_margin_map.py [OUTPUT_DIR]   (default: current directory)
"""

import sys
from pathlib import Path

import numpy as np

import posturelab as pl
from posturelab.model.controllers import get_controller
from posturelab.viz.plots import new_figure, save_figure

RESOLUTION = 41  # grid points per axis [-]


def compute(resolution: int = RESOLUTION):
    """Delay margin [s] over K_a = 0.5–3 mgh × L_a = 0.05–1.2 mgh·s (NaN: unstable at 0)."""
    body = pl.get_body("paper-1link")
    preset = get_controller("peterka-2002")
    muscles = preset.muscles(body)
    mgh = body.load_stiffness
    ka = np.linspace(0.5, 3.0, resolution) * mgh  # [N·m/rad]
    la = np.linspace(0.05, 1.2, resolution) * mgh  # [N·m·s/rad]
    margin = np.full((la.size, ka.size), np.nan)
    for iy, viscosity in enumerate(la):
        for ix, stiffness in enumerate(ka):
            m = muscles.with_active_feedback([stiffness], [viscosity])
            result = pl.delay_margin(body, m)
            if result.stable_without_delay:
                margin[iy, ix] = result.delay_margin
    return body, preset, ka, la, margin


def make_figure(resolution: int = RESOLUTION):
    """The figure (a pyplot-free matplotlib Figure)."""
    body, preset, ka, la, margin = compute(resolution)
    mgh = body.load_stiffness
    fig, ax = new_figure(figsize=(7.0, 5.2))
    shown = np.ma.masked_invalid(margin)
    image = ax.pcolormesh(ka / mgh, la / mgh, shown, cmap="viridis", shading="nearest")
    fig.colorbar(image, ax=ax, label="delay margin [s]")
    tau = preset.feedback_delay
    ax.contour(ka / mgh, la / mgh, shown, levels=[tau],
               colors="w", linewidths=1.5)
    own = pl.delay_margin(body, preset.muscles(body)).delay_margin
    ax.plot(preset.active_stiffness, preset.active_viscosity, "o", ms=8, mfc="gold", mec="k")
    ax.annotate(f"Peterka 2002: {own:.3f} s", (preset.active_stiffness,
                                               preset.active_viscosity),
                xytext=(6, 6), textcoords="offset points", fontsize=9, color="w")
    ax.set_xlabel(f"active ankle stiffness K_a / mgh [-] (mgh = {mgh:.0f} N·m/rad)")
    ax.set_ylabel("active ankle viscosity L_a / mgh [s]")
    ax.set_title(f"Delay margin of the one-link body; white contour: τ = {tau:g} s",
                 fontsize=10)
    finite = margin[np.isfinite(margin)]
    print(f"{margin.size} sets, {finite.size} stable without delay; delay margin "
          f"{finite.min():.3f} … {finite.max():.3f} s; Peterka 2002: {own:.4f} s")
    return fig


def main(out_dir: Path) -> Path:
    return save_figure(make_figure(), out_dir / "delay_margin_map.png")


if __name__ == "__main__":
    out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
    fig = make_figure()
    print(save_figure(fig, out_dir / "delay_margin_map.png"))
