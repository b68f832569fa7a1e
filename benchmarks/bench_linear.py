"""Benchmark: batched linear analysis (posturelab.linear) against plain baselines.

Run:  python benchmarks/bench_linear.py [--sets 1000000] [--repeats 7]

Everything is measured in this one run on this machine:

* the batched stable flags (Routh–Hurwitz) and all poles (Aberth–Ehrlich) of
  ``--sets`` random parameter sets of the paper model, median of ``--repeats``; and
  the stability map of the command's plane with about as many sets (each set's roots
  started from its neighbour's);
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
  warm, median of 3 after one warm-up run (``--skip-command`` leaves it out), against
  numpy eigvals of the same number of sets (``--command-runs``; ``--compare-source SRC``
  interleaves each run with one of another checkout's ``src`` and compares their outputs
  byte for byte; ``--command-only`` times just this, against the baseline on
  ``--baseline-sets``); and where its time goes: a fresh process
  that times each phase in turn (interpreter start, start-up, loading the kernels, the map,
  the CSV, matplotlib, the PNG and the interpreter's exit; the command overlaps the map
  with matplotlib's import and the CSV with the PNG);
* batched delay margins (``posturelab.linear.batch_delay_margin``: the closed form for
  one link, the delay pencil for three) against the single-set ``delay_margin`` on a
  subset of the same sets (``--margin-baseline-sets``), with the largest relative
  difference between the two (``--skip-margins`` leaves it out). Goals: >= 1e5
  one-link and >= 1e4 three-link sets per second.

Random sets: each pair stiffness uniform in [0, 1500] N·m/rad, 15 % of them
set to 0 (pairs switched off, as in Table I); viscosity ratio uniform in
[0.02, 0.6] s; seed 12345.
"""

from __future__ import annotations

import argparse
import filecmp
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

from posturelab.linear import batch as batch_linear
from posturelab.linear import batch_delay_margin, sorted_poles
from posturelab.linear.delay import delay_margin
from posturelab.model.body import get_body, paper_body
from posturelab.model.dynamics import mass_matrix
from posturelab.model.muscles import MusclePair, MuscleSet, paper_muscles

FIRST_CALL = (
    "import time; t0 = time.perf_counter(); import numpy as np; "
    "from posturelab.linear.batch import batch_analyse, batch_stable; "
    "t1 = time.perf_counter(); "
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


#: The axes of the map the command draws (COMMAND). [N·m/rad]
MAP_AXES = (("stiffness:ankle", 0.0, 2000.0), ("stiffness:gastrocnemius", 0.0, 1000.0))

COMMAND = ["stability-map", "--x", "stiffness:ankle:0:2000", "--y",
           "stiffness:gastrocnemius:0:1000",
           "--resolution", "1000"]
COMMAND_SETS = 1000 * 1000


def command_times(runs: int, other_source: str | None = None) -> tuple[list, list]:
    """Wall and CPU time (user + system) of ``posturelab stability-map`` (COMMAND) in fresh
    processes, after one untimed warm-up run (which fills the numba cache if needed). [s]

    With ``other_source`` (the ``src`` folder of another checkout), each run is followed by
    one of that checkout's command, and each list holds pairs (this, other)."""
    sources = [None] if other_source is None else [None, other_source]
    wall, cpu = [], []
    with tempfile.TemporaryDirectory(prefix="posturelab-map-") as folder:
        for i in range(runs + 1):
            pair_wall, pair_cpu = [], []
            for k, source in enumerate(sources):
                env = dict(os.environ)
                if source is not None:
                    env["PYTHONPATH"] = source
                argv = [sys.executable, "-m", "posturelab", *COMMAND, "--out",
                        os.path.join(folder, f"map{k}.png")]
                used = resource.getrusage(resource.RUSAGE_CHILDREN)
                t = time.perf_counter()
                subprocess.run(argv, capture_output=True, text=True, check=True, env=env)
                pair_wall.append(time.perf_counter() - t)
                now = resource.getrusage(resource.RUSAGE_CHILDREN)
                pair_cpu.append(now.ru_utime + now.ru_stime - used.ru_utime - used.ru_stime)
            if i:
                wall.append(pair_wall if other_source else pair_wall[0])
                cpu.append(pair_cpu if other_source else pair_cpu[0])
        if other_source is not None:
            for suffix in (".png", ".csv"):
                same = filecmp.cmp(os.path.join(folder, "map0" + suffix),
                                   os.path.join(folder, "map1" + suffix), shallow=False)
                print(f"  {suffix[1:].upper()} of this checkout and of {other_source}: "
                      f"{'identical' if same else 'DIFFERENT'} bytes")
    return wall, cpu


#: A fresh process timing each phase of the stability-map command in turn, as the command
#: does them (numba's BLAS probe skipped when loading the kernels, the float32 image, the
#: collector frozen before exit). [s]
PHASES = """
import gc, io, sys, time
w0 = time.time()
t0 = time.perf_counter()
import posturelab.cli.stability_map as command
from posturelab.linear.batch import stability_map
from posturelab._jit import skip_blas_probe
t1 = time.perf_counter()
skip_blas_probe()
x, y = ("stiffness:ankle", 0, 2000), ("stiffness:gastrocnemius", 0, 1000)
stability_map(x, y, 2).write_csv(io.StringIO())
t2 = time.perf_counter()
smap = stability_map(x, y, 1000)
t3 = time.perf_counter()
with open(sys.argv[1] + ".csv", "w", encoding="utf-8", newline="") as stream:
    smap.write_csv(stream)
t4 = time.perf_counter()
command._import_plotting()
from posturelab.viz.maps import plot_stability_map
t5 = time.perf_counter()
with open(sys.argv[1] + ".png", "wb") as stream:
    plot_stability_map(smap).savefig(stream, format="png", dpi=150)
t6 = time.perf_counter()
print(w0, t1 - t0, t2 - t1, t3 - t2, t4 - t3, t5 - t4, t6 - t5, time.time(), flush=True)
gc.freeze()
"""
PHASE_NAMES = ("interpreter start", "start-up (imports)", "loading the compiled kernels",
               "the map (10⁶ sets)", "the CSV", "importing matplotlib", "the PNG",
               "exit (interpreter teardown)")


def phase_times(runs: int) -> list[list[float]]:
    """Each phase of the command, in fresh processes (PHASES), ``runs`` times. [s]"""
    out = []
    with tempfile.TemporaryDirectory(prefix="posturelab-phases-") as folder:
        for _ in range(runs):
            launched = time.time()
            proc = subprocess.run([sys.executable, "-c", PHASES, os.path.join(folder, "m")],
                                  capture_output=True, text=True, check=True)
            ended = time.time()
            w0, *inner, w_end = (float(v) for v in proc.stdout.split())
            out.append([w0 - launched, *inner, ended - w_end])
    return out


def startup_time(runs: int) -> float:
    """Median wall time of ``python -c "import posturelab.cli"`` in a fresh process. [s]"""
    times = []
    for _ in range(runs):
        t = time.perf_counter()
        subprocess.run([sys.executable, "-c", "import posturelab.cli"], check=True)
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def margin_sets(count: int, n_links: int, seed: int = 2024) -> dict:
    """Random gain sets with an intrinsic and an active (delayed) part: three links, the
    paper's five pairs (stiffness uniform in [0, 1500] N·m/rad, viscosity 0.25 s of it;
    active stiffness in [0, 1500], active viscosity 0.3 s of it); one link, an ankle pair
    (active stiffness in [0.5, 3] mgh, active viscosity in [0, 600] N·m·s/rad, a small
    intrinsic part)."""
    rng = np.random.default_rng(seed)
    if n_links == 3:
        k = rng.uniform(0.0, 1500.0, (count, 5))
        ka = rng.uniform(0.0, 1500.0, (count, 5))
        return dict(stiffness=k, viscosity=0.25 * k, active_stiffness=ka,
                    active_viscosity=0.3 * ka)
    mgh = get_body("paper-1link").load_stiffness
    ki = rng.uniform(0.0, 0.2, (count, 1)) * mgh
    return dict(stiffness=ki, viscosity=0.1 * ki,
                active_stiffness=rng.uniform(0.5, 3.0, (count, 1)) * mgh,
                active_viscosity=rng.uniform(0.0, 600.0, (count, 1)))


def one_set(n_links: int, gains: dict, i: int) -> MuscleSet:
    if n_links == 3:
        return paper_muscles(**{name: value[i] for name, value in gains.items()})
    return MuscleSet((MusclePair("ankle", 0, 1, gains["stiffness"][i, 0],
                                 gains["viscosity"][i, 0],
                                 active_stiffness=gains["active_stiffness"][i, 0],
                                 active_viscosity=gains["active_viscosity"][i, 0]),), 1)


def margin_rows(repeats: int, baseline_sets: int) -> None:
    """Batched delay margins against the single-set delay_margin (module notes)."""
    print()
    print(f"batched delay margins, median of {repeats} (interleaved); baseline: "
          f"delay_margin one set at a time on {baseline_sets} of the sets")
    head = (f"{'bodies':<34}{'sets':>9}{'batched [sets/s]':>18}{'single [sets/s]':>17}"
            f"{'speed-up':>10}{'max rel. diff':>15}  goal")
    print(head)
    print("-" * len(head))
    for n_links, count, goal in ((1, 100_000, 1e5), (3, 10_000, 1e4)):
        body = get_body("paper-1link") if n_links == 1 else paper_body()
        layout = one_set(n_links, margin_sets(1, n_links), 0)
        gains = margin_sets(count, n_links)
        nb = min(baseline_sets, count)
        batch_delay_margin(body, layout, **{k: v[:10] for k, v in gains.items()})

        def single(nb=nb, body=body, gains=gains, n_links=n_links):
            return [delay_margin(body, one_set(n_links, gains, i)) for i in range(nb)]

        medians, results = median_times({
            "batched": lambda body=body, layout=layout, gains=gains:
                batch_delay_margin(body, layout, **gains),
            "single": single,
        }, repeats)
        out, ref = results["batched"], results["single"]
        diff = 0.0
        for i, d in enumerate(ref):
            if d.stable_without_delay and np.isfinite(d.delay_margin):
                diff = max(diff, abs(out.delay_margin[i] / d.delay_margin - 1),
                           abs(out.crossing_frequency[i] / d.crossing_frequency - 1))
        rate, base = count / medians["batched"], nb / medians["single"]
        label = "one link (closed form)" if n_links == 1 else "three links (delay pencil)"
        print(f"{label:<34}{count:>9,}{rate:>18,.0f}{base:>17,.0f}{rate / base:>9.0f}×"
              f"{diff:>15.1e}  >= {goal:,.0f}/s: {'ok' if rate >= goal else 'MISSED'}")


def command_rows(args, t_base: float) -> None:
    """Time the whole command (against ``--compare-source`` if given, interleaved) and its
    phases; ``t_base`` is the numpy baseline's time for ``--sets`` sets. [s]"""
    if args.compare_source:
        walls, cpus = command_times(args.command_runs, args.compare_source)
        this = [w[0] for w in walls]
        note = (f"  interleaved with {args.compare_source}, {args.command_runs} pairs: "
                f"wall {statistics.median(this):.3f} s against "
                f"{statistics.median(w[1] for w in walls):.3f} s (median ratio "
                f"{statistics.median(w[0] / w[1] for w in walls):.2f}), CPU "
                f"{statistics.median(c[0] for c in cpus):.3f} s against "
                f"{statistics.median(c[1] for c in cpus):.3f} s (median ratio "
                f"{statistics.median(c[0] / c[1] for c in cpus):.2f})")
    else:
        this, cpus = command_times(args.command_runs)
        note = f"  CPU (user + system) median {statistics.median(cpus):.3f} s"
    t_cmd = statistics.median(this)
    base_cmd = t_base * COMMAND_SETS / args.sets  # the baseline for as many sets
    print(f"{'stability-map command, resolution 1000 (warm, whole)':<56}{t_cmd:>11.3f}"
          f"{1e6 * t_cmd / COMMAND_SETS:>14.3f}{base_cmd / t_cmd:>9.1f}×"
          f"   (goal 1.5 s: {'ok' if t_cmd <= 1.5 else 'MISSED'})")
    print(note)
    phases = np.median(np.array(phase_times(3)), axis=0)
    print(f"  where it goes (each phase in turn, fresh processes, median of 3; "
          f"python -c 'import posturelab.cli' alone: {startup_time(3):.2f} s):")
    for name, t in zip(PHASE_NAMES, phases, strict=True):
        print(f"    {name:<34}{t:>7.3f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", type=int, default=1_000_000)
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--baseline-sets", type=int, default=20_000)
    parser.add_argument("--skip-compile", action="store_true",
                        help="skip the cold-compile / cached-load subprocess timings")
    parser.add_argument("--skip-command", action="store_true",
                        help="skip timing the whole stability-map command")
    parser.add_argument("--skip-margins", action="store_true",
                        help="skip the batched delay margins")
    parser.add_argument("--margin-baseline-sets", type=int, default=40)
    parser.add_argument("--command-runs", type=int, default=3,
                        help="timed runs of the whole stability-map command (default 3)")
    parser.add_argument("--command-only", action="store_true",
                        help="time only the whole stability-map command (and its phases), "
                        "against the numpy baseline on --baseline-sets")
    parser.add_argument("--compare-source", metavar="SRC",
                        help="the src folder of another checkout (e.g. `git archive REV src | "
                        "tar -x -C DIR`, then DIR/src): its stability-map command is timed "
                        "interleaved with this one's, and their outputs compared")
    args = parser.parse_args()

    print(f"machine: {machine()}")
    print(f"load average at start: {', '.join(f'{v:.2f}' for v in os.getloadavg())}")

    if args.command_only:
        stiffness, ratio = random_sets(args.baseline_sets)
        medians, _ = median_times({"baseline": lambda: baseline(stiffness, ratio)},
                                  args.repeats)
        command_rows(args, medians["baseline"] * args.sets / args.baseline_sets)
        print(f"load average at end: {', '.join(f'{v:.2f}' for v in os.getloadavg())}")
        return

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

    map_resolution = max(2, round(args.sets ** 0.5))  # a map of about as many sets
    batch_linear.stability_map(*MAP_AXES, 2)
    nb = min(args.baseline_sets, args.sets)
    scale = args.sets / nb
    medians, results = median_times({
        "baseline": lambda: baseline(stiffness[:nb], ratio[:nb]),
        "stable": lambda: batch_linear.batch_stable(stiffness, ratio),
        "max": lambda: batch_linear.batch_analyse(stiffness, ratio),
        "poles": lambda: batch_linear.batch_analyse(stiffness, ratio, keep_poles=True),
        "map": lambda: batch_linear.stability_map(*MAP_AXES, map_resolution),
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
    t_map, map_sets = medians["map"], map_resolution ** 2
    print(f"{f'stability_map {map_resolution}², roots warm-started':<56}{t_map:>11.3f}"
          f"{1e6 * t_map / map_sets:>14.3f}{t_base * map_sets / args.sets / t_map:>9.1f}×")
    if not args.skip_command:
        command_rows(args, t_base)
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
    if not args.skip_margins:
        margin_rows(args.repeats, args.margin_baseline_sets)
    print(f"load average at end: {', '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
