"""Sweeps (posturelab.studies.sweep) and ``posturelab sweep``: tables, formats, Dask, bad input."""

from __future__ import annotations

import csv
import math
import sys

import numpy as np
import pytest

from posturelab.cli import main
from posturelab.errors import ParameterError
from posturelab.model.body import paper_body
from posturelab.model.muscles import paper_muscles
from posturelab.model.platform import NoDisturbance, VelocityStep
from posturelab.paper import BACKWARD_INITIAL_STATE
from posturelab.scenarios import builtin_scenario
from posturelab.simulation.compiled import simulate_batch, simulate_fast
from posturelab.studies.sweep import (
    OUTCOME_COLUMNS,
    VaryRange,
    parse_vary,
    run_sweep,
    sweep_grid,
)

POSTURE = list(BACKWARD_INITIAL_STATE[:3]) + [0.0, 0.0, 0.0]


def read_csv(path):
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    return rows[0], rows[1:]


def cell(text):
    return math.nan if text == "" else float(text)


def test_cli_sweep_csv_equals_batch_and_single_runs(tmp_path, capsys):
    """The CSV's columns, and its values exactly (17 digits), are simulate_batch's; a run
    also equals simulate_fast's single run."""
    out = tmp_path / "sweep.csv"
    code = main(["sweep", "--case", "1", "--disturbance", "backward", "--duration", "2",
                 "--vary", "stiffness:ankle=0:1200:3", "--vary", "stiffness:gastrocnemius=0:600:2",
                 "--out", str(out)])
    assert code == 0
    assert "wrote" in capsys.readouterr().out
    header, rows = read_csv(out)
    assert header == ["stiffness:ankle", "stiffness:gastrocnemius", *OUTCOME_COLUMNS]
    assert len(rows) == 6
    # the grid: first parameter slowest, LO and HI included
    values = np.array([[float(r[0]), float(r[1])] for r in rows])
    np.testing.assert_array_equal(values, [[0, 0], [0, 600], [600, 0], [600, 600],
                                           [1200, 0], [1200, 600]])
    k = np.tile(paper_muscles("1").stiffnesses, (6, 1))
    k[:, 0] = values[:, 0]
    k[:, 4] = values[:, 1]
    batch = simulate_batch(paper_body(), k, 0.25 * k, VelocityStep.backward(1.0), 2.0, POSTURE)
    assert [r[2] for r in rows] == list(batch.outcome)
    assert [r[3] for r in rows] == [""] * 6  # no run failed: no failure words
    assert [r[4] for r in rows] == ["true" if f else "false" for f in batch.fell]
    got = np.array([[cell(x) for x in r[5:]] for r in rows])
    n = 3
    want = np.column_stack([batch.fall_time, batch.peak_theta, batch.settling_time,
                            np.abs(batch.final_state[:, :n]).max(axis=1),
                            np.abs(batch.final_state[:, n:]).max(axis=1)])
    np.testing.assert_array_equal(got, want)
    # the words follow the rule of posturelab.simulation.outcome, as the single run's
    assert rows[0][2] == "fell" and rows[-1][2] == simulate_fast(
        paper_body(), paper_muscles(stiffness=k[-1], viscosity=0.25 * k[-1]),
        VelocityStep.backward(1.0), 2.0, initial_state=POSTURE).outcome.kind
    assert batch.fell[0] and not batch.fell[-1]
    one = simulate_fast(paper_body(), paper_muscles(stiffness=k[-1], viscosity=0.25 * k[-1]),
                        VelocityStep.backward(1.0), 2.0, initial_state=POSTURE)
    np.testing.assert_array_equal(got[-1, 1:4], one.max_abs_theta)
    settle = one.settling_time(0.01)
    assert (math.isnan(got[-1, 4]) if settle is None else got[-1, 4] == settle)


def test_parquet_round_trip(tmp_path):
    pq = pytest.importorskip("pyarrow.parquet")
    sc = builtin_scenario("paper-forward-case2")
    result = run_sweep(sc.replace(duration=1.5), [parse_vary("stiffness:ankle=300:900:3"),
                                                  parse_vary("viscosity_ratio=0.1:0.3:2")])
    path = tmp_path / "sweep.parquet"
    result.write(path)
    table = pq.read_table(path)
    assert table.column_names == ["stiffness:ankle", "viscosity_ratio", *OUTCOME_COLUMNS]
    assert table.schema.field("stiffness:ankle").metadata[b"unit"] == "N·m/rad".encode()
    for name, values in result.columns():
        col = table.column(name).to_numpy(zero_copy_only=False)
        if name in ("fell", "outcome", "failure"):
            np.testing.assert_array_equal(col, values)
        else:
            np.testing.assert_array_equal(np.asarray(col, dtype=float), values)
    assert not list(tmp_path.glob(".*.tmp"))  # no temporary file left behind


def test_viscosity_follows_the_ratio():
    """A varied ratio sets every pair's viscosity; otherwise the base's ratio (0.25) holds."""
    sc = builtin_scenario("paper-backward-case1")
    g = sweep_grid(sc, [VaryRange("stiffness:hip", 0.0, 100.0, 2), VaryRange("viscosity_ratio", 0.1,
                                                                      0.5, 3)])
    assert g.n_runs == 6 and g.shape == (2, 3)
    np.testing.assert_allclose(g.viscosity, g.values[:, 1:2] * g.stiffness)
    g = sweep_grid(sc, [VaryRange("stiffness:knee", 50.0, 50.0, 1)])
    np.testing.assert_allclose(g.viscosity, 0.25 * g.stiffness)
    g = sweep_grid(sc, [VaryRange("stiffness:knee", 50.0, 50.0, 1)], viscosity_ratio=0.4)
    np.testing.assert_allclose(g.viscosity, 0.4 * g.stiffness)


def test_disturbance_scale_sweeps_the_perturbation_size():
    """disturbance_scale multiplies the base step's speed: each row equals a single run with
    the scaled step; a weak ankle that recovers from a small step falls from a large one."""
    sc = builtin_scenario("paper-backward-case1").replace(duration=3.0)
    varies = [parse_vary("stiffness:ankle=300:900:2"), parse_vary("disturbance_scale=0.5:4:3")]
    result = run_sweep(sc, varies)
    assert result.grid.disturbance_scale.tolist() == [0.5, 2.25, 4.0] * 2
    o = result.outcomes
    for r in range(result.grid.n_runs):
        k = result.grid.stiffness[r]
        one = simulate_fast(sc.body, paper_muscles(stiffness=k, viscosity=0.25 * k),
                            sc.disturbance.scaled(result.grid.disturbance_scale[r]),
                            sc.duration, initial_state=sc.initial_state)
        assert one.fell == o.fell[r]
        np.testing.assert_array_equal(one.max_abs_theta, o.peak_theta[r])
    weak = o.fell[:3]
    assert not weak[0] and weak[-1]
    # the peak lean grows with the perturbation for the runs that do not fall
    strong = o.peak_theta[3:, 0]
    assert np.all(np.diff(strong) > 0)


def test_disturbance_scale_needs_a_platform_motion():
    sc = builtin_scenario("paper-backward-case1").replace(disturbance=NoDisturbance())
    with pytest.raises(ParameterError, match="has none"):
        run_sweep(sc, [parse_vary("disturbance_scale=0.5:1:2")])


def test_dask_path_equals_the_local_path():
    """Chunks on a Dask LocalCluster (2 workers, threads, started here) give the same numbers."""
    distributed = pytest.importorskip("distributed")
    sc = builtin_scenario("paper-backward-case1").replace(duration=1.0)
    varies = [parse_vary("stiffness:ankle=200:1400:4"), parse_vary("stiffness:quadriceps=0:600:3"),
              parse_vary("disturbance_scale=0.5:2:2")]
    local = run_sweep(sc, varies)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            remote = run_sweep(sc, varies, client=client, chunk_size=5)
    for (name, a), (_, b) in zip(local.columns(), remote.columns(), strict=True):
        np.testing.assert_array_equal(a, b, err_msg=name)
    np.testing.assert_array_equal(local.outcomes.final_state, remote.outcomes.final_state)


def test_cli_scenario_base_and_progress_bar(tmp_path, capsys):
    """--scenario FILE.toml as the base (one-sided gastrocnemius); --progress draws on stderr."""
    toml = tmp_path / "base.toml"
    toml.write_text('duration = 1.0\n[muscles]\ncase = "1"\ngastrocnemius = "one-sided"\n'
                    'viscosity_ratio = 0.3\n[disturbance]\ntype = "velocity-step"\n'
                    'velocity = -0.5\n[initial]\nposture = [0.1, -0.1, 0.1]\n')
    out = tmp_path / "s.csv"
    assert main(["sweep", "--scenario", str(toml), "--vary", "stiffness:knee=0:300:2", "--out",
                 str(out),
                 "--progress"]) == 0
    err = capsys.readouterr().err
    assert "100%" in err and "2/2 runs" in err
    header, rows = read_csv(out)
    assert header[0] == "stiffness:knee" and len(rows) == 2
    m = paper_muscles("1", gastrocnemius="one-sided", viscosity_ratio=0.3)
    one = simulate_fast(paper_body(), m.with_stiffness(knee=300.0), VelocityStep(-0.5), 1.0,
                        initial_state=POSTURE)
    first = header.index("peak_theta1")
    np.testing.assert_allclose([cell(x) for x in rows[1][first:first + 3]], one.max_abs_theta,
                               rtol=0, atol=0)


@pytest.mark.parametrize("vary, words", [
    ("elbow=0:1:2", "unknown sweep parameter 'elbow'"),
    ("stiffness:ankle=900:100:3", "LO (900) must be <= HI"),
    ("stiffness:ankle=0:100:0", "N must be an integer >= 1"),
    ("stiffness:ankle=0:100", "NAME=LO:HI:N"),
    ("stiffness:ankle=0:100:2.5", "N must be an integer"),
    ("stiffness:ankle=-5:100:3", "LO [N·m/rad] must be in [0, 1e+08], got -5.0"),
    ("stiffness:ankle=0:100:1", "LO must equal HI"),
])
def test_bad_vary_is_one_line_and_exit_2(tmp_path, capsys, vary, words):
    code = main(["sweep", "--case", "1", "--disturbance", "backward", "--vary", vary,
                 "--out", str(tmp_path / "x.csv")])
    assert code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("posturelab: error:")
    assert words in err
    if "unknown" in words:
        assert "stiffness:ankle, stiffness:knee, stiffness:hip, stiffness:quadriceps" in err
    assert not (tmp_path / "x.csv").exists()


@pytest.mark.parametrize("extra, words", [
    (["--vary", "stiffness:ankle=0:1:2", "--vary", "stiffness:ankle=0:1:2"], "more than once"),
    (["--vary", "stiffness:ankle=0:1:100000", "--vary", "stiffness:knee=0:1:1000"],
     "at most 10,000,000"),
    (["--vary", "stiffness:ankle=0:1:2", "--out-format"], "unrecognized"),
])
def test_other_bad_input_exit_2(tmp_path, capsys, extra, words):
    code = main(["sweep", "--case", "1", "--disturbance", "backward", *extra,
                 "--out", str(tmp_path / "x.csv")])
    assert code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and words in err


def test_bad_output_suffix_and_missing_dask(tmp_path, capsys, monkeypatch):
    assert main(["sweep", "--case", "1", "--vary", "stiffness:ankle=0:1:2",
                 "--out", str(tmp_path / "x.xlsx")]) == 2
    assert ".csv or .parquet" in capsys.readouterr().err
    monkeypatch.setitem(sys.modules, "distributed", None)  # as if Dask were not installed
    assert main(["sweep", "--case", "1", "--vary", "stiffness:ankle=0:1:2", "--workers", "2",
                 "--out", str(tmp_path / "x.csv")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "need Dask" in err


def test_parse_vary_values():
    v = parse_vary(" stiffness:ankle = 0 : 2000 : 5 ")
    np.testing.assert_array_equal(v.values, [0.0, 500.0, 1000.0, 1500.0, 2000.0])
    assert v.unit == "N·m/rad"
    assert parse_vary("viscosity_ratio=0.25:0.25:1").values.tolist() == [0.25]
    with pytest.raises(ParameterError):
        sweep_grid(builtin_scenario("paper-backward-case1"), [])


def test_sweep_over_feedback_delay_equals_single_runs():
    """--vary feedback_delay: each row is the compiled single run with that delay (a row
    without delay chooses Radau, the others RK45, as their single runs do)."""
    sc = builtin_scenario("paper-backward-case1").replace(duration=1.0)
    result = run_sweep(sc, [parse_vary("feedback_delay=0:0.04:5"),
                            parse_vary("stiffness:ankle=400:800:2")])
    o = result.outcomes
    assert result.grid.names == ("feedback_delay", "stiffness:ankle")
    for r, (delay, ankle) in enumerate(result.grid.values):
        k = result.grid.stiffness[r]
        assert k[0] == ankle
        one = sc.run(engine="compiled", feedback_delay=float(delay),
                     muscles=paper_muscles(stiffness=k, viscosity=0.25 * k),
                     rtol=1e-6, atol=1e-9)
        assert one.fell == o.fell[r]
        np.testing.assert_array_equal(one.max_abs_theta, o.peak_theta[r])
    assert o.fell[-1] and not o.fell[0]


def test_sweep_over_a_joint_torque_limit_equals_single_runs(tmp_path):
    """--vary torque_limit:ankle keeps the base experiment's other limits (here the hip's)."""
    sc = builtin_scenario("paper-backward-case1").replace(
        duration=1.0, torque_limits=(math.inf, math.inf, 40.0))
    result = run_sweep(sc, [parse_vary("torque_limit:ankle=30:120:4")])
    for r, (limit,) in enumerate(result.grid.values):
        one = sc.run(engine="compiled", torque_limits=(float(limit), math.inf, 40.0),
                     rtol=1e-6, atol=1e-9)
        assert one.fell == result.outcomes.fell[r]
        np.testing.assert_array_equal(one.final_state, result.outcomes.final_state[r])
    assert main(["sweep", "--case", "1", "--disturbance", "backward", "--duration", "0.5",
                 "--vary", "torque_limit:knee=20:60:3", "--torque-limits", "inf,inf,30",
                 "--out", str(tmp_path / "limits.csv")]) == 0
    header = (tmp_path / "limits.csv").read_text().splitlines()[0]
    assert header.startswith("torque_limit:knee,outcome,failure,fell")


def test_a_one_link_sweep_over_delay_active_gain_and_weight_equals_single_runs(tmp_path,
                                                                                capsys):
    """--controller on one link, a tilt, and a grid over feedback_delay × active_ankle ×
    proprioceptive_weight: every row is the single compiled run of its values."""
    import csv

    import posturelab as pl
    from posturelab.model.controllers import get_controller
    from posturelab.model.tilt import SineTilt

    out = tmp_path / "one.csv"
    code = main(["sweep", "--controller", "peterka-2002", "--tilt", "sine:0.02:0.5",
                 "--duration", "4", "--vary", "feedback_delay=0.1:0.3:3",
                 "--vary", "active_stiffness:ankle=600:900:2",
                 "--vary", "proprioceptive_weight=0.5:1:2",
                 "--out", str(out)])
    assert code == 0, capsys.readouterr().err
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 12 and set(rows[0]) >= {"peak_theta1", "fell"}
    assert "peak_theta2" not in rows[0]
    body = pl.get_body("paper-1link")
    base = get_controller("peterka-2002").muscles(body)
    for row in rows:
        ka = float(row["active_stiffness:ankle"])
        muscles = base.with_active_feedback([ka], base.active_viscosities)
        one = pl.simulate(body, muscles, None, 4.0, tilt=SineTilt(0.02, 0.5),
                          feedback_delay=float(row["feedback_delay"]),
                          proprioceptive_weight=float(row["proprioceptive_weight"]),
                          engine="compiled")
        assert (row["fell"] == "true") == one.fell
        assert float(row["peak_theta1"]) == one.max_abs_theta[0]
        # a sine tilt is sustained: a steady sway, never "recovered" (the sine crossing zero)
        assert row["outcome"] == ("fell" if one.fell else "steady sway")
        assert row["settling_time"] == "" and row["outcome"] == one.outcome.kind
        if not one.fell:
            sway = one.steady_sway()
            assert sway.start == 2.0  # after one 2 s period
            assert float(row["steady_rms_theta1"]) == sway.rms_theta[0]
            assert float(row["steady_peak_theta1"]) == sway.peak_theta[0]
    assert "steady_rms_cop" not in rows[0]  # the centre of pressure's: single runs only
    assert {r["fell"] for r in rows} == {"true", "false"}  # τ = 0.3 s is past the margin


def test_a_sweep_refuses_a_name_its_experiment_lacks(tmp_path, capsys):
    code = main(["sweep", "--body", "paper-1link", "--stiffness", "900", "--disturbance",
                 "backward", "--vary", "stiffness:knee=0:10:2", "--out", str(tmp_path / "x.csv")])
    err = capsys.readouterr().err
    assert code == 2 and "unknown pair 'knee' in sweep parameter 'stiffness:knee'; pairs: " \
        "ankle" in err
