"""Figures of frequency-response estimates: Bode plots with their confidence bands and
model curves, and a PRTS trial's cycle averages."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .figure import new_figure

__all__ = ["plot_bode", "plot_prts_cycles"]


def plot_bode(estimates, labels=None, model=None, bootstrap=None) -> Figure:
    """Gain, phase [deg] and coherence against frequency [Hz] of FRF estimates, with their 95 %
    bounds as bands, and optionally model curves.

    Parameters
    ----------
    estimates : sequence of posturelab.frequency.FRFEstimate or FRFTable
        One or several conditions; a table's 95 % bounds come from its standard errors
        (none without), its coherence is left out when not given.
    labels : sequence of str, optional
    model : sequence of (frequency [Hz], complex FRF, label), optional
        Curves to overlay.
    bootstrap : sequence of BootstrapBands or None, optional
        Per estimate, bootstrap bands (:func:`posturelab.frequency.bootstrap_frf_bands`)
        whose gain and phase intervals are drawn as dashed lines.

    Returns
    -------
    Figure
    """
    fig, (ax_g, ax_p, ax_c) = new_figure(3, 1, figsize=(6.5, 7.5), sharex=True)
    labels = list(labels or [f"condition {i + 1}" for i in range(len(estimates))])
    boots = list(bootstrap) if bootstrap is not None else [None] * len(labels)
    for est, label, boot in zip(map(_with_bounds, estimates), labels, boots, strict=True):
        line, = ax_g.loglog(est.frequency, est.gain, "o-", ms=4, label=label)
        if boot is not None:
            for side in (0, 1):
                ax_g.loglog(boot.frequency, np.maximum(boot.gain_ci[:, side], 1e-6), "--",
                            lw=0.9, color=line.get_color(),
                            label=(f"bootstrap {100 * boot.level:g} %" if side == 0
                                   else None))
                ax_p.semilogx(boot.frequency, boot.phase_ci_deg[:, side], "--", lw=0.9,
                              color=line.get_color())
        ok = np.all(np.isfinite(est.gain_ci95), axis=1)
        if ok.any():
            ax_g.fill_between(est.frequency[ok], np.maximum(est.gain_ci95[ok, 0], 1e-6),
                              est.gain_ci95[ok, 1], color=line.get_color(), alpha=0.2)
            ax_p.fill_between(est.frequency[ok], est.phase_ci95_deg[ok, 0],
                              est.phase_ci95_deg[ok, 1], color=line.get_color(), alpha=0.2)
        ax_p.semilogx(est.frequency, est.phase_deg, "o-", ms=4, color=line.get_color())
        ax_c.semilogx(est.frequency, est.coherence, "o-", ms=4, color=line.get_color())
    styles = [("k", "--"), ("#d62728", "-."), ("#2ca02c", ":"), ("#9467bd", "--")]
    for k, (f, h, label) in enumerate(model or ()):
        f, h = np.asarray(f), np.asarray(h)
        color, ls = styles[k % len(styles)]
        ax_g.loglog(f, np.abs(h), color=color, ls=ls, lw=1.3, label=label)
        ax_p.semilogx(f, np.degrees(np.unwrap(np.angle(h))), color=color, ls=ls, lw=1.3)
    from matplotlib.ticker import FormatStrFormatter, LogLocator, NullFormatter

    ax_g.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    ax_g.yaxis.set_major_formatter(FormatStrFormatter("%g"))
    ax_g.yaxis.set_minor_formatter(NullFormatter())
    ax_c.xaxis.set_major_formatter(FormatStrFormatter("%g"))
    ax_g.set_ylabel("gain")
    ax_p.set_ylabel("phase [deg]")
    ax_c.set_ylabel("coherence")
    ax_c.set_ylim(0, 1.05)
    ax_c.set_xlabel("frequency [Hz]")
    ax_g.legend(fontsize=8)
    for ax in (ax_g, ax_p, ax_c):
        ax.grid(True, which="both", alpha=0.3)
    return fig


def _with_bounds(frf):
    """What :func:`plot_bode` draws of a condition: an estimate as it is; a table
    (:class:`posturelab.frequency.table.FRFTable`) with 95 % bounds from its standard errors
    (NaN without) and its coherence NaN when not given."""
    if hasattr(frf, "gain_ci95"):
        return frf
    from types import SimpleNamespace

    nan = np.full(frf.frequency.size, np.nan)
    if frf.gain_se is not None:
        gain_ci = np.stack([frf.gain - 1.96 * frf.gain_se, frf.gain + 1.96 * frf.gain_se],
                           axis=1)
        phase_ci = np.stack([frf.phase_deg - 1.96 * frf.phase_se_deg,
                             frf.phase_deg + 1.96 * frf.phase_se_deg], axis=1)
    else:
        gain_ci = phase_ci = np.stack([nan, nan], axis=1)
    return SimpleNamespace(frequency=frf.frequency, gain=frf.gain, phase_deg=frf.phase_deg,
                           coherence=nan if frf.coherence is None else frf.coherence,
                           gain_ci95=gain_ci, phase_ci95_deg=phase_ci)


def plot_prts_cycles(estimate, *, stimulus_label: str = "tilt",
                     response_label: str = "response",
                     stimulus_unit: tuple[str, float] = ("deg", 180.0 / np.pi),
                     response_unit: tuple[str, float] = ("deg", 180.0 / np.pi)) -> Figure:
    """The stimulus over one cycle and the response averaged over the cycles used (the
    time-domain cycle averages of an FRF estimate), against time within the cycle [s].

    Parameters
    ----------
    estimate : posturelab.frequency.FRFEstimate
    stimulus_label, response_label : str
        Axis words.
    stimulus_unit, response_unit : (str, float)
        The plotted unit and the factor from the series' unit to it (radians to degrees by
        default).

    Returns
    -------
    Figure
    """
    x = np.asarray(estimate.cycle_stimulus) * stimulus_unit[1]
    y = np.asarray(estimate.cycle_response) * response_unit[1]
    t = np.arange(x.size) * estimate.cycle_length / x.size
    fig, (ax_x, ax_y) = new_figure(2, 1, figsize=(6.5, 5.0), sharex=True)
    ax_x.plot(t, x, color="0.25", lw=1.2, drawstyle="default")
    ax_x.set_ylabel(f"{stimulus_label} [{stimulus_unit[0]}]")
    ax_x.set_title(f"One {estimate.cycle_length:g} s cycle of the stimulus, and the response "
                   f"averaged over {estimate.n_cycles} cycles", fontsize=10)
    ax_y.plot(t, y, color="#1f77b4", lw=1.2)
    ax_y.set_ylabel(f"{response_label} [{response_unit[0]}]")
    ax_y.set_xlabel("time within the cycle [s]")
    for ax in (ax_x, ax_y):
        ax.grid(True, alpha=0.3)
        ax.axhline(0.0, color="0.6", lw=0.6)
    return fig
