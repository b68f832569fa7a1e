"""Benchmark of the frequency-domain tools (run as a script, not a test).

``python benchmarks/bench_frequency.py`` prints:

1. 10⁶ model FRFs of the one-link body (intrinsic + delayed active gains, random) at
   Peterka's 11 bands with ``model_frf_batch``, against a plain numpy baseline (a Python loop
   over sets evaluating the closed-form transfer function with numpy, timed on 20,000 sets
   and scaled), and 10⁵ three-link FRFs against a loop of ``numpy.linalg.solve`` per set and
   frequency (timed on 2,000 sets, scaled); the largest difference between the two;
2. one fit of four parameters (``fit_frf``) to a noisy PRTS experiment, against a plain scipy
   baseline: ``scipy.optimize.least_squares`` on the closed-form one-link FRF at the band
   frequencies, unweighted.
"""

from __future__ import annotations

import os
import platform
import time

import numpy as np

import posturelab as pl
from posturelab.frequency import estimate_frf, model_frf
from posturelab.frequency.bands import PETERKA_BAND_HARMONICS, band_frequencies
from posturelab.frequency.fit import fit_frf
from posturelab.frequency.model import model_frf_batch
from posturelab.model.controllers import get_controller
from posturelab.model.tilt import PRTSTilt

SEED = 20261201


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def one_link_sets(count: int, rng: np.random.Generator):
    """``count`` random one-link controller sets (drawn from ``rng``) at the 11 bands of a
    20 s cycle:
    (body, layout, frequencies [Hz], intrinsic stiffness and viscosity, active stiffness and
    viscosity [N·m/rad, N·m·s/rad], shape (count, 1) each, delays [s] and weights [-], shape
    (count,)); bench_readme.py times ``model_frf_batch`` on the same sets."""
    f = band_frequencies(PETERKA_BAND_HARMONICS, 20.0)
    body = pl.get_body("paper-1link")
    layout = get_controller("peterka-2002").muscles(body)
    mgh = body.load_stiffness
    k = rng.uniform(0, 0.2, (count, 1)) * mgh
    v = rng.uniform(0, 0.1, (count, 1)) * mgh
    ka = rng.uniform(0.8, 2.0, (count, 1)) * mgh
    va = rng.uniform(0.2, 0.8, (count, 1)) * mgh
    tau = rng.uniform(0.08, 0.2, count)
    w = rng.uniform(0.3, 1.0, count)
    return body, layout, f, k, v, ka, va, tau, w


def main() -> None:
    print("posturelab frequency-domain benchmark")
    print(f"machine: {platform.platform()}; {os.cpu_count()} CPUs; numpy {np.__version__}")
    rng = np.random.default_rng(SEED)
    M = 1_000_000
    body, layout, f, k, v, ka, va, tau, w = one_link_sets(M, rng)
    mgh = body.load_stiffness
    t_batch, H = timed(lambda: model_frf_batch(body, layout, f, k, v, ka, va, tau, w))
    J = body.inertia_diagonal[0]
    n_base = 20_000

    def baseline():
        out = np.empty((n_base, f.size), complex)
        s = 2j * np.pi * f
        for r in range(n_base):
            ex = np.exp(-s * tau[r])
            num = k[r, 0] + s * v[r, 0] + w[r] * (ka[r, 0] + s * va[r, 0]) * ex
            den = J * s * s - mgh + k[r, 0] + s * v[r, 0] + (ka[r, 0] + s * va[r, 0]) * ex
            out[r] = num / den
        return out

    t_base, H0 = timed(baseline)
    t_base *= M / n_base
    diff = float(np.max(np.abs(H[:n_base] - H0) / np.abs(H0)))
    print(f"1. 10^6 one-link model FRFs at 11 bands: {t_batch:.2f} s; plain numpy loop "
          f"{t_base:.1f} s (scaled from {n_base:,}): {t_base / t_batch:.0f}×; "
          f"max relative difference {diff:.1e}")
    body3, layout3 = pl.paper_body(), pl.paper_muscles("1")
    M3 = 100_000
    k3 = rng.uniform(100, 1500, (M3, 5))
    ka3 = rng.uniform(0, 500, (M3, 5))
    tau3 = rng.uniform(0, 0.02, M3)
    t3, H3 = timed(lambda: model_frf_batch(body3, layout3, f, k3, 0.25 * k3, ka3, 0.3 * ka3,
                                           tau3, 0.8))
    n3 = 2_000

    def baseline3():
        out = np.empty((n3, f.size), complex)
        for r in range(n3):
            m = pl.paper_muscles(stiffness=k3[r], active_stiffness=ka3[r],
                                 active_viscosity=0.3 * ka3[r])
            out[r] = model_frf(body3, m, f, feedback_delay=tau3[r], proprioceptive_weight=0.8)
        return out

    t3b, H3b = timed(baseline3)
    t3b *= M3 / n3
    print(f"   10^5 three-link model FRFs at 11 bands: {t3:.2f} s; one set at a time "
          f"{t3b:.1f} s (scaled from {n3:,}): {t3b / t3:.0f}×; max relative difference "
          f"{float(np.max(np.abs(H3[:n3] - H3b) / np.abs(H3b))):.1e}")

    # ---- 2. one fit ----
    preset = get_controller("icm-pmc5664365")
    true = preset.muscles(body)
    L, T = 1000, 20.0
    x1 = PRTSTilt.named("posturelab-80", 0.035).angle(np.arange(L) * T / L)
    X = np.fft.rfft(x1)
    fk = np.arange(X.size) / T
    Hk = np.zeros(X.size, complex)
    Hk[1:] = model_frf(body, true, fk[1:], **preset.run_options())
    y = np.tile(np.fft.irfft(Hk * X, L), 6) + rng.normal(0, 0.002, 6 * L)
    est = estimate_frf(np.tile(x1, 6), y, L / T, T)
    start = true.with_active_feedback([0.8 * true.active_stiffnesses[0]],
                                      [1.2 * true.active_viscosities[0]])
    names = ["active_stiffness", "active_viscosity", "feedback_delay", "proprioceptive_weight"]
    t_fit, fit = timed(lambda: fit_frf(body, start, est, names, feedback_delay=0.12,
                                       proprioceptive_weight=0.6))
    from scipy.optimize import least_squares

    ki, li = true.stiffnesses[0], true.viscosities[0]

    def plain():
        s = 2j * np.pi * est.frequency

        def res(p):
            ex = np.exp(-s * p[2])
            h = ((ki + s * li) + p[3] * (p[0] + s * p[1]) * ex) / (
                J * s * s - mgh + ki + s * li + (p[0] + s * p[1]) * ex)
            r = h - est.frf
            return np.concatenate([r.real, r.imag])

        return least_squares(res, [0.8 * true.active_stiffnesses[0],
                                   1.2 * true.active_viscosities[0], 0.12, 0.6],
                             bounds=([0, 0, 0, 0], [1e5, 1e5, 1, 1]))

    t_plain, sol = timed(plain)
    print(f"2. one fit of 4 parameters to a noisy PRTS experiment: fit_frf {t_fit * 1e3:.0f} ms "
          f"(band-averaged model, weighted, with errors); plain scipy least_squares on the "
          f"closed form {t_plain * 1e3:.0f} ms ({t_plain / t_fit:.2f}×)")
    print("   truth", np.round([true.active_stiffnesses[0], true.active_viscosities[0],
                                preset.feedback_delay, preset.proprioceptive_weight], 4))
    print("   fit_frf", np.round(fit.estimates, 4), "± ", np.round(fit.standard_errors, 4))
    print("   plain  ", np.round(sol.x, 4))


if __name__ == "__main__":
    main()
