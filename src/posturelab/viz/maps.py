"""Figures of the linear analysis over a parameter plane: the stability map of pair
stiffnesses and the D-subdivision map of one pair's active gains with a feedback delay."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .figure import new_figure

__all__ = ["plot_stability_map", "plot_delay_stability_map", "strategy_map_figure",
           "strategy_limit_figure"]


def plot_stability_map(smap) -> Figure:
    """The stability map of two pair parameters: colour is the largest real part of the
    poles [1/s] (diverging at 0: blue decays, red grows); the stable region is outlined in
    black; Table I cases lying in the plane are marked.

    Parameters
    ----------
    smap : posturelab.linear.batch.StabilityMap

    Returns
    -------
    Figure
    """
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import TwoSlopeNorm
    from matplotlib.lines import Line2D

    grid = smap.grid
    xs, ys = grid.x_values, grid.y_values
    values = smap.max_real_part
    low, high = float(values.min()), float(values.max())
    if low < 0.0 < high:
        norm = TwoSlopeNorm(vmin=low, vcenter=0.0, vmax=high)
    else:
        span = max(abs(low), abs(high), 1e-12)
        norm = TwoSlopeNorm(vmin=-span, vcenter=0.0, vmax=span)
    dx, dy = xs[1] - xs[0], ys[1] - ys[0]
    extent = (xs[0] - dx / 2, xs[-1] + dx / 2, ys[0] - dy / 2, ys[-1] + dy / 2)

    fig, ax = new_figure(figsize=(7.5, 5.8))
    # Coloured once here, as RGBA bytes: matplotlib would map the float array through the
    # norm (masked arrays) at every draw; with nearest interpolation the pixels are the same.
    # Handed over as float32 bytes / 255, the very values matplotlib's resampler makes of
    # uint8 RGBA (np.divide(A, 0xff, dtype=np.float32)), so the PNG is byte for byte the
    # same, without that division on a masked array at draw time (0.07 s at 1000², 0.35 s
    # at 1414² measured).
    colours = ScalarMappable(norm=norm, cmap="RdBu_r")
    rgba = np.divide(colours.to_rgba(values, bytes=True), 0xff, dtype=np.float32)
    ax.imshow(rgba, origin="lower", extent=extent, aspect="auto", interpolation="nearest")
    fig.colorbar(colours, ax=ax, label="largest real part of the poles [1/s]")
    handles = []
    if smap.stable.any() and not smap.stable.all():
        ax.contour(xs, ys, smap.stable.astype(float), levels=[0.5], colors="k", linewidths=1.5)
        handles.append(Line2D([], [], color="k", lw=1.5, label="stable region boundary"))
    points = grid.table_i_points()
    if points:
        ax.plot([p[1] for p in points], [p[2] for p in points], "o", ms=7, mfc="gold",
                mec="k", clip_on=False, zorder=5)
        for case, x, y in points:
            ax.annotate(f"case {case}", (x, y), xytext=(5, 5), textcoords="offset points",
                        fontsize=9, annotation_clip=False,
                        bbox=dict(boxstyle="round,pad=0.2", fc="w", alpha=0.7))
        handles.append(Line2D([], [], ls="", marker="o", ms=7, mfc="gold", mec="k",
                              label="Table I cases"))
    ax.set_xlabel(grid.x.label)
    ax.set_ylabel(grid.y.label)
    ax.set_title(_stability_map_title(smap), fontsize=9)
    if handles:
        ax.legend(handles=handles, loc="upper right", fontsize=8, framealpha=0.8)
    state = "all stable" if smap.stable.all() else "none stable" if not smap.stable.any() else ""
    if state:
        ax.text(0.02, 0.02, state, transform=ax.transAxes, fontsize=9,
                bbox=dict(boxstyle="round", fc="w", alpha=0.8))
    return fig


def _stability_map_title(smap) -> str:
    """The body, where the parameters off the axes come from, and the stable share."""
    grid = smap.grid
    axes = (grid.x.name, grid.y.name)
    fixed = []
    if "viscosity_ratio" not in axes:
        fixed.append(f"viscosity ratio {grid.base_viscosity_ratio:g} s")
    others = [f"{n} {v:g}" for n, v in zip(grid.pair_names, grid.base_stiffness, strict=True)
              if f"stiffness:{n}" not in axes]
    if others:
        fixed.insert(0, f"{', '.join(others)} N·m/rad")
    source = (f"others from Table I case {grid.base_case}" if grid.base_case is not None
              else "others fixed" if fixed else "")
    return (f"Linearised stability about upright of body {smap.body_name}"
            f"{'; ' + source if source else ''}\n"
            f"{'(' + '; '.join(fixed) + '); ' if fixed else ''}"
            f"{100 * smap.stable_fraction:.1f}% stable")


def plot_delay_stability_map(dmap, *, mark=None) -> Figure:
    """The D-subdivision figure: the rightmost root's real part [1/s] over one pair's active
    stiffness × active viscosity at a fixed delay, both axes also as fractions of mgh, the
    stable region outlined.

    Parameters
    ----------
    dmap : posturelab.linear.delay_batch.DelayStabilityMap
    mark : (float, float, str), optional
        A point (active stiffness [N·m/rad], active viscosity [N·m·s/rad], label) to mark,
        such as a published controller.

    Returns
    -------
    Figure
    """
    from matplotlib.colors import TwoSlopeNorm

    fig, ax = new_figure(figsize=(7.0, 5.2))
    mgh = dmap.load_stiffness
    x, y = dmap.active_stiffness / mgh, dmap.active_viscosity / mgh
    values = np.clip(dmap.max_real_part, -20.0, 20.0)
    low, high = float(values.min()), float(values.max())
    span = max(abs(low), abs(high), 1e-9)
    norm = TwoSlopeNorm(vmin=min(low, -1e-9), vcenter=0.0, vmax=max(high, 1e-9)) \
        if low < 0 < high else TwoSlopeNorm(vmin=-span, vcenter=0.0, vmax=span)
    image = ax.pcolormesh(x, y, values, cmap="RdBu_r", norm=norm, shading="nearest")
    fig.colorbar(image, ax=ax, label="real part of the rightmost root [1/s] (clipped at ±20)")
    if dmap.stable.any() and not dmap.stable.all():
        ax.contour(x, y, dmap.stable.astype(float), levels=[0.5], colors="k", linewidths=1.5)
    if mark is not None:
        ax.plot(mark[0] / mgh, mark[1] / mgh, "o", ms=8, mfc="gold", mec="k")
        ax.annotate(mark[2], (mark[0] / mgh, mark[1] / mgh), xytext=(6, 6),
                    textcoords="offset points", fontsize=9)
    ax.set_xlabel(f"active stiffness of the {dmap.pair} pair / mgh [-] (mgh = {mgh:.0f} N·m/rad)")
    ax.set_ylabel(f"active viscosity of the {dmap.pair} pair / mgh [s]")
    ax.set_title(f"Stability with a feedback delay τ = {dmap.delay * 1000:.0f} ms "
                 f"(outlined: stable, {100 * dmap.stable.mean():.1f}% of the grid)", fontsize=10)
    return fig


def strategy_map_figure(smap) -> Figure:
    """A strategy map (:class:`posturelab.studies.strategy.StrategyMap`): the hip fraction
    [-] against the speed [m/s] or the frequency [Hz]; runs that fell marked with a cross,
    runs whose ankle saturated filled; the levels 0.15 and 0.4 dotted and, for sinusoidal
    translations, the transition frequency dashed."""
    fig, ax = new_figure(figsize=(6.0, 4.0))
    v = np.array([r.value for r in smap.runs])
    h = np.array([r.hip_fraction for r in smap.runs])
    fell = np.array([r.outcome != "recovered" for r in smap.runs])
    sat = np.array([r.ankle_saturated for r in smap.runs])
    ax.plot(v, h, color="0.5", lw=1)
    ok = ~fell
    ax.plot(v[ok & sat], h[ok & sat], "o", color="C3", label="ankle saturated")
    ax.plot(v[ok & ~sat], h[ok & ~sat], "o", mfc="white", color="C0", label="recovered")
    if fell.any():
        ax.plot(v[fell], h[fell], "x", color="k", label="fell or failed")
    for level in (0.15, 0.4):
        ax.axhline(level, color="0.7", ls=":", lw=1)
    if smap.kind == "oscillation" and smap.transition_frequency is not None:
        ax.axvline(smap.transition_frequency, color="C2", ls="--", lw=1,
                   label=f"transition {smap.transition_frequency:.3g} Hz")
    ax.set_xlabel("peak speed [m/s]" if smap.variable == "speed" else "frequency [Hz]")
    ax.set_ylabel("hip fraction [-]")
    ax.set_ylim(0, 1)
    ax.set_title(smap.profile[:70] + ("…" if len(smap.profile) > 70 else ""), fontsize=9)
    ax.legend(fontsize=8)
    return fig


def strategy_limit_figure(maps) -> Figure:
    """A two-parameter strategy map (one :class:`posturelab.studies.strategy.StrategyMap` per
    ankle torque limit): the hip fraction [-] in colour over the speed [m/s] or frequency
    [Hz] and the ankle torque limit [N·m]; runs that fell or failed crossed."""
    fig, ax = new_figure(figsize=(6.5, 4.5))
    x = np.array([r.value for r in maps[0].runs])
    y = np.array([m.ankle_torque_limit for m in maps])
    h = np.array([[r.hip_fraction for r in m.runs] for m in maps])
    mesh = ax.pcolormesh(x, y, h, shading="nearest", cmap="viridis", vmin=0, vmax=1)
    fig.colorbar(mesh, ax=ax, label="hip fraction [-]")
    for m in maps:
        bad = [r.value for r in m.runs if r.outcome != "recovered"]
        ax.plot(bad, [m.ankle_torque_limit] * len(bad), "x", color="w")
    ax.set_xlabel("peak speed [m/s]" if maps[0].variable == "speed" else "frequency [Hz]")
    ax.set_ylabel("ankle torque limit [N·m]")
    ax.set_title(maps[0].profile[:70] + ("…" if len(maps[0].profile) > 70 else ""),
                 fontsize=9)
    return fig
