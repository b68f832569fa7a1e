"""Figures of simulation runs (the paper's Figs. 3–10, an overview, several runs compared).

Every ``plot_*`` function draws on an Axes you give it (or on a new
:class:`matplotlib.figure.Figure` it creates) and returns what it drew on; it
never calls ``pyplot.show`` and never touches pyplot's global state, so it is
safe in scripts, tests and servers (Agg). Every axis is labelled with its
unit in brackets.

============================  ==========================================  ==========
function                      what                                         paper
============================  ==========================================  ==========
:func:`plot_time_histories`   angles [rad] and rates [rad/s] vs time [s]   Fig. 3
:func:`plot_angle_angle`      θ2, θ3 against θ1 [rad]                      Fig. 4
:func:`plot_pair_torques`     muscle-pair torques M [N·m] vs time [s]      Figs. 5, 6
:func:`plot_cog_phase`        CoG velocity ẋ_c [m/s] vs position x_c [m]  Figs. 7–10
:func:`plot_run_overview`     a 2×2 summary of one run                     —
============================  ==========================================  ==========

Conventions (see :mod:`posturelab.conventions`): angles are absolute from the
vertical, positive leaning forward; the centre of gravity is relative to the
ankle, x forward.
"""

from __future__ import annotations

import textwrap
from collections.abc import Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ..errors import ParameterError, UnknownNameError
from ..model.options import BaseOfSupport
from ..simulation.results import SimulationResult
from .figure import (
    LINK_COLORS,
    PAIR_COLORS,
    RUN_COLORS,
    RUN_LINESTYLES,
    new_figure,
    unique_legend,
)

__all__ = ["plot_time_histories", "plot_angle_angle", "plot_pair_torques", "plot_cog_phase",
           "plot_run_overview", "plot_compare"]

_OTHER_COLORS = ("#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf")
_FALL_COLOR = "#c00000"
_START_COLOR = "#2ca02c"


def _theta(i: int) -> str:
    return rf"$\theta_{{{i}}}$"


def _link_label(i: int, link_names: Sequence[str] | None, rate: bool = False) -> str:
    sym = rf"$\dot{{\theta}}_{{{i + 1}}}$" if rate else _theta(i + 1)
    if link_names is not None and i < len(link_names):
        return f"{sym} ({link_names[i]})"
    return sym

_FOOT_GID = "posturelab-base-of-support"
_COG_GID = "posturelab-cog-trajectory"


def _mark_fall(ax: Axes, result: SimulationResult, label: bool | str = True,
               ls: object = ":") -> None:
    if result.fell and result.fall_time is not None:
        text = f"fall at t = {result.fall_time:.2f} s"
        if isinstance(label, str):
            text = f"{label}: {text}"
        ax.axvline(result.fall_time, color=_FALL_COLOR, ls=ls, lw=1.5,
                   label=text if label else None)


def _check_result(result: SimulationResult) -> None:
    if not isinstance(result, SimulationResult):
        raise ParameterError(f"result must be a SimulationResult, got {type(result).__name__}")
    if result.time.size == 0:
        raise ParameterError("result holds no samples to plot")


def _runs(results, labels) -> list[tuple[SimulationResult, str | None]]:
    """One run or several, each with its legend label (None: one unlabelled run)."""
    if isinstance(results, SimulationResult):
        runs = [results]
    elif isinstance(results, (str, bytes)) or not hasattr(results, "__iter__"):
        raise ParameterError("result must be a SimulationResult or a sequence of them, got "
                             f"{type(results).__name__}")
    else:
        runs = list(results)
        if not runs:
            raise ParameterError("give at least one SimulationResult to plot")
    for run in runs:
        _check_result(run)
    if labels is None:
        names = [None] if len(runs) == 1 else [f"run {k + 1}" for k in range(len(runs))]
    else:
        names = [labels] if isinstance(labels, str) else [str(lab) for lab in labels]
        if len(names) != len(runs):
            raise ParameterError(f"labels: give one label per run: {len(runs)} runs, "
                                 f"{len(names)} labels")
    return list(zip(runs, names, strict=True))


def _run_style(k: int) -> object:
    return RUN_LINESTYLES[k % len(RUN_LINESTYLES)]


def _add_run_keys(ax: Axes, runs: Sequence[tuple[SimulationResult, str | None]]) -> None:
    """Grey legend keys, one per labelled run, showing its line style."""
    for k, (_, name) in enumerate(runs):
        if name is not None:
            ax.plot([], [], color="0.25", lw=1.6, ls=_run_style(k), label=name)

def plot_time_histories(
    result: SimulationResult | Sequence[SimulationResult],
    axes: Axes | Sequence[Axes] | None = None,
    *,
    labels: str | Sequence[str] | None = None,
    link_names: Sequence[str] | None = None,
    title: str | None = None,
) -> Axes | np.ndarray:
    """Link angles [rad] and angular rates [rad/s] against time [s] (paper Fig. 3).

    Parameters
    ----------
    result : SimulationResult or sequence of SimulationResult
        The run, or several runs to overlay: each link keeps its colour and
        each run gets its own line style (run 1 solid, run 2 dashed, …), with
        one legend entry per link and one per run.
    axes : Axes or sequence of two Axes, optional
        Two Axes: angles on the first, rates on the second. One Axes: both on
        it (angles solid, rates dashed; one run only). None: a new two-panel
        figure.
    labels : str or sequence of str, optional
        One legend label per run ("run 1", "run 2", … by default when there
        are several).
    link_names : sequence of str, optional
        Names for the legend, e.g. ``("leg", "thigh", "torso")``.
    title : str, optional
        Title of the (first) panel; a default names the figure.

    Returns
    -------
    Axes or numpy.ndarray of Axes
        What was drawn on (the new pair of Axes when ``axes`` is None).
    """
    runs = _runs(result, labels)
    created = axes is None
    if created:
        _, axes = new_figure(2, 1, figsize=(7.0, 5.5), sharex=True)
    single = isinstance(axes, Axes)
    if single:
        if len(runs) > 1:
            raise ParameterError("axes: several runs need two Axes (angles, rates), got one")
        ax_a = ax_r = axes
    else:
        seq = list(np.ravel(np.asarray(axes, dtype=object)))
        if len(seq) != 2 or not all(isinstance(a, Axes) for a in seq):
            raise ParameterError("axes must be one Axes or a sequence of two Axes "
                                 "(angles, rates)")
        ax_a, ax_r = seq
    n = {run.n_links for run, _ in runs}
    if len(n) != 1:
        raise ParameterError(f"result: the runs have different numbers of links: {sorted(n)}")
    n = n.pop()
    for k, (run, _name) in enumerate(runs):
        t = run.time
        style = _run_style(k)
        for i in range(n):
            c = LINK_COLORS[i % len(LINK_COLORS)]
            ax_a.plot(t, run.theta[:, i], color=c, lw=1.6, ls=style,
                      label=_link_label(i, link_names) if k == 0 else None)
        for i in range(n):
            c = LINK_COLORS[i % len(LINK_COLORS)]
            ax_r.plot(t, run.omega[:, i], color=c, lw=1.4, ls="--" if single else style,
                      label=_link_label(i, link_names, rate=True) if k == 0 else None)
    for ax in {id(ax_a): ax_a, id(ax_r): ax_r}.values():
        ax.axhline(0.0, color="0.6", lw=0.7, zorder=0)
        for k, (run, name) in enumerate(runs):
            _mark_fall(ax, run, name if name is not None else True,
                       ls=":" if len(runs) == 1 else _run_style(k))
        if len(runs) > 1:
            _add_run_keys(ax, runs)
        ax.grid(True, alpha=0.3)
    if single:
        ax_a.set_ylabel("angle [rad] (solid), rate [rad/s] (dashed)")
        ax_a.set_xlabel("time t [s]")
        unique_legend(ax_a, ncol=2, fontsize="small")
    else:
        ax_a.set_ylabel(r"link angle $\theta_i$ [rad]")
        ax_r.set_ylabel(r"angular rate $\dot{\theta}_i$ [rad/s]")
        ax_r.set_xlabel("time t [s]")
        unique_legend(ax_a, fontsize="small", loc="upper right")
        unique_legend(ax_r, fontsize="small", loc="upper right")
        ax_r.set_title("Angular rates", fontsize="medium")
        ax_a.set_xlabel("time t [s]")
        if created:  # shared time axis: the label and ticks show under the lower panel only
            ax_a.xaxis.label.set_visible(False)
    ax_a.set_title(title or "Link angles (absolute, forward positive)", fontsize="medium")
    return axes


def plot_angle_angle(
    result: SimulationResult | Sequence[SimulationResult],
    ax: Axes | None = None,
    *,
    labels: str | Sequence[str] | None = None,
    link_names: Sequence[str] | None = None,
    title: str | None = None,
) -> Axes:
    """θ2 … θN against θ1 [rad] (paper Fig. 4).

    The dashed diagonal θ = θ1 is where a link is parallel to the leg: a
    curve for θ2 on it means a straight knee (θ2 − θ1 = 0). The start of the
    run is marked with a circle, the end with a square (a cross for a fall).

    Parameters
    ----------
    result : SimulationResult or sequence of SimulationResult
        A run of a chain with at least two links, or several (one line style
        each, the links keep their colours).
    ax : Axes, optional
        Where to draw; a new figure when None.
    labels : str or sequence of str, optional
        One legend label per run.
    link_names : sequence of str, optional
        Names for the legend.
    title : str, optional
        Panel title.

    Returns
    -------
    Axes
    """
    runs = _runs(result, labels)
    n_links = {run.n_links for run, _ in runs}
    if len(n_links) != 1:
        raise ParameterError(f"result: the runs have different numbers of links: "
                             f"{sorted(n_links)}")
    n_links = n_links.pop()
    if n_links < 2:
        raise ParameterError("plot_angle_angle needs a chain of at least 2 links")
    if ax is None:
        _, ax = new_figure(figsize=(6.0, 5.0))
    lo = float(min(run.theta.min() for run, _ in runs))
    hi = float(max(run.theta.max() for run, _ in runs))
    ax.plot([lo, hi], [lo, hi], color="0.5", ls="--", lw=1.0,
            label=r"$\theta = \theta_1$ (link parallel to leg; for $\theta_2$: knee straight)")
    for k, (run, _) in enumerate(runs):
        th = run.theta
        x = th[:, 0]
        end_marker = "X" if run.fell else "s"
        for i in range(1, n_links):
            c = LINK_COLORS[i % len(LINK_COLORS)]
            ax.plot(x, th[:, i], color=c, lw=1.6, ls=_run_style(k) if len(runs) > 1 else "-",
                    label=_link_label(i, link_names) if k == 0 else None)
            ax.plot(x[0], th[0, i], "o", color=c, mec="k", ms=7)
            ax.plot(x[-1], th[-1, i], end_marker, color=c, mec="k", ms=7)
    ax.plot([], [], "o", color="w", mec="k", label="start (t = 0)")
    if len(runs) == 1:
        run = runs[0][0]
        ax.plot([], [], "X" if run.fell else "s", color="w", mec="k",
                label=(f"fall (t = {run.fall_time:.2f} s)" if run.fell
                       else f"end (t = {run.time[-1]:.3g} s)"))
    else:
        if any(not run.fell for run, _ in runs):
            ax.plot([], [], "s", color="w", mec="k", label="end")
        if any(run.fell for run, _ in runs):
            ax.plot([], [], "X", color="w", mec="k", label="fall")
        _add_run_keys(ax, runs)
    ax.axhline(0.0, color="0.7", lw=0.7, zorder=0)
    ax.axvline(0.0, color="0.7", lw=0.7, zorder=0)
    ax.set_xlabel(r"leg angle $\theta_1$ [rad]")
    ax.set_ylabel(r"link angles $\theta_2, \ldots, \theta_N$ [rad]" if n_links > 3
                  else (r"$\theta_2$, $\theta_3$ [rad]" if n_links == 3
                        else r"$\theta_2$ [rad]"))
    ax.set_title(title or r"Link angles against the leg angle $\theta_1$", fontsize="medium")
    ax.grid(True, alpha=0.3)
    unique_legend(ax, fontsize="small", loc="best")
    return ax


def plot_pair_torques(
    result: SimulationResult | Sequence[SimulationResult],
    pairs: Sequence[str] | None = ("ankle", "knee", "hip", "gastrocnemius"),
    ax: Axes | None = None,
    *,
    labels: str | Sequence[str] | None = None,
    title: str | None = None,
) -> Axes:
    """Muscle-pair torques M [N·m] against time [s] (paper Figs. 5 and 6).

    M = K_d E Θ + L_d E Θ̇ for each pair: positive when the pair resists a
    positive stretch. The paper's Fig. 5 shows the ankle, knee and hip pairs
    and the gastrocnemius (the default); Fig. 6 the quadriceps alone
    (``pairs=("quadriceps",)``).

    Parameters
    ----------
    result : SimulationResult or sequence of SimulationResult
        The run, or several (each pair keeps its colour, each run its own line
        style).
    pairs : sequence of str or None
        Pair names, from ``result.pair_names``; None plots every pair.
    ax : Axes, optional
        Where to draw; a new figure when None.
    labels : str or sequence of str, optional
        One legend label per run.
    title : str, optional
        Panel title.

    Returns
    -------
    Axes

    Raises
    ------
    UnknownNameError
        A name not among ``result.pair_names`` (the message lists them).
    """
    runs = _runs(result, labels)
    first = runs[0][0]
    names = list(first.pair_names) if pairs is None else [str(p) for p in pairs]
    if isinstance(pairs, str):
        names = [pairs]
    for run, _ in runs:
        for p in names:
            if p not in run.pair_names:
                raise UnknownNameError(f"unknown muscle pair {p!r}; this run has: "
                                       f"{', '.join(run.pair_names)}")
    if ax is None:
        _, ax = new_figure(figsize=(7.0, 4.5))
    for k, (run, name) in enumerate(runs):
        t = run.time
        for m, p in enumerate(names):
            j = run.pair_names.index(p)
            c = PAIR_COLORS.get(p, _OTHER_COLORS[m % len(_OTHER_COLORS)])
            ax.plot(t, run.pair_torques[:, j], color=c, lw=1.6, ls=_run_style(k),
                    label=f"{p} pair" if k == 0 else None)
        _mark_fall(ax, run, name if name is not None else True,
                   ls=":" if len(runs) == 1 else _run_style(k))
    if len(runs) > 1:
        _add_run_keys(ax, runs)
    ax.axhline(0.0, color="0.6", lw=0.7, zorder=0)
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("muscle-pair torque M [N·m]")
    default = ("Muscle-pair torque: " + names[0]) if len(names) == 1 else "Muscle-pair torques"
    ax.set_title(title or default, fontsize="medium")
    ax.grid(True, alpha=0.3)
    unique_legend(ax, fontsize="small", loc="upper right")
    return ax


def _foot(base_of_support) -> tuple[float, float, str] | None:
    if base_of_support is None:
        return None
    if isinstance(base_of_support, BaseOfSupport):
        return base_of_support.heel, base_of_support.toe, "base of support"
    try:
        heel, toe = (float(v) for v in base_of_support)
    except (TypeError, ValueError):
        raise ParameterError("base_of_support must be a BaseOfSupport or (heel, toe) [m]") \
            from None
    if not heel < 0.0 < toe:
        raise ParameterError(f"base_of_support must have heel < 0 < toe [m], got ({heel:g}, "
                             f"{toe:g})")
    return heel, toe, "base of support"


def plot_cog_phase(
    result: SimulationResult | Sequence[SimulationResult],
    ax: Axes | None = None,
    *,
    base_of_support: BaseOfSupport | tuple[float, float] | None = None,
    foot_label: str | None = None,
    label: str | Sequence[str] | None = None,
    color: str | Sequence[str] | None = None,
    mark_ends: bool = True,
    legend: str | None = "below",
    title: str | None = None,
) -> Axes:
    """Horizontal centre-of-gravity velocity [m/s] against position [m] (Figs. 7–10).

    Position and velocity are relative to the ankle (x forward). The start is
    marked with a green circle, the end with a black square (a red cross for
    a fall), upright rest (0, 0) with a plus.

    Parameters
    ----------
    result : SimulationResult or sequence of SimulationResult
        The run, or several to overlay (one colour each). Calling again with
        the same ``ax`` overlays too: the legend keeps each label once and the
        foot is shaded once.
    ax : Axes, optional
        Where to draw; a new figure when None.
    base_of_support : BaseOfSupport or (heel, toe), optional
        If given, the foot [heel, toe] [m] is shaded.
    foot_label : str, optional
        Legend text of the shaded foot.
    label : str or sequence of str, optional
        Legend text of the trajectory, one per run.
    color : str or sequence of str, optional
        Colour of the trajectory, one per run (default: blue, then red,
        green, …, carrying on over runs already drawn on ``ax``).
    mark_ends : bool
        Mark the start and end of the run.
    legend : {"below", "best"} or None
        Legend under the axes (default; it never hides the trajectory), inside
        at matplotlib's "best" place, or none.
    title : str, optional
        Panel title.

    Returns
    -------
    Axes
    """
    if legend not in ("below", "best", None):
        raise ParameterError(f"legend must be 'below', 'best' or None, got {legend!r}")
    runs = _runs(result, label)
    if ax is None:
        _, ax = new_figure(figsize=(6.5, 5.0))
    drawn = sum(line.get_gid() == _COG_GID for line in ax.get_lines())
    if color is None:  # carry on the colour cycle over runs already on this Axes
        colors = [RUN_COLORS[(drawn + k) % len(RUN_COLORS)] for k in range(len(runs))]
    else:
        colors = [color] if isinstance(color, str) else [str(c) for c in color]
        if len(colors) != len(runs):
            raise ParameterError(f"color: give one colour per run: {len(runs)} runs, "
                                 f"{len(colors)} colours")
    foot = _foot(base_of_support)
    if foot is not None and not any(a.get_gid() == _FOOT_GID for a in ax.patches):
        heel, toe, _ = foot
        span = ax.axvspan(heel, toe, color="#f2c14e", alpha=0.25, lw=0,
                          label=foot_label
                          or f"base of support (heel {heel:+.3f} m, toe {toe:+.3f} m)")
        span.set_gid(_FOOT_GID)
        for edge, name in ((heel, "heel"), (toe, "toe")):
            ax.axvline(edge, color="#b8860b", lw=1.0, ls="-", zorder=1)
            ax.annotate(name, (edge, 1.0), xycoords=("data", "axes fraction"),
                        xytext=(0, -3), textcoords="offset points", ha="center", va="top",
                        fontsize="small", color="#8a6408")
    detailed = len(runs) == 1
    for (run, name), c in zip(runs, colors, strict=True):
        x = run.cog_position[:, 0]
        v = run.cog_velocity[:, 0]
        ax.plot(x, v, color=c, lw=1.6, label=name or "centre of gravity", gid=_COG_GID)
        if mark_ends:
            ax.plot(x[0], v[0], "o", color=_START_COLOR, mec="k", ms=8, zorder=5,
                    label=(f"start (t = 0): x = {x[0]:+.3f} m, v = {v[0]:+.3f} m/s"
                           if detailed else "start (t = 0)"))
            if run.fell:
                ax.plot(x[-1], v[-1], "X", color=_FALL_COLOR, mec="k", ms=10, zorder=5,
                        label=f"fall (t = {run.fall_time:.2f} s)" if detailed else "fall")
            else:
                ax.plot(x[-1], v[-1], "s", color="k", ms=6, zorder=5,
                        label=f"end (t = {run.time[-1]:.3g} s)" if detailed else "end")
    if mark_ends:
        ax.plot(0.0, 0.0, "+", color="k", ms=12, mew=1.5, zorder=4, label="upright at rest")
    ax.axhline(0.0, color="0.7", lw=0.7, zorder=0)
    ax.axvline(0.0, color="0.7", lw=0.7, zorder=0)
    ax.set_xlabel(r"horizontal CoG position $x_c$ (from the ankle) [m]")
    ax.set_ylabel(r"horizontal CoG velocity $\dot{x}_c$ [m/s]")
    ax.set_title(title or "Centre of gravity: horizontal phase plane", fontsize="medium")
    ax.grid(True, alpha=0.3)
    if legend == "below":
        _, texts = ax.get_legend_handles_labels()
        ncol = 2 if max((len(lab) for lab in texts), default=0) <= 45 else 1
        unique_legend(ax, fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.14),
                      ncol=ncol, frameon=False)
    elif legend == "best":
        unique_legend(ax, fontsize="small", loc="best")
    return ax


def plot_run_overview(
    result: SimulationResult,
    *,
    link_names: Sequence[str] | None = None,
    base_of_support: BaseOfSupport | tuple[float, float] | None = None,
    title: str | None = None,
) -> Figure:
    """A 2×2 summary of one run: angles, rates, pair torques, CoG phase plane.

    Used by ``posturelab simulate --plot run.png``.

    Parameters
    ----------
    result : SimulationResult
        The run.
    link_names : sequence of str, optional
        Names for the legends.
    base_of_support : BaseOfSupport or (heel, toe), optional
        Shade the foot [m] in the phase plane.
    title : str, optional
        Figure title; by default the run's description and outcome.

    Returns
    -------
    Figure
    """
    _check_result(result)
    fig, axes = new_figure(2, 2, figsize=(11.0, 8.0))
    plot_time_histories(result, [axes[0, 0], axes[0, 1]], link_names=link_names)
    axes[0, 0].set_xlabel("time t [s]")
    plot_pair_torques(result, None, axes[1, 0])
    plot_cog_phase(result, axes[1, 1], base_of_support=base_of_support)
    head = title or result.description or "posturelab run"
    outcome = result.message or result.status
    fig.suptitle(textwrap.fill(f"{head} — {outcome}", 110), fontsize="medium")
    return fig


def plot_compare(runs, labels: Sequence[str] | None = None, *,
                 link_names: Sequence[str] | None = None, rates: bool = False) -> Figure:
    """Several runs overlaid: one panel per link angle [rad] (or rate [rad/s]) against
    time [s], one colour per run, one legend entry per run, a cross at each fall.

    Parameters
    ----------
    runs : sequence of SimulationResult, or of (time [s], theta [rad] (T, N), omega
        [rad/s] (T, N)) tuples (saved runs, :func:`posturelab.simulation.results.read_run_csv`)
    labels : sequence of str, optional
        One per run; "run 1", "run 2", … by default.
    link_names : sequence of str, optional
        Panel titles.
    rates : bool
        Plot the rates instead of the angles.

    Returns
    -------
    Figure
    """
    series = []
    for run in runs:
        if isinstance(run, SimulationResult):
            _check_result(run)
            series.append((run.time, run.theta, run.omega, run.fall_time if run.fell else None))
        else:
            t, th, om = run[:3]
            series.append((np.asarray(t), np.asarray(th), np.asarray(om), None))
    if not series:
        raise ParameterError("give at least one run to compare")
    n = {s[1].shape[1] for s in series}
    if len(n) != 1:
        raise ParameterError(f"the runs have different numbers of links: {sorted(n)}")
    n_links = n.pop()
    labels = list(labels) if labels is not None else [f"run {k + 1}" for k in range(len(series))]
    if len(labels) != len(series):
        raise ParameterError(f"give one label per run: {len(series)} runs, {len(labels)} labels")
    fig, axes = new_figure(n_links, 1, figsize=(7.0, 2.2 + 1.8 * n_links), sharex=True)
    axes = np.atleast_1d(axes)
    for k, ((t, th, om, fall), label) in enumerate(zip(series, labels, strict=True)):
        y = om if rates else th
        c = RUN_COLORS[k % len(RUN_COLORS)]
        for i, ax in enumerate(axes):
            ax.plot(t, y[:, i], color=c, lw=1.4, label=label if i == 0 else None)
            if fall is not None:
                ax.plot(t[-1], y[-1, i], "X", color=c, mec="k", ms=7)
    for i, ax in enumerate(axes):
        name = link_names[i] if link_names is not None and i < len(link_names) else f"link {i + 1}"
        ax.set_ylabel((r"$\dot{\theta}_%d$ [rad/s]" if rates else r"$\theta_%d$ [rad]") % (i + 1))
        ax.set_title(name, fontsize="medium")
        ax.axhline(0.0, color="0.6", lw=0.7, zorder=0)
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("time t [s]")
    axes[0].legend(fontsize="small", loc="best")
    return fig
