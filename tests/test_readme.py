"""Every ``$ posturelab …`` command of the README runs as written (exit 0, or 1 only where
the README says the run fails), in a fresh folder holding the few input files the README
assumes a reader has (a measured profile ``lab.csv``, a scenario ``my-run.toml``, a second
run ``other.csv`` and measured angles ``measured.csv``). The Python snippet runs too."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from importlib import resources
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"


def readme_commands() -> list[str]:
    text = README.read_text(encoding="utf-8")
    commands = []
    for block in re.findall(r"```console\n(.*?)```", text, re.S):
        current = None
        for line in block.split("\n"):
            if line.startswith("$ "):
                current = line[2:]
            elif current is not None and line.startswith("      "):
                current += " " + line.strip()
            else:
                continue
            if current.rstrip().endswith("\\"):
                current = current.rstrip()[:-1]
                continue
            commands.append(re.sub(r"\s+#.*$", "", current).strip())
            current = None
    return commands


def readme_python() -> str:
    text = README.read_text(encoding="utf-8")
    return "\n".join(re.findall(r"```python\n(.*?)```", text, re.S))


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    d = tmp_path_factory.mktemp("readme")
    (d / "lab.csv").write_text("time [s],x_acceleration [m/s²]\n" + "".join(
        f"{k * 0.01:.2f},{(-2.0 if 10 <= k < 30 else 2.0 if 30 <= k < 50 else 0.0)}\n"
        for k in range(300)))
    builtin = resources.files("posturelab.scenarios.builtin") / "paper-backward-case1.toml"
    shutil.copyfile(str(builtin), d / "my-run.toml")
    subprocess.run([sys.executable, "-m", "posturelab.recordings.example",
                    str(d / "lab-trial.c3d")], check=True, capture_output=True)
    for name, case in (("other.csv", "3"), ("measured.csv", "1")):
        subprocess.run([sys.executable, "-m", "posturelab", "simulate", "--case", case,
                        "--disturbance", "backward", "--duration", "2", "--sample-rate", "100",
                        "--engine", "compiled", "--out", str(d / name)], check=True,
                       capture_output=True)
    return d


def test_the_readme_has_its_commands():
    commands = readme_commands()
    assert len(commands) >= 25
    assert all(c.startswith("posturelab ") for c in commands)


def test_every_readme_command_runs_as_written(folder):
    """Every command, in the README's order in one folder (a later command reads what an
    earlier one wrote, so they run in one test, whatever runs the suite in parallel); every
    failure is reported, not only the first."""
    import shlex

    failures = []
    for command in readme_commands():
        if command.startswith("posturelab explore"):
            _serves_the_explorer(shlex.split(command), folder)
            continue
        p = subprocess.run([sys.executable, "-m", *shlex.split(command)], cwd=folder,
                           capture_output=True, text=True, timeout=600)
        if p.returncode != 0 or "Traceback" in p.stderr:
            failures.append(f"{command}\n{p.stderr[-2000:]}")
    assert not failures, "\n\n".join(failures)


def test_the_readme_python_runs(folder):
    p = subprocess.run([sys.executable, "-c", readme_python()], cwd=folder,
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr[-2000:]


def _serves_the_explorer(argv: list[str], folder: Path) -> None:
    """The explorer serves until stopped: start it (on a free port, without opening a
    browser), load its page, then stop it as Ctrl-C would."""
    import signal
    import urllib.request

    pytest.importorskip("flask")
    p = subprocess.Popen([sys.executable, "-m", *argv, "--port", "0", "--no-browser"],
                         cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        line = p.stdout.readline()
        url = re.search(r"http://127\.0\.0\.1:\d+/", line)
        assert url, line + p.stderr.read()
        with urllib.request.urlopen(url.group(0), timeout=30) as page:
            assert page.status == 200 and b"posturelab explore" in page.read()
    finally:
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=30)
    assert p.returncode == 0, err
    assert "Traceback" not in err and "stopped" in out
