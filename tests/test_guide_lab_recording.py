"""docs/guide/lab-recording.md: every command of its ``bash`` blocks runs, in order, as a
user would run it (a shell in an empty folder, posturelab on PATH)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from posturelab.model.controllers import get_controller

GUIDE = Path(__file__).resolve().parents[1] / "docs" / "guide" / "lab-recording.md"


def commands() -> list[str]:
    """The guide's shell commands, continuation lines joined."""
    blocks = re.findall(r"```bash\n(.*?)```", GUIDE.read_text(encoding="utf-8"), re.S)
    out = []
    for block in blocks:
        out += [c.strip() for c in block.replace("\\\n", " ").splitlines() if c.strip()]
    return out


def test_the_guide_has_its_commands():
    cmds = commands()
    assert any(c.startswith("posturelab convert prts_trial.c3d") for c in cmds)
    assert any(c.startswith("posturelab fit-frf") for c in cmds)
    assert (GUIDE.parent.parent / "images" / "lab-recording-fit.png").is_file()


def test_every_command_of_the_guide_runs(tmp_path):
    import posturelab as pl

    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}"
           f"{os.environ.get('PATH', '')}"}
    outputs = {}
    for cmd in commands():
        done = subprocess.run(["bash", "-c", cmd], cwd=tmp_path, env=env, capture_output=True,
                              text=True, timeout=300)
        assert done.returncode == 0, (cmd, done.stdout, done.stderr)
        outputs[cmd.split()[1] if cmd.startswith("posturelab") else cmd] = done.stdout
    for name in ("trial.csv", "bode.png", "fit.png", "lab.csv", "lab-trial.csv"):
        assert (tmp_path / name).is_file(), name
    # the fit recovers the simulated subject (the file's truth: peterka-2002 on paper-1link)
    body = pl.get_body("paper-1link")
    pair = get_controller("peterka-2002").muscles(body).pairs[0]
    text = outputs["fit-frf"]
    found = {m[0]: float(m[1]) for m in re.findall(r"^\s+(\S+)\s+([-\d.e+]+) ±", text, re.M)}
    assert found["active_stiffness:ankle"] == pytest.approx(pair.active_stiffness, rel=0.01)
    assert found["active_viscosity:ankle"] == pytest.approx(pair.active_viscosity, rel=0.01)
    assert found["feedback_delay"] == pytest.approx(0.15, rel=0.01)
