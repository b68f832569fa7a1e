"""Benchmark: batched linear stability (posturelab.linear.batch) against plain numpy.

Run:  python benchmarks/bench_linear.py [--sets 1000000] [--repeats 7]

Everything is measured in this one run on this machine:

* the batched stable flags (Routh–Hurwitz) and all poles (Aberth–Ehrlich) of
  ``--sets`` random parameter sets of the paper model, median of ``--repeats``;
* a plain baseline: build the stacked 6×6 state matrices with numpy and call
  ``numpy.linalg.eigvals`` on them. It is measured on a subset
  (``--baseline-sets``, default 20,000) and scaled linearly to ``--sets`` —
  the table says so;
* agreement of the batched poles with eigvals on that subset
  (|Δλ| / max(1, |λ|), target 1e-8) and of the stable flags;
* the cold-compile time (a fresh process with an empty numba cache) and the
  cached-load time (a fresh process loading the cache), both as wall time of
  ``python -c "import ...; first call"``;
* the whole ``posturelab stability-map`` command at resolution 1000 (10⁶ sets:
  start-up, kernel, CSV and PNG), a fresh process each time with the numba cache
  warm, median of 3 after one warm-up run (``--skip-command`` leaves it out).

Random sets: each pair stiffness uniform in [0, 1500] N·m/rad, 15 % of them
set to 0 (pairs switched off, as in Table I); viscosity ratio uniform in
[0.02, 0.6] s; seed 12345.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

from posturelab.linear import batch as batch_linear
from posturelab.linear import sorted_poles
from posturelab.model.body import paper_body
from posturelab.model.dynamics import mass_matrix
from posturelab.model.muscles import paper_muscles

FIRST_CALL = (
    "import time; t0 = time.perf_counter(); import numpy as np; "
    "from posturelab.linear.batch import batch_analyse, batch_stable; t1 = time.perf_counter(); "
    "k = np.array([[500.0, 300, 300, 300, 300]]); batch_stable(k); batch_analyse(k); "
    "t2 = time.perf_counter(); print(f'{t1 - t0:.3f} {t2 - t1:.3f}')"
)


def machine() -> str:
    cpu = platform.processor() or "?"
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    import numba

    return (f"{platform.platform()}; {cpu}; {os.cpu_count()} CPUs; Python "
            f"{platform.python_version()}, numpy {np.__version__}, numba {numba.__version__}; "
            f"numba threads {numba.config.NUMBA_NUM_THREADS}")


def random_sets(count: int, seed: int = 12345) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    stiffness = rng.uniform(0.0, 1500.0, (count, 5))
    stiffness[rng.random((count, 5)) < 0.15] = 0.0
    ratio = rng.uniform(0.02, 0.6, count)
    return stiffness, ratio


def baseline_state_matrices(stiffness: np.ndarray, ratio: np.ndarray) -> np.ndarray:
    """Stacked 6×6 state matrices, plain numpy (independent of batch_linear)."""
    body = paper_body()
    E = paper_muscles("1").selection_matrix  # (5, 3)
    jac0 = mass_matrix(body, np.zeros(3))
    stiff = np.einsum("pi,mp,pj->mij", E, stiffness, E)
    visc = ratio[:, None, None] * stiff
    load = body.gravity * np.diag(body.gravity_coefficients) - stiff
    count = stiffness.shape[0]
    A = np.zeros((count, 6, 6))
    A[:, :3, 3:] = np.eye(3)
    A[:, 3:, :3] = np.linalg.solve(jac0, load)
    A[:, 3:, 3:] = -np.linalg.solve(jac0, visc)
    return A


def baseline(stiffness: np.ndarray, ratio: np.ndarray) -> np.ndarray:
    return np.linalg.eigvals(baseline_state_matrices(stiffness, ratio))


def median_times(operations: dict, repeats: int) -> tuple[dict, dict]:
    """Median wall time of each operation; repeats interleaved round-robin so that a
    change of machine load affects every operation alike."""
    times: dict = {name: [] for name in operations}
    results: dict = {}
    for _ in range(repeats):
        for name, func in operations.items():
            t = time.perf_counter()
            results[name] = func()
            times[name].append(time.perf_counter() - t)
    return {name: statistics.median(v) for name, v in times.items()}, results


def first_call_times(cache_dir: str, runs: int) -> list[tuple[float, float, float]]:
    """Wall time of fresh processes running FIRST_CALL with NUMBA_CACHE_DIR=cache_dir."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    out = []
    for _ in range(runs):
        t = time.perf_counter()
        proc = subprocess.run([sys.executable, "-c", FIRST_CALL], env=env, capture_output=True,
                              text=True, check=True)
        wall = time.perf_counter() - t
        imp, call = (float(v) for v in proc.stdout.split())
        out.append((wall, imp, call))
    return out


COMMAND = ["stability-map", "--x", "stiffness:ankle:0:2000", "--y",
           "stiffness:gastrocnemius:0:1000",
           "--resolution", "1000"]
COMMAND_SETS = 1000 * 1000


def command_times(runs: int) -> list[float]:
    """Wall time of ``posturelab stability-map`` (COMMAND) in fresh processes, after one
    untimed warm-up run (which fills the numba cache if needed)."""
    out = []
    with tempfile.TemporaryDirectory(prefix="posturelab-map-") as folder:
        argv = [sys.executable, "-m", "posturelab", *COMMAND, "--out",
                os.path.join(folder, "map.png")]
        for i in range(runs + 1):
            t = time.perf_counter()
            subprocess.run(argv, capture_output=True, text=True, check=True)
            if i:
                out.append(time.perf_counter() - t)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", type=int, default=1_000_000)
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--baseline-sets", type=int, default=20_000)
    parser.add_argument("--skip-compile", action="store_true",
                        help="skip the cold-compile / cached-load subprocess timings")
    parser.add_argument("--skip-command", action="store_true",
                        help="skip timing the whole stability-map command")
    args = parser.parse_args()

    print(f"machine: {machine()}")
    print(f"load average at start: {', '.join(f'{v:.2f}' for v in os.getloadavg())}")

    if not args.skip_compile:
        with tempfile.TemporaryDirectory(prefix="posturelab-numba-") as cache:
            cold = first_call_times(cache, 1)[0]
            warm = first_call_times(cache, 3)
        warm_wall = statistics.median(w[0] for w in warm)
        print(f"cold compile (fresh process, empty numba cache): {cold[0]:.2f} s wall "
              f"(import {cold[1]:.2f} s, first calls incl. compile {cold[2]:.2f} s)")
        print(f"cached load (fresh process, median of 3): {warm_wall:.2f} s wall to first "
              f"result (import {statistics.median(w[1] for w in warm):.2f} s, first calls "
              f"{statistics.median(w[2] for w in warm):.2f} s)")

    stiffness, ratio = random_sets(args.sets)
    batch_linear.batch_analyse(stiffness[:10], ratio[:10])  # load compiled code
    batch_linear.batch_stable(stiffness[:10], ratio[:10])

    nb = min(args.baseline_sets, args.sets)
    scale = args.sets / nb
    medians, results = median_times({
        "baseline": lambda: baseline(stiffness[:nb], ratio[:nb]),
        "stable": lambda: batch_linear.batch_stable(stiffness, ratio),
        "max": lambda: batch_linear.batch_analyse(stiffness, ratio),
        "poles": lambda: batch_linear.batch_analyse(stiffness, ratio, keep_poles=True),
    }, args.repeats)
    t_base = medians["baseline"] * scale
    t_stable, t_max, t_poles = medians["stable"], medians["max"], medians["poles"]
    base_poles, flags = results["baseline"], results["stable"]
    res_max, res = results["max"], results["poles"]

    # Agreement on the baseline subset.
    ref = sorted_poles(base_poles)
    err = np.abs(res.poles[:nb] - ref) / np.maximum(1.0, np.abs(ref))
    ref_stable = ref.real.max(axis=1) < 0.0
    near = np.abs(ref.real.max(axis=1)) < 1e-6

    print()
    print(f"{args.sets:,} random parameter sets, median of {args.repeats} repeats "
          "(interleaved)")
    head = f"{'operation':<56}{'median [s]':>11}{'per set [µs]':>14}{'speed-up':>10}"
    print(head)
    print("-" * len(head))
    rows = [
        (f"numpy baseline: build A + eigvals (scaled from {nb:,})", t_base),
        ("batch_stable: flags (Routh–Hurwitz)", t_stable),
        ("batch_analyse: max real part + flags", t_max),
        ("batch_analyse: all six poles", t_poles),
    ]
    for label, t in rows:
        print(f"{label:<56}{t:>11.3f}{1e6 * t / args.sets:>14.3f}{t_base / t:>9.1f}×")
    if not args.skip_command:
        t_cmd = statistics.median(command_times(3))
        base_cmd = t_base * COMMAND_SETS / args.sets  # the baseline for as many sets
        print(f"{'stability-map command, resolution 1000 (warm, whole)':<56}{t_cmd:>11.3f}"
              f"{1e6 * t_cmd / COMMAND_SETS:>14.3f}{base_cmd / t_cmd:>9.1f}×")
    print()
    print(f"agreement with numpy eigvals on {nb:,} sets:")
    print(f"  poles |Δλ|/max(1,|λ|): max {err.max():.2e}, 99.9th percentile "
          f"{np.quantile(err.max(axis=1), 0.999):.2e}, median {np.median(err):.2e} "
          f"(target 1e-8: {'ok' if err.max() < 1e-8 else 'FAILED'})")
    print(f"  stable flags differing from eigvals (all Re λ < 0): "
          f"{int(np.sum(res.stable[:nb] != ref_stable))} "
          f"(of which near-marginal |max Re λ| < 1e-6: "
          f"{int(np.sum((res.stable[:nb] != ref_stable) & near))})")
    print(f"  batch_stable vs batch_analyse flags on all {args.sets:,}: "
          f"{int(np.sum(flags != res.stable))} differ; "
          f"max-real-only run equals all-poles run: "
          f"{bool(np.array_equal(res_max.max_real_part, res.max_real_part))}")
    print(f"  fraction stable: {res.stable.mean():.3f}")
    print(f"load average at end: {', '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
