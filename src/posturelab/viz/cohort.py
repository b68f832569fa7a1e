"""Figures of several conditions and of cohorts: a parameter against the stimulus amplitude
with its intervals (sensory reweighting, :mod:`posturelab.frequency.reweighting`) and the
distributions of a cohort's fitted parameters (:mod:`posturelab.frequency.cohort`)."""

from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from .figure import new_figure

__all__ = ["plot_reweighting", "plot_cohort"]

#: Colour and marker per vision label (None: not given).
_VISION_STYLE = {"open": ("#1f77b4", "o"), "closed": ("#d62728", "s"), None: ("0.2", "D")}


def plot_reweighting(comparison, ax=None) -> Figure:
    """A parameter per condition against the stimulus amplitude, peak to peak [deg for a
    tilt in rad], with its 95 % intervals, eyes open and closed apart, the shared fit's value
    and interval as a band, and the test's p-value in the title.

    Parameters
    ----------
    comparison : posturelab.frequency.reweighting.ConditionComparison
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure).

    Returns
    -------
    Figure
        Conditions without a known amplitude are placed by their number instead.
    """
    fig, ax = new_figure(figsize=(6.0, 4.2)) if ax is None else (ax.figure, ax)
    amps = np.asarray(comparison.amplitudes, float)
    known = np.isfinite(amps).all()
    tilt = comparison.amplitude_unit == "rad"
    x = np.degrees(amps) if known and tilt else (
        amps if known else np.arange(1, amps.size + 1, dtype=float))
    ci = np.asarray(comparison.confidence_intervals, float)
    est = np.asarray(comparison.estimates, float)
    for v in dict.fromkeys(comparison.vision):
        idx = np.array([k for k, w in enumerate(comparison.vision) if w == v])
        color, marker = _VISION_STYLE.get(v, _VISION_STYLE[None])
        order = idx[np.argsort(x[idx])]
        ax.errorbar(x[order], est[order], yerr=[est[order] - ci[order, 0],
                                                ci[order, 1] - est[order]],
                    color=color, marker=marker, capsize=3, lw=1.2,
                    label=f"eyes {v}" if v is not None else (
                        "vision not given" if any(comparison.vision) else "per condition"))
    lo, hi = comparison.shared_interval
    ax.axhspan(lo, hi, color="0.5", alpha=0.15, lw=0)
    ax.axhline(comparison.shared_estimate, color="0.4", ls="--", lw=1.0,
               label="shared (one value for all)")
    if known:
        ax.set_xlabel("stimulus amplitude, peak to peak " + ("[deg]" if tilt else "[m]"))
    else:
        ax.set_xlabel("condition [-]")
        ax.set_xticks(x)
    unit = comparison.unit
    ax.set_ylabel(f"{comparison.parameter} [{unit}]")
    p = comparison.p_value
    per = ("per vision label" if comparison.grouping == "vision"
           else "per condition")
    ax.set_title(f"{comparison.parameter} {per}: likelihood-ratio test "
                 f"{comparison.distribution}, p = {p:.3g}" if math.isfinite(p) else
                 comparison.parameter, fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def plot_cohort(cohort, parameters=None) -> Figure:
    """The distribution of each fitted parameter over a cohort's subjects: every subject's
    estimate (its 95 % interval as a line, a hollow marker when not determined) over a box of
    the median and quartiles, failed fits left out and counted in the title.

    Parameters
    ----------
    cohort : posturelab.frequency.cohort.CohortFit
    parameters : sequence of str, optional
        Which (default all), one panel each, in their units.

    Returns
    -------
    Figure
    """
    names = list(parameters or cohort.parameters)
    n = len(names)
    cols = n if n <= 3 else (2 if n == 4 else 3)
    rows = -(-n // cols)
    fig, axes = new_figure(rows, cols, figsize=(3.2 * cols, 3.4 * rows))
    axes = np.atleast_1d(axes).ravel()
    ok = [s for s in cohort.subjects if not s.failed]
    jitter = np.random.default_rng(0).uniform(-0.18, 0.18, len(ok))  # fixed: same figure
    for ax, name in zip(axes, names, strict=False):
        k = cohort.parameters.index(name)
        values = np.array([s.estimates[k] for s in ok])
        finite = np.isfinite(values)
        if finite.any():
            ax.boxplot(values[finite], positions=[0.0], widths=0.5, showfliers=False,
                       medianprops={"color": "#d62728"})
        for j, s in enumerate(ok):
            if not finite[j]:
                continue
            lo, hi = s.confidence_intervals[k]
            ax.plot([jitter[j]] * 2, [lo, hi], color="#1f77b4", alpha=0.35, lw=0.8)
            ax.plot(jitter[j], values[j], "o", ms=4, color="#1f77b4",
                    mfc="#1f77b4" if s.determined[k] else "none")
        ax.set_xticks([])
        ax.set_xlim(-0.6, 0.6)
        ax.set_ylabel(f"{name} [{cohort.units[k]}]")
        ax.grid(True, axis="y", alpha=0.3)
    for ax in axes[n:]:
        ax.set_visible(False)
    failed = len(cohort.subjects) - len(ok)
    fig.suptitle(f"{len(ok)} subjects fitted" + (f", {failed} failed" if failed else "")
                 + " (median and quartiles; 95 % intervals)", fontsize=9)
    return fig
