"""Joint moment limits per side (posturelab.model.limits): a pair (lower, upper) per joint, or
"foot" for the ankle; both engines saturate and let go at the side's limit."""

import math

import numpy as np
import pytest

import posturelab as pl
from posturelab.cli import main
from posturelab.model.limits import foot_moment_limits, torque_limit_array
from posturelab.simulation.compiled import simulate_batch
from posturelab.simulation.options import RunOptions
from posturelab.simulation.setup import prepare_run

TOLERANCES = {"rtol": 1e-9, "atol": 1e-12}
THETA_TOL = 1e-6  # [rad], as tests/test_engine_parity.py
TIME_TOL = 1e-6  # [s]
#: Dorsiflexion and plantarflexion limits of the ankle, both binding for this run. [N·m]
LOWER, UPPER = -25.0, 60.0


def _run(engine: str, limits, duration: float = 1.0, **extra) -> pl.SimulationResult:
    """Case 1, a 0.25 m/s backward step, τ = 10 ms (as the parity matrix)."""
    return pl.simulate(pl.paper_body(), pl.paper_muscles("1"), pl.VelocityStep.backward(0.25),
                       duration, feedback_delay=0.01, torque_limits=limits, engine=engine,
                       **TOLERANCES, **extra)


def test_engines_agree_on_a_run_saturating_on_both_sides():
    limits = [(LOWER, UPPER), math.inf, math.inf]
    fast, ref = _run("compiled", limits), _run("reference", limits)
    assert fast.status == ref.status and fast.fall_reason == ref.fall_reason
    assert len(fast.switch_times) == len(ref.switch_times) >= 4
    np.testing.assert_allclose(fast.switch_times, ref.switch_times, rtol=0, atol=TIME_TOL)
    np.testing.assert_allclose(fast.theta, ref.theta, rtol=0, atol=THETA_TOL)
    for r in (fast, ref):  # each side's limit is reached and never passed
        ankle = r.joint_moments[:, 0]
        assert ankle.max() == pytest.approx(UPPER, abs=1e-9)
        assert ankle.min() == pytest.approx(LOWER, abs=1e-9)


def test_engines_agree_with_one_side_unlimited():
    """Only the plantarflexion side limited: the dorsiflexion moment passes any bound."""
    limits = [(-math.inf, UPPER), math.inf, math.inf]
    fast, ref = _run("compiled", limits), _run("reference", limits)
    assert fast.status == ref.status
    np.testing.assert_allclose(fast.switch_times, ref.switch_times, rtol=0, atol=TIME_TOL)
    np.testing.assert_allclose(fast.theta, ref.theta, rtol=0, atol=THETA_TOL)
    assert fast.joint_moments[:, 0].max() == pytest.approx(UPPER, abs=1e-9)
    assert fast.joint_moments[:, 0].min() < -10 * abs(LOWER)


@pytest.mark.parametrize("lean,start", [(-0.05, LOWER), (0.05, 40.0)])
def test_a_start_beyond_one_side_saturates_there_only(lean, start):
    """Leaning back, the start moment (−40 N·m) is beyond the dorsiflexion limit: the ankle
    starts saturated at it; leaning forward the same +40 N·m is inside the plantarflexion
    limit. Both engines."""
    runs = [pl.simulate(pl.paper_body(), pl.paper_muscles("1"), None, 0.5,
                        initial_state=[lean] * 3 + [0.0] * 3,
                        torque_limits=[(LOWER, UPPER), math.inf, math.inf], engine=engine,
                        **TOLERANCES) for engine in ("compiled", "reference")]
    for r in runs:
        assert r.joint_moments[0, 0] == pytest.approx(start, abs=1e-9)
    np.testing.assert_allclose(runs[0].theta, runs[1].theta, rtol=0, atol=THETA_TOL)


@pytest.mark.parametrize("engine", ["compiled", "reference"])
def test_an_equal_pair_is_the_symmetric_limit_bit_for_bit(engine):
    one = _run(engine, [60.0, math.inf, math.inf], 0.5)
    pair = _run(engine, [(-60.0, 60.0), (-math.inf, math.inf), math.inf], 0.5)
    np.testing.assert_array_equal(one.theta, pair.theta)
    assert one.switch_times == pair.switch_times


def test_foot_limits_are_the_weight_times_heel_and_toe():
    body, foot = pl.paper_body(), pl.FOOT_FROM_LITERATURE
    weight = body.total_mass * body.gravity
    setup = prepare_run(body, pl.paper_muscles("1"), None, RunOptions(
        duration=1.0, torque_limits=("foot", 300.0, math.inf),
        fall=pl.FallCriteria(base_of_support=foot)))
    np.testing.assert_array_equal(setup.torque_limits[:, 0],
                                  [-weight * foot.heel, weight * foot.toe])
    np.testing.assert_array_equal(setup.torque_limits[:, 1], [300.0, 300.0])
    assert foot_moment_limits(700.0, -0.06, 0.19) == pytest.approx((-42.0, 133.0))


@pytest.mark.parametrize("limits,match", [
    ([(10.0, 20.0), 1.0, 1.0], r"torque_limits\[0\].*lower in \[-inf, 0\)"),
    ([(-10.0, 0.0), 1.0, 1.0], r"torque_limits\[0\].*upper in \(0, inf\]"),
    ([1.0, "foot", 1.0], r"torque_limits\[1\].*ankle"),
    (["foot", 1.0, 1.0], r"'foot' needs a foot"),
    ([-5.0, 1.0, 1.0], r"torque_limits\[0\].*\(0, inf\].*-5"),
    ([(-1.0, 2.0, 3.0), 1.0, 1.0], r"torque_limits\[0\]"),
    ([1.0, 2.0], r"3 entries"),
])
def test_bad_limits_name_the_field_value_and_range(limits, match):
    with pytest.raises(pl.ParameterError, match=match):
        torque_limit_array(RunOptions(duration=1.0, torque_limits=limits).torque_limits, 3)


def test_scenario_and_command_line_forms(tmp_path, capsys):
    from posturelab.scenarios._parse import torque_limits_from_table

    assert torque_limits_from_table("-40:130,inf,none", 3) == ((-40.0, 130.0), math.inf,
                                                               math.inf)
    assert torque_limits_from_table([[-40, "inf"], "inf", 80], 3) == ((-40.0, math.inf),
                                                                       math.inf, 80.0)
    assert torque_limits_from_table(["foot", 1, 2], 3)[0] == "foot"
    for bad, words in (("40:130,inf,inf", "LO"), ("-40:-1,inf,inf", "HI"),
                       ("inf,foot,inf", "ankle"), ("-1:2:3,inf,inf", "two numbers")):
        with pytest.raises(pl.ParameterError, match=words):
            torque_limits_from_table(bad, 3)
    path = tmp_path / "s.toml"
    path.write_text('duration = 0.5\n[muscles]\ncase = "1"\nfeedback_delay = 0.01\n'
                    '[limits]\ntorque = [[-25, 60], "inf", "inf"]\n', encoding="utf-8")
    sc = pl.load_scenario(path)
    assert sc.torque_limits == ((-25.0, 60.0), math.inf, math.inf)
    assert main(["simulate", "--case", "1", "--disturbance", "backward", "--speed", "0.25",
                 "--duration", "0.3", "--torque-limits", "-25:60,inf,inf"]) == 0
    assert main(["simulate", "--case", "1", "--disturbance", "backward", "--duration", "0.3",
                 "--foot", "literature", "--ankle-limit-from-foot"]) == 0
    capsys.readouterr()
    assert main(["simulate", "--case", "1", "--duration", "0.3", "--disturbance", "backward",
                 "--torque-limits", "5:60,inf,inf"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--torque-limits" in err and "LO" in err
    assert main(["simulate", "--case", "1", "--duration", "0.3", "--ankle-limit-from-foot"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--ankle-limit-from-foot" in err and "--foot" in err


def test_batch_with_pairs_equals_single_runs():
    k = np.tile(np.asarray(pl.paper_muscles("1").stiffnesses), (3, 1))
    pairs = np.array([[[LOWER, UPPER], [-math.inf, math.inf], [-math.inf, math.inf]],
                      [[-60.0, 60.0], [-math.inf, math.inf], [-math.inf, math.inf]],
                      [[-math.inf, math.inf]] * 3])
    d = pl.VelocityStep.backward(0.25)
    out = simulate_batch(pl.paper_body(), k, 0.25 * k, d, 1.0, feedback_delay=0.01,
                         torque_limits=pairs, **TOLERANCES)
    for r, lim in enumerate(([(LOWER, UPPER), math.inf, math.inf], [60.0, math.inf, math.inf],
                             None)):
        one = pl.simulate(pl.paper_body(), pl.paper_muscles("1"), d, 1.0, feedback_delay=0.01,
                          torque_limits=lim, **TOLERANCES)
        assert out.fell[r] == one.fell and out.n_switches[r] == len(one.switch_times)
        if one.fell:
            assert out.fall_time[r] == one.fall_time


def test_sweep_over_a_base_with_limits_per_side_equals_single_runs():
    """A base experiment with the ankle's limits per side and the knee's varied (both ways):
    the grid holds (lower, upper) per joint and each row is its single run."""
    from posturelab.scenarios import Scenario
    from posturelab.simulation.tolerances import DEFAULT_ATOL, DEFAULT_RTOL
    from posturelab.studies.sweep import parse_vary, run_sweep

    options = pl.RunOptions(duration=1.0, feedback_delay=0.01,
                            torque_limits=((LOWER, UPPER), math.inf, math.inf))
    sc = Scenario(name="sides", source="test", body=pl.paper_body(),
                  muscles=pl.paper_muscles("1"), disturbance=pl.VelocityStep.backward(0.25),
                  options=options)
    out = run_sweep(sc, [parse_vary("torque_limit:knee=40:400:2")])
    assert out.grid.torque_limits.shape == (2, 3, 2)
    for r, (knee,) in enumerate(out.grid.values):
        one = pl.simulate(sc.body, sc.muscles, sc.disturbance, options=options.replace(
            torque_limits=((LOWER, UPPER), (-knee, knee), math.inf)),
            rtol=DEFAULT_RTOL, atol=DEFAULT_ATOL)
        assert bool(out.outcomes.fell[r]) == one.fell
        if one.fell:
            assert out.outcomes.fall_time[r] == pytest.approx(one.fall_time, abs=1e-9)
