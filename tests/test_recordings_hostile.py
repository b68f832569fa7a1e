"""Recordings as real labs write them: each hostile file is read or refused in one line
(exit 2), and the library says what it did without printing (issue 21).

What is supported and what refused (stated in docs/guide/lab-recording.md):
a byte-order mark, trailing blank lines and a time column in ms (``--time-unit ms``) are
read; semicolon- or tab-separated files and decimal commas, a time column that repeats a
stamp or goes backwards, a constant stimulus, files over the row bound, C3D files with fewer
than 2 frames are refused; a C3D marker occluded throughout (or for longer than the gap
accepted) is left out of the table and refused when asked for; analog channels without a
label (or with a repeated one) get unique names.
"""

from __future__ import annotations

import json
import struct

import numpy as np
import pytest

from _cli import refused_in_one_line as one_line_exit_2
from _cli import run_main as run
from posturelab.errors import DataFileError
from posturelab.model.tilt import PRTSTilt
from posturelab.recordings.c3d import read_c3d, write_c3d
from posturelab.recordings.table import read_recording

CYCLE = 20.0  # the 80-state PRTS cycle [s]
RATE = 50.0  # [Hz]
FRF = ["--stimulus", "tilt", "--response", "com_angle", "--cycle-length", "20", "--json"]


@pytest.fixture(scope="module")
def trial():
    """Two cycles of the 80-state PRTS tilt [rad] at 50 Hz and a response made from it by a
    periodic first-order low-pass (time constant 0.3 s) plus seeded noise [rad]."""
    rng = np.random.default_rng(20261204)
    n = int(2 * CYCLE * RATE)
    t = np.arange(n) / RATE
    tilt = PRTSTilt.named("posturelab-80", 0.035).angle(t)
    f = np.fft.rfftfreq(n, 1 / RATE)
    com = np.fft.irfft(np.fft.rfft(tilt) / (1 + 2j * np.pi * f * 0.3), n=n)
    return t, tilt, com + 1e-4 * rng.normal(size=n)


def write_csv(path, header, rows, *, sep=",", fmt="{:.10g}", bom=False, tail=""):
    text = header + "\n" + "\n".join(sep.join(fmt.format(v) for v in r) for r in rows) + "\n"
    path.write_text(("\ufeff" if bom else "") + text + tail, encoding="utf-8")
    return path


def frf_json(capsys, path, *extra) -> dict:
    code, out, err = run(capsys, "frf", "--data", path, *FRF, *extra)
    assert code == 0, err
    return json.loads(out)


# ---- CSV ----------------------------------------------------------------------------------

def test_a_bom_and_trailing_blank_lines_are_read(tmp_path, capsys, trial):
    t, tilt, com = trial
    rows = np.column_stack([t, tilt, com])
    plain = frf_json(capsys, write_csv(tmp_path / "plain.csv", "time,tilt,com_angle", rows))
    odd = write_csv(tmp_path / "bom.csv", "time,tilt,com_angle", rows, bom=True,
                    tail="\n\n  \n")
    assert frf_json(capsys, odd)["gain"] == plain["gain"]


@pytest.mark.parametrize("sep, word", [(";", "semicolons"), ("\t", "tabs")])
def test_semicolon_and_tab_separated_files_are_refused(tmp_path, capsys, trial, sep, word):
    t, tilt, com = trial
    path = write_csv(tmp_path / "euro.csv", sep.join(["time", "tilt", "com_angle"]),
                     np.column_stack([t, tilt, com]), sep=sep)
    line = one_line_exit_2(capsys, "frf", "--data", path, *FRF)
    assert f"separated by {word}" in line and "comma-separated" in line
    # without --stimulus (frf looks for the tilt columns in the header): the same refusal
    line = one_line_exit_2(capsys, "frf", "--data", path, "--cycle-length", "20")
    assert f"separated by {word}" in line


def test_decimal_commas_are_refused(tmp_path, capsys, trial):
    t, tilt, com = trial
    rows = np.column_stack([t, tilt, com])
    text = "time,tilt,com_angle\n" + "\n".join(",".join(f"{v:.6f}".replace(".", ",")
                                                        for v in r) for r in rows) + "\n"
    (tmp_path / "comma.csv").write_text(text)
    line = one_line_exit_2(capsys, "frf", "--data", tmp_path / "comma.csv", *FRF)
    assert "decimal commas" in line
    # one quoted cell with a decimal comma
    (tmp_path / "quoted.csv").write_text('time,tilt,com_angle,x\n0,"0,5",0,1\n')
    line = one_line_exit_2(capsys, "frf", "--data", tmp_path / "quoted.csv", *FRF)
    assert "line 2" in line and "decimal comma" in line


def test_a_time_column_in_ms_is_read_when_declared(tmp_path, capsys, trial):
    t, tilt, com = trial
    seconds = frf_json(capsys, write_csv(tmp_path / "s.csv", "time,tilt,com_angle",
                                         np.column_stack([t, tilt, com])))
    ms = write_csv(tmp_path / "ms.csv", "time [ms],tilt,com_angle",
                   np.column_stack([t * 1000, tilt, com]))
    line = one_line_exit_2(capsys, "frf", "--data", ms, *FRF)
    assert "in ms" in line and "--time-unit ms" in line
    got = frf_json(capsys, ms, "--time-unit", "ms")
    np.testing.assert_allclose(got["gain"], seconds["gain"], rtol=1e-9)
    # a time column with no unit in its header, declared ms
    bare = write_csv(tmp_path / "bare.csv", "time,tilt,com_angle",
                     np.column_stack([t * 1000, tilt, com]))
    np.testing.assert_allclose(frf_json(capsys, bare, "--time-unit", "ms")["gain"],
                               seconds["gain"], rtol=1e-9)
    # convert writes it in s
    code, out, err = run(capsys, "convert", ms, "--out", tmp_path / "out.csv", "--time-unit",
                         "ms")
    assert code == 0, err
    written = np.loadtxt(tmp_path / "out.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(written[:, 0], t, rtol=1e-12, atol=1e-12)
    assert (tmp_path / "out.csv").read_text().startswith("time [s],")


@pytest.mark.parametrize("resample", [[], ["--resample", "50"]])
def test_a_time_column_going_backwards_or_repeating_is_refused(tmp_path, capsys, trial,
                                                               resample):
    t, tilt, com = trial
    back = t.copy()
    back[100], back[101] = back[101], back[100]
    path = write_csv(tmp_path / "back.csv", "time,tilt,com_angle",
                     np.column_stack([back, tilt, com]))
    line = one_line_exit_2(capsys, "frf", "--data", path, *FRF, *resample)
    assert "goes backwards at sample 102 (2.02 s, then 2 s)" in line
    rows = np.column_stack([t, tilt, com])
    dup = write_csv(tmp_path / "dup.csv", "time,tilt,com_angle",
                    np.insert(rows, 51, rows[50], axis=0))
    line = one_line_exit_2(capsys, "frf", "--data", dup, *FRF, *resample)
    assert "time stamp 1 s is repeated" in line


def test_a_constant_stimulus_is_refused(tmp_path, capsys, trial):
    t, _, com = trial
    for level in (0.0, 0.01):
        path = write_csv(tmp_path / f"flat{level}.csv", "time,tilt,com_angle",
                         np.column_stack([t, np.full_like(t, level), com]))
        line = one_line_exit_2(capsys, "frf", "--data", path, *FRF)
        assert "no power" in line and "(it is constant)" in line


def test_long_files_are_bounded(tmp_path, capsys, trial, monkeypatch):
    import posturelab.recordings.columns as columns

    t, tilt, com = trial
    path = write_csv(tmp_path / "trial.csv", "time,tilt,com_angle",
                     np.column_stack([t, tilt, com]))
    monkeypatch.setattr(columns, "MAX_ROWS", 1000)
    line = one_line_exit_2(capsys, "frf", "--data", path, *FRF)
    assert "more than 1,000 data rows" in line
    monkeypatch.undo()
    # resampling to a rate that would make more samples than the bound (40 s at 100 kHz)
    line = one_line_exit_2(capsys, "frf", "--data", path, *FRF, "--resample", "100000")
    assert "at most 2,000,000 are made" in line


def test_the_library_prints_nothing_and_says_what_it_did(tmp_path, capsys, trial):
    """read_recording (and the older read_series_csv) print nothing; the Recording says
    what was resampled and cut."""
    from posturelab.frequency.data import read_series_csv

    t, tilt, com = trial
    keep = t < 45.0 / RATE + CYCLE  # one cycle and 45 samples
    rows = np.column_stack([t[keep], tilt[keep], com[keep]])
    path = write_csv(tmp_path / "long.csv", "time,tilt,com_angle", rows)
    rec = read_recording(path, ["tilt", "com_angle"], resample=RATE, drop_partial=True,
                         cycle_length=CYCLE, start=0.1)
    assert capsys.readouterr() == ("", "")
    # 1045 samples (0 … 20.88 s); from 0.1 s: 5 dropped before, 1040 left, one cycle of 1000
    # kept, 40 dropped after
    assert keep.sum() == 1045
    assert rec.trimming.dropped_before == 5 and rec.trimming.dropped_after == 40
    assert rec.trimming.samples == 1000 and rec.columns["tilt"].size == 1000
    assert rec.resampling.rate == RATE
    assert "dropped the last 40 sample(s) (0.8 s)" in rec.trimming.text()
    assert set(rec.report_dict()) == {"resampling", "trimming"}
    read_series_csv(path, ["tilt", "com_angle"], resample=RATE, drop_partial=True,
                    cycle_length=CYCLE)
    assert capsys.readouterr() == ("", "")
    # the command line says it: one line each on stderr, or entries in --json
    code, out, err = run(capsys, "frf", "--data", path, *FRF[:-1], "--drop-partial")
    assert code == 2  # one cycle is too few for an FRF: but the reading note comes first
    rows = np.column_stack([t, tilt, com])
    path = write_csv(tmp_path / "two.csv", "time,tilt,com_angle",
                     np.vstack([rows, rows[:30] + [2 * CYCLE, 0, 0]]))
    code, out, err = run(capsys, "frf", "--data", path, *FRF[:-1], "--drop-partial")
    assert code == 0 and err.count("note:") == 1 and "dropped the last 30 sample(s)" in err
    got = frf_json(capsys, path, "--drop-partial")
    assert got["trimming"]["dropped_after"] == 30 and got["trimming"]["samples"] == 2000


# ---- C3D ----------------------------------------------------------------------------------

def test_a_c3d_with_fewer_than_two_frames_is_refused(tmp_path, capsys):
    path = tmp_path / "one.c3d"
    write_c3d(path, {"a": np.ones((1, 3))}, 100.0)
    with pytest.raises(DataFileError, match="has 1 frame"):
        read_c3d(path)
    # zero frames: the header's last frame before its first (ezc3d cannot write one)
    data = bytearray(path.read_bytes())
    first = struct.unpack("<H", data[6:8])[0]
    data[8:10] = struct.pack("<H", first - 1)
    (tmp_path / "zero.c3d").write_bytes(bytes(data))
    line = one_line_exit_2(capsys, "convert", tmp_path / "zero.c3d", "--out",
                           tmp_path / "out.csv")
    assert "zero.c3d" in line
    assert not (tmp_path / "out.csv").exists()


def _standing(theta, ankle=(0.1, 0.08)):
    """Hip and shoulder markers [m] of a straight body leaning by ``theta`` [rad] about the
    ankle (x forward, z up): the body's centre of mass is on that line, so com_angle is
    theta whatever the segment table."""
    ax, az = ankle
    s, c = np.sin(theta), np.cos(theta)
    at = lambda r: np.column_stack([ax + r * s, np.zeros_like(s), az + r * c])  # noqa: E731
    return {"ank": at(0.0), "hip": at(0.85), "sho": at(1.35)}


def test_occluded_markers_are_left_out_until_asked_for(tmp_path, capsys, trial):
    t, tilt, com = trial
    markers = _standing(com)
    markers["hip"] = np.full_like(markers["hip"], np.nan)  # occluded throughout
    path = tmp_path / "occluded.c3d"
    write_c3d(path, markers, RATE, analogs={"tilt": tilt}, analog_units={"tilt": "rad"})
    rec = read_c3d(path)
    assert "hip_x" not in rec.columns and "sho_x" in rec.columns
    assert rec.unusable["hip_x"] == "the marker is missing (occluded) in every frame"
    code, out, err = run(capsys, "convert", path, "--out", tmp_path / "ok.csv")
    assert code == 0 and "left out: hip_x (the marker is missing (occluded)" in out
    line = one_line_exit_2(capsys, "convert", path, "--out", tmp_path / "no.csv",
                           "--sway", "two-marker", "--hip-marker", "hip",
                           "--shoulder-marker", "sho", "--ankle-marker", "ank")
    assert "marker 'hip' cannot be used: the marker is missing (occluded)" in line
    line = one_line_exit_2(capsys, "frf", "--data", path, "--stimulus", "tilt",
                           "--response", "hip_x", "--cycle-length", "20")
    assert "'hip_x' cannot be used" in line


def test_analog_channels_without_labels_get_unique_names(tmp_path):
    path = tmp_path / "unlabelled.c3d"
    write_c3d(path, {"a": np.zeros((50, 3))}, 100.0,
              analogs={"": np.ones(50), " ": 2 * np.ones(50)})
    rec = read_c3d(path)
    assert rec.analogs == ("analog1", "analog2")
    np.testing.assert_array_equal(rec.columns["analog2"], 2.0)
    assert any("analog 1 labelled '' read as 'analog1'" in n for n in rec.notes)
    # a repeated label (and one equal to a marker column) is kept apart
    path = tmp_path / "repeated.c3d"
    import ezc3d

    write_c3d(path, {"a": np.zeros((50, 3))}, 100.0,
              analogs={"emg": np.ones(50), "emg2": 2 * np.ones(50), "a_x": 3 * np.ones(50)})
    c = ezc3d.c3d(str(path))
    c["parameters"]["ANALOG"]["LABELS"]["value"] = ("EMG", "emg", "A_X")
    c.write(str(path))
    rec = read_c3d(path)
    assert rec.analogs == ("emg", "emg_2", "a_x_2")
    np.testing.assert_array_equal(rec.columns["emg_2"], 2.0)
    np.testing.assert_array_equal(rec.columns["a_x"], 0.0)


def test_a_c3d_table_is_bounded(tmp_path, monkeypatch):
    import posturelab.recordings.c3d as c3d
    from posturelab.errors import ParameterError

    path = tmp_path / "short.c3d"
    write_c3d(path, {"a": np.zeros((50, 3))}, 100.0)
    # a rate above the file's own adds no information (and would only cost memory)
    with pytest.raises(ParameterError, match=r"marker 100 Hz.*must be in \[1, 100\] Hz"):
        read_c3d(path, rate=10_000.0)
    monkeypatch.setattr(c3d, "MAX_TABLE_SAMPLES", 40)  # 50 frames: 0.5 s at 100 Hz
    with pytest.raises(DataFileError, match="is 50 samples per column; at most 40 are made"):
        read_c3d(path)
    monkeypatch.setattr(c3d, "MAX_TABLE_SAMPLES", 1000)
    monkeypatch.setattr(c3d, "MAX_TABLE_CELLS", 100)  # 50 samples × 3 columns
    with pytest.raises(DataFileError, match="= 150 values; at most 100 are made"):
        read_c3d(path)


# ---- --sway straight into frf, and the recording flags on likeness and compare-frf ---------

def test_sway_on_frf_equals_convert_then_frf(tmp_path, capsys, trial):
    """frf --sway computes com_angle by the functions convert uses: the same FRF as
    convert → frf, and (a straight body) the FRF of the true angle to float32 storage."""
    t, tilt, com = trial
    path = tmp_path / "trial.c3d"
    write_c3d(path, _standing(com), RATE, analogs={"tilt": tilt},
              analog_units={"tilt": "rad"})
    sway = ["--sway", "two-marker", "--hip-marker", "hip", "--shoulder-marker", "sho",
            "--ankle-marker", "ank"]
    direct = frf_json(capsys, path, *sway)
    assert direct["reading_notes"][0] == "markers scaled from mm (POINT:UNITS) to m"
    assert direct["reading_notes"][-1].startswith("com_angle by the two-marker method")
    # a C3D read without --sway says what its reading did too
    code, out, err = run(capsys, "frf", "--data", path, "--stimulus", "tilt", "--response",
                         "sho_x", "--cycle-length", "20", "--json")
    assert code == 0, err
    assert json.loads(out)["reading_notes"] == ["markers scaled from mm (POINT:UNITS) to m"]
    code, out, err = run(capsys, "convert", path, "--out", tmp_path / "trial.csv", *sway)
    assert code == 0, err
    converted = frf_json(capsys, tmp_path / "trial.csv")
    np.testing.assert_allclose(direct["gain"], converted["gain"], rtol=1e-9)
    truth = frf_json(capsys, write_csv(tmp_path / "truth.csv", "time,tilt,com_angle",
                                       np.column_stack([t, tilt, com])))
    np.testing.assert_allclose(direct["gain"], truth["gain"], rtol=1e-4)
    np.testing.assert_allclose(direct["phase_deg"], truth["phase_deg"], atol=0.01)
    # --sway writes com_angle: another response is refused, as are markers without --sway
    line = one_line_exit_2(capsys, "frf", "--data", path, "--stimulus", "tilt",
                           "--response", "sho_x", "--cycle-length", "20", *sway)
    assert "--response com_angle" in line
    line = one_line_exit_2(capsys, "frf", "--data", path, *FRF, "--hip-marker", "hip")
    assert "without --sway" in line
    line = one_line_exit_2(capsys, "frf", "--data", path, *FRF, "--sway", "two-marker",
                           "--hip-marker", "hip")
    assert "shoulder not given" in line


def test_likeness_and_compare_frf_take_the_recording_flags(tmp_path, capsys, trial):
    t, tilt, com = trial
    rows = np.column_stack([t, tilt, com])
    seconds = write_csv(tmp_path / "s.csv", "time,tilt,com_angle", rows)
    ms = write_csv(tmp_path / "ms.csv", "time [ms],tilt,com_angle",
                   np.column_stack([t * 1000, tilt, com]))
    base = ["--stimulus", "tilt", "--response", "com_angle", "--cycle-length", "20"]
    like = ["likeness", "--reference", "comtest-eyes-closed", *base, "--json"]
    code, out, err = run(capsys, *like, "--data", seconds)
    assert code == 0, err
    want = json.loads(out)["score"]
    code, out, err = run(capsys, *like, "--data", ms, "--time-unit", "ms")
    assert code == 0, err
    assert json.loads(out)["score"] == pytest.approx(want, rel=1e-9)
    rng = np.random.default_rng(7)
    cohort = [write_csv(tmp_path / f"s{k}.csv", "time [ms],tilt,com_angle",
                        np.column_stack([t * 1000, tilt, com + 1e-3 * rng.normal(size=t.size)]))
              for k in range(4)]
    opts = ["--time-unit", "ms", "--start", "0"]
    code, out, err = run(capsys, "compare-frf", "--a", *cohort[:2], "--b", *cohort[2:], *base,
                         *opts, "--permutations", "10", "--resamples", "10", "--json")
    assert code == 0, err
    got = json.loads(out)
    assert [r["trimming"]["dropped_before"] for r in got["recordings"]] == [0] * 4
    code, out, err = run(capsys, "likeness-reference", "--data", *cohort, *base, *opts,
                         "--shrinkage", "0.5", "--out", tmp_path / "ref.json")
    assert code == 0 and err.count("note:") == 4, err


def test_the_cli_sway_choices_are_the_librarys():
    from posturelab.cli._recording import SWAY_CHOICES
    from posturelab.recordings.sway import SWAY_METHODS

    assert SWAY_CHOICES == tuple(SWAY_METHODS)


def test_a_cohort_says_what_reading_each_trial_did(tmp_path, capsys, trial):
    """cohort reads trials in worker processes: what was cut comes back with each subject
    (SubjectFit.reading; "readings" in --json), not printed by the library."""
    t, tilt, com = trial
    rows = np.column_stack([t, tilt, com])
    path = write_csv(tmp_path / "s01.csv", "time,tilt,com_angle",
                     np.vstack([rows, rows[:30] + [2 * CYCLE, 0, 0]]))
    code, out, err = run(capsys, "cohort", "--data", path, "--body", "paper-1link",
                         "--controller", "peterka-2002", "--free", "feedback_delay",
                         "--stimulus", "tilt", "--response", "com_angle", "--cycle-length",
                         "20", "--drop-partial", "--workers", "1", "--out",
                         tmp_path / "c.csv", "--json")
    assert code == 0, err
    (item,) = json.loads(out)["readings"]
    assert item["subject"] == "s01"
    assert item["reading"] == ["dropped the last 30 sample(s) (0.6 s), a partial cycle of "
                               "20 s; 2000 sample(s) kept"]


def test_sway_on_frf_from_a_lab_csv_equals_convert_then_frf(tmp_path, capsys):
    """A lab CSV (uneven clock, degrees, forward marker positions in mm): --length-unit is
    the markers' unit and the stimulus stays an angle (not a translation in mm)."""
    from posturelab.recordings.example import EXAMPLE_HEIGHT, make_lab_csv

    lab = tmp_path / "lab.csv"
    make_lab_csv(lab)
    units = ["--resample", "100", "--angle-unit", "deg", "--length-unit", "mm",
             "--height", str(EXAMPLE_HEIGHT)]
    code, out, err = run(capsys, "convert", lab, "--out", tmp_path / "t.csv", *units,
                         "--angle-columns", "stim_pitch", "--sway", "two-marker",
                         "--markers", "hip=hip_xpos,shoulder=shld_xpos")
    assert code == 0, err
    frf = ["--stimulus", "stim_pitch", "--response", "com_angle", "--cycle-length", "20",
           "--drop-partial", "--json"]
    code, out, err = run(capsys, "frf", "--data", tmp_path / "t.csv", *frf)
    assert code == 0, err
    want = json.loads(out)
    code, out, err = run(capsys, "frf", "--data", lab, *frf, *units, "--sway", "two-marker",
                         "--hip-marker", "hip_xpos", "--shoulder-marker", "shld_xpos")
    assert code == 0, err
    got = json.loads(out)
    np.testing.assert_allclose(got["gain"], want["gain"], rtol=1e-9)
    np.testing.assert_allclose(got["phase_deg"], want["phase_deg"], atol=1e-7)
    # the example's 3 whole cycles are kept whole: nothing to drop (the resampled grid
    # covers the last sample's interval)
    assert got["trimming"]["dropped_after"] == want["trimming"]["dropped_after"] == 0
    assert got["trimming"]["samples"] == 6000
    assert got["resampling"]["rate_hz"] == 100.0


def test_crlf_latin1_and_repeated_columns(tmp_path, capsys, trial):
    t, tilt, com = trial
    rows = np.column_stack([t, tilt, com])
    plain = frf_json(capsys, write_csv(tmp_path / "plain.csv", "time,tilt,com_angle", rows))
    crlf = tmp_path / "crlf.csv"
    crlf.write_bytes((tmp_path / "plain.csv").read_bytes().replace(b"\n", b"\r\n"))
    assert frf_json(capsys, crlf)["gain"] == plain["gain"]
    latin = tmp_path / "latin1.csv"
    latin.write_bytes("time,tilt [°],com_angle\n0,0,0\n".encode("latin-1"))
    line = one_line_exit_2(capsys, "frf", "--data", latin, *FRF)
    assert "not UTF-8 text (byte 0xb0" in line
    twice = write_csv(tmp_path / "twice.csv", "time,tilt,com_angle,tilt",
                      np.column_stack([t, tilt, com, tilt]))
    line = one_line_exit_2(capsys, "frf", "--data", twice, *FRF)
    assert "names 'tilt' 2 times (columns 2, 4)" in line


def test_an_analog_channel_without_samples_is_left_out(tmp_path, capsys):
    path = tmp_path / "dead.c3d"
    write_c3d(path, {"a": np.zeros((50, 3))}, 100.0,
              analogs={"dead": np.full(500, np.nan), "ok": np.ones(500)}, analog_rate=1000.0)
    rec = read_c3d(path)
    assert "dead" not in rec.columns and "fewer than 4 valid samples" in rec.unusable["dead"]
    np.testing.assert_allclose(rec.columns["ok"], 1.0, rtol=1e-12)
    line = one_line_exit_2(capsys, "frf", "--data", path, "--stimulus", "dead",
                           "--response", "ok", "--cycle-length", "0.2")
    assert "'dead' cannot be used" in line
