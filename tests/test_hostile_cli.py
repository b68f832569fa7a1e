"""The command line under a new user's hands, as real subprocesses: Ctrl-C on a Dask sweep,
scheduler addresses and worker counts, abbreviated options, a closed pipe, combinations and
ranges that are refused in one line."""

from __future__ import annotations

import csv
import os
import re
import signal
import subprocess
import sys

import pytest

from _cli import cli, one_line_exit_2

SWEEP = ["sweep", "--case", "1", "--disturbance", "backward", "--duration", "1",
         "--vary", "stiffness:ankle=0:2000:3"]


def test_ctrl_c_on_a_dask_sweep_is_one_line_and_keeps_the_finished_rows(tmp_path):
    pytest.importorskip("distributed")
    out = tmp_path / "int.csv"
    # the whole process group gets SIGINT, as from a terminal's Ctrl-C or timeout -s INT
    proc = subprocess.Popen([sys.executable, "-m", "posturelab", "sweep", "--case", "1",
                             "--disturbance", "backward", "--duration", "60",
                             "--vary", "stiffness:ankle=0:2000:1000",
                             "--vary", "stiffness:gastrocnemius=0:1000:1000",
                             "--out", str(out), "--workers", "2", "--progress"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    seen = ""
    while not re.search(r"\] +\d+% [1-9][\d,]*/", seen):
        char = proc.stderr.read(1)
        assert char, f"the sweep ended before any progress: {seen}"
        seen += char
    os.killpg(proc.pid, signal.SIGINT)
    _, rest = proc.communicate(timeout=60)
    lines = [line for line in rest.replace("\r", "\n").splitlines()
             if line.strip() and not re.search(r"\] +\d+% ", line)]
    assert proc.returncode == 130, rest
    assert len(lines) == 1 and "Traceback" not in rest, rest
    match = re.fullmatch(r"posturelab: interrupted: wrote the ([\d,]+) of 1,000,000 runs that "
                         rf"finished to {re.escape(str(out))}", lines[0])
    assert match, lines
    rows = list(csv.reader(out.open()))
    assert len(rows) - 1 == int(match.group(1).replace(",", "")) > 0


def test_progress_counts_only_the_rows_an_interrupt_would_keep():
    """Chunks finish out of order; an interrupt keeps the leading finished ones, so the bar
    counts those (it once showed 4,096 finished runs and then wrote none: chunk 0 was still
    running)."""
    import threading

    from posturelab.studies.sweep import run_chunks

    release = threading.Event()

    class Grid:
        n_runs = 40

    class Task:
        def run(self, grid, lo, hi, parallel):
            if lo == 0:  # the first chunk finishes last
                assert release.wait(60)
            return list(range(lo, hi))

    seen: list[int] = []

    def progress(done: int, total: int) -> None:
        assert total == 40
        seen.append(done)
        if len(seen) == 3:  # chunks 1, 2 and 3 done: now let chunk 0 finish
            release.set()

    parts = run_chunks(Task(), Grid(), chunk_size=10, threads=2, progress=progress)
    assert parts == [list(range(lo, lo + 10)) for lo in (0, 10, 20, 30)]
    assert seen == [0, 0, 0, 40]


@pytest.mark.parametrize("address,words", [
    ("nonsense", ["'nonsense'", "HOST:PORT"]),
    ("tcp://127.0.0.1", ["HOST:PORT"]),
    ("tcp://127.0.0.1:99999", ["PORT 1 … 65535"]),
    ("ftp://127.0.0.1:8786", ["unknown protocol 'ftp'"]),
])
def test_a_malformed_scheduler_address_is_refused_before_connecting(tmp_path, address, words):
    one_line_exit_2(cli(*SWEEP, "--out", str(tmp_path / "s.csv"), "--scheduler", address),
                    "--scheduler", *words)
    assert not (tmp_path / "s.csv").exists()


def test_a_scheduler_that_does_not_answer_is_one_line_naming_it(tmp_path):
    pytest.importorskip("distributed")
    import socket

    with socket.socket() as s:  # a free port nobody listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    one_line_exit_2(cli(*SWEEP, "--out", str(tmp_path / "s.csv"), "--scheduler",
                        f"tcp://127.0.0.1:{port}"),
                    f"cannot reach the Dask scheduler at 'tcp://127.0.0.1:{port}'")


@pytest.mark.parametrize("workers", ["0", "1000"])
def test_workers_are_bounded_by_the_cpus(tmp_path, workers):
    bound = str(4 * (os.cpu_count() or 1))
    one_line_exit_2(cli(*SWEEP, "--out", str(tmp_path / "s.csv"), "--workers", workers),
                    "--workers", f"1 … {bound}", f"got {workers}")


@pytest.mark.parametrize("argv,abbreviation", [
    (["sweep", "--cas", "1", "--out", "x.csv"], "--cas"),
    (["simulate", "--case", "1", "--dist", "backward"], "--dist"),
    (["poles", "--al"], "--al"),
])
def test_abbreviated_options_are_refused(argv, abbreviation):
    one_line_exit_2(cli(*argv), abbreviation)


def test_every_parser_refuses_abbreviations():
    from posturelab.cli import SUBCOMMANDS, build_parser

    parser = build_parser()
    assert parser.allow_abbrev is False
    subparsers = next(a for a in parser._actions if a.dest == "command")
    assert set(subparsers.choices) == set(SUBCOMMANDS)
    assert all(p.allow_abbrev is False for p in subparsers.choices.values())


def test_a_closed_pipe_exits_141_without_a_word():
    read_end, write_end = os.pipe()
    os.close(read_end)  # the reader is gone before the first line (| head -0)
    try:
        p = subprocess.run([sys.executable, "-m", "posturelab", "poles", "--all"],
                           stdout=write_end, stderr=subprocess.PIPE, text=True, timeout=120)
    finally:
        os.close(write_end)
    assert p.returncode == 141
    assert p.stderr == ""


def test_a_sweep_refuses_the_viscosity_ratio_and_a_pair_viscosity_together(tmp_path):
    one_line_exit_2(cli("sweep", "--case", "1", "--disturbance", "backward", "--duration", "1",
                        "--vary", "viscosity_ratio=0.1:0.3:2", "--vary",
                        "viscosity:ankle=10:100:2", "--out", str(tmp_path / "v.csv")),
                    "--vary viscosity_ratio or --vary viscosity:ankle, not both")
    assert not (tmp_path / "v.csv").exists()


@pytest.mark.parametrize("command", [
    ["simulate", "--case", "1", "--duration", "0.5", "--platform-profile"],
    ["fit", "--case", "1", "--free", "stiffness:ankle", "--data"],
])
def test_a_csv_row_with_more_fields_than_its_header_is_refused_by_line(tmp_path, command):
    path = tmp_path / "p.csv"
    if command[0] == "simulate":
        path.write_text("time,x_acceleration\n0,0\n0.1,1,5\n0.2,0\n")
    else:
        path.write_text("t,theta1,theta2,theta3\n0,0,0,0\n0.1,0,0,0,7\n0.2,0,0,0\n")
    one_line_exit_2(cli(*command, str(path)), "line 3 has", "fields; the header has")


def test_empty_trailing_fields_are_not_extra_fields(tmp_path):
    from posturelab._files import csv_rows

    rows = list(csv_rows("time,x_acceleration\n0,0,\n0.1,1,,\n", "profile"))
    assert [line for line, _ in rows] == [1, 2, 3]


@pytest.mark.parametrize("posture,word", [("10,0,0", "θ1"), ("0,0,-1.6", "θ3")])
def test_sensitivity_refuses_a_posture_beyond_horizontal(posture, word):
    one_line_exit_2(cli("sensitivity", "--posture", posture), f"--posture {word}",
                    "[-π/2, π/2] rad")


def test_sensitivity_takes_a_posture_up_to_horizontal():
    p = cli("sensitivity", "--posture", "1.5,0,-1.5")
    assert p.returncode == 0, p.stderr


@pytest.mark.parametrize("duration", ["inf", "nan", "-1", "100000"])
def test_a_duration_out_of_range_names_the_range(duration):
    one_line_exit_2(cli("simulate", "--case", "1", "--duration", duration),
                    "--duration: duration [s] must be in (0, 86400] s", f"got {duration}")


PRTS = ["sweep", "--experiment", "prts", "--controller", "peterka-2002", "--tilt",
        "prts:0.035", "--vary", "feedback_delay=0.12:0.18:2"]


def test_too_many_prts_cycles_name_cycles_and_the_longest_run(tmp_path):
    # the posturelab-80 sequence at its 0.25 s state: an 80 × 0.25 = 20 s cycle
    one_line_exit_2(cli(*PRTS, "--cycles", "100000", "--out", str(tmp_path / "x.csv")),
                    "--cycles 100000", "--discard-cycles 1", "the 20 s cycle = 2e+06 s",
                    "exceeds the longest run, 86,400 s")


def test_a_one_link_output_names_only_com_angle_and_theta1(tmp_path):
    p = cli(*PRTS, "--output", "theta7", "--out", str(tmp_path / "x.csv"))
    one_line_exit_2(p, "--output", "must be com_angle or theta1, got 'theta7'")
    assert "…" not in p.stderr


def test_output_choices_read_naturally_for_every_body():
    from posturelab.frequency.experiment import output_choices

    assert output_choices(1) == "com_angle or theta1"
    assert output_choices(2) == "com_angle, theta1 or theta2"
    assert output_choices(3) == "com_angle or theta1 … theta3"


def test_the_stiffness_map_names_the_delayed_axes_with_their_pair(tmp_path):
    one_line_exit_2(cli("stability-map", "--case", "1", "--x", "stiffness:ankle:0:2000",
                        "--y", "stiffness:hip:0:1000", "--resolution", "301",
                        "--feedback-delay", "0.01", "--out", str(tmp_path / "m.png")),
                    "active_stiffness:PAIR:LO:HI", "active_viscosity:PAIR:LO:HI")


@pytest.mark.parametrize("argv", [["--torque-limits", "-5,inf,inf"],
                                  ["--torque-limits=-5,inf,inf"]])
def test_a_negative_torque_limit_is_refused_with_the_range(argv):
    one_line_exit_2(cli("simulate", "--case", "1", *argv),
                    "--torque-limits [N·m] must each be in (0, inf]", "got '-5'")


@pytest.mark.parametrize("engine,advice,not_advice", [
    ("compiled", "the Radau method that ran is already implicit", "such as Radau"),
    ("reference", "an implicit method such as Radau", "already implicit"),
])
def test_a_spent_step_budget_advises_for_the_method_that_ran(engine, advice, not_advice):
    p = cli("simulate", "--case", "1", "--disturbance", "backward", "--duration", "1",
            "--max-steps", "10", "--engine", engine)
    outcome = p.stdout.splitlines()[0]
    assert "the step budget of 10 integrator steps ran out" in outcome, p.stdout
    assert advice in outcome and not_advice not in outcome


@pytest.mark.parametrize("description", ["", 'description = "my run"\n'])
def test_a_scenario_run_prints_its_outcome_first_and_no_empty_line(tmp_path, description):
    path = tmp_path / "my-run.toml"
    path.write_text(f'{description}duration = 1.0\n[body]\npreset = "paper"\n[muscles]\n'
                    'case = "1"\n[disturbance]\ntype = "velocity-step"\n'
                    'direction = "backward"\nspeed = 1.0\n')
    p = cli("simulate", "--scenario", str(path))
    assert p.returncode == 0, p.stderr
    lines = p.stdout.splitlines()
    assert lines[0].startswith("outcome: ")
    assert all(line.strip() for line in lines)
    assert ("my run" in lines[1]) == bool(description)


def test_the_api_refuses_an_experiment_longer_than_the_longest_run_before_running():
    from posturelab.errors import ParameterError
    from posturelab.frequency.experiment import check_length

    check_length(4319, 1, 20.0)  # 86,400 s exactly
    with pytest.raises(ParameterError, match=r"cycles 4320 \(\+ discard 1\) × the 20 s cycle"):
        check_length(4320, 1, 20.0)
