"""The other readers of a CSV header (fit's measured angles, simulate's tilt and platform
profiles) read a declared unit too: SI is read, another unit refused in one line."""

from __future__ import annotations

import pytest

from _cli import cli, one_line_exit_2


def test_fit_refuses_angles_in_an_unknown_unit(tmp_path):
    path = tmp_path / "grad.csv"
    path.write_text("t [s],theta1 [grad],theta2,theta3\n0,5,-5,5\n0.01,4,-4,4\n0.02,3,-3,3\n")
    one_line_exit_2(cli("fit", "--case", "1", "--disturbance", "backward", "--data", str(path),
                        "--free", "stiffness:ankle"), "'theta1 [grad]'", "is in grad",
                    "angles in rad")


def test_a_tilt_profile_in_degrees_is_converted(tmp_path):
    from posturelab.model.tilt import read_tilt_csv

    path = tmp_path / "deg.csv"
    path.write_text("time [s],tilt [deg]\n0,0\n0.2,1\n0.4,2\n0.6,2\n")
    tilt = read_tilt_csv(path)
    assert tilt.angle(0.6) == pytest.approx(2 * 3.141592653589793 / 180)


@pytest.mark.parametrize("content, words", [
    ("time [ms],tilt [rad]\n0,0\n200,0.01\n400,0.02\n600,0.02\n",
     ("tilt profile", "'time [ms]'", "is in ms")),
    ("time [s],tilt [grad]\n0,0\n0.2,1\n0.4,2\n0.6,2\n", ("'tilt [grad]'", "a tilt in rad")),
    ("time [s],x_acceleration [g]\n0,0\n0.5,0.1\n1,0\n",
     ("platform profile", "'x_acceleration [g]'", "m/s²")),
])
def test_simulate_refuses_a_profile_in_another_unit(tmp_path, content, words):
    path = tmp_path / "profile.csv"
    path.write_text(content)
    one_line_exit_2(cli("simulate", "--case", "1", "--platform-profile", str(path),
                        "--duration", "1"), *words)


def test_a_profile_in_si_units_runs(tmp_path):
    path = tmp_path / "profile.csv"
    path.write_text("time [s],x_acceleration [m/s²]\n0,0\n0.5,0.1\n1,0\n", encoding="utf-8")
    p = cli("simulate", "--case", "1", "--platform-profile", str(path), "--duration", "1")
    assert p.returncode == 0, p.stderr
