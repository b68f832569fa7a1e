"""Defects an adversarial trial of the wheel found in the commands that run many
simulations (stability-map, sweep, strategy, design): each test fails before its fix."""

import threading
from types import SimpleNamespace

import pytest

from _cli import refused_in_one_line, run_main
from posturelab.studies.sweep import SweepInterrupted, run_chunks


def test_an_interrupt_does_not_wait_for_a_running_chunk():
    """Ctrl-C during a sweep: the chunk still running is abandoned, not awaited (a PRTS
    chunk ran on for 23 s); the leading finished chunk is kept."""
    release, finished = threading.Event(), []

    class Task:
        def run(self, grid, lo, hi, parallel):
            if lo > 0:  # the second chunk runs until released
                release.wait(60)
                finished.append(lo)
            return [lo]

    def progress(done, total):
        raise KeyboardInterrupt  # (Ctrl-C once the first chunk is in)

    try:
        with pytest.raises(SweepInterrupted) as caught:
            run_chunks(Task(), SimpleNamespace(n_runs=2), chunk_size=1, progress=progress,
                       threads=2)
        assert finished == []  # returned while the second chunk was still running
        assert caught.value.parts == [[0]] and caught.value.rows == 1
    finally:
        release.set()


def test_chunks_in_order_and_errors_raised():
    class Task:
        def run(self, grid, lo, hi, parallel):
            if lo == 3:
                raise ValueError("boom")
            return list(range(lo, hi))

    parts = run_chunks(Task(), SimpleNamespace(n_runs=3), chunk_size=2, threads=2)
    assert parts == [[0, 1], [2]]
    with pytest.raises(ValueError, match="boom"):
        run_chunks(Task(), SimpleNamespace(n_runs=5), chunk_size=1, threads=1)


def test_design_optimise_refuses_the_values_it_would_override(capsys):
    """design --optimise chose 10,000 cycles at 0.07 rad over --cycles 5 --tilt prts:0.035."""
    base = ("design", "--controller", "peterka-2002", "--free", "feedback_delay",
            "--sensor-noise", "0.001", "--optimise", "--budget", "100")
    assert "--cycles" in refused_in_one_line(capsys, *base, "--cycles", "5")
    line = refused_in_one_line(capsys, *base, "--tilt", "prts:0.035")
    assert "--tilt" in line and "--amplitudes" in line


def test_stability_map_never_overwrites_a_csv_beside_the_figure(tmp_path, capsys):
    victim = tmp_path / "victim.csv"
    victim.write_text("mine\n1,2\n", encoding="utf-8")
    axes = ("stability-map", "--x", "stiffness:ankle:0:2000", "--y", "stiffness:knee:0:1000",
            "--resolution", "4")
    line = refused_in_one_line(capsys, *axes, "--out", str(tmp_path / "victim.png"))
    assert "victim.csv" in line and "--csv" in line
    assert victim.read_text(encoding="utf-8") == "mine\n1,2\n"
    assert not (tmp_path / "victim.png").exists()
    code, out, err = run_main(capsys, *axes, "--out", str(tmp_path / "victim.png"),
                              "--csv", str(tmp_path / "map.csv"))
    assert code == 0, err
    assert victim.read_text(encoding="utf-8") == "mine\n1,2\n"
    assert (tmp_path / "map.csv").read_text(encoding="utf-8").startswith("stiffness:ankle,")


def test_stability_map_replaces_its_own_earlier_csv(tmp_path, capsys):
    axes = ("stability-map", "--x", "stiffness:ankle:0:2000", "--y", "stiffness:knee:0:1000",
            "--out", str(tmp_path / "map.png"))
    assert run_main(capsys, *axes, "--resolution", "3")[0] == 0
    assert run_main(capsys, *axes, "--resolution", "4")[0] == 0  # a rerun
    assert len((tmp_path / "map.csv").read_text(encoding="utf-8").splitlines()) == 1 + 16


@pytest.mark.parametrize("argv, words", [
    (("--oscillation", "0.05", "--frequencies", "0.002:0.002:1"),
     ("--frequencies", "0.00250000125 Hz", "got 0.002")),
    (("--translation", "backward", "--speeds", "0.05:100:8"), ("--speeds", "10 m/s", "got 100")),
    (("--oscillation", "0.05", "--frequencies", "0.1:100:6"),
     ("--frequencies", "20 Hz", "got 100")),
    (("--translation", "backward", "--speeds", "0.05:1:1000", "--ankle-torque-limits",
      "40:120:1000"), ("1,000,000 runs", "10,000")),
    (("--translation", "backward", "--speeds", "0.05:1:3", "--displacement", "5"),
     ("--displacement", "got 5")),
    (("--oscillation", "2", "--frequencies", "0.5:1:2"), ("--oscillation", "got 2")),
    (("--oscillation", "0.05", "--frequencies", "0.5:1:2", "--ankle-torque-limit", "-3"),
     ("--ankle-torque-limit", "got -3")),
])
def test_strategy_names_the_option_and_the_value_typed(capsys, argv, words):
    """Before: "duration [s] 2500 at sample_rate …" (strategy has neither option), "got
    14.33" (a grid value, not the 100 typed), or a million runs started."""
    line = refused_in_one_line(capsys, "strategy", *argv)
    for w in words:
        assert w in line, line


def test_strategy_counts_every_map_in_its_progress(monkeypatch):
    """The runs of a two-parameter map counted as one whole: one notice after the second
    run naming all of them, timed from the end of the first (which loads the engine)."""
    import io
    import time

    from posturelab.cli.strategy import _Overall

    clock = iter([100.0, 120.0, 130.0, 140.0, 150.0, 160.0])  # (a fake clock: 20 s a run)
    monkeypatch.setattr(time, "perf_counter", lambda: next(clock))
    stream = io.StringIO()
    overall = _Overall(6, 3, stream)
    for _ in range(2):
        for i in range(3):
            overall(i + 1, 3)
    assert overall.maps_done == 2
    assert stream.getvalue() == "posturelab: strategy: 6 runs, about 100 s in all\n"


def test_api_simulate_refuses_a_bool_duration():
    import posturelab as pl
    from posturelab.errors import ParameterError

    with pytest.raises(ParameterError, match=r"got True \(bool\)"):
        pl.simulate(pl.paper_body(), pl.paper_muscles("1"), pl.VelocityStep.backward(1.0),
                    duration=True)


def test_messages_name_the_value_given(capsys, tmp_path):
    line = refused_in_one_line(capsys, "sweep", "--case", "1", "--disturbance", "backward",
                               "--duration", "1", "--vary", "disturbance_scale=0:100:3",
                               "--out", str(tmp_path / "sw.csv"))
    assert "disturbance_scale 100" in line, line  # (was: "velocity … got -50.0")
    line = refused_in_one_line(capsys, "frf-model", "--case", "1", "--frequencies", "0,1")
    assert "--frequencies" in line and "got 0" in line
    run = tmp_path / "run.csv"
    run.write_text("t,theta1\n0,0\n", encoding="utf-8")
    line = refused_in_one_line(capsys, "compare", str(run), "--plot", str(run))
    assert "RUN.csv" not in line and "input run" in line


def _server(reply: bytes | None):
    """A local TCP server answering every connection with ``reply`` (None: silence, like an
    HTTP server waiting for a request); its port and a stop function."""
    import socket

    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(4)
    held, stop = [], threading.Event()

    def serve():
        listener.settimeout(0.1)
        while not stop.is_set():
            try:
                conn, _ = listener.accept()
            except OSError:
                continue
            held.append(conn)
            if reply is not None:
                conn.sendall(reply)

    threading.Thread(target=serve, daemon=True).start()

    def close():
        stop.set()
        for c in held:
            c.close()
        listener.close()

    return listener.getsockname()[1], close


@pytest.mark.parametrize("reply, words", [
    (b"HTTP/1.0 426 Upgrade Required\r\nContent-Length: 0\r\n\r\n",
     ("is not a Dask scheduler", "HTTP/1.0")),
    (None, ("no Dask scheduler answered within",)),
])
def test_a_scheduler_that_is_not_dask_is_refused_in_one_line(reply, words):
    """Before: a 3.01 EiB allocation error with a traceback, or a hang of minutes."""
    from posturelab.errors import PostureLabError
    from posturelab.studies._sweep_dask import probe_scheduler

    port, close = _server(reply)
    try:
        with pytest.raises(PostureLabError) as caught:
            probe_scheduler(f"tcp://127.0.0.1:{port}", timeout=0.5)
        for w in words:
            assert w in str(caught.value)
        assert "\n" not in str(caught.value)
    finally:
        close()


def test_a_dask_like_handshake_passes_the_probe():
    import struct

    from posturelab.studies._sweep_dask import probe_scheduler

    port, close = _server(struct.pack("<Q", 120) + b"\0" * 120)
    try:
        probe_scheduler(f"127.0.0.1:{port}", timeout=5)
    finally:
        close()


def test_sweep_against_an_http_server_is_refused(tmp_path, capsys):
    port, close = _server(b"HTTP/1.0 426 Upgrade Required\r\n\r\n")
    try:
        line = refused_in_one_line(
            capsys, "sweep", "--case", "1", "--disturbance", "backward", "--duration", "1",
            "--vary", "stiffness:ankle=0:2000:4", "--out", str(tmp_path / "sw.csv"),
            "--scheduler", f"tcp://127.0.0.1:{port}")
    finally:
        close()
    assert "not a Dask scheduler" in line
    assert not (tmp_path / "sw.csv").exists()


def test_a_prts_sweep_beyond_its_bound_is_refused_before_it_starts(tmp_path, capsys):
    """Before: 90,000 experiments of 990 cycles (~100 h) started without a word."""
    line = refused_in_one_line(
        capsys, "sweep", "--case", "1", "--tilt", "prts:0.035", "--experiment", "prts",
        "--cycles", "990", "--vary", "stiffness:ankle=800:1200:300",
        "--vary", "stiffness:knee=500:700:300", "--out", str(tmp_path / "p.csv"))
    assert "90,000 PRTS experiments" in line and "--cycles" in line and "1e+08 s" in line


def test_a_measured_profile_ends_where_its_motion_ends():
    """−2 m/s² for 0.2 s, then zeros to 0.999 s: the perturbation ends at 0.201 s (the
    sample after the last non-zero one, where the interpolated acceleration is back at 0),
    not at the last sample, 0.999 s; an all-zero profile has ended at its first sample."""
    import numpy as np

    from posturelab.model.platform import MeasuredProfile
    from posturelab.simulation.outcome import stimulus_timing

    t = np.round(np.arange(0, 1.0, 0.001), 6)
    moving = MeasuredProfile(t, np.where(t <= 0.2, -2.0, 0.0))
    assert stimulus_timing(moving).end == pytest.approx(0.201, abs=1e-12)
    assert stimulus_timing(MeasuredProfile(t, np.zeros_like(t))).end == 0.0
    y = MeasuredProfile(t, np.zeros_like(t), np.where(t <= 0.5, 1.0, 0.0))
    assert stimulus_timing(y).end == pytest.approx(0.501, abs=1e-12)
    to_the_end = MeasuredProfile(t, np.full_like(t, 0.5))
    assert stimulus_timing(to_the_end).end == pytest.approx(0.999, abs=1e-12)


def test_a_csv_too_large_is_refused_before_the_run(tmp_path, capsys, monkeypatch):
    """Before: 1999.999 s to CSV ran 22 s and took 1.1 GB, then was refused at 512 MiB."""
    from posturelab.scenarios import Scenario

    ran = []
    monkeypatch.setattr(Scenario, "run", lambda self, **kw: ran.append(1))
    line = refused_in_one_line(capsys, "simulate", "--case", "1", "--disturbance", "backward",
                               "--duration", "1999.999", "--out", str(tmp_path / "long.csv"))
    assert ran == [] and "--duration 1999.999" in line and ".parquet" in line
    assert not (tmp_path / "long.csv").exists()


def test_data_files_take_several_after_one_flag_or_the_flag_repeated():
    import argparse

    from posturelab.cli._flags import add_data_files

    p = argparse.ArgumentParser()
    add_data_files(p, "the trials")
    assert p.parse_args(["--data", "a", "b"]).data == ["a", "b"]
    assert p.parse_args(["--data", "a", "--data", "b"]).data == ["a", "b"]
    assert p.parse_args(["--data", "a", "b", "--data", "c"]).data == ["a", "b", "c"]


def test_a_prts_sweep_takes_sample_rate_as_its_record_rate(tmp_path, capsys):
    """--sample-rate means the recording's samples per second there, as --record-rate."""
    import argparse

    from posturelab.cli import sweep

    base = ["--case", "1", "--tilt", "prts:0.035", "--experiment", "prts", "--cycles", "3",
            "--vary", "stiffness:ankle=800:1200:2", "--out", str(tmp_path / "p.csv")]
    seen = []

    def keep(args, scenario, varies, ratio):
        seen.append(args.record_rate)
        return 0

    p = argparse.ArgumentParser()
    sweep.add_arguments(p)
    original = sweep._run_experiments
    sweep._run_experiments = keep
    try:
        assert sweep.run(p.parse_args([*base, "--sample-rate", "50"])) == 0
    finally:
        sweep._run_experiments = original
    assert seen == [50.0]
    line = refused_in_one_line(capsys, "sweep", *base, "--sample-rate", "50", "--record-rate",
                               "100")
    assert "--sample-rate" in line and "--record-rate" in line


def test_a_real_dask_scheduler_passes_the_probe():
    import asyncio

    distributed = pytest.importorskip("distributed")
    from posturelab.studies._sweep_dask import probe_scheduler

    async def main():
        async with distributed.Scheduler(host="127.0.0.1", port=0,
                                         dashboard_address=None) as scheduler:
            loop = asyncio.get_running_loop()
            await loop.run_in_executor(None, probe_scheduler, scheduler.address)
            return scheduler.address

    assert asyncio.run(main()).startswith("tcp://127.0.0.1:")


@pytest.mark.parametrize("argv, words", [
    (["--translation", "backward", "--speeds", "1:10:4"],
     ("--speeds up to 10 m/s", "--displacement 0.06 m", "at most 6.18 m/s")),
    (["--oscillation", "0.2", "--frequencies", "1:12:3"],
     ("--frequencies up to 12 Hz", "--oscillation 0.2 m", "at most 11.25 Hz")),
])
def test_strategy_names_the_grid_the_platform_cannot_move(argv, words):
    """A grid beyond the platform's ±1000 m/s² names its option, the other that sets the
    acceleration and the largest value allowed (it said 'peak acceleration 2πD/T² ...')."""
    from _cli import cli, one_line_exit_2

    one_line_exit_2(cli("strategy", *argv, "--json"), *words)
