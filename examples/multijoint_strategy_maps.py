"""Strategy maps of a designed multi-joint controller
=====================================================

The paper's body with ``multijoint-default`` (:func:`posturelab.linear.lqr.multijoint_controller`:
an LQR full-state feedback of the ankle–hip chain, after Kuo 1995 and Park, Horak & Kuo 2004,
designed on the undelayed linear model and applied 0.08 s late, the knee locked). Left: the
hip fraction (after Creath et al. 2005; 0 for a body swaying as one pendulum, 1 for pure
counter-rotation about the hip) against the peak speed of a 6 cm backward ramp-and-hold
(after Horak & Nashner 1986's ramp translations). Right: against the frequency of a 5 cm
sinusoidal translation, over the steady part. Blue: the ankle moment limited both ways to
m g x_toe, 121 N·m (the design's τ_max, the default of ``posturelab strategy``); orange:
limited per side to what the foot carries, m g x_toe toward the toes and m g (−x_heel), 40 N·m,
toward the heel (:mod:`posturelab.model.limits`, ``--ankle-limit-from-foot``); grey: no
limit. Filled markers: the ankle saturated; crosses: the run fell.

With the foot's limit the hip fraction stays below 0.1 for the slowest translations and at
0.1–0.5 Hz and rises above 0.8 for the fastest translations and at 1.25 Hz, as the ankle
saturates, and at 1.5 Hz the body falls; without the limit it rises less (the fast ramp
excites the anti-phase mode on its own), and at 1 Hz it stays low: the limit is what hands
the sway to the hip there. With the heel's 40 N·m the ends of the maps are the same, but in
between the body falls backward once dorsiflexion saturates (at 0.3 m/s, at 0.75 and 1 Hz).

Usage: python examples/multijoint_strategy_maps.py [OUTPUT_DIR]   (default: current directory)
"""

import sys
from pathlib import Path

import numpy as np

import posturelab as pl
from posturelab.linear.lqr import multijoint_controller
from posturelab.model.limits import foot_moment_limits
from posturelab.studies.strategy import oscillation_map, translation_map
from posturelab.viz.plots import new_figure, save_figure

SPEEDS = np.linspace(0.05, 1.0, 12)  # peak platform speeds [m/s]
FREQUENCIES = np.array([0.1, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5])  # [Hz]
AMPLITUDE = 0.05  # [m]


def _draw(ax, smap, colour, label):
    v = np.array([r.value for r in smap.runs])
    h = np.array([r.hip_fraction for r in smap.runs])
    ok = np.array([r.outcome == "recovered" for r in smap.runs])
    sat = np.array([r.ankle_saturated for r in smap.runs])
    ax.plot(v[ok], h[ok], "-", color=colour, lw=1, label=label)
    ax.plot(v[ok & sat], h[ok & sat], "o", color=colour, ms=5)
    ax.plot(v[ok & ~sat], h[ok & ~sat], "o", mfc="white", color=colour, ms=5)
    if (~ok).any():
        ax.plot(v[~ok], np.nan_to_num(h[~ok], nan=1.0), "x", color=colour)


def make_figure():
    """The figure (a pyplot-free matplotlib Figure)."""
    body = pl.paper_body()
    c = multijoint_controller(body)
    limit = float(c.effort_limits[0])
    foot = pl.FOOT_FROM_LITERATURE
    pair = foot_moment_limits(body.total_mass * body.gravity, foot.heel, foot.toe)
    fig, (ax_t, ax_o) = new_figure(1, 2, figsize=(10.0, 4.2))
    for lim, colour, label in ((limit, "#1f77b4", f"|ankle| ≤ {limit:.0f} N·m"),
                               (pair, "#ff7f0e",
                                f"ankle in [{pair[0]:.0f}, {pair[1]:.0f}] N·m (the foot)"),
                               (None, "0.5", "ankle unlimited")):
        t = translation_map(body, c.muscles, SPEEDS, ankle_torque_limit=lim,
                            **c.run_options())
        o = oscillation_map(body, c.muscles, AMPLITUDE, FREQUENCIES, ankle_torque_limit=lim,
                            **c.run_options())
        _draw(ax_t, t, colour, label)
        _draw(ax_o, o, colour, label)
        print(f"{label}: translations {t.runs[0].hip_fraction:.3f} … "
              f"{t.runs[-1].hip_fraction:.3f}; transition frequency "
              f"{o.transition_frequency} Hz")
    for ax in (ax_t, ax_o):
        for level in (0.15, 0.4):
            ax.axhline(level, color="0.8", ls=":", lw=1)
        ax.set_ylim(0, 1)
        ax.set_ylabel("hip fraction [-]")
        ax.legend(fontsize=8)
    ax_t.set_xlabel("peak speed of a 6 cm backward translation [m/s]")
    ax_o.set_xlabel(f"frequency of a {AMPLITUDE * 100:.0f} cm sinusoidal translation [Hz]")
    ax_t.set_title("transient translations", fontsize=10)
    ax_o.set_title("sinusoidal translations (steady part)", fontsize=10)
    return fig


if __name__ == "__main__":
    out = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    figure = make_figure()
    print(f"wrote {save_figure(figure, out / 'multijoint_strategy_maps.png')}")
