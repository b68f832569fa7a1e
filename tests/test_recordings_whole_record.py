"""Resampling keeps the whole record: a recording of duration D (each sample standing for
its interval [t_k, t_k + step)) resampled at a rate r gives round(D·r) samples, so a
3-cycle trial keeps its 3 cycles (issue: the grid used to stop at the last time stamp and
lose one sample, hence a whole cycle)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from _cli import run_main as run
from posturelab.recordings.resample import record_duration, resample_uniform


def clock(rng, rate, jitter):
    """Sample times of a 60 s record at ``rate`` [Hz]: uniform (k / rate, k < 60·rate), or
    with steps uniform in ±5 % of 1 / rate, every time stamp before 60 s."""
    step = 1.0 / rate
    if not jitter:
        return np.arange(int(round(60.0 * rate))) / rate
    steps = rng.uniform(0.95 * step, 1.05 * step, int(60.0 / step) + 10)
    t = np.concatenate([[0.0], np.cumsum(steps)])
    return t[t < 60.0]


def test_the_grid_covers_the_last_samples_interval():
    t = np.arange(3000) / 50.0  # 60 s at 50 Hz: the last stamp 59.98 s
    assert record_duration(t) == pytest.approx(60.0)
    x = np.sin(2 * np.pi * 0.05 * t)
    for rate, n, past in ((100.0, 6000, 1), (50.0, 3000, 0), (200.0, 12000, 3),
                          (10.0, 600, 0)):
        grid, cols, report = resample_uniform(t, {"x": x}, rate)
        assert grid.size == n == report.samples_out
        assert report.extrapolated == past  # the points past 59.98 s, within its interval
        assert grid[-1] < t[-1] + 1 / 50.0
        # the spline's end continued over less than one input step stays accurate
        np.testing.assert_allclose(cols["x"], np.sin(2 * np.pi * 0.05 * grid), atol=1e-7)


@pytest.mark.parametrize("jitter", [False, True])
def test_three_cycle_records_keep_three_cycles_and_their_frf(tmp_path, capsys, prts_trial,
                                                             jitter):
    from scipy.interpolate import CubicSpline

    time, tilt, com = prts_trial
    args = ["frf", "--stimulus", "tilt", "--response", "com_angle", "--cycle-length", "20",
            "--discard-cycles", "1", "--json"]
    uniform = tmp_path / "uniform.csv"
    keep = slice(0, 60000, 10)  # 100 Hz, 0 … 59.99 s: 3 whole cycles
    np.savetxt(uniform, np.column_stack([time[keep], tilt[keep], com[keep]]), delimiter=",",
               header="time,tilt,com_angle", comments="")
    code, out, err = run(capsys, *args, "--data", uniform)
    assert code == 0, err
    want = json.loads(out)
    rng = np.random.default_rng(7)
    for rate in (50.0, 100.0, 200.0):
        t = clock(rng, rate, jitter)
        path = tmp_path / f"at{rate:g}.csv"
        np.savetxt(path, np.column_stack([t, CubicSpline(time, tilt)(t),
                                          CubicSpline(time, com)(t)]),
                   delimiter=",", header="time,tilt,com_angle", comments="")
        code, out, err = run(capsys, *args, "--data", path, "--resample", "100",
                             "--drop-partial")
        assert code == 0, (rate, err)
        got = json.loads(out)
        trim = got["trimming"]
        assert trim["samples"] == 6000, (rate, trim)  # 3 cycles of 2000
        assert trim["dropped_after_s"] <= 0.02  # a jittered clock's last stamp: ≤ 2 samples
        # the same bounds as tests/test_recordings.py (spline rounding the PRTS corners)
        np.testing.assert_allclose(got["gain"], want["gain"], rtol=0.005)
        np.testing.assert_allclose(got["phase_deg"], want["phase_deg"], atol=0.05)
        if not jitter:  # a whole record needs no --drop-partial
            code, out, err = run(capsys, *args, "--data", path, "--resample", "100")
            assert code == 0, (rate, err)


def test_c3d_at_another_rate_keeps_three_cycles(tmp_path, capsys):
    from posturelab.recordings.c3d import read_c3d
    from posturelab.recordings.example import EXAMPLE_C3D

    for rate, n in ((None, 3000), (100.0, 6000), (25.0, 1500)):
        rec = read_c3d(EXAMPLE_C3D, rate=rate)
        assert rec.time.size == n and all(v.size == n for v in rec.columns.values())
    out = tmp_path / "r100.csv"
    code, _, err = run(capsys, "convert", EXAMPLE_C3D, "--out", out, "--angle-columns", "tilt",
                       "--sway", "segments", "--markers",
                       "ankle=ank,knee=kne,hip=hip,shoulder=sho", "--rate", "100")
    assert code == 0, err
    code, out_text, err = run(capsys, "frf", "--data", out, "--stimulus", "tilt",
                              "--response", "com_angle", "--cycle-length", "20",
                              "--discard-cycles", "1", "--json")
    assert code == 0, err
