"""Fits do not report success on garbage (trial issue 4): a time-domain fit to white noise
does not describe the data; an FRF fit to a noise-only response is no success (its loop
unstable or its variance accounted for below a half), with the reason; a fit with no
residual degrees of freedom is refused in one line. The inputs are generated here, seeded."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from _cli import refused_in_one_line, run_main
from posturelab.studies.identification import _describes

FRF_FIT = ("--stimulus", "tilt", "--response", "com_angle", "--cycle-length", "20",
           "--discard-cycles", "1", "--controller", "peterka-2002",
           "--free", "active_stiffness:ankle,feedback_delay", "--json")


@pytest.fixture(scope="module")
def tilt_trial(tmp_path_factory) -> pd.DataFrame:
    """t, tilt, com_angle of a simulated Peterka 2002 PRTS trial (120 s at 100 Hz)."""
    from posturelab.cli import main

    path = tmp_path_factory.mktemp("trial") / "trial.csv"
    assert main(["simulate", "--controller", "peterka-2002", "--tilt", "prts:0.035",
                 "--duration", "120", "--sample-rate", "100", "--out", str(path)]) == 0
    return pd.read_csv(path)[["t", "tilt", "com_angle"]]


def test_describes_refuses_white_noise_data():
    rng = np.random.default_rng(4)
    data = rng.normal(0.0, 0.1, (301, 3))
    sway = float(np.sqrt(np.mean(data**2)))
    # a model that explains nothing leaves the data themselves: they look like noise
    assert not _describes(data.ravel(), sway, 3)
    assert not _describes(1.003 * data.ravel(), sway, 3)
    # noise-like residuals from data with a real signal still describe them (VAF 0.36)
    assert _describes(rng.normal(0.0, 0.08, (301, 3)).ravel(), 0.1, 3)


def test_time_domain_fit_to_white_noise_is_no_success(capsys, tmp_path):
    run = tmp_path / "run.csv"
    code, _, err = run_main(capsys, "simulate", "--stiffness", "800,300,300,300,100",
                            "--disturbance", "backward", "--duration", "3",
                            "--sample-rate", "100", "--out", str(run))
    assert code == 0, err
    df = pd.read_csv(run)
    rng = np.random.default_rng(7)
    garbage = pd.DataFrame({"t": df["t"]})
    for name in ("theta1", "theta2", "theta3"):
        garbage[name] = rng.normal(0.0, 0.1, len(df))
    garbage.to_csv(tmp_path / "g.csv", index=False)
    code, out, err = run_main(capsys, "fit", "--data", str(tmp_path / "g.csv"),
                              "--stiffness", "800,300,300,300,100", "--disturbance",
                              "backward", "--free",
                              "stiffness:ankle,stiffness:gastrocnemius,viscosity_ratio",
                              "--json")
    assert code == 0, err
    fit = json.loads(out)
    assert fit["describes_data"] is False and fit["success"] is False
    assert "does not describe the data" in fit["warning"]


def test_frf_fit_of_a_noise_response_is_no_success(capsys, tmp_path, tilt_trial):
    good = tmp_path / "good.csv"
    tilt_trial.to_csv(good, index=False)
    code, out, err = run_main(capsys, "fit-frf", "--data", str(good), *FRF_FIT)
    assert code == 0, err
    fit = json.loads(out)
    assert fit["success"] is True and fit["describes_data"] is True and fit["reason"] == ""
    assert fit["variance_accounted_for"] > 0.99  # noise-free trial

    noise = tilt_trial.copy()
    rng = np.random.default_rng(11)
    noise["com_angle"] = rng.normal(0.0, float(tilt_trial["com_angle"].std()), len(noise))
    bad = tmp_path / "noise.csv"
    noise.to_csv(bad, index=False)
    code, out, err = run_main(capsys, "fit-frf", "--data", str(bad), *FRF_FIT)
    assert code == 0, err
    fit = json.loads(out)
    assert fit["success"] is False and fit["describes_data"] is False
    assert fit["variance_accounted_for"] < 0.5
    assert "does not describe the data" in fit["reason"]
    assert all(p["estimate"] is not None for p in fit["parameters"])  # kept, flagged
    if fit["stable"] is False:
        assert "unstable" in fit["reason"]


def test_unstable_fitted_loop_is_no_success(capsys, tmp_path):
    # one band at gain 1, phase −30°: the fitted active stiffness goes to 0, the loop falls
    table = tmp_path / "t.json"
    table.write_text(json.dumps({"frequency": [0.5], "gain": [1.0], "phase_deg": [-30]}))
    code, out, err = run_main(capsys, "fit-frf", "--data", str(table), "--controller",
                              "peterka-2002", "--free", "active_stiffness:ankle", "--json")
    assert code == 0, err
    fit = json.loads(out)
    assert fit["stable"] is False and fit["success"] is False
    assert "the fitted loop is unstable" in fit["reason"]
    assert fit["parameters"][0]["estimate"] is not None


def test_more_free_parameters_than_numbers_is_refused(capsys, tmp_path):
    table = tmp_path / "t.json"
    table.write_text(json.dumps({"frequency": [0.5], "gain": [1.0], "phase_deg": [-30]}))
    line = refused_in_one_line(capsys, "fit-frf", "--data", str(table), "--controller",
                               "peterka-2002", "--free",
                               "active_stiffness:ankle,feedback_delay,proprioceptive_weight")
    assert "3 free parameter(s) cannot be fitted to 2 numbers" in line


def test_frf_fit_api_refuses_zero_dof():
    import posturelab as pl
    from posturelab.errors import ParameterError
    from posturelab.frequency.fit import fit_frf
    from posturelab.frequency.table import FRFTable
    from posturelab.model.controllers import get_controller

    table = FRFTable(np.array([0.5]), np.array([np.exp(-1j * np.pi / 6)]))
    body = pl.get_body("paper-1link")
    muscles = get_controller("peterka-2002").muscles(body)
    with pytest.raises(ParameterError, match="no degrees of freedom"):
        fit_frf(body, muscles, table, ["active_stiffness:ankle", "feedback_delay",
                                       "proprioceptive_weight"])


def test_cohort_leaves_flagged_subjects_out_of_the_summary(capsys, tmp_path, tilt_trial):
    """Trial issue 5: a noise subject and a degrees-as-radians subject no longer pull the
    median; the table says why (stable, describes_data columns)."""
    good = tmp_path / "good.csv"
    tilt_trial.to_csv(good, index=False)
    deg = tilt_trial.copy()
    deg["tilt"] = np.degrees(deg["tilt"])
    deg.to_csv(tmp_path / "deg.csv", index=False)
    noise = tilt_trial.copy()
    noise["com_angle"] = np.random.default_rng(5).normal(
        0.0, float(tilt_trial["com_angle"].std()), len(noise))
    noise.to_csv(tmp_path / "noise.csv", index=False)
    out = tmp_path / "c.csv"
    code, text, err = run_main(capsys, "cohort", "--data", str(good), str(tmp_path / "deg.csv"),
                               str(tmp_path / "noise.csv"), *FRF_FIT[:-1], "--workers", "1",
                               "--out", str(out), "--json")
    assert code == 0, err
    summary = json.loads(text)["summary"]
    assert summary["left_out"]["count"] == 2
    assert summary["left_out"]["by_reason"]["model does not describe the data"] == 2
    delay = summary["parameters"]["feedback_delay"]
    assert delay["subjects"] == 1 and abs(delay["median"] - 0.15) < 0.005
    table = pd.read_csv(out, keep_default_na=False)
    for column in ("stable", "describes_data", "converged", "variance_accounted_for"):
        assert column in table.columns
    by = table.drop_duplicates("subject").set_index("subject")
    assert by.loc["good", "describes_data"] in (True, "true")
    assert by.loc["noise", "describes_data"] in (False, "false")
    assert by.loc["noise", "failed"] in (True, "true")
