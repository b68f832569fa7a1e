"""Smoke test of an installed posturelab (a wheel or an sdist in a fresh environment).

Run it with that environment's python from a folder outside the checkout, e.g.
``/tmp/venv/bin/python /path/to/checkout/.ci/smoke.py`` (``.ci/run`` does). It checks that
posturelab is imported from the environment, not the checkout, then runs every subcommand's
``--help``, one compiled simulation, ``frf`` on a short simulated PRTS trial, and ``explore``
started on a free port, asked for its page and stopped with SIGINT. Each step prints one
line; the first failure stops it with exit 1. Needs ``posturelab[explore]`` (or ``[all]``).
"""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

BIN = Path(sys.executable).parent
POSTURELAB = str(BIN / "posturelab")
CHECKOUT = Path(__file__).resolve().parent.parent


def say(message: str) -> None:
    print(f"smoke: {message}", flush=True)


def fail(message: str) -> None:
    print(f"smoke: FAILED: {message}", file=sys.stderr, flush=True)
    sys.exit(1)


def posturelab(*args: str, cwd: Path, timeout: float = 600) -> str:
    """Run the installed console script; its standard output (fails on a non-zero exit)."""
    done = subprocess.run([POSTURELAB, *args], cwd=cwd, capture_output=True, text=True,
                          timeout=timeout)
    if done.returncode != 0:
        fail(f"posturelab {' '.join(args)} exited {done.returncode}: {done.stderr.strip()}")
    return done.stdout


def check_installed() -> None:
    """posturelab comes from this environment's site-packages, not from the checkout."""
    import posturelab

    where = Path(posturelab.__file__).resolve()
    if CHECKOUT in where.parents or "site-packages" not in where.parts:
        fail(f"posturelab is imported from {where}, not from an installed environment")
    say(f"posturelab {posturelab.__version__} from {where.parent}")


def check_help(cwd: Path) -> None:
    from posturelab.cli import SUBCOMMANDS

    posturelab("--help", cwd=cwd)
    for command in SUBCOMMANDS:
        if "usage: posturelab" not in posturelab(command, "--help", cwd=cwd):
            fail(f"posturelab {command} --help printed no usage")
    say(f"--help of posturelab and its {len(SUBCOMMANDS)} subcommands")


def check_compiled_simulation(cwd: Path) -> None:
    out = posturelab("simulate", "--case", "1", "--disturbance", "backward", "--duration", "5",
                     "--engine", "compiled", "--json", cwd=cwd)
    result = json.loads(out)
    if result.get("outcome") != "recovered":
        fail(f"compiled simulation: outcome {result.get('outcome')!r}, expected 'recovered'")
    say("compiled simulation (case 1, backward step): recovered")


def check_frf(cwd: Path) -> None:
    posturelab("simulate", "--controller", "peterka-2002", "--tilt", "prts:0.035:0.25",
               "--duration", "60", "--engine", "compiled", "--sample-rate", "50",
               "--out", "trial.csv", cwd=cwd)
    out = posturelab("frf", "--data", "trial.csv", "--stimulus", "tilt", "--response",
                     "com_angle", "--cycle-length", "20", "--discard-cycles", "1", "--json",
                     cwd=cwd)
    gain = json.loads(out).get("gain") or []
    if not gain or not all(g > 0 for g in gain):
        fail(f"frf: gains {gain!r}, expected one positive gain per band")
    say(f"frf of a simulated 60 s PRTS trial: {len(gain)} bands")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def check_explore(cwd: Path) -> None:
    port = free_port()
    server = subprocess.Popen([POSTURELAB, "explore", "--no-browser", "--port", str(port)],
                              cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True)
    try:
        deadline = time.monotonic() + 120
        while True:
            if server.poll() is not None:
                fail(f"explore exited {server.returncode}: {server.stderr.read().strip()}")
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=5) as page:
                    if page.status == 200 and b"<html" in page.read().lower():
                        break
            except OSError:
                pass
            if time.monotonic() > deadline:
                fail(f"explore did not answer on port {port} within 120 s")
            time.sleep(0.2)
        server.send_signal(signal.SIGINT)
        out, err = server.communicate(timeout=30)
    finally:
        if server.poll() is None:
            server.kill()
            server.wait()
    if server.returncode != 0 or "stopped" not in out:
        fail(f"explore after SIGINT: exit {server.returncode}, {out.strip()!r} {err.strip()!r}")
    say(f"explore served its page on port {port} and stopped on SIGINT")


def main() -> None:
    os.environ.pop("PYTHONPATH", None)
    check_installed()
    with tempfile.TemporaryDirectory(prefix="posturelab-smoke-") as folder:
        cwd = Path(folder)
        check_help(cwd)
        check_compiled_simulation(cwd)
        check_frf(cwd)
        check_explore(cwd)
    say("passed")


if __name__ == "__main__":
    main()
