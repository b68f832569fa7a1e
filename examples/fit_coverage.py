"""How often the time-domain fit's 95 % intervals cover the truth
================================================================

Synthetic experiments of known gains: the paper's case 1 after a 1 m/s backward step,
2 s sampled at 50 Hz (the 'measurement'), plus seeded sensor noise of 2 mrad that is
either independent from sample to sample or a first-order autoregression (AR(1)) of
lag-1 correlation phi, as low-pass filtered sensors and unmodelled slow sway make it.
Each trial fits the ankle and gastrocnemius stiffness and the viscosity ratio with
``posturelab.identify.fit_stiffness`` and records whether each 95 % interval holds the
true value, once with the default AR(1) residual model and once with the textbook
independent one.

Run:  python examples/fit_coverage.py [--trials 300]
(about 0.06 s per fit: 300 trials take about two minutes; not run when the documentation
is built).
"""

from __future__ import annotations

import argparse

import numpy as np
from posturelab.identify import fit_stiffness

import posturelab as pl

#: The fitted parameters and their true values. [N·m/rad], [N·m/rad], [s]
FREE = ("stiffness:ankle", "stiffness:gastrocnemius", "viscosity_ratio")
TRUTH = np.array([500.0, 300.0, 0.25])
#: Standard deviation of the sensor noise. [rad]
NOISE = 0.002


def experiment():
    """The scenario, its noise-free run and the fit's starting point."""
    sc = pl.builtin_scenario("paper-backward-case1").replace(duration=2.0, sample_rate=50)
    start = sc.replace(muscles=pl.paper_muscles(stiffness=[700, 300, 300, 300, 200]))
    return start, sc.run(engine="compiled")


def ar1_noise(rng: np.random.Generator, shape: tuple[int, int], phi: float) -> np.ndarray:
    """Stationary AR(1) noise of standard deviation :data:`NOISE` along axis 0. [rad]"""
    w = rng.normal(0.0, NOISE, shape)
    e = np.empty_like(w)
    e[0] = w[0]
    for k in range(1, shape[0]):
        e[k] = phi * e[k - 1] + np.sqrt(1.0 - phi**2) * w[k]
    return e


def coverage(phi: float, trials: int, residual_model: str, seed: int = 2027) -> np.ndarray:
    """Fraction of trials whose 95 % interval holds each true value, shape (3,). [-]"""
    start, truth = experiment()
    hits = np.zeros(len(FREE))
    for trial in range(trials):
        rng = np.random.default_rng([seed, trial])
        noisy = truth.theta + ar1_noise(rng, truth.theta.shape, phi)
        fit = fit_stiffness(start, truth.time, noisy, list(FREE),
                            residual_model=residual_model)
        lo, hi = fit.confidence_intervals.T
        hits += (lo <= TRUTH) & (TRUTH <= hi)
    return hits / trials


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=300, help="trials per row")
    args = parser.parse_args()
    print(f"coverage of the 95 % intervals, {args.trials} seeded trials per row")
    print(f"{'noise lag-1 correlation':>24}  {'residual model':>14}  "
          + "  ".join(f"{name:>23}" for name in FREE))
    for phi in (0.0, 0.5, 0.8):
        for model in ("ar1", "independent"):
            c = coverage(phi, args.trials, model)
            print(f"{phi:>24.1f}  {model:>14}  " + "  ".join(f"{v:>23.3f}" for v in c))


if __name__ == "__main__":
    main()
