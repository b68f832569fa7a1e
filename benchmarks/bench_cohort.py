"""Benchmark of a cohort fit (run as a script, not a test).

``python benchmarks/bench_cohort.py [REPEATS]`` fits 50 seeded virtual subjects (one-link
body, active gains, delay and W drawn within ±20 % of icm-pmc5664365, W 0.5 … 0.9; each a
PRTS trial estimate from six 20 s cycles of the exact model response plus white sensor noise)
with four free parameters, three ways, in the same run:

1. the baseline: a plain Python loop of ``fit_frf`` calls, one per subject;
2. ``fit_cohort(..., workers=1)``: the same fits through the cohort (its own overhead);
3. ``fit_cohort(..., workers=N)``: N worker processes, N the CPUs this process may use.

Each is timed REPEATS times (default 3; the three interleaved), the best kept; it prints the
times and the ratio of the loop to each cohort run (above 1: the cohort is faster), and
checks that the three agree to the last digit. On a shared machine the process pool's gain
is bounded by the idle CPUs, not by the CPU count: compare ratios measured in one run,
never times across runs.
"""

from __future__ import annotations

import os
import platform
import sys
import time

import numpy as np

import posturelab as pl
from posturelab.frequency import estimate_frf, model_frf
from posturelab.frequency.cohort import fit_cohort, usable_cpus
from posturelab.frequency.fit import fit_frf
from posturelab.model.controllers import get_controller
from posturelab.model.tilt import PRTSTilt

SEED = 20261202
SUBJECTS = 50
FREE = ["active_stiffness:ankle", "active_viscosity:ankle", "feedback_delay",
        "proprioceptive_weight"]
START = {"feedback_delay": 0.1, "proprioceptive_weight": 0.7}


def cohort_estimates(count: int, rng: np.random.Generator):
    """``count`` virtual subjects' FRF estimates (module notes) and the starting gains."""
    body = pl.get_body("paper-1link")
    preset = get_controller("icm-pmc5664365")
    base = preset.muscles(body)
    L, T, cycles = 1000, 20.0, 6
    x = PRTSTilt.named("posturelab-80", 0.035).angle(np.arange(L) * T / L)
    X = np.fft.rfft(x)
    f = np.arange(1, X.size) / T
    out = []
    for _ in range(count):
        muscles = base.with_active_feedback(
            [base.active_stiffnesses[0] * rng.uniform(0.8, 1.2)],
            [base.active_viscosities[0] * rng.uniform(0.8, 1.2)])
        H = np.zeros(X.size, complex)
        H[1:] = model_frf(body, muscles, f,
                          feedback_delay=preset.feedback_delay * rng.uniform(0.8, 1.2),
                          proprioceptive_weight=rng.uniform(0.5, 0.9))
        y = np.tile(np.fft.irfft(H * X, L), cycles) + rng.normal(0.0, 0.002, cycles * L)
        out.append(estimate_frf(np.tile(x, cycles), y, L / T, T))
    return body, base, out


def best_of(repeats: int, runs: dict) -> dict:
    """{name: (best time [s], result)}, the runs interleaved in each repeat (so that a change
    of the machine's load falls on all of them alike)."""
    best: dict = {name: (np.inf, None) for name in runs}
    for _ in range(repeats):
        for name, fn in runs.items():
            t0 = time.perf_counter()
            result = fn()
            best[name] = (min(best[name][0], time.perf_counter() - t0), result)
    return best


def main() -> None:
    repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    workers = usable_cpus()
    print("posturelab cohort benchmark")
    print(f"  {platform.python_version()} on {platform.machine()}, {os.cpu_count()} CPUs "
          f"({workers} usable); load average {os.getloadavg()[0]:.2f}; best of {repeats}")
    body, base, subjects = cohort_estimates(SUBJECTS, np.random.default_rng(SEED))
    fit_frf(body, base, subjects[0], FREE, **START)  # (imports and caches warmed)

    best = best_of(repeats, {
        "loop": lambda: [fit_frf(body, base, s, FREE, **START) for s in subjects],
        "one": lambda: fit_cohort(body, base, subjects, FREE, workers=1, **START),
        "many": lambda: fit_cohort(body, base, subjects, FREE, workers=workers, **START)})
    (t_loop, loop), (t_one, one), (t_many, many) = best["loop"], best["one"], best["many"]
    for fits in (one, many):
        for plain, subject in zip(loop, fits.subjects, strict=True):
            assert np.array_equal(plain.estimates, subject.estimates)
    print(f"  {SUBJECTS} subjects, {len(FREE)} free parameters each (the three agree exactly)")
    print(f"  plain loop of fit_frf            {t_loop:8.2f} s   (baseline)")
    print(f"  fit_cohort, 1 process            {t_one:8.2f} s   loop/cohort {t_loop / t_one:5.2f}")
    print(f"  fit_cohort, {workers} processes          {t_many:8.2f} s   "
          f"loop/cohort {t_loop / t_many:5.2f}")


if __name__ == "__main__":
    main()
