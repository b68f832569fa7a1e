"""``posturelab frf`` and ``posturelab frf-model``: the API's numbers, one-line errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import posturelab as pl
from posturelab.cli import main
from posturelab.frequency import estimate_frf, model_frf
from posturelab.frequency.bands import PETERKA_BAND_FREQUENCIES
from posturelab.model.controllers import get_controller
from posturelab.model.tilt import PRTSTilt

KEYS = {"frequency", "frf", "gain", "phase_deg", "coherence", "gain_ci95", "phase_ci95_deg",
        "frf_se", "dof", "response_sign", "sign_convention", "warnings", "harmonic_frequency",
        "harmonic_weight", "frf_covariance"}


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def trial(tmp_path_factory):
    """A simulated PRTS trial written by posturelab simulate (3 cycles of 20 s at 50 Hz)."""
    path = tmp_path_factory.mktemp("frf") / "trial.csv"
    assert main(["simulate", "--controller", "peterka-2002", "--tilt", "prts:0.035",
                 "--duration", "60", "--engine", "compiled", "--sample-rate", "50",
                 "--out", str(path)]) == 0
    return path


def test_frf_json_is_the_estimate_of_the_simulated_trial(capsys, trial):
    code, out, err = run(capsys, "frf", "--data", str(trial), "--stimulus", "tilt",
                         "--response", "com_angle", "--cycle-length", "20",
                         "--discard-cycles", "1", "--json")
    assert code == 0, err
    obj = json.loads(out)
    assert set(obj) == KEYS and len(obj["frequency"]) == 11
    body = pl.get_body("paper-1link")
    preset = get_controller("peterka-2002")
    r = pl.simulate(body, preset.muscles(body), None, 60.0,
                    tilt=PRTSTilt.named("posturelab-80", 0.035),
                    engine="compiled", sample_rate=50.0, rtol=1e-8, atol=1e-10,
                    **preset.run_options())
    est = estimate_frf(r.tilt[:-1], r.com_angle[:-1], 50.0, 20.0, discard_cycles=1,
                       response_sign=-1)
    np.testing.assert_allclose(obj["gain"], est.gain, rtol=1e-9)
    np.testing.assert_allclose(obj["frequency"], PETERKA_BAND_FREQUENCIES, atol=0.005)
    # the model explains the noise-free trial closely (band averaging aside)
    model = model_frf(body, preset.muscles(body), obj["frequency"], **preset.run_options())
    np.testing.assert_allclose(obj["gain"], np.abs(model), rtol=0.1)


def test_frf_model_json_is_model_frf(capsys):
    code, out, _ = run(capsys, "frf-model", "--controller", "icm-pmc5664365", "--bands",
                       "peterka", "--json")
    obj = json.loads(out)
    assert code == 0 and set(obj) == {"frequency", "frf", "gain", "phase_deg",
                                      "sign_convention"}
    assert obj["sign_convention"].startswith("−y/α")
    body = pl.get_body("paper-1link")
    preset = get_controller("icm-pmc5664365")
    H = model_frf(body, preset.muscles(body), obj["frequency"], **preset.run_options())
    np.testing.assert_allclose([complex(z["re"], z["im"]) for z in obj["frf"]], H, rtol=1e-12)
    code, out, _ = run(capsys, "frf-model", "--case", "1", "--input", "translation",
                       "--output", "hip_angle", "--frequencies", "0.1,1,3", "--json")
    H = model_frf(pl.paper_body(), pl.paper_muscles("1"), [0.1, 1, 3], input="translation",
                  output="hip_angle")
    np.testing.assert_allclose(json.loads(out)["gain"], np.abs(H), rtol=1e-12)


def write(path, rows, header="time,tilt,com_angle"):
    path.write_text(header + "\n" + "".join(",".join(map(str, r)) + "\n" for r in rows))
    return path


@pytest.mark.parametrize("case,needle", [
    ("nonuniform", "the time column is not uniform"),
    ("not-whole", "not a whole number of cycles"),
    ("unknown", "has no column 'sway'"),
    ("nan", "NaN and inf are not allowed"),
    ("one-cycle", "at least 2 cycles"),
])
def test_bad_frf_input_is_one_line_and_exit_2(capsys, tmp_path, case, needle):
    t = np.arange(0, 40, 0.1)
    x = np.sin(2 * np.pi * t / 20)
    rows = [[a, b, 0.5 * b] for a, b in zip(t, x, strict=True)]
    response, cycle = "com_angle", "20"
    if case == "nonuniform":
        rows[10][0] += 0.03
    elif case == "not-whole":
        cycle = "15"
    elif case == "unknown":
        response = "sway"
    elif case == "nan":
        rows[5][2] = "nan"
    elif case == "one-cycle":
        rows = rows[:200]
    path = write(tmp_path / "t.csv", rows)
    code, out, err = run(capsys, "frf", "--data", str(path), "--stimulus", "tilt",
                         "--response", response, "--cycle-length", cycle)
    assert code == 2 and out == "" and err.count("\n") == 1 and needle in err, err


def test_fit_frf_recovers_the_preset_from_a_simulated_trial(capsys, trial, tmp_path):
    """From the trial CSV, and from its FRF JSON, the active gains and the delay of the
    simulated preset come back within 1 % (starting 20–40 % off)."""
    start = ["--body", "paper-1link", "--stiffness", "0", "--viscosity", "0",
             "--active-stiffness", "600", "--active-viscosity", "200", "--feedback-delay",
             "0.12"]
    code, out, err = run(capsys, "fit-frf", "--data", str(trial), "--stimulus", "tilt",
                         "--response", "com_angle", "--cycle-length", "20",
                         "--discard-cycles", "1", *start, "--free",
                         "active_stiffness,active_viscosity,feedback_delay", "--json")
    assert code == 0, err
    got = {p["name"]: p["estimate"] for p in json.loads(out)["parameters"]}
    mgh = pl.get_body("paper-1link").load_stiffness
    assert got["active_stiffness:ankle"] == pytest.approx(1.35 * mgh, rel=0.01)
    assert got["active_viscosity:ankle"] == pytest.approx(0.47 * mgh, rel=0.01)
    assert got["feedback_delay"] == pytest.approx(0.15, rel=0.01)
    frf_json = tmp_path / "frf.json"
    frf_json.write_text(_frf_json(trial))
    code, out, err = run(capsys, "fit-frf", "--data", str(frf_json), *start, "--free",
                         "active_stiffness,feedback_delay")
    assert code == 0, err
    assert "active_stiffness" in out and "feedback_delay" in out


def _frf_json(trial) -> str:
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        main(["frf", "--data", str(trial), "--stimulus", "tilt", "--response", "com_angle",
              "--cycle-length", "20", "--discard-cycles", "1", "--json"])
    return buf.getvalue()


def test_bad_fit_frf_requests_are_one_line(capsys, trial):
    code, out, err = run(capsys, "fit-frf", "--data", str(trial), "--free", "active_stiffness",
                         "--controller", "peterka-2002")
    assert code == 2 and "needs --stimulus, --response and --cycle-length" in err
    code, out, err = run(capsys, "fit-frf", "--data", str(trial), "--stimulus", "tilt",
                         "--response", "com_angle", "--cycle-length", "20",
                         "--controller", "peterka-2002", "--free", "elbow")
    assert code == 2 and err.count("\n") == 1 and "unknown FRF fit parameter 'elbow'" in err


def test_the_text_tables_print_the_json_numbers(capsys, trial):
    """The text of frf and frf-model shows, band by band, the numbers their JSON gives."""
    argv = ["frf", "--data", str(trial), "--stimulus", "tilt", "--response", "com_angle",
            "--cycle-length", "20", "--discard-cycles", "1"]
    _, text, _ = run(capsys, *argv)
    _, out, _ = run(capsys, *argv, "--json")
    obj = json.loads(out)
    rows = [line.split() for line in text.splitlines()[2:13]]
    for row, f, g, p, c in zip(rows, obj["frequency"], obj["gain"], obj["phase_deg"],
                               obj["coherence"], strict=True):
        assert row[:4] == [f"{f:.3f}", f"{g:.4g}", f"{p:.1f}", f"{c:.3f}"]
    argv = ["frf-model", "--controller", "peterka-2002", "--bands", "peterka"]
    _, text, _ = run(capsys, *argv)
    _, out, _ = run(capsys, *argv, "--json")
    obj = json.loads(out)
    rows = [line.split() for line in text.splitlines()[2:]]
    assert [r[1] for r in rows] == [f"{g:.4g}" for g in obj["gain"]]
    assert [r[2] for r in rows] == [f"{p:.1f}" for p in obj["phase_deg"]]


def test_simulate_prints_the_hip_fraction_of_its_json(capsys):
    argv = ["simulate", "--case", "1", "--disturbance", "backward", "--duration", "2",
            "--engine", "compiled"]
    _, text, _ = run(capsys, *argv)
    _, out, _ = run(capsys, *argv, "--json")
    assert f"hip fraction (anti-phase leg–trunk mode): {json.loads(out)['hip_fraction']:.3f}" \
        in text


def test_the_figures_of_frf_and_fit_frf_are_written(capsys, trial, tmp_path):
    """--plot and --plot-cycles write images; fit-frf --plot draws every condition with its
    fitted curve, and the curve is the fit's model FRF."""
    bode, cycles, fitted = tmp_path / "b.png", tmp_path / "c.svg", tmp_path / "f.pdf"
    code, out, err = run(capsys, "frf", "--data", str(trial), "--stimulus", "tilt",
                         "--response", "com_angle", "--cycle-length", "20",
                         "--discard-cycles", "1", "--plot", str(bode), "--plot-cycles",
                         str(cycles))
    assert code == 0, err
    assert bode.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and b"<svg" in cycles.read_bytes()[:500]
    assert f"wrote {cycles}" in out
    second = tmp_path / "trial2.csv"  # (one file given twice is refused)
    second.write_bytes(Path(trial).read_bytes())
    code, out, err = run(capsys, "fit-frf", "--data", str(trial), "--data", str(second),
                         "--stimulus", "tilt", "--response", "com_angle", "--cycle-length",
                         "20", "--discard-cycles", "1", "--controller", "peterka-2002",
                         "--free", "active_stiffness", "--plot", str(fitted))
    assert code == 0, err
    assert fitted.read_bytes()[:4] == b"%PDF"
    code, _, err = run(capsys, "frf", "--data", str(trial), "--stimulus", "tilt", "--response",
                       "com_angle", "--cycle-length", "20", "--plot-cycles", "c.txt")
    assert code == 2 and "must end in .png, .svg or .pdf, got 'c.txt'" in err


def test_fit_curves_are_the_fitted_models_frf(trial):
    from posturelab.frequency.data import read_series_csv
    from posturelab.frequency.fit import fit_frf

    fs, cols = read_series_csv(trial, ["tilt", "com_angle"])
    est = estimate_frf(cols["tilt"][:-1], cols["com_angle"][:-1], fs, 20.0, discard_cycles=1,
                       response_sign=-1)
    body = pl.get_body("paper-1link")
    preset = get_controller("peterka-2002")
    fit = fit_frf(body, preset.muscles(body), est, ["active_stiffness"],
                  feedback_delay=preset.feedback_delay)
    (f, h), = fit.curves
    assert f[0] < est.frequency[0] and f[-1] > est.frequency[-1] and f.size == 200
    muscles = preset.muscles(body).with_active_feedback(
        [fit.estimates[0]], preset.muscles(body).active_viscosities)
    np.testing.assert_allclose(h, model_frf(body, muscles, f, **preset.run_options()),
                               rtol=1e-12)


def cli(*args):
    """posturelab as a real subprocess."""
    import subprocess
    import sys

    return subprocess.run([sys.executable, "-m", "posturelab", *args], capture_output=True,
                          text=True, timeout=300)


@pytest.mark.parametrize("extra,needle", [
    (["--bounds", "feedback_delay=0:1e308"],
     "bound feedback_delay HI [s] must be in [0, 1], got 1e+308"),
    (["--bounds", "feedback_delay=-0.1:0.3"],
     "bound feedback_delay LO [s] must be in [0, 1], got -0.1"),
    (["--bounds", "feedback_delai=0:0.3"], "unknown FRF fit parameter 'feedback_delai'"),
    (["--bounds", "feedback_delay=nan:0.3"], "must be finite, got nan:0.3"),
    (["--bounds", "feedback_delay=0:inf"], "must be finite"),
    (["--bounds", "active_viscosity=0:300"], "which is not fitted"),
    (["--free", "active_stiffness,active_stiffness"], "named twice"),
    (["--cycle-length", "inf"], "--cycle-length [s] must be a finite number"),
    (["--cycle-length", "1e300"], "--cycle-length [s] must be in"),
])
def test_hostile_fit_frf_input_is_one_line_and_exit_2(trial, extra, needle):
    args = ["fit-frf", "--data", str(trial), "--stimulus", "tilt", "--response", "com_angle",
            "--cycle-length", "20", "--controller", "peterka-2002", "--free",
            "active_stiffness,feedback_delay", *extra]
    r = cli(*args)
    assert r.returncode == 2 and r.stdout == "" and r.stderr.count("\n") == 1, r.stderr
    assert needle in r.stderr, r.stderr


@pytest.mark.parametrize("content,needle", [
    ("{}", "has no 'frequency'"),
    ("[" * 100000 + "]" * 100000, "nested too deeply"),
    ('{"frequency": [0.1], "gain": [true], "phase_deg": [0]}', "must be a number, got True"),
    ('{"frequency": [0.1], "gain": [1e300], "phase_deg": [0]}', "gain [-] entry 1 must be in"),
    ('{"frequency": [0.1], "gain": [1], "phase_deg": [0], "coherence": [NaN]}',
     "NaN is not a number JSON allows"),
    ('{"frequency": [], "gain": [], "phase_deg": []}', "must have 1 … 10,000 entries"),
    ('{"frequency": [0.1], "gain": [1], "phase_deg": [0], "gain_se": [0.1]}',
     "gain_se and phase_se_deg together"),
])
def test_hostile_frf_json_is_one_line_and_exit_2(tmp_path, content, needle):
    path = tmp_path / "frf.json"
    path.write_text(content)
    r = cli("fit-frf", "--data", str(path), "--controller", "peterka-2002", "--free",
            "active_stiffness")
    assert r.returncode == 2 and r.stdout == "" and r.stderr.count("\n") == 1, r.stderr
    assert needle in r.stderr, r.stderr


def test_frf_states_the_sign_and_warns_near_180_degrees(trial):
    """The default sign is -1 (posturelab's tilt convention) and says so; +1 on posturelab's
    own recording puts the lowest band near 180° with coherence 1: one warning line on
    stderr and in the JSON."""
    base = ["frf", "--data", str(trial), "--stimulus", "tilt", "--response", "com_angle",
            "--cycle-length", "20", "--discard-cycles", "1"]
    r = cli(*base, "--json")
    obj = json.loads(r.stdout)
    assert r.returncode == 0 and obj["response_sign"] == -1 and obj["warnings"] == []
    assert "posturelab's tilt convention" in obj["sign_convention"] and r.stderr == ""
    r = cli(*base, "--response-sign", "+1", "--json")
    obj = json.loads(r.stdout)
    assert obj["response_sign"] == 1 and len(obj["warnings"]) == 1
    assert r.stderr.count("\n") == 1 and "check --response-sign" in r.stderr
    r = cli(*base)
    assert "response × −1" in r.stdout
    r = cli("fit-frf", *base[1:], "--response-sign", "+1", "--controller", "peterka-2002",
            "--free", "active_stiffness", "--json")
    obj = json.loads(r.stdout)
    assert obj["response_sign"] == [1] and "check --response-sign" in obj["warnings"][0]
    assert "check --response-sign" in r.stderr


def test_frf_model_refuses_a_loop_unstable_at_its_delay():
    r = cli("frf-model", "--controller", "peterka-2002", "--feedback-delay", "0.6")
    assert r.returncode == 2 and r.stdout == "" and "not measurable" in r.stderr, r.stderr


def test_fit_frf_takes_gain_and_phase_with_standard_errors(tmp_path):
    """A table of gain and phase (the model's own, at Peterka's band frequencies) with
    standard errors of 1 % and 0.6°: the stiffness comes back inside its interval, and the
    output names the weighting; without standard errors it says 1/|H|."""
    body = pl.get_body("paper-1link")
    preset = get_controller("peterka-2002")
    f = list(PETERKA_BAND_FREQUENCIES)
    H = model_frf(body, preset.muscles(body), f, **preset.run_options())
    table = {"frequency": f, "gain": np.abs(H).tolist(),
             "phase_deg": np.degrees(np.unwrap(np.angle(H))).tolist(),
             "gain_se": (0.01 * np.abs(H)).tolist(), "phase_se_deg": [0.6] * len(f)}
    path = tmp_path / "table.json"
    path.write_text(json.dumps(table))
    start = ["--body", "paper-1link", "--stiffness", "0", "--viscosity", "0",
             "--active-stiffness", "600", "--active-viscosity", "265.07135614",
             "--feedback-delay", "0.15"]
    r = cli("fit-frf", "--data", str(path), *start, "--free", "active_stiffness", "--json")
    obj = json.loads(r.stdout)
    (p,) = obj["parameters"]
    true = preset.muscles(body).active_stiffnesses[0]
    assert obj["weighting"] == "gain-phase" and p["ci95"][0] <= true <= p["ci95"][1]
    del table["gain_se"], table["phase_se_deg"]
    path.write_text(json.dumps(table))
    r = cli("fit-frf", "--data", str(path), *start, "--free", "active_stiffness")
    assert r.returncode == 0 and "relative: no per-band precision given" in r.stdout


@pytest.mark.parametrize("extra,needle", [
    (["--record-rate", "nan"], "--record-rate) [Hz] must be a finite number"),
    (["--record-rate", "inf"], "--record-rate) [Hz] must be a finite number"),
    (["--record-rate", "1e300"], "--record-rate) [Hz] must be in"),
    (["--record-rate", "0.3"], "--record-rate) [Hz] must be in [1, 100000] Hz, got 0.3"),
    (["--record-rate", "1.01"], "at least 8 samples per PRTS cycle"),
    (["--sensor-noise", "1e300"], "sensor_noise [rad] must be in"),
])
def test_hostile_prts_sweeps_are_one_line_and_exit_2(tmp_path, extra, needle):
    out = tmp_path / "pop.csv"
    r = cli("sweep", "--experiment", "prts", "--controller", "peterka-2002", "--tilt",
            "prts:0.035", "--vary", "feedback_delay=0.12:0.18:2", *extra, "--out", str(out))
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and needle in r.stderr, r.stderr
    assert not out.exists()


def test_json_is_built_whole_and_never_prints_nan(capsys):
    """print_json writes nothing when the object cannot be written, and a non-finite number
    as null."""
    from posturelab.cli._common import print_json

    print_json({"a": [1.0, float("nan")], "b": {"c": float("inf")}})
    assert json.loads(capsys.readouterr().out) == {"a": [1.0, None], "b": {"c": None}}
    with pytest.raises(TypeError):
        print_json({"a": 1.0, "b": object()})
    assert capsys.readouterr().out == ""


def test_fit_frf_from_the_frf_json_equals_the_fit_from_the_trial(trial, tmp_path):
    """frf --json carries the band harmonics, the standard errors and the band covariance,
    so fitting its JSON gives the trial's fit (not the model at band centres, 2 % off)."""
    frf_json = tmp_path / "frf.json"
    frf_json.write_text(_frf_json(trial))
    common = ["--controller", "peterka-2002", "--free", "active_stiffness,feedback_delay",
              "--json"]
    a = json.loads(cli("fit-frf", "--data", str(trial), "--stimulus", "tilt", "--response",
                       "com_angle", "--cycle-length", "20", "--discard-cycles", "1",
                       *common).stdout)
    b = json.loads(cli("fit-frf", "--data", str(frf_json), *common).stdout)
    assert a["weighting"] == b["weighting"] == "variance"
    for pa, pb in zip(a["parameters"], b["parameters"], strict=True):
        assert pa["estimate"] == pytest.approx(pb["estimate"], rel=1e-6)
        assert pa["ci95"] == pytest.approx(pb["ci95"], rel=1e-4)
