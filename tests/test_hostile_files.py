"""Hostile input files, on the command line as a real subprocess: each gets exit 2 and one
line on standard error with no traceback, quickly, and nothing is written.

Classes: a device given as a file (it used to hang), a non-UTF-8 byte (the fit reader used
to crash), a UTF-8 byte-order mark (it used to read as a missing column), a CSV field over
the csv module's limit, TOML nested past the parser's recursion limit, a non-CSV file
(its first line is not quoted back), and too many rows (the API, with a small bound).
"""

from __future__ import annotations

import os

import pytest

from _cli import cli, one_line_exit_2
from posturelab._files import csv_rows
from posturelab.errors import DataFileError


def trajectory(tmp_path, name="run.csv", bom=False):
    path = tmp_path / name
    assert cli("simulate", "--case", "1", "--disturbance", "backward", "--duration", "0.5",
               "--engine", "compiled", "--sample-rate", "100", "--out", str(path)
               ).returncode == 0
    if bom:
        path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes())
    return path


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="needs /dev/zero")
def test_a_device_as_a_profile_or_data_file_is_refused_at_once(tmp_path):
    out = tmp_path / "x.csv"
    one_line_exit_2(cli("simulate", "--case", "1", "--platform-profile", "/dev/zero",
                        "--out", str(out)), "not a regular file")
    one_line_exit_2(cli("fit", "--case", "1", "--data", "/dev/zero", "--free", "stiffness:ankle"),
                    "not a regular file")
    one_line_exit_2(cli("frf", "--data", "/dev/zero", "--stimulus", "tilt", "--response",
                        "com_angle", "--cycle-length", "20"), "not a regular file")
    one_line_exit_2(cli("simulate", "--scenario", "/dev/zero"), "not a regular file")
    assert not out.exists()


def test_a_non_utf8_byte_in_the_fit_data_names_its_offset(tmp_path):
    path = trajectory(tmp_path)
    data = bytearray(path.read_bytes())
    data[40] = 0xFF
    path.write_bytes(bytes(data))
    one_line_exit_2(cli("fit", "--case", "1", "--disturbance", "backward", "--data", str(path),
                        "--free", "stiffness:ankle"), "is not UTF-8 text (byte 0xff at offset 40)")


def test_a_byte_order_mark_is_read_as_utf8(tmp_path):
    path = trajectory(tmp_path, bom=True)
    p = cli("fit", "--case", "1", "--disturbance", "backward", "--data", str(path), "--free",
            "stiffness:ankle", "--json")
    assert p.returncode == 0, p.stderr
    profile = tmp_path / "profile.csv"
    profile.write_bytes(b"\xef\xbb\xbftime,x_acceleration\n0,0\n0.5,-1\n1,0\n")
    p = cli("simulate", "--case", "1", "--platform-profile", str(profile), "--duration", "1",
            "--engine", "compiled", "--json")
    assert p.returncode == 0, p.stderr


def test_a_field_over_the_csv_limit_names_its_line(tmp_path):
    path = tmp_path / "profile.csv"
    path.write_text("time,x_acceleration\n0,0\n" + "1," + "9" * 200_000 + "\n")
    one_line_exit_2(cli("simulate", "--case", "1", "--platform-profile", str(path)),
                    "line 3: a field longer than 131,072 characters")


def test_deeply_nested_toml_is_one_line(tmp_path):
    path = tmp_path / "deep.toml"
    path.write_text("duration = 1.0\nx = " + "[" * 5000 + "]" * 5000 + "\n")
    one_line_exit_2(cli("simulate", "--scenario", str(path)), "nested too deeply")


def test_a_non_csv_file_is_not_quoted_back(tmp_path):
    path = tmp_path / "notes.csv"
    path.write_text("my-secret-token-1234 and some words\nmore words\nand more\n")
    p = cli("simulate", "--case", "1", "--platform-profile", str(path))
    one_line_exit_2(p, "lacks column")
    assert "my-secret-token-1234" not in p.stderr


def test_too_many_rows_is_one_error_naming_the_bound():
    text = "time,x\n" + "".join(f"{k},0\n" for k in range(12))
    with pytest.raises(DataFileError, match="more than 10 data rows; at most 10 are read"):
        list(csv_rows(text, "f.csv", max_rows=10))
    assert len(list(csv_rows(text, "f.csv", max_rows=12))) == 13
    # refused before the first row is parsed (the generator raises on its first next()),
    # while blank lines do not count against the bound
    with pytest.raises(DataFileError, match="more than 10 data rows"):
        next(csv_rows(text, "f.csv", max_rows=10))
    spaced = "time,x\n" + "".join(f"{k},0\n\n" for k in range(12))
    assert len(list(csv_rows(spaced, "f.csv", max_rows=12))) == 13
