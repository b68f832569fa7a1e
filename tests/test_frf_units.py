"""frf and fit-frf: units declared in a trial's header (SI read, any other unit refused, never
rescaled) and the band names both commands take."""

from __future__ import annotations

import json

import numpy as np
import pytest

from _cli import cli, one_line_exit_2
from posturelab.errors import ParameterError
from posturelab.frequency import estimate_frf
from posturelab.frequency.bands import PETERKA_BAND_FREQUENCIES

SAMPLE_RATE = 10.0  # [Hz]
CYCLE = 20.0  # [s]
GAIN = 0.8  # the response is −GAIN × stimulus: gain 0.8, phase 0 with --response-sign -1


def write_trial(path, header: str, time_scale: float = 1.0, angle_scale: float = 1.0):
    """Three cycles of a periodic stimulus (odd harmonics of 1/CYCLE) and its response."""
    t = np.arange(int(3 * CYCLE * SAMPLE_RATE)) / SAMPLE_RATE
    rng = np.random.default_rng(18)
    stim = sum(0.01 * np.sin(2 * np.pi * k / CYCLE * t + rng.uniform(0, 2 * np.pi))
               for k in range(1, 45, 2))
    rows = np.column_stack([t * time_scale, stim * angle_scale, -GAIN * stim])
    path.write_text(header + "\n" + "\n".join(",".join(f"{v:.12g}" for v in r) for r in rows)
                    + "\n")
    return str(path)


def frf(path, *extra):
    return cli("frf", "--data", path, "--stimulus", "stim", "--response", "com",
               "--cycle-length", str(CYCLE), *extra)


def test_si_units_in_the_header_are_read(tmp_path):
    p = frf(write_trial(tmp_path / "si.csv", "time [s],stim [rad],com [rad]"), "--json")
    assert p.returncode == 0, p.stderr
    np.testing.assert_allclose(json.loads(p.stdout)["gain"], GAIN, rtol=1e-6)


@pytest.mark.parametrize("header, words", [
    ("time [s],stim [furlong],com [rad]", ("'stim [furlong]'", "is in furlong", "rad")),
    ("time [ms],stim [rad],com [rad]", ("'time [ms]'", "is in ms", "time in s")),
    ("t [s],stim [rad],com [mm]", ("'com [mm]'", "is in mm")),
])
def test_frf_refuses_a_column_in_another_unit(tmp_path, header, words):
    one_line_exit_2(frf(write_trial(tmp_path / "mixed.csv", header)), *words)


def test_fit_frf_refuses_a_tilt_in_an_unknown_unit(tmp_path):
    path = write_trial(tmp_path / "mixed.csv", "time [s],stim [furlong],com [rad]")
    one_line_exit_2(cli("fit-frf", "--data", path, "--stimulus", "stim", "--response", "com",
                        "--cycle-length", str(CYCLE), "--controller", "peterka-2002",
                        "--free", "feedback_delay"), "'stim [furlong]'", "is in furlong")


def test_fit_frf_refuses_a_tilt_in_metres(tmp_path):
    path = write_trial(tmp_path / "m.csv", "time [s],stim [m],com [rad]")
    one_line_exit_2(cli("fit-frf", "--data", path, "--stimulus", "stim", "--response", "com",
                        "--cycle-length", str(CYCLE), "--controller", "peterka-2002",
                        "--free", "feedback_delay"), "'stim [m]'", "is in m;")


def test_a_missing_time_column_names_the_accepted_names(tmp_path):
    path = write_trial(tmp_path / "no_time.csv", "seconds,stim,com")
    one_line_exit_2(frf(path), "no time column", "t or time")


def test_the_cycle_length_message_counts_samples_per_cycle():
    x = np.ones(64)
    with pytest.raises(ParameterError, match=r"is 2 samples at 0.1 Hz; a cycle needs at "
                                             r"least 4"):
        estimate_frf(x, x, 0.1, 20.0)
    with pytest.raises(ParameterError, match=r"is 6.6 samples at 0.33 Hz, not a whole number"):
        estimate_frf(x, x, 0.33, 20.0)


@pytest.mark.parametrize("name", ["peterka", "posturelab-80", "comtest-80"])
def test_frf_and_frf_model_take_the_same_80_state_band_names(tmp_path, name):
    p = frf(write_trial(tmp_path / "si.csv", "t,stim,com"), "--bands", name, "--json")
    assert p.returncode == 0, p.stderr
    f = json.loads(p.stdout)["frequency"]
    np.testing.assert_allclose(f, PETERKA_BAND_FREQUENCIES, atol=0.005)  # COMTEST's Fr
    m = cli("frf-model", "--controller", "peterka-2002", "--bands", name, "--json")
    assert m.returncode == 0, m.stderr
    np.testing.assert_allclose(json.loads(m.stdout)["frequency"], f, rtol=1e-12)


def test_frf_and_frf_model_take_the_242_state_band_name(tmp_path):
    p = cli("frf-model", "--controller", "peterka-2002", "--bands", "peterka-2002-242",
            "--json")
    assert p.returncode == 0, p.stderr
    assert len(json.loads(p.stdout)["frequency"]) == 17
    for command in ("frf", "frf-model"):
        assert "historical name" in cli(command, "--help").stdout


def test_the_estimate_itself_warns_of_a_sign_near_180_degrees():
    """The API's default sign is +1 (the CLI's -1): a response recorded in posturelab's
    convention (following the stimulus with the opposite sign) then reads 180 deg in the
    lowest band, and the estimate says so; with -1 it does not."""
    t = np.arange(int(3 * CYCLE * SAMPLE_RATE)) / SAMPLE_RATE
    stim = sum(0.01 * np.sin(2 * np.pi * k / CYCLE * t + k) for k in range(1, 45, 2))
    as_recorded = estimate_frf(stim, -GAIN * stim, SAMPLE_RATE, CYCLE)
    assert as_recorded.response_sign == 1.0 and len(as_recorded.warnings) == 1
    assert "check --response-sign" in as_recorded.warnings[0]
    assert as_recorded.to_dict()["warnings"] == list(as_recorded.warnings)
    flipped = estimate_frf(stim, -GAIN * stim, SAMPLE_RATE, CYCLE, response_sign=-1)
    assert flipped.warnings == () and flipped.to_dict()["warnings"] == []


def test_fit_frf_lists_its_conditions_in_the_order_of_data(tmp_path):
    """NAME#k is condition k's value: the text and the JSON list each --data with its kind."""
    import posturelab as pl
    from posturelab.frequency import model_frf
    from posturelab.model.controllers import get_controller

    body, preset = pl.get_body("paper-1link"), get_controller("peterka-2002")
    f = list(PETERKA_BAND_FREQUENCIES)
    H = model_frf(body, preset.muscles(body), f, **preset.run_options())
    table = tmp_path / "table.json"
    table.write_text(json.dumps({"frequency": f, "gain": np.abs(H).tolist(),
                                 "phase_deg": np.degrees(np.unwrap(np.angle(H))).tolist()}))
    trial = write_trial(tmp_path / "trial.csv", "t [s],stim [rad],com [rad]")
    argv = ["fit-frf", "--data", trial, "--data", str(table), "--stimulus", "stim",
            "--response", "com", "--cycle-length", str(CYCLE), "--controller", "peterka-2002",
            "--free", "feedback_delay", "--per-condition", "proprioceptive_weight"]
    p = cli(*argv, "--json")
    assert p.returncode == 0, p.stderr
    obj = json.loads(p.stdout)
    assert obj["conditions"] == [{"data": trial, "kind": "trial"},
                                 {"data": str(table), "kind": "table"}]
    text = cli(*argv)
    assert text.returncode == 0, text.stderr
    assert f"#1 {trial} (trial), #2 {table} (table)" in text.stdout
    assert "proprioceptive_weight#2" in text.stdout
