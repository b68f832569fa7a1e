"""When is a step needed? Young and older, against the move's duration
=====================================================================

Beyond the paper.

The largest backward platform translation withstood with the feet in place
(:func:`posturelab.studies.stepping.step_threshold`: a run needs a step when the
extrapolated centre of mass x + v/ω0 of Hof, Gazendam & Sinke 2005, with the platform's
remaining path counted, leaves the population's functional base of support (King, Judge &
Wolfson 1994), or the body falls), for the young and older presets (a 1.75 m, 75 kg
subject), against the duration T of each ramp-and-hold move, beside the published thresholds
of Koushyar et al. 2019 (PLoS ONE 14:e0210049, PMC6338353): 16.2 ± 2.6 cm (young) and 11.8 ±
2.1 cm (older), drawn as bands of ± two standard deviations. The study's protocol assumes T
= 0.5 s (the paper's profile was not available to posturelab); the curves show how much the
comparison hangs on it. Each threshold takes 15–40 runs of the compiled engine.

Writes step_threshold_vs_duration.png: largest translation [cm] against T [s].

Usage: python examples/step_threshold_vs_duration.py [OUTPUT_DIR]   (default: current directory)
"""

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from posturelab.studies.stepping import PROTOCOL, PUBLISHED, step_threshold
from posturelab.viz.plots import new_figure, save_figure

DURATIONS = np.round(np.arange(0.3, 1.01, 0.05), 2)  # [s]
HEIGHT, MASS = 1.75, 75.0  # [m], [kg]: posturelab's assumption (the paper's not available)
COLOURS = {"young": "tab:blue", "older": "tab:red"}


def thresholds(durations: np.ndarray = DURATIONS) -> dict[str, np.ndarray]:
    """Largest translation without a step [m] per move duration, for each population."""
    return {population: np.array([
        step_threshold(HEIGHT, MASS, population,
                       protocol=replace(PROTOCOL, move_duration=float(t))).largest_translation
        for t in durations]) for population in ("young", "older")}


def make_figure():
    """The figure (a pyplot-free matplotlib Figure)."""
    values = thresholds()
    fig, ax = new_figure(figsize=(7.0, 4.2))
    for population, largest in values.items():
        published = PUBLISHED[(population, "backward")]
        colour = COLOURS[population]
        ax.axhspan(100 * (published.mean - 2 * published.sd),
                   100 * (published.mean + 2 * published.sd), color=colour, alpha=0.12,
                   label=f"{population}, published mean ± 2 SD")
        ax.axhline(100 * published.mean, color=colour, lw=0.8, ls="--")
        ax.plot(DURATIONS, 100 * largest, "o-", color=colour, label=f"{population}, model")
    ax.axvline(PROTOCOL.move_duration, color="0.5", lw=0.8, ls=":")
    ax.set_xlabel("duration of the platform move T [s]")
    ax.set_ylabel("largest translation without a step [cm]")
    ax.set_title("Backward translations: model (XCoM criterion) and Koushyar et al. 2019")
    ax.legend(loc="upper left", fontsize=8)
    return fig


def main(out_dir: Path) -> Path:
    return save_figure(make_figure(), out_dir / "step_threshold_vs_duration.png")


if __name__ == "__main__":
    out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
    fig = make_figure()
    print(save_figure(fig, out_dir / "step_threshold_vs_duration.png"))
