"""``posturelab delay-margin`` with a one-sided pair: the margin is of the engaged side
only, and a slack side unstable at every delay is said so plainly (text and JSON)."""

import json
import os
import subprocess
import sys

import posturelab as pl


def run_cli(*argv):
    env = dict(os.environ, PYTHONIOENCODING="utf-8")
    return subprocess.run([sys.executable, "-m", "posturelab", *argv], capture_output=True,
                          encoding="utf-8", env=env, timeout=120, check=False)


def test_the_slack_side_unstable_at_every_delay_is_said_plainly():
    """Case 1 with the one-sided gastrocnemius: slack, the gains are case 2's, whose
    stiffness does not hold the load (a real root 1.17 1/s at τ = 0). The verdict at
    several delays agrees: that side is unstable at each."""
    args = ("delay-margin", "--case", "1", "--gastrocnemius", "one-sided")
    proc = run_cli(*args, "--json")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["delay_margin"] is not None  # of the engaged side
    (side,) = out["unstable_sides"]
    assert side["slack"] == ["gastrocnemius"] and side["engaged"] == []
    assert side["unstable_at_every_delay"] is True
    assert abs(side["rightmost_root_without_delay"]["re"] - 1.169) < 1e-3
    muscles = pl.paper_muscles("1", gastrocnemius="one-sided")
    for delay in (0.01, 0.1, 0.3):
        verdict = pl.upright_verdict(pl.paper_body(), muscles, delay)
        assert verdict.side(engaged=False).status == "unstable", delay
    text = run_cli(*args).stdout
    assert text.splitlines()[0].startswith(
        "upright is unstable while gastrocnemius slack, whatever the delay")
    assert "only while gastrocnemius engaged" in text
    assert "of the side where the one-sided pairs are engaged" not in text


def test_two_sided_pairs_have_no_unstable_sides():
    proc = run_cli("delay-margin", "--case", "1", "--json")
    assert proc.returncode == 0, proc.stderr
    assert "unstable_sides" not in json.loads(proc.stdout)
    assert "unstable while" not in run_cli("delay-margin", "--case", "1").stdout
