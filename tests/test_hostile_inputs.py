"""Hostile input, as real subprocesses: absurd platform accelerations, an output naming an
input, messages that name the option and the value as given."""

from __future__ import annotations

import shutil
import sys

import numpy as np
import pytest

from _cli import cli, one_line_exit_2
from posturelab.errors import ParameterError
from posturelab.model.platform import (
    MAX_PLATFORM_ACCELERATION,
    HalfSinePulse,
    MeasuredProfile,
    SumOfSines,
)

PROFILE = "time,x_acceleration\n0,0\n0.1,1\n0.2,0\n"


@pytest.mark.parametrize("value", ["1e300", "-1e300", "1000.5"])
def test_an_absurd_profile_acceleration_is_one_line_with_its_line(tmp_path, value):
    path = tmp_path / "p.csv"
    path.write_text(f"time,x_acceleration\n0,0\n0.1,{value}\n0.2,0\n")
    for engine in ("reference", "compiled"):
        one_line_exit_2(cli("simulate", "--case", "1", "--platform-profile", str(path),
                            "--duration", "0.5", "--engine", engine),
                        "line 3", "x_acceleration", "1000 m/s²")


def test_profile_samples_closer_than_a_microsecond_are_refused(tmp_path):
    path = tmp_path / "p.csv"
    path.write_text("time,x_acceleration\n0,0\n1e-300,1\n0.1,0\n")
    p = cli("simulate", "--case", "1", "--platform-profile", str(path), "--duration", "0.5")
    one_line_exit_2(p, "line 3", "at least 1e-06 s")
    assert "tilt" not in p.stderr
    with pytest.raises(ParameterError, match="samples 1 and 2 are 1e-07 s apart"):
        MeasuredProfile(np.array([0.0, 1e-7]), np.zeros(2))


def test_platform_accelerations_are_bounded_in_the_api():
    assert MAX_PLATFORM_ACCELERATION == 1000.0
    t = np.array([0.0, 0.1, 0.2])
    MeasuredProfile(t, np.array([0.0, 1000.0, 0.0]))  # the bound itself is allowed
    with pytest.raises(ParameterError, match=r"acceleration_y \[m/s²\] \(sample 2\)"):
        MeasuredProfile(t, np.zeros(3), np.array([0.0, -1e300, 0.0]))
    with pytest.raises(ParameterError, match="peak_acceleration"):
        HalfSinePulse(2000.0, 0.1)
    with pytest.raises(ParameterError, match="sum of"):
        SumOfSines((600.0, 600.0), (1.0, 2.0))


def test_a_profile_is_zero_after_its_last_sample():
    profile = MeasuredProfile(np.array([0.0, 1.0]), np.array([2.0, 2.0]))
    assert profile.acceleration(np.array([0.5, 1.0, 1.0 + 1e-9, 5.0]))[:, 0].tolist() == \
        [2.0, 2.0, 0.0, 0.0]


@pytest.mark.parametrize("speed", ["25", "-3", "0"])
def test_speed_is_named_with_the_value_as_given(speed):
    p = cli("simulate", "--case", "1", "--disturbance", "backward", f"--speed={speed}",
            "--duration", "0.1")
    one_line_exit_2(p, "--speed [m/s] must be in (0, 20]", f"got {speed}")


def test_speed_without_a_step_is_refused():
    one_line_exit_2(cli("simulate", "--case", "1", "--speed", "3", "--duration", "0.1"),
                    "--speed", "--disturbance backward or forward")


@pytest.mark.parametrize("option,value", [("--duration", "1e9"), ("--rtol", "5"),
                                          ("--sample-rate", "0"), ("--max-steps", "0"),
                                          ("--time-limit", "-3"), ("--max-link-angle", "9"),
                                          ("--tilt", "sine:9:1")])
def test_run_settings_name_their_option(option, value):
    p = cli("simulate", "--case", "1", "--disturbance", "backward", "--duration", "0.1",
            f"{option}={value}")
    one_line_exit_2(p, f"{option}: ")


def _run_csv(tmp_path, name):
    path = tmp_path / name
    p = cli("simulate", "--case", "1", "--disturbance", "backward", "--duration", "0.2",
            "--engine", "compiled", "--out", str(tmp_path / "run.csv"))
    assert p.returncode == 0, p.stderr
    shutil.copy(tmp_path / "run.csv", path)
    return path


def _commands(tmp_path):
    """(command line, input) pairs whose output names the input by another spelling."""
    profile = tmp_path / "p.csv"
    profile.write_text(PROFILE)
    run_png = _run_csv(tmp_path, "a.png")
    run_json = _run_csv(tmp_path, "d.json")
    frf_png = tmp_path / "f.png"
    frf_png.write_text("t,tilt,com_angle\n0,0,0\n")
    (tmp_path / "link.csv").symlink_to(profile)
    scenario = tmp_path / "s.toml"
    scenario.write_text('duration = 1.0\n[muscles]\ncase = "1"\n')
    run_csv = _run_csv(tmp_path, "x.csv")
    return [
        (["simulate", "--scenario", "s.toml", "--out", "s.toml"], scenario),
        (["sweep", "--scenario", "s.toml", "--vary", "stiffness:ankle=1:2:2", "--out", "s.toml"],
         scenario),
        (["compare", "x.csv", "--plot", "x.csv"], run_csv),
        (["fit", "--data", "x.csv", "--case", "1", "--disturbance", "backward", "--free",
          "ankle", "--report", "x.csv"], run_csv),
        (["simulate", "--case", "1", "--platform-profile", "p.csv", "--out", "./p.csv"],
         profile),
        (["simulate", "--case", "1", "--platform-profile", "link.csv", "--out", "p.csv"],
         profile),
        (["sweep", "--case", "1", "--platform-profile", "p.csv", "--vary",
          "stiffness:ankle=100:200:2", "--out", "p.csv"], profile),
        (["compare", "a.png", "--plot", "a.png"], run_png),
        (["fit", "--data", "d.json", "--case", "1", "--disturbance", "backward", "--free",
          "ankle", "--report", "d.json"], run_json),
        (["frf", "--data", "f.png", "--stimulus", "tilt", "--response", "com_angle",
          "--cycle-length", "20", "--plot", "f.png"], frf_png),
        (["fit-frf", "--data", "f.png", "--case", "1", "--free", "active_stiffness",
          "--plot", "f.png"], frf_png),
    ]


def test_an_output_never_overwrites_an_input(tmp_path):
    for argv, source in _commands(tmp_path):
        before = source.read_bytes()
        p = cli(*argv, cwd=tmp_path)
        one_line_exit_2(p, "is the input", "an output never overwrites an input")
        assert source.read_bytes() == before, argv


def test_the_scenario_schema_takes_the_prts_register_seed(tmp_path):
    from posturelab.model.tilt import PETERKA_SEED, PETERKA_TAPS
    from posturelab.scenarios import load_scenario

    path = tmp_path / "prts.toml"
    path.write_text("duration = 1.0\n[muscles]\ncase = '1'\n[tilt]\ntype = 'prts'\n"
                    "amplitude = 0.02\nstate_duration = 0.25\nregisters = 4\n"
                    f"taps = {list(PETERKA_TAPS)}\nseed = [2, 0, 0, 1]\n")
    tilt = load_scenario(path).tilt
    assert tilt.seed == (2, 0, 0, 1) and tilt.taps == PETERKA_TAPS
    assert tilt.seed != PETERKA_SEED
    p = cli("simulate", "--scenario", str(path), "--engine", "compiled", "--duration", "0.5")
    assert p.returncode == 0, p.stderr
    path.write_text(path.read_text().replace("seed = [2, 0, 0, 1]", "seed = 1000"))
    one_line_exit_2(cli("simulate", "--scenario", str(path)), "tilt.seed must be an array")


def test_table_ii_caption_counts_its_rows():
    from posturelab.paper.printed import TABLE_II_PRINTED, TABLE_II_SOURCE

    assert len(TABLE_II_PRINTED) == 9 and "nine rows" in TABLE_II_SOURCE
    assert "6a" in TABLE_II_PRINTED and "6b" in TABLE_II_PRINTED
    assert "the seven cases of Table I" in TABLE_II_SOURCE


def test_delay_margin_json_carries_its_units():
    import json

    p = cli("delay-margin", "--case", "1", "--json")
    assert p.returncode == 0, p.stderr
    obj = json.loads(p.stdout)
    assert obj["units"] == {"delay_margin": "s", "crossing_frequency": "rad/s"}
    assert obj["delay_margin"] > 0 and obj["crossing_frequency"] > 0


def test_the_readme_commands_write_distinct_files():
    import collections
    import re
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from test_readme import readme_commands

    written = collections.Counter(m.group(1) for command in readme_commands()
                                  for m in re.finditer(r"--out[= ](\S+)", command))
    assert written and [name for name, n in written.items() if n > 1] == []


def _write_run(path, t, theta):
    lines = ["t,theta1,theta2,omega1,omega2"]
    lines += [f"{float(a)!r},{float(b)!r},{float(c)!r},0,0"
              for a, (b, c) in zip(t, theta, strict=True)]
    path.write_text("\n".join(lines) + "\n")


def test_compare_gives_the_differences_against_the_first_run(tmp_path):
    import json

    t = np.linspace(0.0, 2.0, 201)
    first = np.column_stack([np.sin(t), 0.5 * np.cos(t)])
    # the second: shorter, on another grid, link 1 off by 0.1·t, link 2 by a constant 0.02
    t2 = np.linspace(0.0, 1.5, 76)
    second = np.column_stack([np.sin(t2) + 0.1 * t2, 0.5 * np.cos(t2) - 0.02])
    _write_run(tmp_path / "a.csv", t, first)
    _write_run(tmp_path / "b.csv", t2, second)
    p = cli("compare", "a.csv", "b.csv", "--json", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    (d,) = json.loads(p.stdout)["differences"]
    assert d["label"] == "b.csv" and d["against"] == "a.csv"
    assert d["common_time"] == [0.0, 1.5]
    # largest at t = 1.5 s for link 1; linear interpolation of sin over 0.02 s steps
    assert d["max_abs_theta_difference"] == pytest.approx([0.15, 0.02], abs=5e-5)
    assert d["peak_difference"] == pytest.approx(  # the sampled peaks: sin(1.57) for link 1
        [np.sin(1.5) + 0.15 - np.sin(1.57), 0.5 - 0.02 - 0.5], abs=1e-12)
    assert d["end_time_difference"] == pytest.approx(-0.5)
    assert d["units"]["max_abs_theta_difference"] == "rad"
    text = cli("compare", "a.csv", "b.csv", cwd=tmp_path).stdout
    assert "b.csv − a.csv: max |Δθ| [rad] 0.1500, 0.0200 over t = 0–1.5 s" in text


@pytest.mark.parametrize("argv, words", [
    (["simulate", "--case", "1", "--active-stiffness", "1e12,0,0,0,0"],
     "--active-stiffness: muscle pair 'ankle' active stiffness must be in [0, 1e+08]"),
    (["simulate", "--stiffness", "1e12,0,0,0,0"],
     "--stiffness: muscle pair 'ankle' stiffness must be in [0, 1e+08]"),
    (["simulate", "--case", "1", "--viscosity", "-1,0,0,0,0"], "--viscosity: "),
    (["simulate", "--height", "9", "--mass", "80", "--stiffness", "100,100,100,100,100"],
     "--height: height [m] must be in [0.5, 2.5]"),
    (["poles", "--stiffness", "-5,1,1,1,1"], "--stiffness: "),
    (["sweep", "--case", "1", "--disturbance", "backward", "--vary", "stiffness:ankle=100:200:2",
      "--out", "never.csv", "--duration", "1e9"], "--duration: duration [s]"),
    (["sweep", "--experiment", "prts", "--controller", "peterka-2002", "--tilt", "prts:0.035",
      "--vary", "feedback_delay=0.1:0.2:2", "--out", "never.csv", "--cycles", "0"],
     "--cycles: cycles must be an integer >= 2, got 0"),
    (["sweep", "--experiment", "prts", "--controller", "peterka-2002", "--tilt", "prts:0.035",
      "--vary", "feedback_delay=0.1:0.2:2", "--out", "never.csv", "--sensor-noise", "-1"],
     "--sensor-noise: "),
    (["fit", "--data", "never.csv", "--case", "1", "--free", "ankle", "--duration", "3"],
     "fit: --duration is set by --data"),
])
def test_deeper_checks_name_the_option_as_typed(tmp_path, argv, words):
    one_line_exit_2(cli(*argv, cwd=tmp_path), words)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
@pytest.mark.parametrize("engine", ["reference", "compiled"])
def test_a_run_that_fails_before_its_first_sample_keeps_its_initial_state(engine):
    """The cause of the old traceback ("need at least one array to concatenate", an
    IndexError in the compiled engine): a run that ends before its first sample. The bound
    keeps such accelerations out; past it (here forced into the frozen profile), the run
    is failed with its initial state as its one sample."""
    import posturelab as pl

    profile = MeasuredProfile(np.array([0.0, 0.1, 0.2]), np.array([0.0, 1.0, 0.0]))
    object.__setattr__(profile, "acceleration_x", np.array([1e300, 1e300, 0.0]))
    run = pl.simulate(pl.paper_body(), pl.paper_muscles("1"), profile, 1.0, engine=engine)
    assert run.status == "failed" and run.outcome.kind == "failed"
    assert run.time.tolist() == [0.0]
    assert run.final_state.tolist() == [0.0] * 6


def test_json_with_a_nan_is_whole_and_says_null(capsys):
    """A number JSON cannot hold (NaN, inf: an undefined bound, a CoP with the foot unloaded)
    is written as null, in one whole object: never half an object, never bare NaN."""
    import json

    from posturelab.cli._common import print_json

    print_json({"first": [1.0, 2.0] * 1000, "later": float("nan"), "far": float("inf")})
    out = capsys.readouterr().out
    assert out.count("\n") == 1 and "NaN" not in out and "Infinity" not in out
    obj = json.loads(out)
    assert obj["later"] is None and obj["far"] is None and len(obj["first"]) == 2000
    print_json({"fine": 1.0})
    assert capsys.readouterr().out == '{"fine": 1.0}\n'
