"""posturelab reads back the Parquet tables it writes (simulate/convert/sweep --out
FILE.parquet): the same columns as the CSV of the same run, units from the fields' metadata,
and a damaged or foreign file refused in one line."""

from __future__ import annotations

import numpy as np
import pytest

from posturelab.cli import main
from posturelab.errors import DataFileError
from posturelab.recordings.columns import read_table

pytest.importorskip("pyarrow")

RUN = ["simulate", "--controller", "peterka-2002", "--tilt", "prts:0.035", "--duration",
       "40", "--sample-rate", "50"]


@pytest.fixture(scope="module")
def both(tmp_path_factory):
    d = tmp_path_factory.mktemp("parquet")
    for suffix in ("csv", "parquet"):
        assert main([*RUN, "--out", str(d / f"run.{suffix}")]) == 0
    return d


def test_a_parquet_run_reads_as_its_csv(both):
    t_csv, c_csv, u_csv = read_table(both / "run.csv", ["tilt", "com_angle"])
    t_pq, c_pq, u_pq = read_table(both / "run.parquet", ["tilt", "com_angle"])
    np.testing.assert_allclose(t_pq, t_csv, rtol=0, atol=1e-12)
    for c in ("tilt", "com_angle"):  # the CSV prints 10 significant digits
        np.testing.assert_allclose(c_pq[c], c_csv[c], rtol=1e-9, atol=1e-15)
    assert u_pq == {"tilt": "rad", "com_angle": "rad"}  # (the simulated CSV's header has none)
    assert set(u_csv.values()) <= {"", "rad"}


def test_frf_of_a_parquet_run_equals_the_csv_one(both, capsys):
    args = ["--stimulus", "tilt", "--response", "com_angle", "--cycle-length", "20",
            "--json"]
    import json

    out = []
    for suffix in ("csv", "parquet"):
        capsys.readouterr()
        assert main(["frf", "--data", str(both / f"run.{suffix}"), *args]) == 0
        out.append(json.loads(capsys.readouterr().out))
    np.testing.assert_allclose(out[1]["gain"], out[0]["gain"], rtol=1e-7)


def test_a_file_that_is_not_parquet_is_refused_in_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.parquet"
    bad.write_text("time,tilt\n0,0\n")
    with pytest.raises(DataFileError, match="cannot read .* as Parquet"):
        read_table(bad, ["tilt"])
    assert main(["frf", "--data", str(bad), "--stimulus", "tilt", "--response", "tilt",
                 "--cycle-length", "20"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err


def test_a_missing_column_is_named_with_the_known_ones(both):
    with pytest.raises(DataFileError, match="no column 'nope'; columns: time, theta1"):
        read_table(both / "run.parquet", ["nope"])
