"""Lab recordings: resampling an uneven time column, C3D files (ezc3d), sway from markers
and force plates, ``posturelab convert``; every bad file one line and exit 2."""

from __future__ import annotations

import json

import numpy as np
import pytest

import posturelab as pl
from _cli import refused_in_one_line as one_line_exit_2
from _cli import run_main as run
from posturelab.cli import main
from posturelab.errors import DataFileError
from posturelab.model.tilt import PRTSTilt
from posturelab.recordings.c3d import read_c3d, write_c3d
from posturelab.recordings.resample import MAX_GAP_STEPS, resample_uniform
from posturelab.recordings.sway import (
    com_angle_cop,
    com_angle_segments,
    com_angle_two_markers,
)
from posturelab.recordings.table import read_table


def jittered_times(rng, duration, low=0.0107, high=0.0117):
    """A motion-capture clock: steps uniform in [low, high] s (as the lab data of issue 21)."""
    steps = rng.uniform(low, high, int(duration / low) + 10)
    t = np.concatenate([[0.0], np.cumsum(steps)])
    return t[t <= duration]


# ---- resampling --------------------------------------------------------------------------

def test_resampling_a_jittered_sinusoid_is_accurate(rng):
    t = jittered_times(rng, 20.0)
    f = 2.2  # the highest band of the 80-state PRTS protocol [Hz]
    grid, cols, report = resample_uniform(t, {"x": np.sin(2 * np.pi * f * t)}, 90.0)
    assert np.allclose(np.diff(grid), 1 / 90.0, rtol=0, atol=1e-12)
    err = np.abs(cols["x"] - np.sin(2 * np.pi * f * grid))[5:-5].max()
    # spline error ~ (2π f Δt)^4 / 384 of the amplitude, Δt ≤ 0.0117 s; measured 2.0e-6
    assert err < 1e-5
    assert report.samples_in == t.size and report.step_max <= 0.0117
    assert "cubic spline" in report.text()


def test_a_gap_is_refused_naming_its_time(rng):
    t = jittered_times(rng, 5.0)
    t = np.concatenate([t[t < 2.0], t[t > 2.1]])
    with pytest.raises(DataFileError, match=r"gap of 0\.1\d* s .*t = 1\.9"):
        resample_uniform(t, {"x": np.sin(t)}, 100.0)
    # a missing sample (NaN) in one column is filled; a long run of them refused
    x = np.sin(t)
    x[40] = np.nan
    _, cols, report = resample_uniform(t, {"x": x}, 100.0, max_gap=0.2)
    assert report.filled == 1 and np.all(np.isfinite(cols["x"]))
    x[40:80] = np.nan
    with pytest.raises(DataFileError, match="column 'x' is missing for"):
        resample_uniform(t, {"x": x}, 100.0, max_gap=0.2)
    assert MAX_GAP_STEPS == 3.0




def test_resampled_frf_equals_the_uniform_one(tmp_path, capsys, rng, prts_trial):
    from scipy.interpolate import CubicSpline

    time, tilt, com = prts_trial
    uniform = tmp_path / "uniform.csv"
    keep = slice(0, None, 10)  # 100 Hz
    np.savetxt(uniform, np.column_stack([time[keep], tilt[keep], com[keep]]), delimiter=",",
               header="time,tilt,com_angle", comments="")
    t = jittered_times(rng, 60.0)
    uneven = tmp_path / "uneven.csv"
    np.savetxt(uneven, np.column_stack([t, CubicSpline(time, tilt)(t),
                                        CubicSpline(time, com)(t)]),
               delimiter=",", header="time,tilt,com_angle", comments="")
    args = ["frf", "--stimulus", "tilt", "--response", "com_angle", "--cycle-length", "20",
            "--discard-cycles", "1", "--json"]
    line = one_line_exit_2(capsys, *args, "--data", uneven)
    assert "not uniform" in line and "--resample" in line
    code, out, err = run(capsys, *args, "--data", uneven, "--resample", "100")
    assert code == 0, err
    assert err == ""  # with --json, what was done is in the object, not on stderr
    got = json.loads(out)
    assert "cubic spline" in got["resampling"]["interpolation"]
    assert got["resampling"]["rate_hz"] == 100.0
    assert got["resampling"]["step_max_s"] <= 0.0117
    code, out, _ = run(capsys, *args, "--data", uniform)
    want = json.loads(out)
    # the PRTS tilt's velocity jumps at each state change: the spline rounds those corners,
    # the largest error, growing with frequency. Measured: gain 0.16 % (2.2 Hz band), phase
    # 0.003 deg; stated bounds 0.5 % and 0.05 deg in every band
    np.testing.assert_allclose(got["gain"], want["gain"], rtol=0.005)
    np.testing.assert_allclose(got["phase_deg"], want["phase_deg"], atol=0.05)
    # fit-frf takes the same option
    code, out, err = run(capsys, "fit-frf", "--data", uneven, "--stimulus", "tilt",
                         "--response", "com_angle", "--cycle-length", "20",
                         "--discard-cycles", "1", "--controller", "peterka-2002",
                         "--free", "feedback_delay", "--resample", "100", "--json")
    assert code == 0, err


# ---- C3D ---------------------------------------------------------------------------------

def test_c3d_markers_in_mm_read_back_in_m(tmp_path, rng):
    frames = 200
    markers = {"LANK": rng.uniform(-1, 1, (frames, 3)), "RSHO": rng.uniform(-1, 1, (frames, 3))}
    analog = rng.normal(size=frames * 10)
    path = tmp_path / "known.c3d"
    write_c3d(path, markers, 100.0, analogs={"Tilt": analog}, analog_rate=1000.0,
              analog_units={"Tilt": "rad"}, point_units="mm")
    rec = read_c3d(path, rate=1000.0)
    assert rec.rate == 1000.0 and rec.point_rate == 100.0 and rec.markers == ("lank", "rsho")
    np.testing.assert_allclose(rec.columns["tilt"], analog[:rec.time.size], rtol=1e-6,
                               atol=1e-6)  # stored as float32
    rec = read_c3d(path)
    assert rec.units["lank_x"] == "m" and rec.units["tilt"] == "rad"
    for label, key in (("LANK", "lank"), ("RSHO", "rsho")):
        for a, axis in enumerate("xyz"):
            # float32 storage of millimetres: 1 m = 1000 mm to 6e-5 mm, i.e. 6e-8 m
            np.testing.assert_allclose(rec.columns[f"{key}_{axis}"], markers[label][:, a],
                                       rtol=0, atol=1e-7)
    assert np.allclose(rec.time, np.arange(frames) / 100.0)


def _write_plate_c3d(path, cop_x_mm, fz=-700.0, rate=100.0, ratio=10):
    """A C3D with one type-2 force plate whose centre of pressure is ``cop_x_mm`` [mm] at
    the analog rate (``ratio`` × ``rate``)."""
    import ezc3d
    from ezc3d import ezc3d as low

    n = cop_x_mm.size // ratio
    c = ezc3d.c3d()
    c["parameters"]["POINT"]["RATE"]["value"] = [rate]
    c["parameters"]["POINT"]["LABELS"]["value"] = ("ank",)
    c["parameters"]["POINT"]["UNITS"]["value"] = ["mm"]
    c["data"]["points"] = np.ones((4, 1, n))
    c["parameters"]["ANALOG"]["RATE"]["value"] = [rate * ratio]
    c["parameters"]["ANALOG"]["LABELS"]["value"] = ("Fx", "Fy", "Fz", "Mx", "My", "Mz")
    c["parameters"]["ANALOG"]["UNITS"]["value"] = ["N"] * 3 + ["Nmm"] * 3
    an = np.zeros((1, 6, n * ratio))
    cop = cop_x_mm
    an[0, 2] = fz
    an[0, 4] = -fz * cop * -1.0  # My = -x_P F_z (origin at the surface)
    c["data"]["analogs"] = an

    def integer(name, values):
        c.add_parameter("FORCE_PLATFORM", name, np.asarray(values, dtype=float))
        c["parameters"]["FORCE_PLATFORM"][name]["type"] = low.INT

    integer("USED", [1])
    integer("TYPE", [2])
    integer("ZERO", [1, 0])
    integer("CHANNEL", np.arange(1, 7).reshape(6, 1))
    c.add_parameter("FORCE_PLATFORM", "CORNERS", np.array(
        [[250, 250, 0], [-250, 250, 0], [-250, -250, 0], [250, -250, 0]], float).T[:, :, None])
    c.add_parameter("FORCE_PLATFORM", "ORIGIN", np.array([[0.0], [0.0], [0.0]]))
    c.write(str(path))


def test_c3d_force_plate_centre_of_pressure(tmp_path):
    cop = 30.0 + 10.0 * np.sin(2 * np.pi * 0.2 * np.arange(4000) / 1000.0)  # [mm] at 1 kHz
    path = tmp_path / "plate.c3d"
    _write_plate_c3d(path, cop)
    cop = cop[::10]
    rec = read_c3d(path)
    assert rec.plates == 1
    np.testing.assert_allclose(rec.columns["fp1_fz"], -700.0, rtol=1e-6)
    # decimated from 1 kHz (zero phase): the slow sinusoid to 1e-6 m away from the ends
    np.testing.assert_allclose(np.abs(rec.columns["fp1_copx"][20:-20]), cop[20:-20] / 1000,
                               atol=1e-6)


# ---- sway --------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def winter_run():
    """A three-link body scaled by Winter's table on a PRTS tilt (paper's Table I case 1),
    and markers on its joints (ankle at the origin)."""
    body = pl.get_body("winter-1.75m-75kg")
    r = pl.simulate(body, pl.paper_muscles("1"), None, 60.0,
                    tilt=PRTSTilt.named("posturelab-80", 0.035), engine="compiled",
                    sample_rate=100.0)
    assert not r.fell
    th = r.theta
    unit = np.stack([np.sin(th), np.cos(th)], axis=-1)  # (T, 3, 2)
    joints = np.cumsum(body.lengths[None, :, None] * unit, axis=1)
    ankle = np.zeros((th.shape[0], 2))
    return body, r, ankle, joints[:, 0], joints[:, 1], joints[:, 2]


def test_sway_from_segment_markers_is_the_simulated_centre_of_mass(winter_run):
    body, r, ankle, knee, hip, shoulder = winter_run
    got = com_angle_segments(ankle, knee, hip, shoulder)
    exact = np.arctan2(r.cog_position[:, 0], r.cog_position[:, 1])
    np.testing.assert_allclose(got, exact, rtol=0, atol=1e-12)
    # posturelab's com_angle is the linearised Σ a_i θ_i / Σ a_i: equal to second order
    # (measured 7e-6 of the RMS sway, 0.085 rad)
    rms = np.sqrt(np.mean(r.com_angle ** 2))
    assert np.sqrt(np.mean((got - r.com_angle) ** 2)) < 1e-4 * rms


def test_two_marker_sway_error_is_small(winter_run):
    body, r, ankle, knee, hip, shoulder = winter_run
    exact = np.arctan2(r.cog_position[:, 0], r.cog_position[:, 1])
    got = com_angle_two_markers(hip, shoulder, ankle)
    rms = np.sqrt(np.mean(exact ** 2))
    error = np.sqrt(np.mean((got - exact) ** 2)) / rms
    assert error < 0.01  # measured 0.42 % of the sway's RMS (the knee's flexion, 0.011 rad)
    # forward positions only, heights from Winter's Fig. 4.1 fractions of 1.75 m
    fwd = com_angle_two_markers(hip[:, 0], shoulder[:, 0], height=1.75)
    assert np.sqrt(np.mean((fwd - exact) ** 2)) / rms < 0.01  # measured 0.42 %


def test_cop_sway_matches_the_simulated_centre_of_mass(winter_run):
    body, r, *_ = winter_run
    cop = r.centre_of_pressure
    cop = cop[:, 0] if cop.ndim == 2 else cop
    keep = slice(2000, 6000)  # the last two cycles (whole cycles: the method is periodic)
    got = com_angle_cop(cop[keep], 100.0, height=1.75, mass=75.0)
    exact = np.arctan2(r.cog_position[keep, 0], r.cog_position[keep, 1])
    exact = exact - exact.mean()
    error = np.sqrt(np.mean((got - exact) ** 2)) / np.sqrt(np.mean(exact ** 2))
    assert error < 0.02  # measured 0.70 % of the RMS sway


# ---- convert and the bad files -------------------------------------------------------------

def test_convert_a_lab_csv_then_estimate_its_frf(tmp_path, capsys, rng, winter_run):
    from scipy.interpolate import CubicSpline

    body, r, ankle, knee, hip, shoulder = winter_run
    t = jittered_times(rng, 60.0)
    t = np.append(t[t < 59.995], 60.0)  # the recording spans whole cycles: 0 … 60 s
    lab = tmp_path / "lab.csv"
    cols = [t, np.degrees(CubicSpline(r.time, r.tilt)(t)),
            1000 * CubicSpline(r.time, hip[:, 0])(t), 1000 * CubicSpline(r.time,
                                                                         shoulder[:, 0])(t)]
    np.savetxt(lab, np.column_stack(cols), delimiter=",",
               header="time,stim_pitch,hip_xpos,shld_xpos", comments="")
    out = tmp_path / "trial.csv"
    code, text, err = run(capsys, "convert", lab, "--out", out, "--angle-unit", "deg",
                          "--angle-columns", "stim_pitch", "--length-unit", "mm",
                          "--sway", "two-marker", "--markers", "hip=hip_xpos,shoulder=shld_xpos",
                          "--height", "1.75", "--resample", "100")
    assert code == 0, err
    assert "resampled" in text and "two-marker" in text
    header = out.read_text().splitlines()[0]
    assert header.startswith("time [s],stim_pitch [rad]") and header.endswith("com_angle [rad]")
    code, text, err = run(capsys, "frf", "--data", out, "--stimulus", "stim_pitch",
                          "--response", "com_angle", "--cycle-length", "20",
                          "--discard-cycles", "1", "--json")
    assert code == 0, err
    assert len(json.loads(text)["gain"]) == 11


def test_convert_c3d_to_parquet_has_units(tmp_path, capsys, winter_run):
    import pyarrow.parquet as pq

    body, r, ankle, knee, hip, shoulder = winter_run
    path = tmp_path / "run.c3d"
    to3 = lambda p: np.column_stack([p[:, 0], np.zeros(len(p)), p[:, 1]])  # noqa: E731
    write_c3d(path, {"ank": to3(ankle), "kne": to3(knee), "hip": to3(hip),
                     "sho": to3(shoulder)}, 100.0, analogs={"tilt": r.tilt},
              analog_units={"tilt": "rad"})
    out = tmp_path / "run.parquet"
    code, _, err = run(capsys, "convert", path, "--out", out, "--sway", "segments",
                       "--markers", "ankle=ank,knee=kne,hip=hip,shoulder=sho")
    assert code == 0, err
    table = pq.read_table(out)
    assert table.schema.field("hip_x").metadata == {b"unit": b"m"}
    exact = np.arctan2(r.cog_position[:, 0], r.cog_position[:, 1])
    # markers stored as float32 millimetres: the angle to 1e-6 rad
    np.testing.assert_allclose(table.column("com_angle").to_numpy(), exact, atol=1e-6)
    from posturelab.recordings.convert import convert_recording

    later = convert_recording(path, start=20.0)
    assert later.time[0] == pytest.approx(20.0) and later.time.size == 4001
    # frf and fit read the .c3d directly
    code, _, err = run(capsys, "frf", "--data", path, "--stimulus", "tilt", "--response",
                       "hip_x", "--cycle-length", "20", "--discard-cycles", "1", "--json")
    assert code == 0, err


def test_bad_files_get_one_line_and_exit_2(tmp_path, capsys, rng):
    good = tmp_path / "good.c3d"
    write_c3d(good, {"a": rng.uniform(size=(300, 3))}, 100.0, analogs={"tilt": np.zeros(300)})
    cut = tmp_path / "cut.c3d"
    cut.write_bytes(good.read_bytes()[:-1000])
    line = one_line_exit_2(capsys, "convert", cut, "--out", tmp_path / "o.csv")
    assert "truncated" in line
    junk = tmp_path / "junk.c3d"
    junk.write_bytes(b"not a c3d file" * 100)
    assert "not a C3D file" in one_line_exit_2(capsys, "convert", junk, "--out",
                                                 tmp_path / "o.csv")
    notime = tmp_path / "notime.csv"
    notime.write_text("a,b\n1,2\n")
    assert "no time column" in one_line_exit_2(capsys, "convert", notime, "--out",
                                                 tmp_path / "o.csv")
    t = np.concatenate([np.arange(100) * 0.011, 2.0 + np.arange(100) * 0.011])
    gap = tmp_path / "gap.csv"
    np.savetxt(gap, np.column_stack([t, np.sin(t), np.cos(t)]), delimiter=",",
               header="time,tilt,com_angle", comments="")
    line = one_line_exit_2(capsys, "frf", "--data", gap, "--stimulus", "tilt", "--response",
                           "com_angle", "--cycle-length", "1", "--resample", "100")
    assert "gap of" in line and "t = 1.089" in line
    line = one_line_exit_2(capsys, "convert", good, "--out", tmp_path / "o.csv", "--sway",
                           "two-marker", "--markers", "hip=nohip,shoulder=a")
    assert "no marker 'nohip'" in line
    line = one_line_exit_2(capsys, "frf", "--data", good, "--stimulus", "tilt", "--response",
                           "nothere", "--cycle-length", "1")
    assert "no column 'nothere'" in line
    line = one_line_exit_2(capsys, "frf", "--data", gap, "--stimulus", "tilt", "--response",
                           "com_angle", "--cycle-length", "1")
    assert "--resample" in line
    deg = tmp_path / "deg.csv"
    deg.write_text("time,tilt [furlong],com_angle\n" + "".join(
        f"{k * 0.01},{k},{k}\n" for k in range(50)))
    assert "is in furlong" in one_line_exit_2(
        capsys, "frf", "--data", deg, "--stimulus", "tilt", "--response", "com_angle",
        "--cycle-length", "0.1")
    assert not (tmp_path / "o.csv").exists()


def test_fit_reads_an_uneven_recording_in_degrees(tmp_path, capsys, rng):
    """posturelab fit with --resample and --angle-unit deg gives the fit of the uniform
    recording (Table I case 1 after a backward step, 2 s)."""
    from scipy.interpolate import CubicSpline

    fine = tmp_path / "fine.csv"
    assert main(["simulate", "--case", "1", "--disturbance", "backward", "--duration", "2",
                 "--sample-rate", "1000", "--out", str(fine)]) == 0
    uniform = tmp_path / "uniform.csv"
    assert main(["simulate", "--case", "1", "--disturbance", "backward", "--duration", "2",
                 "--sample-rate", "100", "--out", str(uniform)]) == 0
    capsys.readouterr()
    data = np.genfromtxt(fine, delimiter=",", names=True)
    t = jittered_times(rng, 2.0)
    cols = [t] + [np.degrees(CubicSpline(data["t"], data[f"theta{i}"])(t))
                  for i in (1, 2, 3)]
    uneven = tmp_path / "uneven.csv"
    np.savetxt(uneven, np.column_stack(cols), delimiter=",", header="t,theta1,theta2,theta3",
               comments="")
    args = ["fit", "--case", "1", "--disturbance", "backward", "--free", "stiffness:ankle",
            "--json"]
    code, out, err = run(capsys, *args, "--data", uneven, "--resample", "100",
                         "--angle-unit", "deg")
    assert code == 0, err
    got = json.loads(out)["parameters"]["stiffness:ankle"]["estimate"]
    code, out, err = run(capsys, *args, "--data", uniform)
    assert code == 0, err
    want = json.loads(out)["parameters"]["stiffness:ankle"]["estimate"]
    assert got == pytest.approx(want, rel=1e-3)


def test_a_marker_missing_for_a_few_frames_is_filled_and_for_long_refused(tmp_path, rng):
    """A short gap is filled; a long one leaves the marker out of the table (the file's other
    markers stay usable) and is refused, with its time, when the marker is asked for."""
    m = rng.uniform(size=(100, 3))
    m[10:12] = np.nan  # two frames: within the 3 frames accepted
    write_c3d(tmp_path / "short.c3d", {"a": m}, 100.0)
    rec = read_c3d(tmp_path / "short.c3d")
    assert np.all(np.isfinite(rec.columns["a_x"]))
    assert any("a_x: 2 missing frame(s) filled" in n for n in rec.notes)
    m[10:30] = np.nan
    write_c3d(tmp_path / "long.c3d", {"a": m}, 100.0)
    rec = read_c3d(tmp_path / "long.c3d")
    assert "a_x" not in rec.columns and "a_x" in rec.unusable
    with pytest.raises(DataFileError, match=r"'a_x' is missing for 0\.21 s at t = 0\.09 … "
                       r"0\.3 s, longer than the 0\.03 s accepted \(3 frames\)"):
        read_table(tmp_path / "long.c3d", ["a_x"])


def test_the_sway_tables_are_winters_printed_numbers():
    """Winter DA (2009) Biomechanics and Motor Control of Human Movement, 4th ed.: Table 4.1
    (leg 0.0465 of body mass, CoM 0.433 of its length from the knee; thigh 0.100, 0.433 from
    the hip; HAT 0.678, 0.626 from the hip) and Fig. 4.1 (lateral malleolus 0.039 H, knee
    0.285 H, greater trochanter 0.530 H, shoulder 0.818 H); tolerances by the printed
    digits."""
    from posturelab.recordings.sway import LANDMARK_HEIGHTS, WINTER_SEGMENTS

    assert WINTER_SEGMENTS["leg"][:2] == pytest.approx((2 * 0.0465, 1 - 0.433), abs=5e-4)
    assert WINTER_SEGMENTS["thigh"][:2] == pytest.approx((2 * 0.100, 1 - 0.433), abs=5e-4)
    assert WINTER_SEGMENTS["hat"][:2] == pytest.approx((0.678, 0.626), abs=5e-4)
    printed = {"ankle": 0.039, "knee": 0.285, "hip": 0.530, "shoulder": 0.818}
    for name, value in printed.items():
        assert LANDMARK_HEIGHTS[name] == pytest.approx(value, abs=5e-4)


def test_convert_leaves_out_text_columns_and_says_so(tmp_path, capsys):
    lab = tmp_path / "labels.csv"
    lab.write_text("time,subject,tilt\n" + "".join(f"{k / 100},s01,{k}\n" for k in range(20)))
    out = tmp_path / "t.csv"
    code, text, err = run(capsys, "convert", lab, "--out", out)
    assert code == 0, err
    assert "left out (not numbers): subject" in text
    assert out.read_text().splitlines()[0] == "time [s],tilt"
