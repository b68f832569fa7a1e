"""`posturelab simulate` from the command line: outputs, JSON, and bad input."""

import csv
import json
import subprocess
import sys

import pytest

from posturelab.cli import main

FIRST = ["t", "theta1", "theta2", "theta3", "omega1", "omega2", "omega3"]


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_simulate_csv_and_json(tmp_path, capsys):
    out = tmp_path / "run.csv"
    code, stdout, err = run(capsys, "simulate", "--case", "1", "--disturbance", "backward",
                            "--duration", "5", "--out", str(out), "--json")
    assert code == 0, err
    summary = json.loads(stdout)
    assert set(summary) == {"outcome", "settling_time", "fall_time", "fall_reason",
                            "final_lean", "final_rate", "outcome_message", "fell", "status",
                            "message", "max_abs_theta", "final_state", "hip_fraction",
                            "engine", "linear_stability", "perturbation_end", "steady_from",
                            "steady_rms_theta", "steady_peak_theta", "steady_rms_cop",
                            "steady_peak_cop"}
    assert summary["engine"] == "compiled"  # the default
    assert summary["outcome"] == "recovered" and 0 < summary["settling_time"] < 5
    assert summary["linear_stability"]["stable"] is True
    assert 0.0 <= summary["hip_fraction"] <= 1.0
    assert summary["fell"] is False and summary["fall_time"] is None
    assert summary["status"] == "completed"
    assert len(summary["max_abs_theta"]) == 3 and len(summary["final_state"]) == 6
    assert all(abs(x) < 1e-2 for x in summary["final_state"][:3])
    with out.open() as fh:
        rows = list(csv.reader(fh))
    assert rows[0][:7] == FIRST
    assert len(rows) == 1 + 5001  # 1 kHz for 5 s, both ends included
    assert [float(x) for x in rows[1][1:4]] == [0.1, -0.1, 0.1]


def test_simulate_forward_case2_reports_fall(capsys):
    code, stdout, _ = run(capsys, "simulate", "--case", "2", "--disturbance", "forward", "--json")
    s = json.loads(stdout)
    assert code == 0 and s["fell"] is True and s["status"] == "fell"
    assert 0.5 < s["fall_time"] < 3


def test_simulate_profile_starts_upright(tmp_path, capsys):
    prof = tmp_path / "p.csv"
    prof.write_text("time,x_acceleration\n0,0\n0.1,-3\n0.2,0\n")
    code, stdout, err = run(capsys, "simulate", "--case", "1", "--platform-profile", str(prof),
                            "--duration", "1", "--json")
    assert code == 0, err
    s = json.loads(stdout)
    assert s["max_abs_theta"][0] > 1e-3


def test_simulate_builtin_and_scenario(tmp_path, capsys):
    code, stdout, _ = run(capsys, "simulate", "--builtin", "paper-forward-case3", "--json")
    assert code == 0 and json.loads(stdout)["fell"] is False
    sc = tmp_path / "s.toml"
    sc.write_text('duration = 1\n[muscles]\ncase = "3"\n')
    code, stdout, _ = run(capsys, "simulate", "--scenario", str(sc), "--json")
    assert code == 0


BAD = [
    (["simulate", "--case", "1", "--disturbance", "backward", "--duration", "-1"], "duration"),
    (["simulate", "--case", "1", "--disturbance", "sideways"], "invalid choice"),
    (["simulate", "--case", "1", "--disturbance", "backward", "--out", "/nonexistent/r.csv"],
     "does not exist"),
    (["simulate", "--disturbance", "backward"], "--case"),
    (["simulate", "--case", "1", "--initial-posture", "0.1,0.2"], "--initial-posture"),
    (["simulate", "--builtin", "paper-forward-case1", "--case", "2"], "cannot be combined"),
    (["simulate", "--case", "1", "--foot", "0.1,0.2"], "heel"),
]


@pytest.mark.parametrize("argv,needle", BAD)
def test_simulate_bad_input_one_line_exit_2(capsys, argv, needle):
    code, _, err = run(capsys, *argv)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0]


@pytest.mark.parametrize("content,needle", [
    ("time,x_acceleration\n0,0\n0.1,nan\n", "NaN"),
    ("time,x_acceleration\n0,0\n0.2,1\n0.1,0\n", "increasing"),
    ("time,z\n0,0\n0.1,1\n", "x_acceleration"),
])
def test_simulate_bad_profile(tmp_path, capsys, content, needle):
    prof = tmp_path / "p.csv"
    prof.write_text(content)
    out = tmp_path / "run.csv"
    code, _, err = run(capsys, "simulate", "--case", "1", "--platform-profile", str(prof),
                       "--out", str(out))
    assert code == 2 and needle in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


@pytest.mark.parametrize("content,needle", [
    ("duration = 1\n[muscles]\ncase = '1'\nbogus = 3\n", "bogus"),
    ("duration = = 1\n", "TOML"),
])
def test_simulate_bad_scenario(tmp_path, capsys, content, needle):
    sc = tmp_path / "s.toml"
    sc.write_text(content)
    code, _, err = run(capsys, "simulate", "--scenario", str(sc))
    assert code == 2 and needle in err and len(err.strip().splitlines()) == 1


def test_unwritable_out_leaves_nothing(tmp_path, capsys):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        code, _, err = run(capsys, "simulate", "--case", "1", "--disturbance", "backward",
                           "--out", str(ro / "run.csv"))
        if code == 0:  # running as root: permissions are not enforced
            assert (ro / "run.csv").exists()
        else:
            assert code == 2 and len(err.strip().splitlines()) == 1
            assert list(ro.iterdir()) == []
    finally:
        ro.chmod(0o700)


def test_out_is_a_directory(tmp_path, capsys):
    code, _, err = run(capsys, "simulate", "--case", "1", "--out", str(tmp_path))
    assert code == 2 and "directory" in err


def test_subprocess_error_has_no_traceback(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "posturelab", "simulate", "--case", "1", "--disturbance",
         "backward", "--duration", "-2"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def _simulate(*args):
    return subprocess.run([sys.executable, "-m", "posturelab", "simulate", *args],
                          capture_output=True, text=True, timeout=300)


def test_simulate_says_which_engine_ran():
    """The compiled engine is the default; --engine reference is the independent check, and
    both say which one ran, in JSON and in words, with the same outcome."""
    common = ["--case", "2", "--disturbance", "forward", "--duration", "2"]
    runs = {}
    for engine in ("compiled", "reference"):
        proc = _simulate(*common, "--json", *(["--engine", engine] if engine == "reference"
                                               else []))
        assert proc.returncode == 0, proc.stderr
        runs[engine] = json.loads(proc.stdout)
        assert runs[engine]["engine"] == engine
    assert runs["compiled"]["fell"] and runs["reference"]["fell"]
    # both at the scenario's tolerances (rtol 1e-8): the same fall within 1e-6 s
    assert runs["compiled"]["fall_time"] == pytest.approx(runs["reference"]["fall_time"],
                                                          abs=1e-6)
    text = _simulate(*common)
    assert text.returncode == 0 and "engine: compiled" in text.stdout.splitlines()


def test_scenario_method_the_compiled_engine_lacks_is_refused(tmp_path):
    """A scenario that names DOP853 runs on the reference engine; on the compiled engine (the
    default) it is refused in one line naming the method, instead of being dropped."""
    from importlib import resources

    text = (resources.files("posturelab.scenarios") / "builtin" / "paper-forward-case2.toml"
            ).read_text(encoding="utf-8")
    path = tmp_path / "dop.toml"
    path.write_text(text + '\n[solver]\nmethod = "DOP853"\n', encoding="utf-8")
    proc = _simulate("--scenario", str(path), "--duration", "0.5")
    assert proc.returncode == 2 and proc.stdout == ""
    assert len(proc.stderr.strip().splitlines()) == 1
    assert "solver.method 'DOP853'" in proc.stderr and "--engine reference" in proc.stderr
    proc = _simulate("--scenario", str(path), "--duration", "0.5", "--engine", "reference")
    assert proc.returncode == 0, proc.stderr
    path.write_text(text + '\n[solver]\nmethod = "RK45"\n', encoding="utf-8")
    proc = _simulate("--scenario", str(path), "--duration", "0.5", "--json")
    assert proc.returncode == 0 and json.loads(proc.stdout)["engine"] == "compiled"
