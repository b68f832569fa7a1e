"""The reproduction report's figures: Figs. 3–10 of the paper and the one-sided
gastrocnemius beyond it, drawn from the runs of :mod:`.runs` with
:mod:`posturelab.viz.plots` and returned as PNG and SVG bytes.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .checks import SETTLE_TOLERANCE
from .runs import PaperRuns

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["DPI", "FIGURE_STEPS", "FigureImage", "draw_figure", "render_figure",
           "render_figures"]

#: Figure resolution. [dots/inch]
DPI = 110

#: Stem of each figure's files -> the progress message before it is drawn, in drawing order.
FIGURE_STEPS: dict[str, str] = {
    "fig03": "Fig. 3: angles and rates against time (backward, case 1)",
    "fig04": "Fig. 4: θ2 and θ3 against θ1",
    "fig05": "Fig. 5: torques of the ankle, knee, hip and gastrocnemius pairs",
    "fig06": "Fig. 6: torque of the quadriceps (two-joint) pair",
    "fig07": "Fig. 7: centre-of-gravity phase plane",
    "fig08": "Fig. 8: centre-of-gravity phase plane",
    "fig09": "Fig. 9: centre-of-gravity phase plane",
    "fig10": "Fig. 10: centre-of-gravity phase plane",
    "beyond1": "Beyond the paper: the real one-sided gastrocnemius in the forward case 1",
    "frf": "Beyond the paper: tilt FRFs (Bode) of the models and of a simulated PRTS experiment",
    "prts": "Beyond the paper: the PRTS stimulus and the cycle-averaged sway",
}

_PHASE_TITLES = {
    7: "Fig. 7 — backward platform motion, case 1: forward sway",
    8: "Fig. 8 — forward platform motion, case 1, artificial antagonist gastrocnemius",
    9: "Fig. 9 — forward platform motion, case 2 (no gastrocnemius): falls",
    10: "Fig. 10 — forward platform motion, case 3 (no gastrocnemius, 2× ankle)",
}


@dataclass(frozen=True)
class FigureImage:
    """One figure, rendered.

    Attributes
    ----------
    stem : str
        Stem of its files, e.g. ``"fig03"``.
    png : bytes
        PNG at :data:`DPI` [dots/inch].
    svg : bytes
        SVG (text as paths).
    """

    stem: str
    png: bytes
    svg: bytes


def _foot_label(runs: PaperRuns) -> str:
    foot = runs.foot
    return (f"typical foot, heel {foot.heel:+.3f} m to toe {foot.toe:+.3f} m "
            "(not in the paper's model)")


def _fig3(runs: PaperRuns, names: list[str]) -> Figure:
    from ..viz.plots import new_figure, plot_time_histories

    b = runs.backward
    fig, axes = new_figure(2, 1, figsize=(7.5, 6.0), sharex=True)
    plot_time_histories(b, axes, link_names=names,
                        title="Link angles (absolute from vertical, forward positive)")
    axes[0].xaxis.label.set_visible(False)
    settle = b.settling_time(SETTLE_TOLERANCE)
    if settle is not None:
        for ax in axes:
            ax.axvline(settle, color="0.3", ls="-.", lw=1.0,
                       label=f"all |θ| < {SETTLE_TOLERANCE} rad from t = {settle:.2f} s")
        axes[0].legend(fontsize="small", loc="upper right")
    fig.suptitle("Fig. 3 — backward platform motion (1 m/s step), case 1")
    return fig


def _fig4(runs: PaperRuns, names: list[str]) -> Figure:
    from ..viz.plots import new_figure, plot_angle_angle

    b = runs.backward
    fig, ax = new_figure(figsize=(7.0, 5.5))
    plot_angle_angle(b, ax, link_names=names)
    i_max = int(np.argmax(b.theta[:, 0]))
    knee_at = b.theta[i_max, 1] - b.theta[i_max, 0]
    ax.annotate(f"max forward excursion (t = {b.time[i_max]:.2f} s):\n"
                f"knee θ2 − θ1 = {knee_at:+.3f} rad",
                (b.theta[i_max, 0], b.theta[i_max, 1]), xytext=(0.6, 0.2),
                textcoords="axes fraction", fontsize="small",
                arrowprops={"arrowstyle": "->", "color": "0.3"})
    fig.suptitle("Fig. 4 — backward platform motion, case 1: forward sway")
    return fig


def _fig5(runs: PaperRuns, names: list[str]) -> Figure:
    from ..viz.plots import new_figure, plot_pair_torques

    fig, ax = new_figure(figsize=(7.5, 4.8))
    plot_pair_torques(runs.backward, ("ankle", "knee", "hip", "gastrocnemius"), ax,
                      title="Torques of the three single-joint pairs and the gastrocnemius")
    fig.suptitle("Fig. 5 — backward platform motion, case 1")
    return fig


def _fig6(runs: PaperRuns, names: list[str]) -> Figure:
    from ..viz.plots import new_figure, plot_pair_torques

    fig, ax = new_figure(figsize=(7.5, 4.2))
    plot_pair_torques(runs.backward, ("quadriceps",), ax,
                      title="Torque of the two-joint quadriceps–hamstring pair")
    fig.suptitle("Fig. 6 — backward platform motion, case 1")
    return fig


def _phase(num: int) -> Callable[[PaperRuns, list[str]], Figure]:
    def draw(runs: PaperRuns, names: list[str]) -> Figure:
        from ..viz.plots import new_figure, plot_cog_phase

        run = {7: runs.backward, 8: runs.forward1, 9: runs.forward2, 10: runs.forward3}[num]
        fig, ax = new_figure(figsize=(7.0, 6.2))
        if num == 10:
            long3 = runs.forward3_long
            ax.plot(long3.cog_position[:, 0], long3.cog_velocity[:, 0], color="0.6", lw=1.0,
                    ls="--", label=f"same run continued to {long3.time[-1]:.0f} s "
                    "(beyond the paper)", zorder=1)
        plot_cog_phase(run, ax, base_of_support=runs.foot, foot_label=_foot_label(runs),
                       label=f"centre of gravity, 0–{run.time[-1]:.2f} s")
        fig.suptitle(_PHASE_TITLES[num])
        return fig

    return draw


def _beyond1(runs: PaperRuns, names: list[str]) -> Figure:
    from ..viz.plots import new_figure, plot_cog_phase

    fig, ax = new_figure(figsize=(7.0, 6.8))
    plot_cog_phase(runs.forward1, ax, base_of_support=runs.foot,
                   foot_label=_foot_label(runs),
                   label="two-sided gastrocnemius (the paper's artificial antagonist)",
                   color="#1f77b4")
    plot_cog_phase(runs.one_sided, ax,
                   label="one-sided gastrocnemius (the paper's: acts only while θ2 ≥ 0)",
                   color="#d62728")
    fig.suptitle("Forward platform motion, case 1: artificial vs real gastrocnemius")
    return fig


def _frf(runs: PaperRuns, names: list[str]) -> Figure:
    """Bode plot: the simulated experiment's estimate with its 95 % bounds, and the model
    FRFs of the paper's case 1, of the peterka-2002 preset and of the fit."""
    from ..frequency import model_frf
    from ..model.body import get_body, paper_body
    from ..model.controllers import get_controller
    from ..model.muscles import paper_muscles
    from ..viz.plots import plot_bode
    from .checks import frf_experiment

    exp = frf_experiment()
    f = np.geomspace(0.03, 3.0, 200)
    body = get_body("paper-1link")
    preset = get_controller("peterka-2002")
    muscles = preset.muscles(body)
    kp, kd, tau = exp.fitted
    fitted = muscles.with_active_feedback([kp], [kd])
    curves = [
        (f, model_frf(paper_body(), paper_muscles("1"), f),
         "paper case 1, 3 links (instantaneous impedance)"),
        (f, model_frf(body, muscles, f, **preset.run_options()),
         "peterka-2002 on one link (150 ms delay)"),
        (f, model_frf(body, fitted, f, feedback_delay=tau), "fitted to the simulated experiment"),
    ]
    fig = plot_bode([exp.estimate], [f"simulated PRTS experiment ({exp.cycles} cycles, "
                                     f"{exp.noise * 1000:g} mrad sensor noise)"], model=curves)
    fig.suptitle("Tilt FRF of the centre-of-mass sway (gain 1, phase 0: following the surface)",
                 fontsize=10)
    return fig


def _prts(runs: PaperRuns, names: list[str]) -> Figure:
    from ..viz.plots import plot_prts_cycles
    from .checks import frf_experiment

    return plot_prts_cycles(frf_experiment().estimate, stimulus_label="tilt α",
                            response_label="−sway θ")


_DRAW: dict[str, Callable[[PaperRuns, list[str]], Figure]] = {
    "fig03": _fig3, "fig04": _fig4, "fig05": _fig5, "fig06": _fig6,
    "fig07": _phase(7), "fig08": _phase(8), "fig09": _phase(9), "fig10": _phase(10),
    "beyond1": _beyond1, "frf": _frf, "prts": _prts,
}


def draw_figure(stem: str, runs: PaperRuns, link_names: list[str]) -> Figure:
    """Draw one figure of the report.

    Parameters
    ----------
    stem : str
        A key of :data:`FIGURE_STEPS`.
    runs : PaperRuns
    link_names : list of str
        The link names, for the legends.

    Returns
    -------
    matplotlib.figure.Figure
    """
    return _DRAW[stem](runs, link_names)


def render_figure(stem: str, runs: PaperRuns, link_names: list[str],
                  dpi: float = DPI) -> FigureImage:
    """Draw one figure and render it as PNG (at ``dpi`` [dots/inch]) and SVG, with the same
    layout (text layout is most of a figure's time)."""
    from ..viz.plots import figure_bytes

    fig = draw_figure(stem, runs, link_names)
    png = figure_bytes(fig, "png", dpi)
    fig.set_layout_engine("none")  # the SVG keeps the PNG's layout: laid out once, not twice
    return FigureImage(stem, png, figure_bytes(fig, "svg", dpi))


_SHARED: tuple | None = None  # (runs, link_names) for the forked renderers


def _render_shared(stem: str) -> FigureImage:
    runs, link_names = _SHARED
    return render_figure(stem, runs, link_names)


def render_figures(runs: PaperRuns, link_names: list[str],
                   tick: Callable[[str], None] | None = None,
                   done: Callable[[FigureImage], None] | None = None,
                   processes: int | None = None) -> dict[str, FigureImage]:
    """Draw and render every figure of the report, in the order of :data:`FIGURE_STEPS`.

    On Linux the figures are rendered by forked processes, one per CPU available (text
    layout for the PNG and SVG files is most of the report's time); each figure's bytes
    are the same as when drawn in this process.

    Parameters
    ----------
    runs : PaperRuns
    link_names : list of str
    tick : callable(message), optional
        Called before each figure.
    done : callable(FigureImage), optional
        Called with each figure once rendered (the report writes its files then).
    processes : int, optional
        Processes to render with; by default the CPUs available (1 renders here).

    Returns
    -------
    dict of str to FigureImage
        By stem.
    """
    import os
    import sys

    global _SHARED
    if processes is None:
        processes = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else 1
    images = {}
    if processes > 1 and sys.platform.startswith("linux"):
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        from .checks import frf_experiment

        frf_experiment()  # (two figures and a finding use it: computed once, before forking)
        _SHARED = (runs, link_names)
        try:
            with ProcessPoolExecutor(max_workers=min(processes, len(FIGURE_STEPS)),
                                     mp_context=multiprocessing.get_context("fork")) as pool:
                futures = {stem: pool.submit(_render_shared, stem) for stem in FIGURE_STEPS}
                for stem, message in FIGURE_STEPS.items():
                    if tick is not None:
                        tick(message)
                    images[stem] = image = futures[stem].result()
                    if done is not None:
                        done(image)
        finally:
            _SHARED = None
        return images
    for stem, message in FIGURE_STEPS.items():
        if tick is not None:
            tick(message)
        images[stem] = image = render_figure(stem, runs, link_names)
        if done is not None:
            done(image)
    return images
