"""The README's timing statements, measured (run as a script, not a test).

``python benchmarks/bench_readme.py`` prints, warm, median of 3 after one warm-up:

1. the README's "how large a step" sweep (40 × 30 = 1,200 runs): the run time the command
   itself prints, and the whole command in a fresh process;
2. ``largest_recoverable_batch`` on 10,000 random gain sets to 0.01 m/s (backward step,
   literature foot, 3 s runs), in this process;
3. ``posturelab reproduce`` in a fresh process.

The two statements about a new machine (the README's first command, with the install, and
the first test run) are measured on a clean clone by hand; ``docs/develop.md`` says how.
"""

from __future__ import annotations

import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

SEED = 20261201
REPEATS = 3


def posturelab_command(args: list[str]) -> list[str]:
    """The command line that runs ``posturelab ARGS`` with this interpreter's install."""
    exe = os.path.join(os.path.dirname(sys.executable), "posturelab")
    return [exe, *args] if os.path.exists(exe) else [sys.executable, "-m", "posturelab", *args]


def command_seconds(args: list[str], cwd: str) -> tuple[float, str]:
    """Median wall time of ``posturelab ARGS`` in fresh processes, and its last output. [s]"""
    cmd = posturelab_command(args)
    subprocess.run(cmd, check=True, capture_output=True, cwd=cwd, timeout=900)
    times, out = [], ""
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        done = subprocess.run(cmd, check=True, capture_output=True, text=True, cwd=cwd,
                              timeout=900)
        times.append(time.perf_counter() - t0)
        out = done.stdout
    return statistics.median(times), out


def bisection_seconds(n_sets: int) -> tuple[float, int]:
    """Median seconds of one ``largest_recoverable_batch`` over ``n_sets`` random ankle and
    gastrocnemius stiffnesses (others from case 1), and how many sets it bracketed."""
    from posturelab.recovery import largest_recoverable_batch

    import posturelab as pl

    rng = np.random.default_rng(SEED)
    base = np.asarray(pl.paper_muscles("1").stiffnesses, dtype=float)
    k = np.tile(base, (n_sets, 1))
    k[:, 0] = rng.uniform(300.0, 2000.0, n_sets)
    k[:, 4] = rng.uniform(0.0, 1000.0, n_sets)
    fall = pl.FallCriteria(base_of_support=pl.FOOT_FROM_LITERATURE)
    step = pl.VelocityStep.backward(1.0)

    def run():
        return largest_recoverable_batch(pl.paper_body(), k, 0.25 * k, step, 3.0, 0.05, 1.6,
                                         tolerance=0.01, fall=fall)

    out = run()
    times = []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        run()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), int(np.count_nonzero(out.bracketed))


def main() -> None:
    print("posturelab: the README's timing statements")
    print(f"machine: {platform.platform()}; {os.cpu_count()} CPUs; python "
          f"{platform.python_version()}; load average at start "
          f"{', '.join(f'{v:.2f}' for v in os.getloadavg())}")
    with tempfile.TemporaryDirectory() as tmp:
        sweep = ["sweep", "--case", "1", "--disturbance", "backward", "--speed", "1",
                 "--foot", "literature", "--vary", "stiffness:ankle=300:2000:40",
                 "--vary", "disturbance_scale=0.05:1.5:30",
                 "--out", os.path.join(tmp, "how-large.csv")]
        whole, out = command_seconds(sweep, tmp)
        found = re.search(r"in ([0-9.]+) s", out)
        printed = found.group(1) + " s" if found else "(not printed)"
        print(f"1. how-large sweep, 1,200 runs: the command prints {printed}; "
              f"whole command {whole:.2f} s")
        seconds, bracketed = bisection_seconds(10_000)
        print(f"2. largest_recoverable_batch, 10,000 sets to 0.01 m/s: {seconds:.2f} s "
              f"({bracketed} bracketed)")
        whole, _ = command_seconds(["reproduce", "--out", os.path.join(tmp, "paper")], tmp)
        print(f"3. reproduce: {whole:.2f} s")


if __name__ == "__main__":
    main()
