"""Every figure of posturelab under one name.

The functions live in :mod:`.run_figures` (simulation runs: the paper's Figs. 3–10, an
overview, several runs compared; its docstring maps each function to its figure),
:mod:`.maps` (parameter planes), :mod:`.frequency` (frequency responses),
:mod:`posturelab.viz.cohort` (conditions and cohorts) and :mod:`.figure` (new figures,
colours, saving). Each draws without pyplot, on an Axes you give it or on a new Figure,
and labels every axis with its unit in brackets.
"""

from __future__ import annotations

from .cohort import plot_cohort, plot_reweighting
from .figure import (
    LINK_COLORS,
    PAIR_COLORS,
    RUN_COLORS,
    RUN_LINESTYLES,
    figure_bytes,
    new_figure,
    save_figure,
    unique_legend,
)
from .frequency import plot_bode, plot_prts_cycles
from .maps import (
    plot_delay_stability_map,
    plot_stability_map,
    strategy_limit_figure,
    strategy_map_figure,
)
from .run_figures import (
    plot_angle_angle,
    plot_cog_phase,
    plot_compare,
    plot_pair_torques,
    plot_run_overview,
    plot_time_histories,
)

__all__ = [
    "new_figure",
    "plot_time_histories",
    "plot_angle_angle",
    "plot_pair_torques",
    "plot_cog_phase",
    "plot_run_overview",
    "figure_bytes",
    "save_figure",
    "plot_stability_map",
    "strategy_map_figure",
    "strategy_limit_figure",
    "plot_delay_stability_map",
    "plot_bode",
    "plot_prts_cycles",
    "plot_compare",
    "plot_reweighting",
    "plot_cohort",
    "unique_legend",
    "LINK_COLORS",
    "RUN_COLORS",
    "RUN_LINESTYLES",
    "PAIR_COLORS",
]
