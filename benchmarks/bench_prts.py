"""The compiled engine against jitcdde on a PRTS tilt, at equal accuracy (run as a script).

``python benchmarks/bench_prts.py`` integrates one tilt experiment: the one-link body
(``paper-1link``) under intrinsic gains and delayed active gains (the ``icm-pmc5664365``
controller: τ = 97 ms, W = 0.8), posturelab's 80-state PRTS of 0.035 rad peak to peak for
40 s, 100 Hz samples. A PRTS is piecewise linear: its rate jumps at every state switch
(every 0.25 s), and the delayed feedback feels each jump τ later, so the right-hand side
jumps at t_k and t_k + τ and its derivatives at t_k + 2τ, 3τ, … The compiled engine knows
these times in advance and ends a step on each (``docs/simulators.md``); jitcdde steps
through them under its error control (it cannot step onto the discontinuities of an
input: ``step_on_discontinuities`` refuses inputs).

It prints, for a ladder of tolerances (atol = 1e-3 · rtol), each engine's largest angle
error against a tight run (the compiled engine's RK45 at rtol 1e-12, itself checked against
the reference engine's DOP853 at rtol 1e-11 unless ``--quick``) and its least time per run
over repeats (jitcdde: the integration only, its C compiled once beforehand; its samples are
read with ``integrate(t)`` on the same grid). Then, for every jitcdde setting, the compiled engine's
cheapest setting at least as accurate and the ratio of their times: the target is >= 20×
(issue 19).

jitcdde is not a dependency of posturelab: ``pip install jitcdde`` (it needs a C compiler).
Without it the script prints the compiled engine's half and says so.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import tempfile
import time
import warnings

import numpy as np

DURATION = 40.0  # [s]
SAMPLE_RATE = 100.0  # [Hz]
COMPILED_RTOLS = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9)
JITCDDE_RTOLS = (1e-5, 1e-6, 1e-7, 1e-8)
TIGHT = {"rtol": 1e-12, "atol": 1e-14}
CHECK = {"rtol": 1e-11, "atol": 1e-13}
TARGET = 20.0  # [-] the compiled engine's lead at equal accuracy


def experiment():
    """The body, muscles, tilt and run options of the experiment."""
    import posturelab as pl
    from posturelab.model.controllers import get_controller
    from posturelab.model.tilt import PRTSTilt

    body = pl.get_body("paper-1link")
    preset = get_controller("icm-pmc5664365")
    return body, preset.muscles(body), PRTSTilt.named("posturelab-80", 0.035), \
        preset.run_options()


def compiled_run(rtol: float, atol: float, method: str | None = None, engine="compiled"):
    import posturelab as pl

    body, muscles, tilt, options = experiment()
    extra = {} if method is None else {"method": method}
    return pl.simulate(body, muscles, None, DURATION, tilt=tilt, engine=engine,
                       sample_rate=SAMPLE_RATE, rtol=rtol, atol=atol, **options, **extra)


def best_seconds(fn, repeats: int) -> float:
    """Least wall time of ``fn()`` over ``repeats`` calls after one warm-up call: the call
    least disturbed by other work on a shared machine (both engines are timed so). [s]"""
    from bench_simulate import wall_times  # (benchmarks/ is on the path of a script run)

    return min(wall_times(fn, repeats))


class JitcddeModel:
    """The same one-link experiment as a jitcdde delay differential equation.

    J θ̈ = a g sin θ − τ(t), τ = T_K θ + T_L θ̇ + T_K' θ(t − τ) + T_L' θ̇(t − τ)
    + G₀ α(t) + G₁ α̇(t) + G₂ α(t − τ) + G₃ α̇(t − τ), with the joint-moment gains of the
    run's set-up; α and α̇, now and τ ago, are four inputs (cubic Hermite splines that are
    exact on the piecewise-linear PRTS: two anchors 1e-9 s apart at each corner).
    """

    def __init__(self, folder: str):
        import symengine
        from chspy import CubicHermiteSpline
        from jitcdde import input as u
        from jitcdde import jitcdde_input, t, y

        from posturelab.simulation.setup import prepare_run

        body, muscles, tilt, options = experiment()
        setup = prepare_run(body, muscles, None, DURATION, tilt=tilt, sample_rate=SAMPLE_RATE,
                            **options)
        E, C = muscles.selection_matrix, muscles.crossing_matrix
        weight = C[:, 0] * E[:, 0] * setup.active0
        tk, tl, tkd, tld = (float(np.sum(weight * setup.gains[i])) for i in range(4))
        g0, g1, g2, g3 = (setup.tilt_gains @ C)[:, 0]
        delay = setup.feedback_delay
        a, inertia, gravity = (body.gravity_coefficients[0], body.inertia_diagonal[0],
                               body.gravity)
        self.grid = setup.grid
        self.before = setup.before
        spline = CubicHermiteSpline(n=4)
        period = float(tilt.terms()[0].period)
        cycles = int(np.ceil((DURATION + 1.0) / period))
        knots = [c * period + k for c in range(cycles)
                 for k in (0.0, *tilt.breakpoints(period))] + [cycles * period]
        corners = sorted({*knots, *(k + delay for k in knots)})
        eps = 1e-9

        def values(s: float, side: float):
            now, rate = tilt.angle_and_rate(s + side)
            then, rate_then = tilt.angle_and_rate(s - delay + side)
            a_now = float(tilt.angle_and_rate(s)[0])
            a_then = float(tilt.angle_and_rate(s - delay)[0])
            return [a_now, float(rate), a_then, float(rate_then)], \
                [float(rate), 0.0, float(rate_then), 0.0]

        for c in corners:
            if c > 0:
                spline.add((c - eps, *values(c - eps, -1e-12)))
            spline.add((c, *values(c, 1e-12)))
        moment = (tk * y(0) + tl * y(1) + tkd * y(0, t - delay) + tld * y(1, t - delay)
                  + g0 * u(0) + g1 * u(1) + g2 * u(2) + g3 * u(3))
        self.f = [y(1), (a * gravity * symengine.sin(y(0)) - moment) / inertia]
        self.spline = spline
        self.module = os.path.join(folder, "prts_dde.so")
        cwd = os.getcwd()
        os.chdir(folder)  # jitcdde builds in the working directory
        try:
            dde = jitcdde_input(self.f, self.spline, verbose=False)
            dde.compile_C(simplify=False, do_cse=False, verbose=False)
            dde.save_compiled(self.module, overwrite=True)
        finally:
            os.chdir(cwd)
        self._factory = jitcdde_input

    def run(self, rtol: float, atol: float) -> tuple[np.ndarray, float]:
        """θ on the grid and the seconds of the integration."""
        dde = self._factory(self.f, self.spline, verbose=False, module_location=self.module)
        dde.constant_past(list(self.before), time=0.0)
        dde.set_integration_parameters(rtol=rtol, atol=atol, max_step=0.25)
        dde.initial_discontinuities_handled = True  # the past is the state before the run
        theta = np.empty(self.grid.size)
        theta[0] = self.before[0]
        t0 = time.perf_counter()
        for i in range(1, self.grid.size):
            theta[i] = dde.integrate(self.grid[i])[0]
        return theta, time.perf_counter() - t0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="fewer repeats; skip checking the tight run against the reference "
                             "engine (about 30 s)")
    args = parser.parse_args()
    repeats_compiled, repeats_jit = (5, 1) if args.quick else (30, 3)
    warnings.simplefilter("ignore")  # jitcdde's notes about its own discontinuity handling

    print("PRTS tilt: the compiled engine against jitcdde at equal accuracy")
    print(f"machine: {platform.platform()}; {os.cpu_count()} CPUs; python "
          f"{platform.python_version()}; load average {os.getloadavg()[0]:.2f}")
    body, muscles, tilt, options = experiment()
    print(f"one link, icm-pmc5664365 (τ = {options['feedback_delay']:g} s, W = "
          f"{options['proprioceptive_weight']:g}), {tilt.describe()}, {DURATION:g} s, "
          f"{SAMPLE_RATE:g} Hz samples")
    tight = compiled_run(**TIGHT, method="RK45")
    if not args.quick:
        check = compiled_run(**CHECK, engine="reference")
        print(f"tight run: compiled RK45 rtol {TIGHT['rtol']:g}; against the reference engine "
              f"(DOP853, rtol {CHECK['rtol']:g}): "
              f"{np.max(np.abs(check.theta - tight.theta)):.1e} rad")

    def error(theta) -> float:
        return float(np.max(np.abs(np.asarray(theta).reshape(tight.theta[:, 0].shape)
                                   - tight.theta[:, 0])))

    rows = []  # (engine label, rtol, error, seconds)
    for method in ("RK45", "Radau"):
        for rtol in COMPILED_RTOLS:
            res = compiled_run(rtol, 1e-3 * rtol, method)
            seconds = best_seconds(lambda r=rtol, m=method: compiled_run(r, 1e-3 * r, m),
                                     repeats_compiled)
            rows.append((f"compiled {method}", rtol, error(res.theta[:, 0]), seconds))
    try:
        import jitcdde  # noqa: F401
    except ImportError:
        jit = None
        print("jitcdde is not installed (pip install jitcdde): its half is skipped")
    else:
        with tempfile.TemporaryDirectory(prefix="posturelab-jitcdde-") as folder:
            jit = JitcddeModel(folder)
            for rtol in JITCDDE_RTOLS:
                theta, _ = jit.run(rtol, 1e-3 * rtol)
                seconds = min(jit.run(rtol, 1e-3 * rtol)[1] for _ in range(repeats_jit))
                rows.append(("jitcdde (RK3(2))", rtol, error(theta), seconds))
    print()
    print(f"{'engine':22}{'rtol':>8}{'max |Δθ| [rad]':>17}{'time per run':>16}")
    for label, rtol, err, seconds in rows:
        print(f"{label:22}{rtol:>8.0e}{err:>17.2e}{seconds * 1e3:>13.2f} ms")
    if jit is None:
        return 0
    print()
    print("at equal accuracy: for each jitcdde setting, the compiled engine's cheapest setting "
          "with an error no larger")
    ratios = []
    for label, rtol, err, seconds in rows:
        if not label.startswith("jitcdde"):
            continue
        for method in ("RK45", "Radau"):
            fits = [r for r in rows if r[0] == f"compiled {method}" and r[2] <= err]
            if not fits:
                print(f"   jitcdde rtol {rtol:.0e} ({err:.1e} rad): no compiled {method} "
                      "setting in the ladder is as accurate")
                continue
            best = min(fits, key=lambda r: r[3])
            ratio = seconds / best[3]
            if method == "RK45":  # the compiled engine's own choice for a delayed run
                ratios.append(ratio)
            print(f"   jitcdde rtol {rtol:.0e} ({err:.1e} rad, {seconds * 1e3:.1f} ms)  vs  "
                  f"compiled {method} rtol {best[1]:.0e} ({best[2]:.1e} rad, "
                  f"{best[3] * 1e3:.2f} ms):{ratio:7.0f}×")
    met = bool(ratios) and min(ratios) >= TARGET
    print()
    print(f"target: the compiled engine (its default method, RK45) >= {TARGET:g}× jitcdde at "
          f"equal accuracy: {'met' if met else 'NOT met'} (smallest ratio "
          f"{min(ratios) if ratios else float('nan'):.0f}×; load average "
          f"{os.getloadavg()[0]:.2f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
