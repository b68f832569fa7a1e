"""Benchmark of the compiled simulator (posturelab.fast) against a plain scipy baseline.

Run it as a script (not a test): ``python benchmarks/bench_simulate.py``. In one run it

1. times, as medians of repeats,
   * the baseline: scipy ``solve_ivp`` RK45 with a plain numpy right-hand side
     (rtol 1e-6), on the paper's case 1 backward (built-in scenario
     ``paper-backward-case1``), 5 s sampled at 1 kHz;
   * a second baseline: the same solve_ivp call with a right-hand side built from
     posturelab's public numpy functions (``state_derivative`` of ``joint_torques``);
   * ``simulate_fast`` on the same case (a SimulationResult), with its default
     integrator (``method="Radau"``), once more reading every derived series (torques,
     accelerations, centre of gravity, ...; computed on first access), and with the
     explicit ``method="RK45"`` and ``"RK23"``; speed-ups against both baselines;
   * ``simulate_batch``: 10,000 runs of 5 s with random gains (ankle 400–1500,
     the other four pairs 0–600 N·m/rad, viscosity 0.25 × stiffness), the
     paper's body, a 1 m/s backward step from the paper's initial posture;
2. checks each against a reference (``posturelab.simulate.simulate``, DOP853,
   rtol 1e-10, atol 1e-12): the largest angle error on the common sample grid,
   for the batch on a random sample of its runs (whose trajectories
   ``simulate_fast`` reproduces bit for bit: checked too);
3. measures the cold compile (a fresh numba cache directory) and the cached
   load (a fresh process, cache present) in subprocesses;
4. prints the machine, a table of medians, ratios and errors, and the targets.

Environment: ``BENCH_QUICK=1`` shortens every part (for a smoke test).
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
N_SAMPLE = 4 if QUICK else 12  # batch runs checked against the reference
REPEATS_BASELINE = 3 if QUICK else 7
REPEATS_FAST = 20 if QUICK else 100
REPEATS_BATCH = 1 if QUICK else 3
SEED = 20261122
RTOL = 1e-6
REF_RTOL, REF_ATOL = 1e-10, 1e-12


def median_time(fn, repeats: int) -> float:
    """Median wall time of ``fn()`` over ``repeats`` calls after one warm-up call. [s]"""
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


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
    from posturelab.fast import simulate_fast, simulate_batch
    from posturelab.scenarios import builtin_scenario
    t1 = time.perf_counter()
    sc = builtin_scenario("paper-backward-case1")
    simulate_fast(sc.body, sc.muscles, sc.disturbance, sc.duration,
                  initial_state=sc.initial_state)
    t2 = time.perf_counter()
    k = np.asarray(sc.muscles.stiffnesses)[None, :]
    simulate_batch(sc.body, k, 0.25 * k, sc.disturbance, 0.1, sc.initial_state)
    t3 = time.perf_counter()
    print("import =", t1 - t0)
    print("first_fast =", t2 - t1)
    print("first_batch =", t3 - t2)
    print("total =", t3 - t0)
"""


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
    import numba
    from posturelab.fast import DEFAULT_ATOL, simulate_batch, simulate_fast, warm_up
    from posturelab.muscles import paper_muscles
    from posturelab.platform import VelocityStep
    from posturelab.simulate import initial_state_for, simulate

    from posturelab.scenarios import builtin_scenario

    print("posturelab simulation benchmark" + (" (BENCH_QUICK)" if QUICK else ""))
    warm_up()  # also makes sure the default cache is populated for the cached-load measurement
    print(f"machine: {platform.platform()}; {_cpu_name()}; {os.cpu_count()} CPUs; numba "
          f"{numba.__version__} ({numba.get_num_threads()} threads, "
          f"{numba.threading_layer()} layer); numpy {np.__version__}; "
          f"python {platform.python_version()}")

    # ---- compile times in fresh processes ---------------------------------------------
    env = dict(os.environ)
    with tempfile.TemporaryDirectory(prefix="posturelab-numba-cache-") as cache:
        cold = subprocess_seconds(FIRST_CALL, {**env, "NUMBA_CACHE_DIR": cache})
    cached = subprocess_seconds(FIRST_CALL, env)

    # ---- the single case --------------------------------------------------------------
    sc = builtin_scenario("paper-backward-case1")
    body, muscles, dist = sc.body, sc.muscles, sc.disturbance
    duration = sc.duration
    ref = simulate(body, muscles, dist, duration, initial_state=sc.initial_state,
                   rtol=REF_RTOL, atol=REF_ATOL)
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

    # ---- the batch -----------------------------------------------------------------------
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
        reference = simulate(body, m, step, duration, initial_state=posture, rtol=REF_RTOL,
                             atol=REF_ATOL)
        k = min(one.time.size, reference.time.size)
        err_batch = max(err_batch, float(np.max(np.abs(one.theta[:k] - reference.theta[:k]))))

    # ---- report ----------------------------------------------------------------------
    per_run = t_batch / N_BATCH
    rows = [
        ("scipy RK45 + numpy RHS (baseline)", t_base, 1.0, err_base),
        ("scipy RK45 + posturelab's public numpy functions", t_pub, t_base / t_pub, err_pub),
        ("simulate_fast (one run, default method='Radau')", t_fast, t_base / t_fast, err_fast),
        ("  the same, then reading every derived series", t_all, t_base / t_all, err_fast),
        ("simulate_fast (one run, method='RK45')", t_fast45, t_base / t_fast45, err_fast45),
        ("simulate_fast (one run, method='RK23')", t_fast23, t_base / t_fast23, err_fast23),
        (f"simulate_batch ({N_BATCH} runs)", t_batch, t_base * N_BATCH / t_batch, err_batch),
    ]
    print()
    print(f"case: paper-backward-case1, {duration:g} s, rtol {RTOL:g}, atol {DEFAULT_ATOL:g} "
          f"(fast and baselines); reference DOP853 rtol {REF_RTOL:g} atol {REF_ATOL:g}")
    print(f"{'':50}{'median':>12}{'speed-up':>12}{'vs public':>12}{'max |Δθ|':>12}")
    for label, t, ratio, err in rows:
        pub = ratio * t_pub / t_base
        print(f"{label:50}{t * 1e3:>9.3f} ms{ratio:>11.{0 if ratio >= 10 else 2}f}×"
              f"{pub:>11.{0 if pub >= 10 else 2}f}×{err:>12.2e}")
    print("  speed-up: against the first baseline (hand-written numpy RHS); vs public: "
          "against the second (posturelab.state_derivative + joint_torques)")
    print(f"  batch: {per_run * 1e6:.1f} µs per run on {numba.get_num_threads()} threads; "
          f"{int(out.fell.sum())} of {N_BATCH} runs fell; errors on {N_SAMPLE} random runs; "
          f"batch == simulate_fast bit for bit: {'yes' if identical else 'NO'}")
    print()
    print("compile (fresh processes): "
          f"cold (empty cache) import {cold['import']:.2f} s + first simulate_fast "
          f"{cold['first_fast']:.2f} s + first simulate_batch {cold['first_batch']:.2f} s "
          f"= {cold['total']:.2f} s; cached: import {cached['import']:.2f} s + first "
          f"simulate_fast {cached['first_fast']:.2f} s + first simulate_batch "
          f"{cached['first_batch']:.2f} s = {cached['total']:.2f} s")
    print()
    print("targets: simulate_fast >= 500× baseline: "
          f"{'met' if t_base / t_fast >= 500 else 'NOT met'} ({t_base / t_fast:.0f}×; "
          f"{t_pub / t_fast:.0f}× the public-function baseline; {t_base / t_all:.0f}× reading "
          "every derived series too); "
          f"batch <= 1.5 s: {'met' if t_batch <= 1.5 else 'NOT met'} ({t_batch:.2f} s"
          f"{', scaled from ' + str(N_BATCH) + ' runs' if QUICK else ''}); "
          f"errors <= 1e-6 rad: "
          f"{'met' if max(err_fast, err_fast45, err_fast23, err_batch) <= 1e-6 else 'NOT met'}; "
          f"cached first call < 2 s: {'met' if cached['total'] < 2 else 'NOT met'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
