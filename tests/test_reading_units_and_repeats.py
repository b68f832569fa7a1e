"""Reading recordings and FRFs: declared units honoured, Parquet read like CSV by every
reader, a stimulus that does not repeat every --cycle-length refused, files and columns
given twice refused, time in ms caught, FRF JSON that contradicts itself refused.

Every input is generated here (seeded): a sum of sines at the odd harmonics of a 20 s cycle
(half-cycle antiperiodic, as a PRTS is) and a response that is -GAIN times it, so the FRF's
gain is GAIN at every band whatever the unit bookkeeping; a wrong unit shows as a factor
of 57.3 (deg/rad), a wrong cycle length as a refusal.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from _cli import refused_in_one_line as one_line_exit_2
from _cli import run_main as run
from posturelab.errors import DataFileError, ParameterError
from posturelab.frequency.estimate import estimate_frf
from posturelab.frequency.table import frf_table_from_json, read_frf_json

CYCLE, RATE, CYCLES, GAIN = 20.0, 50.0, 5, 2.5
DEG = 180.0 / math.pi


def stimulus(seed: int = 7, noise: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Time [s] and a periodic stimulus [rad] (odd harmonics of CYCLE), with white noise of
    ``noise`` times its RMS added."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(CYCLES * CYCLE * RATE)) / RATE
    x = sum(0.01 * np.sin(2 * np.pi * k * t / CYCLE + rng.uniform(0, 2 * np.pi))
            for k in range(1, 40, 2))
    if noise:
        x = x + noise * float(np.std(x)) * rng.standard_normal(x.size)
    return t, x


def write_csv(path, header: str, *columns) -> str:
    rows = np.column_stack(columns)
    path.write_text(header + "\n" + "\n".join(",".join(f"{v:.12g}" for v in r)
                                              for r in rows) + "\n")
    return str(path)


def write_parquet(path, columns: list[tuple[str, np.ndarray]], units: dict) -> str:
    from posturelab.studies._sweep_grid import table_parquet_bytes

    path.write_bytes(table_parquet_bytes(columns, units))
    return str(path)


def frf_json(capsys, path, *extra) -> dict:
    code, out, err = run(capsys, "frf", "--data", str(path), "--stimulus", "tilt",
                         "--response", "com_angle", "--cycle-length", str(CYCLE), "--json",
                         *extra)
    assert code == 0, err
    return json.loads(out)


# ---- 2: a unit declared in a header is honoured; --angle-unit only for the others ----

def test_a_tilt_header_in_degrees_is_converted_and_the_unlabelled_response_kept(
        tmp_path, capsys):
    t, x = stimulus()
    path = write_csv(tmp_path / "c_deg.csv", "t,tilt [deg],com_angle", t, x * DEG, GAIN * x)
    np.testing.assert_allclose(frf_json(capsys, path)["gain"], GAIN, rtol=1e-6)


def test_angle_unit_deg_applies_to_the_columns_without_a_unit_only(tmp_path, capsys):
    t, x = stimulus()
    path = write_csv(tmp_path / "mixed.csv", "t,tilt [rad],com_angle", t, x, GAIN * x * DEG)
    out = frf_json(capsys, path, "--angle-unit", "deg")
    np.testing.assert_allclose(out["gain"], GAIN, rtol=1e-6)
    from _cli import cli

    assert "header declares no unit" in " ".join(cli("frf", "--help").stdout.split())


def test_a_parquet_column_named_with_a_unit_is_read_as_a_csv_header(tmp_path, capsys):
    t, x = stimulus()
    path = write_parquet(tmp_path / "deg.parquet",
                         [("t", t), ("tilt [deg]", x * DEG), ("com_angle", GAIN * x)], {})
    np.testing.assert_allclose(frf_json(capsys, path)["gain"], GAIN, rtol=1e-6)
    meta = write_parquet(tmp_path / "meta.parquet",
                         [("t", t), ("tilt", x * DEG), ("com_angle", GAIN * x)],
                         {"tilt": "deg"})
    np.testing.assert_allclose(frf_json(capsys, meta)["gain"], GAIN, rtol=1e-6)


def test_a_parquet_name_and_metadata_that_disagree_are_refused(tmp_path, capsys):
    t, x = stimulus()
    path = write_parquet(tmp_path / "both.parquet",
                         [("t", t), ("tilt [deg]", x), ("com_angle", x)], {"tilt [deg]": "rad"})
    line = one_line_exit_2(capsys, "frf", "--data", path, "--stimulus", "tilt", "--response",
                           "com_angle", "--cycle-length", str(CYCLE))
    assert "declares deg in its name and rad in its metadata" in line


# ---- 3: a stimulus that does not repeat every --cycle-length ----

@pytest.mark.parametrize("wrong", [10.0, 5.0, 1.0])
def test_a_wrong_cycle_length_is_refused_and_the_period_suggested(wrong):
    _, x = stimulus()
    with pytest.raises(ParameterError, match=r"does not repeat every --cycle-length .*"
                                             r"repeats every 20 s"):
        estimate_frf(x, -GAIN * x, RATE, wrong, bands="harmonics")


def test_a_noisy_measured_stimulus_still_counts_as_periodic():
    from posturelab.frequency.estimate import cycle_change

    _, x = stimulus(noise=0.03)  # sensor noise of 3 % of its RMS
    change = cycle_change([x.reshape(-1, int(CYCLE * RATE))])
    assert 0.02 < change < 0.04  # the noise's share, as √2·σ / (√2·RMS)
    est = estimate_frf(x, -GAIN * x, RATE, CYCLE, response_sign=-1)
    np.testing.assert_allclose(est.gain, GAIN, rtol=1e-9)


@pytest.mark.parametrize("wrong", [10.0, 5.0])
def test_broadband_noise_counts_only_in_the_bands_and_a_wrong_length_is_still_refused(wrong):
    """Sensor noise of 30 % of the stimulus's RMS spread over every frequency: judged over
    the analysed bands only, the stimulus repeats every cycle (the whole-signal change is
    about 0.3, above the bound); a wrong cycle length is refused all the same."""
    from posturelab.frequency.estimate import MAX_CYCLE_CHANGE, cycle_change

    _, x = stimulus(noise=0.3)
    assert cycle_change([x.reshape(-1, int(CYCLE * RATE))]) > MAX_CYCLE_CHANGE
    est = estimate_frf(x, -GAIN * x, RATE, CYCLE, response_sign=-1)
    np.testing.assert_allclose(est.gain, GAIN, rtol=1e-9)
    with pytest.raises(ParameterError, match="does not repeat every --cycle-length"):
        estimate_frf(x, -GAIN * x, RATE, wrong, bands="harmonics")


def test_unrelated_cycles_give_a_change_near_one_and_no_period():
    from posturelab.frequency.estimate import MAX_CYCLE_CHANGE, cycle_change, repeat_period

    rng = np.random.default_rng(3)
    x = rng.standard_normal(5000)
    assert abs(cycle_change([x.reshape(-1, 1000)]) - 1.0) < 0.05 < MAX_CYCLE_CHANGE + 1
    assert repeat_period(x, RATE) is None
    _, periodic = stimulus()
    assert repeat_period(periodic, RATE) == pytest.approx(CYCLE)


def test_frf_cli_refuses_a_wrong_cycle_length_naming_the_option(tmp_path, capsys):
    t, x = stimulus()
    path = write_csv(tmp_path / "small.csv", "t,tilt,com_angle", t, x, GAIN * x)
    line = one_line_exit_2(capsys, "frf", "--data", path, "--stimulus", "tilt", "--response",
                           "com_angle", "--cycle-length", "10")
    assert "--cycle-length" in line and "20 s" in line


# ---- 9: Parquet read by every reader of a run or a profile ----

def test_a_platform_profile_a_run_and_a_trajectory_are_read_from_parquet(tmp_path, capsys):
    from posturelab.model.platform import read_profile_csv
    from posturelab.simulation.results import read_run_csv
    from posturelab.studies.identification import read_trajectory_csv

    t = np.arange(0, 1.0, 0.01)
    a = np.where(t < 0.2, -2.0, 0.0)
    prof = write_parquet(tmp_path / "p.parquet", [("time", t), ("x_acceleration", a)],
                         {"time": "s", "x_acceleration": "m/s²"})
    profile = read_profile_csv(prof)
    np.testing.assert_array_equal(profile.time, t)
    theta = np.column_stack([np.sin(t + k) for k in range(3)])
    omega = np.column_stack([np.cos(t + k) for k in range(3)])
    cols = [("t", t), *((f"theta{k + 1}", theta[:, k]) for k in range(3)),
            *((f"omega{k + 1}", omega[:, k]) for k in range(3))]
    runp = write_parquet(tmp_path / "run.parquet", cols, {"t": "s"})
    time, th, om = read_run_csv(runp)
    np.testing.assert_array_equal(th, theta)
    np.testing.assert_array_equal(om, omega)
    time2, th2 = read_trajectory_csv(runp, 3)
    np.testing.assert_array_equal(th2, theta)
    runc = write_csv(tmp_path / "run.csv", "t,theta1,theta2,theta3,omega1,omega2,omega3", t,
                     theta, omega)
    code, out, err = run(capsys, "compare", runp, runc)
    assert code == 0, err
    assert "max |Δθ| [rad] 0.0000, 0.0000, 0.0000" in out


# ---- 10: convert writes SI, and refuses flags that do nothing ----

def test_convert_writes_a_declared_degree_column_in_radians(tmp_path, capsys):
    t, x = stimulus()
    path = write_csv(tmp_path / "lab.csv", "time,tilt [deg],com_angle", t, x * DEG, x)
    out = tmp_path / "out.csv"
    code, text, err = run(capsys, "convert", path, "--out", str(out))
    assert code == 0, err
    assert "tilt from deg to rad" in text
    lines = out.read_text().splitlines()
    assert lines[0] == "time [s],tilt [rad],com_angle"
    back = np.loadtxt(out, delimiter=",", skiprows=1)
    np.testing.assert_allclose(back[:, 1], x, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(frf_json(capsys, out)["gain"], 1.0, rtol=1e-6)


def test_convert_refuses_an_unknown_unit_and_flags_that_do_nothing(tmp_path, capsys):
    t, x = stimulus()
    bad = write_csv(tmp_path / "bad.csv", "time,tilt [furlong]", t, x)
    assert "is in furlong" in one_line_exit_2(capsys, "convert", bad, "--out",
                                              str(tmp_path / "o.csv"))
    plain = write_csv(tmp_path / "plain.csv", "time,tilt", t, x)
    assert "--angle-columns" in one_line_exit_2(capsys, "convert", plain, "--out",
                                                str(tmp_path / "o.csv"), "--angle-unit", "deg")
    assert "--length-unit" in one_line_exit_2(capsys, "convert", plain, "--out",
                                              str(tmp_path / "o.csv"), "--length-unit", "mm")
    assert not (tmp_path / "o.csv").exists()


def test_a_c3d_angle_in_degrees_is_converted_and_angle_unit_rad_refused(tmp_path, capsys):
    from posturelab.recordings.c3d import write_c3d

    _, x = stimulus()
    x = x[:500]
    path = tmp_path / "deg.c3d"
    write_c3d(path, {"a": np.zeros((500, 3))}, 100.0, analogs={"tilt": x * DEG},
              analog_units={"tilt": "deg"})
    out = tmp_path / "o.csv"
    line = one_line_exit_2(capsys, "convert", str(path), "--out", str(out), "--angle-unit",
                           "rad", "--angle-columns", "tilt")
    assert "does nothing" in line and "'tilt' is in deg" in line
    code, _, err = run(capsys, "convert", str(path), "--out", str(out))
    assert code == 0, err
    header = out.read_text().splitlines()[0].split(",")
    assert "tilt [rad]" in header
    back = np.loadtxt(out, delimiter=",", skiprows=1)[:, header.index("tilt [rad]")]
    np.testing.assert_allclose(back, x, rtol=1e-5, atol=1e-7)


# ---- 11: columns, frequencies, keys and files given twice ----

def test_a_profile_naming_a_column_twice_is_refused(tmp_path):
    from posturelab.model.platform import read_profile_csv

    path = tmp_path / "dup.csv"
    path.write_text("time,x_acceleration,x_acceleration\n0,0,1\n0.1,1,0\n0.2,0,0\n")
    with pytest.raises(DataFileError, match="names 'x_acceleration' 2 times"):
        read_profile_csv(path)
    import pyarrow as pa
    import pyarrow.parquet as pq

    t = pa.array([0.0, 0.1, 0.2])
    pq.write_table(pa.Table.from_arrays([t, t, t], names=["time", "x_acceleration",
                                                          "x_acceleration"]),
                   tmp_path / "dup.parquet")
    with pytest.raises(DataFileError, match="names 'x_acceleration' 2 times"):
        read_profile_csv(tmp_path / "dup.parquet")


def _frf_object(gain=(2.0, 1.0), phase=(-10.0, -40.0), freq=(0.05, 0.15)) -> dict:
    H = np.array(gain) * np.exp(1j * np.radians(phase))
    return {"frequency": list(freq), "frf": [{"re": z.real, "im": z.imag} for z in H]}


def test_an_frf_table_repeating_a_frequency_or_a_key_is_refused(tmp_path):
    with pytest.raises(ParameterError, match="0.05 Hz is given 2 times"):
        frf_table_from_json(_frf_object(freq=(0.05, 0.05)))
    text = json.dumps(_frf_object()).replace('{"frequency"', '{"frequency": [1, 2], '
                                             '"frequency"', 1)
    (tmp_path / "dup.json").write_text(text)
    with pytest.raises(ParameterError, match="'frequency' is given twice"):
        read_frf_json(tmp_path / "dup.json")


@pytest.mark.parametrize("argv", [
    ("fit-frf", "--data", "{a}", "--data", "{a}", "--controller", "peterka-2002", "--free",
     "feedback_delay"),
    ("compare-frf", "--a", "{a}", "{b}", "--b", "{a}"),
    ("likeness-reference", "--data", "{a}", "{a}", "--out", "{out}"),
])
def test_the_same_file_given_twice_is_refused(tmp_path, capsys, argv):
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    a.write_text(json.dumps(_frf_object()))
    b.write_text(json.dumps(_frf_object(gain=(2.1, 1.1))))
    names = {"a": str(a), "b": str(b), "out": str(tmp_path / "ref.json")}
    line = one_line_exit_2(capsys, *(s.format(**names) for s in argv))
    assert "the same file twice" in line
    assert not (tmp_path / "ref.json").exists()


# ---- 16: labels, one column twice, a dead response ----

def test_an_frf_json_is_labelled_as_such_and_a_gain_table_as_a_table():
    from posturelab.frequency.estimate import estimate_frf as est_frf

    _, x = stimulus()
    est = est_frf(x, -GAIN * x + 1e-4 * np.sin(np.arange(x.size)), RATE, CYCLE)
    assert frf_table_from_json(json.loads(json.dumps(est.to_dict()))).kind == "frf --json"
    assert frf_table_from_json({"frequency": [0.1], "gain": [1.0],
                                "phase_deg": [0.0]}).kind == "table"


def test_the_same_column_as_stimulus_and_response_is_refused(tmp_path, capsys):
    t, x = stimulus()
    path = write_csv(tmp_path / "s.csv", "t,tilt,com_angle", t, x, x)
    line = one_line_exit_2(capsys, "frf", "--data", path, "--stimulus", "tilt", "--response",
                           "tilt", "--cycle-length", str(CYCLE))
    assert "same column" in line


def test_a_constant_response_is_refused_by_frf_and_likeness(tmp_path, capsys):
    t, x = stimulus()
    with pytest.raises(ParameterError, match="the response is constant"):
        estimate_frf(x, np.zeros_like(x), RATE, CYCLE)
    path = write_csv(tmp_path / "dead.csv", "t,tilt,com_angle", t, x, np.zeros_like(x))
    for argv in (("frf",), ("likeness", "--reference", "comtest-eyes-closed")):
        line = one_line_exit_2(capsys, *argv, "--data", path, "--stimulus", "tilt",
                               "--response", "com_angle", "--cycle-length", str(CYCLE))
        assert "the response is constant" in line


# ---- 18: time in ms without a declared unit ----

def test_time_in_milliseconds_is_caught_with_the_advice(tmp_path, capsys):
    t, x = stimulus()
    path = write_csv(tmp_path / "lab_ms.csv", "time,tilt,com_angle", t * 1000, x, x)
    line = one_line_exit_2(capsys, "convert", path, "--out", str(tmp_path / "o.csv"))
    assert "--time-unit ms" in line and "0.05 Hz" in line
    code, text, err = run(capsys, "convert", path, "--out", str(tmp_path / "o.csv"),
                          "--time-unit", "ms")
    assert code == 0 and f"at {RATE:g} Hz" in text, err
    declared = write_csv(tmp_path / "lab_s.csv", "time [s],tilt,com_angle", t * 1000, x, x)
    code, text, err = run(capsys, "convert", declared, "--out", str(tmp_path / "o2.csv"))
    assert code == 0 and "at 0.05 Hz" in text, err


def test_a_profile_in_milliseconds_is_refused(tmp_path):
    from posturelab.model.platform import read_profile_csv

    path = tmp_path / "ms.csv"
    path.write_text("time,x_acceleration\n" + "".join(f"{k},{0.5 if k < 100 else 0}\n"
                                                       for k in range(1000)))
    with pytest.raises(DataFileError, match="is it in ms"):
        read_profile_csv(path)


# ---- 20: an FRF JSON whose gain or phase contradicts its frf ----

def test_a_gain_contradicting_frf_is_refused_naming_the_band():
    obj = _frf_object() | {"gain": [2.0, 3.0], "phase_deg": [-10.0, -40.0]}
    with pytest.raises(ParameterError, match=r"gain 3 at band 2 \(0.15 Hz\) contradicts "
                                             r"\|frf\| = 1"):
        frf_table_from_json(obj)
    obj = _frf_object() | {"gain": [2.0, 1.0], "phase_deg": [-10.0, 140.0]}
    with pytest.raises(ParameterError, match="phase_deg 140 at band 2"):
        frf_table_from_json(obj)
    unwrapped = _frf_object() | {"gain": [2.00004, 1.0], "phase_deg": [-10.0, -400.0]}
    np.testing.assert_allclose(frf_table_from_json(unwrapped).gain, [2.0, 1.0])


@pytest.mark.parametrize("spelling", ["°", "degrees", "Degree"])
def test_other_spellings_of_degrees_are_read_as_deg(spelling):
    """A header [°] or [degrees] is the unit [deg] (it was refused as unknown)."""
    from posturelab._files import column_unit

    assert column_unit(f"tilt [{spelling}]") == "deg"
    assert column_unit("t [sec]") == "s" and column_unit("x [furlong]") == "furlong"


def test_a_trial_not_a_whole_number_of_cycles_is_told_the_flags_that_fix_it():
    _, x = stimulus()
    with pytest.raises(ParameterError, match="--drop-partial .* --start"):
        estimate_frf(x[:-7], -GAIN * x[:-7], RATE, CYCLE)
