"""The README's timing statements, measured (run as a script, not a test).

``python benchmarks/bench_readme.py`` measures every timing the README states that the other
scripts do not, each next to the README's claim, and prints the machine and the load
average (1, 5, 15 min) at the start, after each statement and at the end. Each command
runs as the README writes it, in a fresh process, in a temporary folder holding the inputs
it needs, warm (one run first, not counted), median of ``--repeats`` runs (default 3):

1. the "how large a step" sweep (40 × 30 = 1,200 runs): the run time the command itself
   prints, and the whole command;
2. ``largest_recoverable_batch`` on 10,000 random gain sets to 0.01 m/s (backward step,
   literature foot, 3 s runs), in this process;
3. ``posturelab reproduce --out DIR``: the whole command and the time it prints;
4. the D-subdivision figure of ``examples/delay_stability_map.py`` (200 × 200 = 40,000
   sets): ``delay_stability_map`` in this process, and the whole script;
5. ``model_frf_batch``: 10⁶ random one-link sets (intrinsic and delayed active gains) at
   the 11 bands, in this process (``bench_frequency.py`` has its baseline);
6. the population sweep of the frequency section (``sweep --experiment prts``, 4 × 5 = 20
   virtual subjects, each a 120 s PRTS experiment, its FRF and a two-parameter fit): the run
   time the command prints, and the whole command;
7. a delayed stability map of the three-link body (the limits table's "300 × 300"): the
   ``stability-map`` command at ``--resolution 60`` (3,600 sets), scaled per set to
   300 × 300 (``--full-delay-map`` runs the 300 × 300 command itself, once: minutes).

Measured elsewhere: the engines, start-up, whole ``stability-map``/10,000-run ``sweep``
commands and compilation (``bench_simulate.py``), the batched linear analysis
(``bench_linear.py``), the explorer's round trip (``bench_explore.py``), the FRF baselines
(``bench_frequency.py``). The README's two new-machine timings (its first command, with the
install, and the first test run) and the documentation build are measured by hand on a
clean clone, the README's commands as written under ``/usr/bin/time`` (``docs/develop.md``).
"""

from __future__ import annotations

import argparse
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

SEED = 20261201
ROOT = Path(__file__).resolve().parents[1]


def load() -> str:
    """The load average over 1, 5 and 15 min. [-]"""
    return ", ".join(f"{v:.2f}" for v in os.getloadavg())


def cpu_name() -> str:
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def posturelab_command(args: list[str]) -> list[str]:
    """The command line that runs ``posturelab ARGS`` with this interpreter's install."""
    exe = os.path.join(os.path.dirname(sys.executable), "posturelab")
    return [exe, *args] if os.path.exists(exe) else [sys.executable, "-m", "posturelab", *args]


def fresh_seconds(cmd: list[str], cwd: str, repeats: int,
                  warm_up: bool = True) -> tuple[float, list[float], str]:
    """Wall times of ``cmd`` in fresh processes (one uncounted warm-up run first): the
    median, every run, and the last run's standard output and error. [s]"""
    if warm_up:
        subprocess.run(cmd, check=True, capture_output=True, cwd=cwd, timeout=1800)
    times, out = [], ""
    for _ in range(repeats):
        t0 = time.perf_counter()
        done = subprocess.run(cmd, check=True, capture_output=True, text=True, cwd=cwd,
                              timeout=1800)
        times.append(time.perf_counter() - t0)
        out = done.stdout + done.stderr
    return statistics.median(times), times, out


def in_process_seconds(fn, repeats: int) -> tuple[float, list[float], object]:
    """Wall times of ``fn()`` after one uncounted call: the median, every call, the result."""
    result = fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), times, result


def spread(times: list[float]) -> str:
    return f"runs {min(times):.2f}–{max(times):.2f} s" if len(times) > 1 else "one run"


def report(number: str, what: str, claim: str, measured: str) -> None:
    print(f"{number} {what}")
    print(f"   README: {claim}")
    print(f"   measured: {measured}; load {load()}")
    sys.stdout.flush()


def printed_seconds(out: str, pattern: str = r"in ([0-9.]+) s") -> str:
    found = re.search(pattern, out)
    return f"{found.group(1)} s" if found else "(not printed)"


def bisection(repeats: int) -> tuple[float, list[float], int]:
    """``largest_recoverable_batch`` over 10,000 random ankle and gastrocnemius stiffnesses
    (others from case 1): median seconds, every call, and how many sets it bracketed."""
    from posturelab.recovery import largest_recoverable_batch

    import posturelab as pl

    n_sets = 10_000
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

    med, times, out = in_process_seconds(run, repeats)
    return med, times, int(np.count_nonzero(out.bracketed))


def frf_batch(repeats: int) -> tuple[float, list[float]]:
    """``model_frf_batch`` on 10⁶ random one-link sets at the 11 bands (bench_frequency's
    sets): median seconds and every call."""
    from bench_frequency import one_link_sets

    from posturelab.frequency.model import model_frf_batch

    body, layout, f, k, v, ka, va, tau, w = one_link_sets(1_000_000, np.random.default_rng(SEED))
    med, times, _ = in_process_seconds(
        lambda: model_frf_batch(body, layout, f, k, v, ka, va, tau, w), repeats)
    return med, times


def d_subdivision(repeats: int) -> tuple[float, list[float]]:
    """``delay_stability_map`` of examples/delay_stability_map.py (200 × 200), in this
    process: median seconds and every call."""
    sys.path.insert(0, str(ROOT / "examples"))
    try:
        import delay_stability_map as example
    finally:
        sys.path.pop(0)
    med, times, _ = in_process_seconds(lambda: example.compute(200), repeats)
    return med, times


def timed_sweep(number: str, what: str, claim: str, argv: list[str], folder: str,
                n: int) -> None:
    """Time a ``posturelab sweep`` command in fresh processes and report the time it prints
    and the whole command's [s] beside the README's claim."""
    whole, times, out = fresh_seconds(posturelab_command(argv), folder, n)
    report(number, what, claim, f"the command prints {printed_seconds(out)}; whole command "
           f"{whole:.2f} s ({spread(times)})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3,
                        help="timed runs of each statement after the warm-up (default 3)")
    parser.add_argument("--full-delay-map", action="store_true",
                        help="also run the 300 × 300 delayed three-link map once (minutes)")
    args = parser.parse_args()
    n = args.repeats

    import numpy

    print("posturelab: the README's timing statements")
    print(f"machine: {platform.platform()}; {cpu_name()}; {os.cpu_count()} CPUs; python "
          f"{platform.python_version()}; numpy {numpy.__version__}")
    print(f"{time.strftime('%Y-%m-%d %H:%M %Z')}; load average at start {load()}; "
          f"median of {n} runs after a warm-up, fresh processes for commands")
    sys.stdout.flush()
    with tempfile.TemporaryDirectory() as tmp:
        sweep = ["sweep", "--case", "1", "--disturbance", "backward", "--speed", "1",
                 "--foot", "literature", "--vary", "stiffness:ankle=300:2000:40",
                 "--vary", "disturbance_scale=0.05:1.5:30", "--out", "how-large.csv"]
        timed_sweep("1.", "how-large sweep, 1,200 runs (sweep ... --out how-large.csv)",
                    "1,200 runs in 0.3 s", sweep, tmp, n)

        seconds, times, bracketed = bisection(n)
        report("2.", "largest_recoverable_batch, 10,000 sets to 0.01 m/s",
               "about 5–6 s", f"{seconds:.2f} s ({spread(times)}; {bracketed} bracketed)")

        whole, times, out = fresh_seconds(posturelab_command(["reproduce", "--out", "paper"]),
                                          tmp, n)
        report("3.", "posturelab reproduce --out DIR", "about 9 s (7–11 s on 2026-12-01)",
               f"whole command {whole:.2f} s ({spread(times)}); it prints "
               f"{printed_seconds(out, r'done in ([0-9.]+) s')}")

        seconds, times = d_subdivision(n)
        whole, wtimes, _ = fresh_seconds(
            [sys.executable, str(ROOT / "examples" / "delay_stability_map.py"), tmp], tmp, n)
        report("4.", "D-subdivision figure (examples/delay_stability_map.py, 40,000 sets)",
               "40,000 sets in about 4 s",
               f"delay_stability_map {seconds:.2f} s ({spread(times)}); whole script with "
               f"the figure {whole:.2f} s ({spread(wtimes)})")

        seconds, times = frf_batch(n)
        report("5.", "model_frf_batch, 10⁶ one-link sets at 11 bands", "about 2 s",
               f"{seconds:.2f} s ({spread(times)})")

        prts = ["sweep", "--experiment", "prts", "--controller", "peterka-2002",
                "--tilt", "prts:0.035", "--vary", "feedback_delay=0.12:0.18:4",
                "--vary", "active_stiffness:ankle=650:850:5", "--sensor-noise", "0.001",
                "--motor-noise", "2", "--motor-noise-cutoff", "1",
                "--fit", "active_stiffness:ankle,feedback_delay", "--out", "pop.csv"]
        timed_sweep("6.", "PRTS population sweep, 20 fitted subjects (sweep --experiment "
                    "prts ...)", "the 20 fitted subjects in about 3 s", prts, tmp, n)

        resolution = 60
        dmap = ["stability-map", "--case", "1", "--feedback-delay", "0.05",
                "--x", "active_stiffness:ankle:0:1000", "--y", "active_viscosity:ankle:0:300",
                "--out", "dmap3.png"]
        whole, times, _ = fresh_seconds(
            posturelab_command([*dmap, "--resolution", str(resolution)]), tmp, n,
            warm_up=False)
        per_set = whole / resolution**2
        measured = (f"{resolution} × {resolution} whole command {whole:.1f} s ({spread(times)}"
                    f"), {1e3 * per_set:.1f} ms a set: 300 × 300 ≈ "
                    f"{per_set * 300**2 / 60:.1f} min (scaled)")
        if args.full_delay_map:
            full, _, out = fresh_seconds(posturelab_command([*dmap, "--resolution", "300"]),
                                         tmp, 1, warm_up=False)
            said = re.search(r"about ([0-9]+ (?:min|s)) in all", out)
            measured += (f"; 300 × 300 run once: {full / 60:.1f} min (it said "
                         f"{said.group(1) if said else 'nothing'} up front)")
        report("7.", "delayed stability map, three links (stability-map --case 1 "
               "--feedback-delay 0.05 --x active_stiffness:ankle --y active_viscosity:ankle)",
               "300 × 300 takes about 5 min for three links", measured)
    print(f"load average at end: {load()}")


if __name__ == "__main__":
    main()
