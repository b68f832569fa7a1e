"""RunOptions: each option of a run declared once, its bounds from the parameter table, one-line
errors, and the API, a scenario file and the command line parsing into equal options."""

from __future__ import annotations

import ast
import dataclasses
import inspect
import math
from pathlib import Path

import numpy as np
import pytest

import posturelab as pl
from posturelab.errors import ParameterError, ScenarioError
from posturelab.model.tilt import SineTilt
from posturelab.parameters import QUANTITIES, RUN_SETTINGS
from posturelab.scenarios import builtin_scenario, parse_scenario
from posturelab.scenarios._parse import OPTION_KEYS
from posturelab.simulation.compiled import simulate_batch
from posturelab.simulation.compiled._batch import PER_RUN_OPTIONS
from posturelab.simulation.options import OPTION_NAMES, RunOptions
from posturelab.simulation.setup import RUN_OPTIONS, prepare_run

SRC = Path(pl.__file__).resolve().parent


# ---- declared once ------------------------------------------------------------------------


def test_every_option_is_a_field_of_run_options_and_nothing_else_declares_one():
    """The names are RunOptions' fields; simulate's signature, RUN_OPTIONS, the scenario
    keys and a Scenario's attributes are read from them, not written again."""
    fields = tuple(f.name for f in dataclasses.fields(RunOptions))
    assert OPTION_NAMES == fields
    assert tuple(RUN_OPTIONS) == fields
    shown = list(inspect.signature(pl.simulate).parameters)
    assert shown[:5] == ["body", "muscles", "disturbance", "duration", "options"]
    assert shown[5:] == [f for f in fields if f != "duration"]
    assert set(OPTION_KEYS) == set(fields) - {"engine"}  # a file does not choose the engine
    sc = builtin_scenario("paper-backward-case1")
    for name in fields:
        assert getattr(sc, name) == getattr(sc.options, name) or name == "initial_state"
    for f in dataclasses.fields(RunOptions):  # each with its meaning (and unit) stated
        assert f.metadata["meaning"], f.name


def test_no_public_function_lists_the_run_options_again():
    """simulate, simulate_batch and Scenario take the options as one object (plus the
    batch's per-run arrays), not as their own parameters."""
    batch = set(inspect.signature(simulate_batch).parameters)
    assert batch & set(OPTION_NAMES) == {"duration", "initial_state", *PER_RUN_OPTIONS}
    assert {f.name for f in dataclasses.fields(pl.Scenario)} == {
        "name", "source", "body", "muscles", "disturbance", "options", "case"}


def test_the_compiled_engine_no_longer_imports_the_entry_point():
    """compiled/ imports neither simulation.engines nor anything above the simulation (the
    former cycle compiled/__init__ → engines → compiled)."""
    for path in (SRC / "simulation" / "compiled").glob("*.py"):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module:
                assert "engines" not in node.module, path.name
                assert not node.module.startswith(("studies", "cli", "scenarios")), path.name


# ---- bounds from the parameter table --------------------------------------------------------


@pytest.mark.parametrize("name", ["feedback_delay", "proprioceptive_weight"])
def test_feedback_bounds_are_the_parameter_tables(name):
    q = QUANTITIES[name]
    assert getattr(RunOptions(**{name: q.high}), name) == q.high
    assert getattr(RunOptions(**{name: q.low}), name) == q.low
    for bad in (q.high * (1 + 1e-9), q.low - 1e-9, math.nan):
        with pytest.raises(ParameterError, match=rf"{name} \[{q.unit}\] must be in "
                                                 rf"\[{q.low:g}, {q.high:g}\]"):
            RunOptions(**{name: bad})


@pytest.mark.parametrize("name", ["duration", "tilt_axis_depth", "rtol", "atol", "sample_rate",
                                  "time_limit"])
def test_setting_bounds_are_the_run_settings_table(name):
    q = RUN_SETTINGS[name]
    extra = {"tilt": SineTilt(0.01, 1.0)} if name == "tilt_axis_depth" else {}
    if name == "sample_rate":
        extra["duration"] = 1.0
    if name == "duration":  # (a day at 1 kHz is more samples than a run keeps)
        extra["sample_rate"] = 1.0
    ok = RunOptions(**{name: q.high}, **extra)
    assert getattr(ok, name) == q.high
    if not q.low_open:
        assert getattr(RunOptions(**{name: q.low}, **extra), name) == q.low
    for bad in (q.high * 1.01, q.low if q.low_open else q.low * 0.99 - 1e-300, math.inf):
        with pytest.raises(ParameterError) as err:
            RunOptions(**{name: bad}, **extra)
        text = str(err.value)
        assert text.startswith(name) and "\n" not in text
        assert f"{q.high:g}" in text and f"got {bad!r}"[:8] in text


def test_the_step_budget_bounds_are_the_tables():
    high = int(RUN_SETTINGS["max_steps"].high)
    assert RunOptions(max_steps=high).step_budget == high
    assert RunOptions(duration=2.0).step_budget == 1_000_000 + 20_000
    with pytest.raises(ParameterError, match=rf"max_steps must be an integer in \[1, "
                                             rf"{high:,}\], got 0"):
        RunOptions(max_steps=0)


# ---- one-line errors naming the field, the value and the range ------------------------------


@pytest.mark.parametrize("changes, words", [
    ({"feedback_delay": -0.1}, "feedback_delay [s] must be in [0, 1], got -0.1"),
    ({"proprioceptive_weight": 1.5}, "proprioceptive_weight [-] must be in [0, 1], got 1.5"),
    ({"duration": 0.0}, "duration [s] must be in (0, 86400] s, got 0.0"),
    ({"sample_rate": 0.5}, "sample_rate [Hz] must be in [1, 1e+06] Hz, got 0.5"),
    ({"rtol": 1.0}, "rtol must be in [1e-14, 0.1], got 1.0"),
    ({"tilt_axis_depth": 0.2}, "tilt_axis_depth [m] needs a tilt"),
    ({"rates_from": "above"}, "rates_from must be 'upright' or 'posture', got 'above'"),
    ({"max_switches": -1}, "max_switches must be an integer >= 0, got -1"),
    ({"engine": "numba"}, "engine must be one of 'reference', 'compiled', got 'numba'"),
    ({"tilt": "sine"}, "tilt must be a Tilt, got str 'sine'"),
    ({"initial_state": [0.1, math.nan]}, "initial_state [rad, rad/s] must contain only finite"),
])
def test_a_bad_option_is_one_line_naming_it(changes, words):
    with pytest.raises(ParameterError) as err:
        RunOptions(**changes)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_an_unknown_option_is_named_with_the_known_ones():
    for call in (lambda: pl.simulate(pl.paper_body(), pl.paper_muscles("1"), feedback=0.1),
                 lambda: RunOptions().replace(feedback=0.1),
                 lambda: pl.builtin_scenario("paper-backward-case1").replace(feedback=0.1)):
        with pytest.raises(ParameterError, match="'feedback'.*feedback_delay"):
            call()


def test_options_are_frozen_and_replace_checks_again():
    o = RunOptions(feedback_delay=0.1)
    with pytest.raises(dataclasses.FrozenInstanceError):
        o.feedback_delay = 0.2  # type: ignore[misc]
    with pytest.raises(ParameterError, match="feedback_delay"):
        o.replace(feedback_delay=2.0)
    assert o.replace(feedback_delay=0.2).feedback_delay == 0.2 and o.feedback_delay == 0.1
    assert RunOptions(initial_state=np.array([0.1, 0.0])).initial_state == (0.1, 0.0)
    assert RunOptions(engine="fast").engine == "compiled"


# ---- the API, a scenario file and the command line give equal options -----------------------


SCENARIO = """
duration = 2.0
[muscles]
case = "1"
feedback_delay = 0.1
proprioceptive_weight = 0.7
[tilt]
type = "sine"
amplitude = 0.01
frequency = 0.5
[initial]
posture = [0.05, 0.0, 0.0]
[limits]
torque = [300.0, "inf", "inf"]
[solver]
rtol = 1e-7
atol = 1e-10
sample_rate = 200.0
max_steps = 500000
"""

EXPECTED = RunOptions(
    duration=2.0, initial_state=(0.05, 0.0, 0.0, 0.0, 0.0, 0.0), feedback_delay=0.1,
    proprioceptive_weight=0.7, tilt=SineTilt(0.01, 0.5), torque_limits=(300.0, math.inf,
                                                                       math.inf),
    rtol=1e-7, atol=1e-10, sample_rate=200.0, max_steps=500_000)


def test_a_scenario_file_parses_into_the_same_options_as_the_api(tmp_path):
    import tomllib

    sc = parse_scenario(tomllib.loads(SCENARIO), tmp_path, "s.toml")
    assert sc.options == EXPECTED


def test_the_command_line_parses_into_the_same_options_as_the_api():
    from posturelab.cli import build_parser
    from posturelab.cli.simulate import scenario_from_args

    args = build_parser("simulate").parse_args([
        "simulate", "--case", "1", "--duration", "2", "--feedback-delay", "0.1",
        "--proprioceptive-weight", "0.7", "--tilt", "sine:0.01:0.5",
        "--initial-posture", "0.05,0,0", "--torque-limits", "300,inf,inf", "--rtol", "1e-7",
        "--atol", "1e-10", "--sample-rate", "200", "--max-steps", "500000"])
    options = scenario_from_args(args).options
    assert options.replace(description="") == EXPECTED


def test_the_command_line_changes_a_scenarios_options_by_name(tmp_path):
    from posturelab.cli import build_parser
    from posturelab.cli.simulate import scenario_from_args

    path = tmp_path / "s.toml"
    path.write_text(SCENARIO, encoding="utf-8")
    args = build_parser("simulate").parse_args(
        ["simulate", "--scenario", str(path), "--feedback-delay", "0.05"])
    assert scenario_from_args(args).options == EXPECTED.replace(feedback_delay=0.05)


def test_a_scenario_option_out_of_range_names_its_key(tmp_path):
    import tomllib

    data = tomllib.loads(SCENARIO)
    data["tilt"]["axis_depth"] = 2.0
    with pytest.raises(ScenarioError, match=r"s.toml: tilt.axis_depth \[m\] must be in \[0, 1\]"):
        parse_scenario(data, tmp_path, "s.toml")


# ---- one set-up: the same options give the same run ------------------------------------------


def test_options_and_keywords_give_the_same_run():
    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    step = pl.VelocityStep.backward(0.5)
    options = RunOptions(duration=0.5, feedback_delay=0.02, initial_state=(0.05, 0, 0, 0, 0, 0))
    a = pl.simulate(body, muscles, step, options=options)
    b = pl.simulate(body, muscles, step, 0.5, feedback_delay=0.02,
                    initial_state=[0.05, 0, 0, 0, 0, 0])
    np.testing.assert_array_equal(a.theta, b.theta)
    assert prepare_run(body, muscles, step, options) is prepare_run(body, muscles, step, options)


def test_a_scenarios_method_reaches_the_compiled_engine():
    """Scenario.run hands solver.method to the compiled engine: RK23 there is RK23 in
    simulate, and differs from the default."""
    sc = builtin_scenario("paper-forward-case1").replace(duration=0.5)
    api = pl.simulate(sc.body, sc.muscles, sc.disturbance, options=sc.options.replace(
        method="RK23"))
    np.testing.assert_array_equal(sc.replace(method="RK23").run().theta, api.theta)
    assert not np.array_equal(sc.replace(method="RK23").run().theta, sc.run().theta)


def test_a_batch_takes_its_shared_options_as_one_object():
    """simulate_batch(options=...) equals the same options by keyword, and its rows equal
    their single runs with those options (bit for bit)."""
    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    step = pl.VelocityStep.backward(0.6)
    k = np.array([muscles.stiffnesses, 1.3 * np.asarray(muscles.stiffnesses)])
    options = RunOptions(duration=1.0, initial_state=(0.05, 0, 0, 0, 0, 0),
                         tilt=SineTilt(0.01, 1.0), proprioceptive_weight=0.6)
    delays = np.array([0.0, 0.03])
    by_object = simulate_batch(body, k, 0.25 * k, step, muscles=muscles, options=options,
                               feedback_delay=delays)
    by_name = simulate_batch(body, k, 0.25 * k, step, 1.0, [0.05, 0, 0, 0, 0, 0],
                             muscles=muscles, tilt=SineTilt(0.01, 1.0),
                             proprioceptive_weight=0.6, feedback_delay=delays)
    np.testing.assert_array_equal(by_object.final_state, by_name.final_state)
    for r in range(2):
        one = pl.simulate(body, pl.paper_muscles(stiffness=k[r], viscosity=0.25 * k[r]), step,
                          options=options.replace(feedback_delay=float(delays[r])))
        np.testing.assert_array_equal(by_object.final_state[r], one.final_state)
    with pytest.raises(ParameterError, match="compiled engine"):
        simulate_batch(body, k, 0.25 * k, step, muscles=muscles, engine="reference")
    with pytest.raises(ParameterError, match="unknown option 'feedback'"):
        simulate_batch(body, k, 0.25 * k, step, muscles=muscles, feedback=0.1)
