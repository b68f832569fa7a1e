"""Benchmark of the simulation engines and of the whole commands, in one run.

Run it as a script (not a test): ``python benchmarks/bench_simulate.py``. It prints

1. one 5 s run of the paper's case 1 backward (``paper-backward-case1``, rtol 1e-6, atol
   1e-9, 1 kHz samples): a plain baseline (scipy ``solve_ivp`` RK45 with a hand-written
   numpy right-hand side), a second baseline (the same with posturelab's public numpy
   functions), and the compiled engine with each integrator, its speed-up against both,
   and its largest angle error against a tight reference (DOP853, rtol 1e-10);
2. ``simulate_batch`` of 10,000 runs with random gains, against the baseline per run;
3. delayed feedback: case 1 with τ = 10 ms for 5 s (it survives, oscillating near
   90 Hz) on the reference engine and on the compiled engine at the same tolerances,
   and a delayed batch (1,000 runs, τ from 0 to 50 ms) against the reference engine's
   time per run measured on a sample; 3b. a tilt experiment (one link, intrinsic and
   delayed active gains, Peterka's PRTS for 40 s) on both engines, and a batch of 1,000
   over the active stiffness against the reference per run;
4. start-up and whole commands in fresh processes (median of 3, warm): ``import
   posturelab``, ``posturelab --help``, ``stability-map`` at resolution 1000, the
   README's ``sweep`` of 10,000 runs and ``reproduce``;
5. compilation: building the C engine from its sources (what ``pip install`` does once),
   the first compiled run in a fresh process, and the numba kernels of ``stability-map``
   from an empty cache and from the cache;
6. the targets, met or not.

Environment: ``BENCH_QUICK=1`` shortens every part (for a smoke test). The PRTS experiment
of 3b against jitcdde at equal accuracy is ``bench_prts.py``.
"""

from __future__ import annotations

import os
import platform
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time

import numpy as np
from scipy.integrate import solve_ivp

QUICK = os.environ.get("BENCH_QUICK", "") not in ("", "0")
N_BATCH = 1_000 if QUICK else 10_000
N_DELAYED_BATCH = 200 if QUICK else 1_000
DELAY = 0.01  # [s]
REPEATS_COMMAND = 1 if QUICK else 3
N_SAMPLE = 4 if QUICK else 12  # batch runs checked against the reference
REPEATS_BASELINE = 3 if QUICK else 7
REPEATS_FAST = 20 if QUICK else 100
REPEATS_BATCH = 1 if QUICK else 3
SEED = 20261122
RTOL = 1e-6
REF_RTOL, REF_ATOL = 1e-10, 1e-12


def wall_times(fn, repeats: int) -> list[float]:
    """Wall times of ``repeats`` calls of ``fn()`` after one warm-up call. [s]"""
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return times


def median_time(fn, repeats: int) -> float:
    """Median wall time of ``fn()`` over ``repeats`` calls after one warm-up call. [s]"""
    return statistics.median(wall_times(fn, repeats))


def numpy_rhs(body, muscles):
    """A plain numpy right-hand side: J(Θ)Θ̈ = U − B(Θ, Θ̇)Θ̇ + g G(Θ) (no platform motion)."""
    n = body.n_links
    E = muscles.selection_matrix
    kd, ld = muscles.stiffnesses, muscles.viscosities
    a, coupling, jdiag, g = (body.gravity_coefficients, body.coupling, body.inertia_diagonal,
                             body.gravity)

    def rhs(t, x):
        theta, omega = x[:n], x[n:]
        diff = theta[:, None] - theta[None, :]  # θ_i − θ_j
        J = coupling * np.cos(diff)
        J[np.arange(n), np.arange(n)] = jdiag
        B = (coupling * np.sin(diff)) @ omega**2
        U = -E.T @ (kd * (E @ theta) + ld * (E @ omega))
        acc = np.linalg.solve(J, U - B + g * a * np.sin(theta))
        return np.concatenate([omega, acc])

    return rhs


def public_rhs(body, muscles):
    """The right-hand side from posturelab's public numpy functions."""
    import posturelab

    n = body.n_links

    def rhs(t, x):
        return posturelab.state_derivative(
            body, x, posturelab.joint_torques(muscles, x[:n], x[n:]))

    return rhs


def subprocess_seconds(code: str, env: dict) -> dict:
    """Run ``code`` in a fresh interpreter; it prints 'key=value' lines of seconds."""
    out = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], env=env, check=True,
                         capture_output=True, text=True, timeout=900).stdout
    values = {}
    for line in out.splitlines():
        if "=" in line:
            k, v = line.split("=", 1)
            values[k.strip()] = float(v)
    return values


FIRST_CALL = """
    import time
    t0 = time.perf_counter()
    import numpy as np
    import posturelab as pl
    from posturelab.simulation.compiled import simulate_batch
    t1 = time.perf_counter()
    sc = pl.builtin_scenario("paper-backward-case1")
    pl.simulate(sc.body, sc.muscles, sc.disturbance, sc.duration,
                initial_state=sc.initial_state, engine="compiled")
    t2 = time.perf_counter()
    k = np.asarray(sc.muscles.stiffnesses)[None, :]
    simulate_batch(sc.body, k, 0.25 * k, sc.disturbance, 0.1, sc.initial_state)
    t3 = time.perf_counter()
    print("import =", t1 - t0)
    print("first_run =", t2 - t1)
    print("first_batch =", t3 - t2)
    print("total =", t3 - t0)
"""

STABILITY_MAP_KERNELS = """
    import time
    t0 = time.perf_counter()
    from posturelab.linear import batch
    t1 = time.perf_counter()
    batch.stability_map(("stiffness:ankle", 0.0, 2000.0), ("stiffness:gastrocnemius", 0.0, 1000.0),
                        8)
    t2 = time.perf_counter()
    print("import =", t1 - t0)
    print("first_map =", t2 - t1)
"""


def command_seconds(args: list[str], repeats: int, cwd: str) -> float:
    """Median wall time of ``posturelab ARGS`` in a fresh process (after one warm-up). [s]"""
    exe = os.path.join(os.path.dirname(sys.executable), "posturelab")
    cmd = [exe, *args] if os.path.exists(exe) else [sys.executable, "-m", "posturelab", *args]
    subprocess.run(cmd, check=True, capture_output=True, cwd=cwd, timeout=900)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True, cwd=cwd, timeout=900)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def c_build_seconds() -> float:
    """Seconds to compile the C engine from its sources with the build's compiler and flags
    (what ``pip install`` does once; the extension itself is not replaced). [s]"""
    import sysconfig

    import posturelab.simulation.compiled as compiled
    from posturelab.simulation.compiled._sources import COMPILE_FLAGS

    csrc = os.path.join(os.path.dirname(compiled.__file__), "csrc")
    flags = list(COMPILE_FLAGS)
    cc = (sysconfig.get_config_var("CC") or "cc").split()
    include = sysconfig.get_paths()["include"]
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "engine.so")
        t0 = time.perf_counter()
        subprocess.run([*cc, "-shared", "-fPIC", *flags, f"-I{csrc}", f"-I{include}",
                        os.path.join(csrc, "pl_engine.c"), "-o", out, "-lm"], check=True,
                       capture_output=True, timeout=600)
        return time.perf_counter() - t0


def _cpu_name() -> str:
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def main() -> int:
    import posturelab as pl
    from posturelab.model.muscles import paper_muscles
    from posturelab.model.platform import VelocityStep
    from posturelab.scenarios import builtin_scenario
    from posturelab.simulation.compiled import (
        DEFAULT_ATOL,
        batch_threads,
        simulate_batch,
        simulate_fast,
    )
    from posturelab.simulation.setup import initial_state_for

    print("posturelab simulation benchmark" + (" (BENCH_QUICK)" if QUICK else ""))
    print(f"machine: {platform.platform()}; {_cpu_name()}; {os.cpu_count()} CPUs "
          f"({batch_threads()} batch threads); numpy {np.__version__}; "
          f"python {platform.python_version()}")

    # ---- 1. the single case ---------------------------------------------------------------
    sc = builtin_scenario("paper-backward-case1")
    body, muscles, dist = sc.body, sc.muscles, sc.disturbance
    duration = sc.duration
    ref = pl.simulate(body, muscles, dist, duration, initial_state=sc.initial_state,
                      rtol=REF_RTOL, atol=REF_ATOL, engine="reference")
    x0 = initial_state_for(body, dist, sc.initial_state, sc.rates_from)
    rhs = numpy_rhs(body, muscles)
    grid = ref.time

    def baseline():
        return solve_ivp(rhs, (0.0, duration), x0, method="RK45", rtol=RTOL, atol=DEFAULT_ATOL,
                         t_eval=grid)

    rhs_public = public_rhs(body, muscles)

    def baseline_public():
        return solve_ivp(rhs_public, (0.0, duration), x0, method="RK45", rtol=RTOL,
                         atol=DEFAULT_ATOL, t_eval=grid)

    def fast(method="Radau"):
        return simulate_fast(body, muscles, dist, duration, initial_state=sc.initial_state,
                             rtol=RTOL, method=method)

    def fast_all_series():
        res = fast()
        for name in ("pair_torques", "joint_torques", "joint_moments", "cog_position",
                     "cog_velocity", "platform_acceleration", "platform_velocity",
                     "platform_position", "angular_acceleration", "ground_reaction",
                     "centre_of_pressure"):
            getattr(res, name)
        return res

    t_base = median_time(baseline, REPEATS_BASELINE)
    err_base = float(np.max(np.abs(baseline().y[: body.n_links].T - ref.theta)))
    t_pub = median_time(baseline_public, REPEATS_BASELINE)
    err_pub = float(np.max(np.abs(baseline_public().y[: body.n_links].T - ref.theta)))
    t_fast = median_time(fast, REPEATS_FAST)
    err_fast = float(np.max(np.abs(fast().theta - ref.theta)))
    t_all = median_time(fast_all_series, REPEATS_FAST)
    t_fast45 = median_time(lambda: fast("RK45"), REPEATS_FAST)
    err_fast45 = float(np.max(np.abs(fast("RK45").theta - ref.theta)))
    t_fast23 = median_time(lambda: fast("RK23"), REPEATS_FAST)
    err_fast23 = float(np.max(np.abs(fast("RK23").theta - ref.theta)))

    # ---- 2. the batch ---------------------------------------------------------------------
    rng = np.random.default_rng(SEED)
    stiffness = np.empty((N_BATCH, 5))
    stiffness[:, 0] = rng.uniform(400.0, 1500.0, N_BATCH)
    stiffness[:, 1:] = rng.uniform(0.0, 600.0, (N_BATCH, 4))
    viscosity = 0.25 * stiffness
    step = VelocityStep.backward(1.0)
    posture = sc.initial_state  # the paper's initial posture, at rest before the step

    def batch():
        return simulate_batch(body, stiffness, viscosity, step, duration, posture, rtol=RTOL)

    t_batch = median_time(batch, REPEATS_BATCH)
    out = batch()
    sample = rng.choice(N_BATCH, size=N_SAMPLE, replace=False)
    err_batch = 0.0
    identical = True
    for r in sample:
        m = paper_muscles(stiffness=stiffness[r], viscosity=viscosity[r])
        one = simulate_fast(body, m, step, duration, initial_state=posture, rtol=RTOL)
        identical &= bool(np.array_equal(one.max_abs_theta, out.peak_theta[r])
                          and np.array_equal(one.final_state, out.final_state[r])
                          and one.fell == out.fell[r])
        reference = pl.simulate(body, m, step, duration, initial_state=posture,
                                rtol=REF_RTOL, atol=REF_ATOL, engine="reference")
        k = min(one.time.size, reference.time.size)
        err_batch = max(err_batch, float(np.max(np.abs(one.theta[:k] - reference.theta[:k]))))

    # ---- 3. delayed feedback -----------------------------------------------------------------
    tol = {"rtol": RTOL, "atol": DEFAULT_ATOL}

    def delayed(engine, delay=DELAY, k=None):
        mus = muscles if k is None else paper_muscles(stiffness=k, viscosity=0.25 * k)
        return pl.simulate(body, mus, dist, duration, initial_state=sc.initial_state,
                           feedback_delay=delay, engine=engine, **tol)

    t0 = time.perf_counter()
    ref_delayed = delayed("reference")
    t_ref_delayed = time.perf_counter() - t0
    t_fast_delayed = median_time(lambda: delayed("compiled"), REPEATS_FAST // 2)
    fast_delayed = delayed("compiled")
    delays = np.linspace(0.0, 0.05, N_DELAYED_BATCH)
    k_delayed = np.tile(np.asarray(muscles.stiffnesses), (N_DELAYED_BATCH, 1))
    k_delayed[:, 0] = rng.uniform(400.0, 1500.0, N_DELAYED_BATCH)

    def delayed_batch():
        return simulate_batch(body, k_delayed, 0.25 * k_delayed, dist, duration, posture,
                              feedback_delay=delays, **tol)

    t_delayed_batch = median_time(delayed_batch, REPEATS_BATCH)
    ref_sample = rng.choice(N_DELAYED_BATCH, size=3 if QUICK else 6, replace=False)
    t0 = time.perf_counter()
    for r in ref_sample:
        delayed("reference", float(delays[r]), k_delayed[r])
    t_ref_per_run = (time.perf_counter() - t0) / ref_sample.size

    # ---- 3b. a tilt experiment: intrinsic + delayed active feedback under a PRTS tilt --------
    from posturelab.model.controllers import get_controller
    from posturelab.model.tilt import PRTSTilt

    body1 = pl.get_body("paper-1link")
    preset = get_controller("icm-pmc5664365")
    m1 = preset.muscles(body1)
    prts = PRTSTilt.named("posturelab-80", 0.035)
    tilt_duration = 20.0 if QUICK else 40.0

    def tilted(engine, ka=None):
        mus = m1 if ka is None else m1.with_active_feedback([ka], m1.active_viscosities)
        return pl.simulate(body1, mus, None, tilt_duration, tilt=prts, engine=engine,
                           sample_rate=100.0, **tol, **preset.run_options())

    t0 = time.perf_counter()
    ref_tilted = tilted("reference")
    t_ref_tilted = time.perf_counter() - t0
    t_fast_tilted = median_time(lambda: tilted("compiled"), REPEATS_FAST // 4)
    fast_tilted = tilted("compiled")
    d_tilted = float(np.max(np.abs(ref_tilted.theta - fast_tilted.theta)))
    n_tilted = N_DELAYED_BATCH
    ka_tilted = rng.uniform(0.9, 1.9, n_tilted) * body1.load_stiffness

    def tilted_batch():
        k1 = np.tile(m1.stiffnesses, (n_tilted, 1))
        return simulate_batch(body1, k1, np.tile(m1.viscosities, (n_tilted, 1)), None,
                              tilt_duration, muscles=m1, active_stiffness=ka_tilted[:, None],
                              active_viscosity=np.tile(m1.active_viscosities, (n_tilted, 1)),
                              tilt=prts, sample_rate=100.0, **tol, **preset.run_options())

    t_tilted_batch = median_time(tilted_batch, REPEATS_BATCH)
    t0 = time.perf_counter()
    tilt_sample = rng.choice(n_tilted, size=2 if QUICK else 4, replace=False)
    for r in tilt_sample:
        tilted("reference", float(ka_tilted[r]))
    t_ref_tilt_run = (time.perf_counter() - t0) / tilt_sample.size

    # ---- 4. start-up and whole commands -------------------------------------------------------
    startup = {}
    for label, code in (("import posturelab", "import posturelab"),
                        ("import posturelab.cli", "import posturelab.cli")):
        times = []
        for _ in range(REPEATS_COMMAND + 2):
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-c", code], check=True, timeout=120)
            times.append(time.perf_counter() - t0)
        startup[label] = statistics.median(times)
    with tempfile.TemporaryDirectory(prefix="posturelab-bench-") as tmp:
        commands = {
            "posturelab --help": command_seconds(["--help"], REPEATS_COMMAND, tmp),
            "stability-map, resolution 1000": command_seconds(
                ["stability-map", "--x", "stiffness:ankle:0:2000", "--y",
                 "stiffness:gastrocnemius:0:1000",
                 "--resolution", "1000", "--out", "map.png"], REPEATS_COMMAND, tmp),
            "sweep, 10,000 runs (README)": command_seconds(
                ["sweep", "--case", "1", "--disturbance", "backward", "--duration", "5",
                 "--vary", "stiffness:ankle=0:2000:100",
                 "--vary", "stiffness:gastrocnemius=0:1000:100",
                 "--out", "sweep.csv"], REPEATS_COMMAND, tmp),
            "reproduce": command_seconds(["reproduce", "--out", "paper-out"],
                                         1 if QUICK else 2, tmp),
        }

    # ---- 5. compilation -------------------------------------------------------------------------
    env = dict(os.environ)
    t_c_build = c_build_seconds()
    first = subprocess_seconds(FIRST_CALL, env)
    with tempfile.TemporaryDirectory(prefix="posturelab-numba-cache-") as cache:
        numba_cold = subprocess_seconds(STABILITY_MAP_KERNELS, {**env, "NUMBA_CACHE_DIR": cache})
    numba_cached = subprocess_seconds(STABILITY_MAP_KERNELS, env)

    # ---- report ---------------------------------------------------------------------------------
    per_run = t_batch / N_BATCH
    rows = [
        ("scipy RK45 + numpy RHS (baseline)", t_base, 1.0, err_base),
        ("scipy RK45 + posturelab's public numpy functions", t_pub, t_base / t_pub, err_pub),
        ("compiled engine (one run, default: Radau)", t_fast, t_base / t_fast, err_fast),
        ("  the same, then reading every derived series", t_all, t_base / t_all, err_fast),
        ("compiled engine (one run, method='RK45')", t_fast45, t_base / t_fast45, err_fast45),
        ("compiled engine (one run, method='RK23')", t_fast23, t_base / t_fast23, err_fast23),
        (f"simulate_batch ({N_BATCH} runs)", t_batch, t_base * N_BATCH / t_batch, err_batch),
    ]
    print()
    print(f"1-2. case: paper-backward-case1, {duration:g} s, rtol {RTOL:g}, atol "
          f"{DEFAULT_ATOL:g} (engine and baselines); reference DOP853 rtol {REF_RTOL:g} atol "
          f"{REF_ATOL:g}")
    print(f"{'':52}{'median':>12}{'speed-up':>11}{'vs public':>11}{'max |Δθ|':>11}")
    for label, t, ratio, err in rows:
        pub = ratio * t_pub / t_base
        print(f"{label:52}{t * 1e3:>9.3f} ms{ratio:>10.{0 if ratio >= 10 else 2}f}×"
              f"{pub:>10.{0 if pub >= 10 else 2}f}×{err:>11.2e}")
    print(f"  batch: {per_run * 1e6:.1f} µs per run on {batch_threads()} threads; "
          f"{int(out.fell.sum())} of {N_BATCH} runs fell; errors on {N_SAMPLE} random runs; "
          f"batch == single runs bit for bit: {'yes' if identical else 'NO'}")
    n = min(ref_delayed.time.size, fast_delayed.time.size)
    d_delayed = float(np.max(np.abs(ref_delayed.theta[:n] - fast_delayed.theta[:n])))
    print()
    print(f"3. delayed feedback, τ = {DELAY * 1e3:g} ms, case 1 backward, {duration:g} s, both "
          f"engines at rtol {RTOL:g}, atol {DEFAULT_ATOL:g} ({fast_delayed.status} / "
          f"{ref_delayed.status}; the two differ by {d_delayed:.1e} rad: the delayed model "
          "oscillates and amplifies errors)")
    print(f"   reference engine (scipy DOP853, method of steps)   {t_ref_delayed:9.3f} s")
    print(f"   compiled engine (default for a delay: RK45)        {t_fast_delayed * 1e3:9.3f} ms"
          f"   {t_ref_delayed / t_fast_delayed:7.0f}×")
    print(f"   compiled batch, {N_DELAYED_BATCH} runs, τ 0–50 ms       "
          f"{t_delayed_batch:9.3f} s    {t_ref_per_run * N_DELAYED_BATCH / t_delayed_batch:7.0f}× "
          f"(reference {t_ref_per_run:.2f} s per run on {ref_sample.size} of them)")
    print()
    print(f"3b. tilt experiment: one link ({preset.name}: intrinsic + active gains, τ = "
          f"{preset.feedback_delay:g} s, W = {preset.proprioceptive_weight:g}), Peterka's PRTS "
          f"0.035 rad peak to peak, {tilt_duration:g} s ({fast_tilted.status} / "
          f"{ref_tilted.status}; engines differ by {d_tilted:.1e} rad)")
    print(f"   reference engine                                    {t_ref_tilted:9.3f} s")
    print(f"   compiled engine                                     {t_fast_tilted * 1e3:9.3f} ms"
          f"   {t_ref_tilted / t_fast_tilted:7.0f}×")
    print(f"   compiled batch, {n_tilted} runs, K_a 0.9–1.9 mgh     {t_tilted_batch:9.3f} s    "
          f"{t_ref_tilt_run * n_tilted / t_tilted_batch:7.0f}× (reference "
          f"{t_ref_tilt_run:.2f} s per run on {tilt_sample.size} of them)")
    print()
    print("4. start-up and whole commands (fresh processes, warm, medians)")
    for label, t in {**startup, **commands}.items():
        print(f"   {label:40}{t:8.2f} s")
    print()
    print("5. compilation")
    print(f"   C engine from its sources (pip install does this once)   {t_c_build:6.2f} s")
    print(f"   fresh process: import {first['import']:.2f} s + first compiled run "
          f"{first['first_run']:.3f} s + first batch {first['first_batch']:.3f} s "
          "(nothing is compiled at run time)")
    print(f"   stability-map's numba kernels: cold (empty cache) {numba_cold['first_map']:.2f} s;"
          f" cached {numba_cached['first_map']:.2f} s (import {numba_cached['import']:.2f} s)")
    print()

    def met(ok: bool) -> str:
        return "met" if ok else "NOT met"

    cold = max(t_c_build, numba_cold["first_map"] + numba_cold["import"])
    print("6. targets: "
          f"one run >= 500× baseline: {met(t_base / t_fast >= 500)} ({t_base / t_fast:.0f}×); "
          f"delayed run >= 500× the reference's: "
          f"{met(t_ref_delayed / t_fast_delayed >= 500)} "
          f"({t_ref_delayed / t_fast_delayed:.0f}×); "
          f"cold start <= 20 s: {met(cold <= 20)} ({cold:.1f} s); "
          f"stability-map <= 1.5 s: "
          f"{met(commands['stability-map, resolution 1000'] <= 1.5)}; "
          f"sweep <= 1.5 s: {met(commands['sweep, 10,000 runs (README)'] <= 1.5)}; "
          f"reproduce <= 10 s: {met(commands['reproduce'] <= 10)}; "
          f"errors <= 1e-6 rad: "
          f"{met(max(err_fast, err_fast45, err_fast23, err_batch) <= 1e-6)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
