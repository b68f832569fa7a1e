"""Benchmark of the FRF group comparison (run as a script, not a test).

``python benchmarks/bench_statistics.py [--repeats N]`` prints, for two synthetic cohorts
of 25 subjects each over the 11 bands (complex FRFs, seeded), the time of a
10⁴-permutation test with ``compare_frf_groups`` (all permutations vectorised: the group
means of every permutation are one matrix product, the pooled 2×2 covariances follow from
them) against a plain Python loop in the same run (per permutation: draw the labels, then
per band the groups' means, their pooled covariance and a 2×2 solve, as
:func:`~posturelab.frequency.statistics.band_t2_statistic` writes it), the ratio, and the
largest difference between the two's statistics over the first 200 permutations. Both draw
their permutations from one seeded generator in the same order (numpy's ``permuted`` row by
row consumes the stream as ``permutation`` does, with numpy 2.x), so they test the same
splits and their p-values agree exactly. Each
timing is the best of ``--repeats`` (default 3); on a shared machine they are noisy, the
ratio less so.
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

from posturelab.frequency.statistics import (
    band_t2_statistic,
    compare_frf_groups,
    permutation_statistics,
)

SEED = 20261202
PERMUTATIONS = 10_000
SUBJECTS = 25
BANDS = 11


def cohorts(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Two cohorts of ``SUBJECTS`` complex FRFs over ``BANDS`` bands: one mean, 30 % scatter."""
    h = np.exp(1j * np.linspace(0, -3, BANDS)) * np.linspace(2, 0.2, BANDS)

    def one():
        noise = rng.normal(size=(SUBJECTS, BANDS)) + 1j * rng.normal(size=(SUBJECTS, BANDS))
        return h + 0.3 * np.abs(h) * noise / np.sqrt(2)

    return one(), one()


def plain_loop(a: np.ndarray, b: np.ndarray, permutations: int, seed: int):
    """The permutation test as a plain loop: p and the statistics drawn."""
    rng = np.random.default_rng(seed)
    Z = np.concatenate([a, b])
    na = len(a)
    observed = band_t2_statistic(a, b)
    drawn = np.empty(permutations)
    for r in range(permutations):
        order = rng.permutation(len(Z))
        drawn[r] = band_t2_statistic(Z[order[:na]], Z[order[na:]])
    return (1 + np.sum(drawn >= observed)) / (1 + permutations), drawn


def best(fn, repeats: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    print("posturelab FRF-statistics benchmark")
    print(f"machine: {platform.platform()}; {os.cpu_count()} CPUs; numpy {np.__version__}")
    a, b = cohorts(np.random.default_rng(SEED))
    t_fast, result = best(lambda: compare_frf_groups(list(a), list(b),
                                                     permutations=PERMUTATIONS, resamples=1,
                                                     seed=1), args.repeats)
    t_loop, (p_loop, drawn) = best(lambda: plain_loop(a, b, PERMUTATIONS, 1), args.repeats)
    # the same statistic: the vectorised form on the loop's first 200 splits
    rng = np.random.default_rng(1)
    Z = np.concatenate([a, b])
    splits = np.zeros((200, len(Z)), dtype=bool)
    for r in range(200):
        splits[r, rng.permutation(len(Z))[:SUBJECTS]] = True
    diff = float(np.max(np.abs(permutation_statistics(Z, splits) - drawn[:200])
                        / drawn[:200]))
    print(f"{PERMUTATIONS:,}-permutation comparison of two groups of {SUBJECTS} FRFs over "
          f"{BANDS} bands (best of {args.repeats}): compare_frf_groups {t_fast:.3f} s "
          f"(p = {result.p_value:.3f}); plain Python loop {t_loop:.2f} s (p = {p_loop:.3f}): "
          f"{t_loop / t_fast:.0f}× faster; statistics agree to {diff:.1e} (relative)")


if __name__ == "__main__":
    main()
