"""PRTS experiments over a population of parameter sets (posturelab.frequency.population).

Checked against: each row run on its own by prts_experiment with the stated seeds; the same
table whatever the chunks, threads or Dask workers; the fitted parameters against the ones
each virtual subject was simulated with; the command line and its bad input.
"""

from __future__ import annotations

import csv
from dataclasses import replace

import numpy as np
import pytest

from posturelab.cli import main
from posturelab.errors import ParameterError
from posturelab.frequency.experiment import prts_experiment
from posturelab.frequency.population import PRTSProtocol, _row_seed, prts_sweep
from posturelab.model.noise import MotorNoise
from posturelab.model.tilt import PRTSTilt, SineTilt
from posturelab.scenarios import parse_scenario
from posturelab.studies.sweep import parse_vary

BASE = {"duration": 5.0, "body": {"preset": "paper-1link"},
        "muscles": {"pairs": [{"name": "ankle", "lo": 0, "hi": 1, "stiffness": 300.0,
                               "viscosity": 100.0, "active_stiffness": 1000.0,
                               "active_viscosity": 300.0}],
                    "feedback_delay": 0.15, "proprioceptive_weight": 0.7},
        "tilt": {"type": "prts", "amplitude": 0.035},
        "motor_noise": {"standard_deviation": [2.0], "cutoff": 1.0, "seed": 4}}


@pytest.fixture(scope="module")
def scenario():
    return parse_scenario(BASE)


def test_each_row_is_the_experiment_run_on_its_own(scenario):
    varies = [parse_vary("active_stiffness:ankle=800:1200:2"),
              parse_vary("feedback_delay=0.12:0.18:2")]
    protocol = PRTSProtocol(cycles=3, sensor_noise=5e-4, seed=8)
    res = prts_sweep(scenario, varies, protocol)
    assert res.frf.shape == (4, 11) and not res.fell.any()
    body, base = scenario.body, scenario.muscles
    for r, (ka, tau) in enumerate(res.grid.values):
        muscles = base.with_active_feedback([ka], [300.0])
        exp = prts_experiment(body, muscles, tilt=scenario.tilt, cycles=3, discard=1,
                              sensor_noise=5e-4, seed=_row_seed(8, r), feedback_delay=tau,
                              proprioceptive_weight=0.7,
                              motor_noise=MotorNoise(2.0, 1.0, seed=_row_seed(4, r)))
        np.testing.assert_array_equal(res.frf[r], exp.estimate.frf)
    assert len({tuple(row) for row in np.round(res.gain, 12)}) == 4  # each its own noise


def test_the_table_does_not_depend_on_how_the_runs_are_spread(scenario):
    distributed = pytest.importorskip("distributed")
    varies = [parse_vary("feedback_delay=0.1:0.2:3")]
    protocol = PRTSProtocol(cycles=2, sensor_noise=1e-3)
    local = prts_sweep(scenario, varies, protocol)
    one_by_one = prts_sweep(scenario, varies, protocol, chunk_size=1)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            remote = prts_sweep(scenario, varies, protocol, client=client, chunk_size=1)
    for other in (one_by_one, remote):
        for (name, a), (_, b) in zip(local.columns(), other.columns(), strict=True):
            np.testing.assert_array_equal(a, b, err_msg=name)


def test_the_fit_finds_each_subjects_delay_and_gain(scenario):
    """Six virtual subjects, each fitted from the base experiment's values: the delay and the
    active stiffness come back within 3 standard errors (and 10 %) of the simulated ones."""
    varies = [parse_vary("active_stiffness:ankle=800:1200:3"),
              parse_vary("feedback_delay=0.12:0.18:2")]
    res = prts_sweep(scenario, varies,
                     PRTSProtocol(fit=("active_stiffness", "feedback_delay"), seed=3))
    truth = res.grid.values  # columns: active_ankle, feedback_delay
    z = np.abs(res.fit_estimates - truth) / res.fit_standard_errors
    assert np.all(z < 3.5) and np.mean(z < 2) >= 0.75
    np.testing.assert_allclose(res.fit_estimates, truth, rtol=0.1)


def test_the_command_line_writes_the_table(tmp_path, capsys):
    out = tmp_path / "pop.csv"
    assert main(["sweep", "--experiment", "prts", "--body", "paper-1link", "--controller",
                 "icm-pmc5664365", "--tilt", "prts:0.035", "--vary",
                 "feedback_delay=0.12:0.18:2", "--cycles", "2", "--sensor-noise", "0.001",
                 "--seed", "5", "--fit", "feedback_delay", "--out", str(out)]) == 0
    assert "2 PRTS experiments" in capsys.readouterr().out
    with open(out, newline="") as fh:
        rows = list(csv.reader(fh))
    header = rows[0]
    assert header[:3] == ["feedback_delay", "fell", "gain_1"]
    assert "phase_deg_11" in header and "coherence_11" in header
    assert header[-3:] == ["fit_feedback_delay", "se_feedback_delay", "fit_error"]
    fitted = [float(r[header.index("fit_feedback_delay")]) for r in rows[1:]]
    np.testing.assert_allclose(fitted, [0.12, 0.18], rtol=0.1)


@pytest.mark.parametrize("args, words", [
    (["--tilt", "sine:0.01:0.5"], "needs a PRTS tilt"),
    (["--tilt", "prts:0.035", "--vary", "proprioceptive_weight=0:1:2", "--fit", "gain"],
     "unknown FRF fit parameter 'gain'"),
    (["--tilt", "prts:0.035", "--cycles", "1"], "cycles must be an integer >= 2"),
])
def test_bad_experiment_sweeps_are_one_line_and_exit_2(args, words, tmp_path, capsys):
    out = tmp_path / "pop.csv"
    code = main(["sweep", "--experiment", "prts", "--body", "paper-1link", "--controller",
                 "icm-pmc5664365", "--vary", "feedback_delay=0.1:0.2:2", "--out", str(out),
                 *args])
    err = capsys.readouterr().err.strip()
    assert code == 2 and words in err and len(err.splitlines()) == 1
    assert not out.exists()


def test_api_bad_input_names_the_problem(scenario):
    with pytest.raises(ParameterError, match="needs a PRTS tilt"):
        prts_sweep(replace(scenario, tilt=SineTilt(0.01, 0.5)),
                   [parse_vary("feedback_delay=0.1:0.2:2")])
    with pytest.raises(ParameterError, match="disturbance_scale has no meaning"):
        prts_sweep(scenario, [parse_vary("disturbance_scale=0.5:1:2")])
    with pytest.raises(ParameterError, match="sensor_noise"):
        PRTSProtocol(sensor_noise=-1.0)
    assert isinstance(scenario.tilt, PRTSTilt)
