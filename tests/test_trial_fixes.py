"""Defects found by a new-user trial: written tables bounded so posturelab reads them back,
repeated cohort files, CSV markers listed, fit's time column and degrees, a path ending in
a separator, --start and --height messages, notes in order, simulate --out .parquet."""

from __future__ import annotations

import json

import numpy as np
import pytest

from _cli import refused_in_one_line as one_line_exit_2
from _cli import run_main as run
from posturelab.cli import main
from posturelab.recordings.example import EXAMPLE_C3D, EXAMPLE_HEIGHT, make_lab_csv


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    path = tmp_path_factory.mktemp("lab") / "lab.csv"
    make_lab_csv(path)
    return path


# ---- 2: resource bounds ------------------------------------------------------------------

def test_simulate_samples_are_bounded_by_the_rows_posturelab_reads(tmp_path, capsys):
    from posturelab._files import MAX_DATA_ROWS
    from posturelab.simulation.options import MAX_OUTPUT_SAMPLES

    assert MAX_OUTPUT_SAMPLES == MAX_DATA_ROWS == 2_000_000
    base = ["simulate", "--controller", "peterka-2002", "--out", tmp_path / "x.csv"]
    # 2000 s at 1 kHz: the samples at 0 … 2000 s are 2,000,001, one more than allowed
    line = one_line_exit_2(capsys, *base, "--duration", "2000")
    assert "duration [s] 2000 at sample_rate [Hz] 1000 gives 2,000,001 output samples" in line
    assert "at most 2,000,000" in line
    assert not (tmp_path / "x.csv").exists()


def test_convert_rate_is_bounded_by_the_files_rates(tmp_path, capsys):
    out = tmp_path / "big.csv"
    line = one_line_exit_2(capsys, "convert", EXAMPLE_C3D, "--out", out, "--angle-columns",
                           "tilt", "--rate", "1e5")
    assert "--rate [Hz]" in line and "analog 100 Hz" in line and "[1, 100] Hz" in line
    assert "100000" in line and not out.exists()


def test_a_csv_over_the_readers_limits_is_refused_and_not_left(tmp_path, monkeypatch):
    import posturelab._files as files
    from posturelab.errors import ParameterError

    path = tmp_path / "t.csv"
    cols = [np.arange(5000.0), np.full(5000, np.pi)]
    monkeypatch.setattr(files, "MAX_DATA_ROWS", 4000)
    with pytest.raises(ParameterError, match=r"5,000 rows; at most 4,000"):
        files.atomic_write_csv(path, ["a", "b"], cols)
    monkeypatch.setattr(files, "MAX_DATA_ROWS", 10_000)
    monkeypatch.setattr(files, "MAX_INPUT_BYTES", 50_000)  # 5000 rows × ~25 bytes
    monkeypatch.setattr(files, "CSV_CHUNK_ROWS", 1000)
    with pytest.raises(ParameterError, match="would be more than"):
        files.atomic_write_csv(path, ["a", "b"], cols)
    assert list(tmp_path.iterdir()) == []  # nothing half-written
    monkeypatch.setattr(files, "MAX_INPUT_BYTES", 512 * 2**20)
    files.atomic_write_csv(path, ["a", "b"], cols)
    back = np.loadtxt(path, delimiter=",", skiprows=1)
    np.testing.assert_array_equal(back, np.column_stack(cols))  # 17 digits: exact


def test_stability_map_resolution_is_bounded_by_the_rows_posturelab_reads(tmp_path, capsys):
    from posturelab.cli.stability_map import MAX_RESOLUTION

    assert MAX_RESOLUTION ** 2 <= 2_000_000 < (MAX_RESOLUTION + 1) ** 2
    line = one_line_exit_2(capsys, "stability-map", "--x", "stiffness:ankle:0:1", "--y",
                           "stiffness:hip:0:1", "--resolution", "5000", "--out",
                           tmp_path / "m.png")
    assert "--resolution must be in [2, 1414]" in line and "5000" in line


# ---- 3: cohort ---------------------------------------------------------------------------

def test_cohort_refuses_a_file_given_twice(tmp_path, capsys):
    a3 = tmp_path / "a3.json"
    a3.write_text("{}")
    line = one_line_exit_2(capsys, "cohort", "--data", a3, tmp_path / "." / "a3.json",
                           "--controller", "peterka-2002", "--free", "feedback_delay",
                           "--out", tmp_path / "c.csv")
    assert "the same file twice" in line and "a3.json" in line


# ---- 4: convert's columns ----------------------------------------------------------------

def test_convert_refuses_repeated_columns_and_lists_markers(tmp_path, capsys, lab):
    twice = tmp_path / "twice.csv"
    twice.write_text("time,a,b,a\n" + "".join(f"{k / 10},1,2,3\n" for k in range(10)))
    line = one_line_exit_2(capsys, "convert", twice, "--out", tmp_path / "o.csv")
    assert "names 'a' 2 times (columns 2, 4)" in line
    line = one_line_exit_2(capsys, "convert", lab, "--out", tmp_path / "o.csv", "--resample",
                           "100", "--length-unit", "mm", "--sway", "two-marker", "--markers",
                           "hip=hip_xpos,shoulder=nothere", "--height", "1.75")
    assert "no marker 'nothere'" in line and "hip_xpos, shld_xpos" in line
    line = one_line_exit_2(capsys, "convert", EXAMPLE_C3D, "--out", tmp_path / "o.csv",
                           "--sway", "segments", "--markers",
                           "ankle=ank,knee=kne,hip=hip,shoulder=nothere")
    assert line.endswith("markers (LABEL_x, LABEL_y, LABEL_z): ank, hip, kne, sho")


# ---- 5: fit's time column ----------------------------------------------------------------

def test_fit_reads_a_time_column_and_converts_a_header_in_degrees(tmp_path, capsys):
    from posturelab.studies.identification import read_trajectory_csv

    t = np.arange(0, 2, 0.01)
    path = tmp_path / "traj.csv"
    np.savetxt(path, np.column_stack([t, 0.01 * np.sin(t)]), delimiter=",",
               header="time [s],theta1 [rad]", comments="")
    time, theta = read_trajectory_csv(path, 1)
    np.testing.assert_array_equal(time, t)
    deg = tmp_path / "deg.csv"
    np.savetxt(deg, np.column_stack([t, np.sin(t)]), delimiter=",", header="t,theta1 [deg]",
               comments="")
    _, theta = read_trajectory_csv(deg, 1)  # a declared unit is honoured (converted)
    np.testing.assert_allclose(theta[:, 0], np.radians(np.sin(t)), rtol=1e-12)


# ---- 6: a path ending in a separator -----------------------------------------------------

def test_an_output_ending_in_a_separator_is_refused(tmp_path, capsys):
    out = f"{tmp_path / 'o.csv'}/"
    line = one_line_exit_2(capsys, "simulate", "--controller", "peterka-2002", "--duration",
                           "1", "--out", out)
    assert "a file name cannot end in '/'" in line
    assert not (tmp_path / "o.csv").exists()
    from posturelab._files import atomic_write_text
    from posturelab.errors import PostureLabError

    with pytest.raises(PostureLabError, match="cannot end in"):
        atomic_write_text(out, "x")
    assert list(tmp_path.iterdir()) == []


# ---- 7: messages -------------------------------------------------------------------------

@pytest.mark.parametrize("start, words", [("-5", "--start [s] must be in [0, 1e+07] s"),
                                          ("nan", "--start [s] must be a finite number"),
                                          ("inf", "--start [s] must be a finite number")])
def test_start_must_be_a_finite_time_from_zero(tmp_path, capsys, lab, start, words):
    line = one_line_exit_2(capsys, "convert", EXAMPLE_C3D, "--out", tmp_path / "o.csv",
                           f"--start={start}")
    assert words in line
    line = one_line_exit_2(capsys, "frf", "--data", lab, "--stimulus", "stim_pitch",
                           "--response", "hip_xpos", "--cycle-length", "20",
                           f"--start={start}")
    assert words in line


def test_two_marker_sway_without_height_says_it_is_required(tmp_path, capsys, lab):
    line = one_line_exit_2(capsys, "convert", lab, "--out", tmp_path / "o.csv", "--resample",
                           "100", "--length-unit", "mm", "--sway", "two-marker", "--markers",
                           "hip=hip_xpos,shoulder=shld_xpos")
    assert "--height is required for --sway two-marker" in line and "None" not in line


def test_notes_are_prefixed_and_in_the_order_done(capsys, lab):
    code, out, err = run(capsys, "frf", "--data", lab, "--stimulus", "stim_pitch", "--response",
                         "com_angle", "--cycle-length", "20", "--resample", "100",
                         "--angle-unit", "deg", "--length-unit", "mm", "--sway",
                         "two-marker", "--markers", "hip=hip_xpos,shoulder=shld_xpos",
                         "--height", str(EXAMPLE_HEIGHT), "--start", "1", "--drop-partial")
    assert code == 0, err
    lines = err.splitlines()
    assert all(ln.startswith("posturelab: note: ") for ln in lines), err
    order = [next(i for i, ln in enumerate(lines) if words in ln)
             for words in ("dropped 90 sample(s) before 1 s", "resampled", "com_angle by",
                           "dropped the last")]
    assert order == sorted(order), err


# ---- 8: simulate --out .parquet ----------------------------------------------------------

def test_simulate_writes_parquet_with_units(tmp_path, capsys):
    import pyarrow.parquet as pq

    csv, parquet = tmp_path / "run.csv", tmp_path / "run.parquet"
    base = ["simulate", "--controller", "peterka-2002", "--tilt", "sine:0.01:0.5",
            "--duration", "2", "--json"]
    code, _, err = run(capsys, *base, "--out", csv)
    assert code == 0, err
    code, out, err = run(capsys, *base, "--out", parquet)
    assert code == 0, err and json.loads(out)
    table = pq.read_table(parquet)
    want = np.genfromtxt(csv, delimiter=",", names=True)
    assert table.column_names == list(want.dtype.names)
    for name in table.column_names:  # the CSV has 10 significant digits
        np.testing.assert_allclose(table.column(name).to_numpy(), want[name], rtol=1e-9,
                                   atol=1e-12)
    units = {f.name: (f.metadata or {}).get(b"unit", b"").decode() for f in table.schema}
    assert units["t"] == "s" and units["theta1"] == "rad" and units["omega1"] == "rad/s"
    assert units["M_ankle"] == "N·m" and units["tilt"] == "rad" and units["cop_x"] == "m"
    assert all(units.values()), units


def test_an_unknown_flag_points_to_the_subcommand_help(capsys):
    """`posturelab frf … --bogus 1`: one line naming the subcommand and its own help."""

    assert main(["frf", "--data", "x.csv", "--cycle-length", "20", "--bogus", "1"]) == 2
    err = capsys.readouterr().err
    assert err.strip() == ("posturelab: error: frf: unrecognized arguments: --bogus 1 "
                           "(see 'posturelab frf --help')")


def test_a_missing_likeness_reference_file_is_named_as_missing(tmp_path, capsys):

    missing = tmp_path / "ref.json"
    assert main(["likeness", "--data", str(tmp_path / "a.json"), "--reference",
                 str(missing)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no such file" in err and "ref.json" in err
