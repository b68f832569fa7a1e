"""Bode plot: a simulated PRTS tilt experiment against the model FRF
===================================================================

The independent-channel model of the identification literature on one link: the paper's
body as an inverted pendulum (``paper-1link``) with the ``peterka-2002`` preset (active
stiffness 1.35 mgh, active viscosity 0.47 mgh·s, feedback delay 0.15 s: round values after
Peterka 2002; proprioceptive weight 1: posturelab's choice). The support surface turns by
posturelab's own 80-state pseudorandom ternary sequence (``posturelab-80``: 0.035 rad peak to
peak, 20 s cycle; Peterka 2002 used 242-state ones) for five cycles, the first discarded, on
the compiled engine; the recorded centre-of-mass angle gets 1 mrad of seeded white sensor
noise (:func:`posturelab.frequency.experiment.prts_experiment`). The FRF is estimated over
the 11 frequency bands of an 80-state sequence with its coherence and 95 % bounds
(:func:`posturelab.frequency.estimate_frf`) and drawn against the linearised model's FRF,
exact in the delay (:func:`posturelab.frequency.model_frf`), with
:func:`posturelab.viz.plots.plot_bode`. The literature's sign: a body that follows the
surface has gain 1 and phase 0 [deg].

Usage: python examples/prts_bode.py [OUTPUT_DIR]   (default: current directory)
"""

import sys
from pathlib import Path

import numpy as np

import posturelab as pl
from posturelab.frequency import model_frf
from posturelab.frequency.experiment import prts_experiment
from posturelab.model.controllers import get_controller
from posturelab.viz.plots import plot_bode, save_figure

CYCLES = 4  # cycles analysed, after one discarded [-]
SENSOR_NOISE = 0.001  # [rad]


def make_figure():
    """The figure (a pyplot-free matplotlib Figure)."""
    body = pl.get_body("paper-1link")
    preset = get_controller("peterka-2002")
    muscles = preset.muscles(body)
    exp = prts_experiment(body, muscles, cycles=CYCLES, discard=1, sensor_noise=SENSOR_NOISE,
                          seed=1, **preset.run_options())
    est = exp.estimate
    f = np.geomspace(0.03, 3.0, 200)  # [Hz]
    model = model_frf(body, muscles, f, **preset.run_options())
    fig = plot_bode([est], [f"simulated PRTS experiment ({CYCLES} cycles, "
                            f"{SENSOR_NOISE * 1000:g} mrad sensor noise)"],
                    model=[(f, model, "model FRF (peterka-2002, one link)")])
    fig.suptitle("Tilt FRF of the centre-of-mass sway", fontsize=10)
    at_bands = est.band_average(lambda x: model_frf(body, muscles, x, **preset.run_options()))
    for fk, g, gm in zip(est.frequency, est.gain, np.abs(at_bands), strict=True):
        print(f"{fk:5.2f} Hz   gain {g:6.3f}   model {gm:6.3f}")
    return fig


def main(out_dir: Path) -> Path:
    return save_figure(make_figure(), out_dir / "prts_bode.png")


if __name__ == "__main__":
    out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
    fig = make_figure()
    print(save_figure(fig, out_dir / "prts_bode.png"))
