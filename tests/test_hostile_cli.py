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


def cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "posturelab", *args], capture_output=True,
                          text=True, timeout=120, cwd=cwd)


def one_line_exit_2(p, *words: str) -> None:
    err = p.stderr.strip()
    assert p.returncode == 2, p.stderr
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    for w in words:
        assert w in err, err


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
