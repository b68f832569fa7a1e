"""Comparing runs: ``posturelab compare`` overlays saved runs, ``plot_compare`` gives one
legend entry per run, ``to_dataframe`` is the CSV's table."""

from __future__ import annotations

import json

import numpy as np
import pytest

import posturelab as pl
from posturelab.cli import main
from posturelab.simulation.results import read_run_csv
from posturelab.viz.plots import plot_compare

POSTURE = np.array([0.1, -0.1, 0.1, 0.0, 0.0, 0.0])


@pytest.fixture(scope="module")
def runs():
    return [pl.simulate(pl.paper_body(), pl.paper_muscles(case), pl.VelocityStep.backward(1.0),
                        2.0, initial_state=POSTURE, engine="compiled", sample_rate=200.0)
            for case in ("1", "3")]


def test_compare_reads_saved_runs_and_draws_them(runs, tmp_path, capsys):
    paths = []
    for k, r in enumerate(runs):
        paths.append(tmp_path / f"r{k}.csv")
        r.to_csv(paths[-1])
    t, th, om = read_run_csv(paths[1])
    np.testing.assert_allclose(th, runs[1].theta, rtol=1e-9)
    np.testing.assert_allclose(t, runs[1].time)
    plot = tmp_path / "cmp.svg"
    assert main(["compare", str(paths[0]), str(paths[1]), "--labels", "case 1,case 3",
                 "--plot", str(plot), "--json"]) == 0
    obj = json.loads(capsys.readouterr().out)
    assert [r["label"] for r in obj["runs"]] == ["case 1", "case 3"]
    np.testing.assert_allclose(obj["runs"][0]["max_abs_theta"], runs[0].max_abs_theta,
                               rtol=1e-9)
    assert b"<svg" in plot.read_bytes()[:500]
    assert main(["compare", str(paths[0]), "--labels", "a,b"]) == 2
    assert "one label per run" in capsys.readouterr().err
    bad = tmp_path / "bad.csv"
    bad.write_text("a,b\n1,2\n3,4\n")
    assert main(["compare", str(bad)]) == 2
    assert "not a run written by posturelab simulate" in capsys.readouterr().err


def test_plot_compare_has_one_legend_entry_per_run(runs):
    fig = plot_compare(runs, ["case 1", "case 3"])
    texts = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert texts == ["case 1", "case 3"]
    assert all(ax.get_legend() is None for ax in fig.axes[1:])
    assert len(fig.axes) == 3 and len(fig.axes[0].lines) >= 2


def test_to_dataframe_is_the_csv_table(runs):
    pytest.importorskip("pandas")
    df = runs[0].to_dataframe()
    names, table = runs[0].columns()
    assert list(df.columns) == names[1:] and df.index.name == "t"
    np.testing.assert_array_equal(df.to_numpy(), table[:, 1:])
