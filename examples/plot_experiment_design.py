"""Experiment design: how many cycles pin the feedback delay down, and at what state duration
==========================================================================================

Before a PRTS tilt experiment, :func:`posturelab.frequency.design.predict_errors` predicts
the standard error of each parameter a fit of the model FRF will give, from the Fisher
information of the exact model FRF under the stated noise (the derivation and its sources
are in the module). Here: the paper's body as one link (``paper-1link``) with the
``peterka-2002`` controller (active stiffness, active viscosity and delay fitted), 2 N·m of
white motor noise at the ankle and 1 mrad of sensor noise on the recorded centre-of-mass
angle, posturelab's 80-state sequence at 0.035 rad peak to peak.

Left: the predicted standard error of the delay against the number of cycles (it falls as
1/√cycles), with the spread (standard deviation) of the fitted delays over ``SEEDS`` seeded
simulated experiments (compiled engine; estimated and fitted with ``fit_frf``) at a few
cycle counts; each spread is drawn with its own sampling error, s/√(2(n − 1)). Right:
:func:`posturelab.frequency.design_search.optimise_design` over the state duration within
a 240 s budget (one cycle discarded): the predicted relative error of the delay at each
state duration's best design; the larger amplitude always wins under the linear model, so
the amplitude is held at 0.035 rad here.

Usage: python examples/plot_experiment_design.py [OUTPUT_DIR]   (default: current directory)
"""

import sys
from pathlib import Path

import numpy as np

import posturelab as pl
from posturelab.frequency.design import predict_errors
from posturelab.frequency.design_search import optimise_design
from posturelab.frequency.experiment import prts_experiment
from posturelab.frequency.fit import fit_frf
from posturelab.model.controllers import get_controller
from posturelab.model.noise import MotorNoise
from posturelab.model.tilt import PRTSTilt
from posturelab.viz.plots import new_figure, save_figure

FREE = ["active_stiffness", "active_viscosity", "feedback_delay"]
MOTOR_NOISE = 2.0  # [N·m]
SENSOR_NOISE = 0.001  # [rad]
AMPLITUDE = 0.035  # peak to peak [rad]
CYCLES = (2, 4, 8)  # simulated [-]
SEEDS = 20  # simulated experiments per cycle count [-]
BUDGET = 240.0  # [s]


def _model():
    body = pl.get_body("paper-1link")
    preset = get_controller("peterka-2002")
    return body, preset.muscles(body), preset.run_options()


def spread_of_fits(cycles: int, seeds: int = SEEDS) -> np.ndarray:
    """The fitted values of ``FREE`` over ``seeds`` simulated experiments, shape (seeds, 3)."""
    body, muscles, options = _model()
    tilt = PRTSTilt.named("posturelab-80", AMPLITUDE)
    out = []
    for seed in range(seeds):
        exp = prts_experiment(body, muscles, tilt=tilt, cycles=cycles, discard=1, seed=seed,
                              sensor_noise=SENSOR_NOISE,
                              motor_noise=MotorNoise(MOTOR_NOISE, seed=10_000 + seed),
                              **options)
        out.append(fit_frf(body, muscles, exp.estimate, FREE, **options).estimates)
    return np.array(out)


def make_figure(seeds: int = SEEDS):
    """The figure (a pyplot-free matplotlib Figure)."""
    body, muscles, options = _model()
    noise = {"sensor_noise": SENSOR_NOISE, "motor_noise": MotorNoise(MOTOR_NOISE)}
    tilt = PRTSTilt.named("posturelab-80", AMPLITUDE)
    fig, (left, right) = new_figure(1, 2, figsize=(9.0, 4.0))
    counts = np.arange(2, 33)
    predicted = np.array([predict_errors(body, muscles, FREE, tilt=tilt, cycles=int(c),
                                         **noise, **options).standard_errors[2]
                          for c in counts])
    left.loglog(counts, 1e3 * predicted, label="predicted (Fisher information)")
    print("cycles  predicted se(τ) [ms]  spread of fitted τ over seeds [ms]")
    for c in CYCLES:
        fitted = spread_of_fits(c, seeds)[:, 2]
        s = float(np.std(fitted, ddof=1))
        err = s / np.sqrt(2 * (seeds - 1))
        left.errorbar([c], [1e3 * s], yerr=[1e3 * err], fmt="o", color="C1",
                      label=f"spread of {seeds} simulated fits" if c == CYCLES[0] else None)
        print(f"{c:6d}  {1e3 * predicted[counts == c][0]:20.3f}  {1e3 * s:.3f} ± "
              f"{1e3 * err:.3f}")
    from matplotlib.ticker import NullFormatter, ScalarFormatter

    left.set_xticks([2, 4, 8, 16, 32])
    left.set_yticks([0.4, 0.6, 0.8, 1.0, 1.5])
    for axis in (left.xaxis, left.yaxis):
        axis.set_major_formatter(ScalarFormatter())
        axis.set_minor_formatter(NullFormatter())
    left.set_xlabel("cycles analysed [-]")
    left.set_ylabel("standard error of the delay [ms]")
    left.legend(fontsize=8)
    best = optimise_design(body, muscles, FREE, budget=BUDGET, targets=["feedback_delay"],
                           amplitude_range=(AMPLITUDE / 2, AMPLITUDE), grid=9, **noise,
                           **options)
    rows = best.table
    right.plot([r["state_duration"] for r in rows],
               [100 * np.sqrt(r["objective"]) for r in rows], "o-")
    for r in rows:
        right.annotate(f"{r['cycles']}", (r["state_duration"], 100 * np.sqrt(r["objective"])),
                       textcoords="offset points", xytext=(0, 5), fontsize=7, ha="center")
    right.set_xlabel("PRTS state duration [s] (80 states; cycles annotated)")
    right.set_ylabel("predicted relative error of the delay [%]")
    right.set_title(f"best within {BUDGET:g} s: {best.best.state_duration:g} s states, "
                    f"{best.best.cycles} cycles", fontsize=9)
    fig.suptitle("Designing a PRTS tilt experiment (peterka-2002, one link)", fontsize=10)
    return fig


def main(out_dir: Path, seeds: int = SEEDS) -> Path:
    return save_figure(make_figure(seeds), out_dir / "experiment_design.png")


if __name__ == "__main__":
    out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
    fig = make_figure()
    print(save_figure(fig, out_dir / "experiment_design.png"))
