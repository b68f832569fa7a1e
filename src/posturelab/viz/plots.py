"""Figures of a simulation run (the paper's Figs. 3–10 and an overview).

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

The functions live in :mod:`.run_figures` (runs), :mod:`.maps` (parameter planes),
:mod:`.frequency` (frequency responses), :mod:`posturelab.viz.cohort` (conditions and cohorts) and
:mod:`.figure` (new figures, colours, saving);
this module gathers them under one name.

Conventions (see :mod:`posturelab.conventions`): angles are absolute from the
vertical, positive leaning forward; the centre of gravity is relative to the
ankle, x forward.
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
from .maps import plot_delay_stability_map, plot_stability_map
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
