"""Strategy maps: the hip fraction of runs built to be pure ankle and pure hip, the maps'
records and JSON, the issue's targets on the paper's body with multijoint-default, and
``posturelab strategy``."""

from __future__ import annotations

import json

import numpy as np
import pytest
from tests._cli import cli, one_line_exit_2

import posturelab as pl
from posturelab.linear.lqr import multijoint_controller
from posturelab.model.kinematics import hip_fraction
from posturelab.studies.strategy import (
    StrategyMap,
    StrategyRun,
    oscillation_map,
    oscillation_profile,
    translation_map,
    translation_profile,
)


def _sway(t, leg, trunk):
    """Θ (T, 3): shank and thigh at ``leg`` (a locked knee), trunk at ``trunk``. [rad]"""
    return np.column_stack([leg(t), leg(t), trunk(t)])


def test_pure_ankle_and_pure_hip_runs():
    t = np.linspace(0.0, 10.0, 2001)
    wave = lambda t: 0.05 * np.sin(2 * np.pi * 0.5 * t)  # noqa: E731
    assert hip_fraction(_sway(t, wave, wave)) == pytest.approx(0.0, abs=1e-15)
    assert hip_fraction(_sway(t, wave, lambda t: -wave(t))) == pytest.approx(1.0, abs=1e-15)
    # leg still, trunk moving: u = 0, w ≠ 0, a = −b: half and half
    assert hip_fraction(_sway(t, lambda t: 0 * t, wave)) == pytest.approx(0.5, abs=1e-12)


def test_runs_built_to_be_pure_ankle_and_legs_held():
    """Simulated: a hip 25 times stiffer than the ankle (knee locked) sways as one pendulum,
    hip fraction ~0; an ankle a thousand times stiffer than the hip holds the legs while the
    trunk swings, u ≈ 0, hip fraction ~1/2 (a = −b)."""
    from posturelab.model.options import KneeModel
    from posturelab.model.platform import RampAndHold

    body, locked = pl.paper_body(), KneeModel("locked")
    rigid = pl.simulate(body, pl.paper_muscles(stiffness=(2000, 0, 50000, 0, 0)),
                        RampAndHold(-0.03, 0.5), 3.0, knee=locked)
    assert rigid.hip_fraction < 1e-4
    held = pl.simulate(body, pl.paper_muscles(stiffness=(200000, 0, 300, 0, 0)),
                       RampAndHold(-0.03, 0.5), 3.0, knee=locked)
    assert held.hip_fraction == pytest.approx(0.5, abs=0.01)


def test_profiles_are_the_stated_ones():
    ramp = translation_profile(0.3, "backward", 0.06)
    assert ramp.displacement == -0.06 and ramp.duration == pytest.approx(0.4)  # 2D/speed
    assert translation_profile(0.3, "forward", 0.06).displacement == 0.06
    sine = oscillation_profile(0.05, 1.25)
    t = np.linspace(0, 3, 7)
    np.testing.assert_allclose(sine.acceleration(t)[:, 0],
                               -0.05 * (2 * np.pi * 1.25) ** 2 * np.sin(2 * np.pi * 1.25 * t),
                               atol=1e-12)
    with pytest.raises(pl.ParameterError, match="backward"):
        translation_profile(0.3, "sideways")


def test_transition_frequency_is_the_first_recovered_run_where_the_hip_dominates():
    runs = tuple(StrategyRun(f, h, o, 0.0, False, 0.0) for f, h, o in (
        (0.5, 0.1, "recovered"), (0.8, 0.7, "fell"), (1.0, 0.6, "recovered"),
        (1.2, 0.9, "recovered")))
    smap = StrategyMap("oscillation", "frequency", runs, "", float("inf"))
    assert smap.transition_frequency == 1.0
    d = smap.to_dict()
    assert d["transition_frequency"] == 1.0 and d["runs"][1]["outcome"] == "fell"
    assert d["runs"][0]["frequency"] == 0.5 and d["ankle_torque_limit"] is None


@pytest.fixture(scope="module")
def paper():
    body = pl.paper_body()
    c = multijoint_controller(body)
    return body, c, dict(ankle_torque_limit=c.effort_limits[0], **c.run_options())


def test_issue_targets_backward_translations(paper):
    """The issue's target: below 0.15 for the slowest backward translations, above 0.4 for
    the fastest recovered."""
    body, c, opts = paper
    smap = translation_map(body, c.muscles, [0.05, 0.1, 0.6, 1.0], **opts)
    h = [r.hip_fraction for r in smap.runs]
    assert h[0] < 0.15 and h[1] < 0.15
    recovered = [r for r in smap.runs if r.outcome == "recovered"]
    assert recovered[-1].value == 1.0 and recovered[-1].hip_fraction > 0.4


def test_issue_targets_sinusoidal_translations(paper):
    """Under a 5 cm sinusoidal translation: below 0.15 at 0.1 Hz, above 0.4 at 1.25 Hz."""
    body, c, opts = paper
    smap = oscillation_map(body, c.muscles, 0.05, [0.1, 1.25], **opts)
    assert smap.runs[0].hip_fraction < 0.15
    assert smap.runs[1].hip_fraction > 0.4 and smap.runs[1].outcome == "recovered"
    assert smap.transition_frequency == 1.25


@pytest.fixture(scope="module")
def foot_bounded(paper):
    """The paper's options with the ankle limited by the foot both ways: m g x_heel and
    m g x_toe (posturelab.model.limits; −40 and 121 N·m)."""
    from posturelab.model.limits import foot_moment_limits

    body, c, opts = paper
    foot = pl.FOOT_FROM_LITERATURE
    pair = foot_moment_limits(body.total_mass * body.gravity, foot.heel, foot.toe)
    return body, c, {**opts, "ankle_torque_limit": pair}


def test_issue_targets_hold_with_the_foot_bounded_ankle(foot_bounded):
    """The same targets with dorsiflexion limited to m g |x_heel| (not the default: between
    them runs fall, docs/design.md)."""
    body, c, opts = foot_bounded
    smap = translation_map(body, c.muscles, [0.05, 0.1, 0.6, 1.0], **opts)
    h = [r.hip_fraction for r in smap.runs]
    assert h[0] < 0.15 and h[1] < 0.15
    recovered = [r for r in smap.runs if r.outcome == "recovered"]
    assert recovered[-1].value == 1.0 and recovered[-1].hip_fraction > 0.4
    assert smap.ankle_dorsiflexion_limit == pytest.approx(-opts["ankle_torque_limit"][0])
    assert smap.to_dict()["ankle_dorsiflexion_limit"] == smap.ankle_dorsiflexion_limit
    osc = oscillation_map(body, c.muscles, 0.05, [0.1, 1.25], **opts)
    assert osc.runs[0].hip_fraction < 0.15
    assert osc.runs[1].hip_fraction > 0.4 and osc.runs[1].outcome == "recovered"
    for m in (smap, osc):  # the ankle moment stays within the foot's limits
        assert all(r.peak_ankle_moment <= opts["ankle_torque_limit"][1] + 1e-6 for r in m.runs)


def test_strategy_command_ankle_limit_from_foot():
    p = cli("strategy", "--translation", "backward", "--speeds", "0.05:0.05:1",
            "--ankle-limit-from-foot", "--json")
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    body, foot = pl.paper_body(), pl.FOOT_FROM_LITERATURE
    weight = body.total_mass * body.gravity
    assert out["ankle_torque_limit"] == pytest.approx(weight * foot.toe, rel=1e-12)
    assert out["ankle_dorsiflexion_limit"] == pytest.approx(-weight * foot.heel, rel=1e-12)


def test_strategy_command_json_and_figure(tmp_path):
    fig = tmp_path / "map.png"
    p = cli("strategy", "--translation", "backward", "--speeds", "0.05:0.3:2", "--json",
            "--figure", str(fig))
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert [r["speed"] for r in out["runs"]] == [0.05, 0.3]
    assert {"hip_fraction", "outcome", "peak_ankle_moment"} <= set(out["runs"][0])
    assert out["controller"] == "multijoint-default" and fig.stat().st_size > 1000


def test_strategy_command_oscillation_over_limits():
    p = cli("strategy", "--oscillation", "0.05", "--frequencies", "0.1:1.25:2",
            "--ankle-torque-limits", "60:121:2", "--json")
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert [(r["ankle_torque_limit"], r["frequency"]) for r in out["runs"]] == [
        (60.0, 0.1), (60.0, 1.25), (121.0, 0.1), (121.0, 1.25)]
    assert [t["frequency"] for t in out["transition_frequencies"]] == [None, 1.25]
    assert "transition_frequency" not in out
    assert out["delay_margin"] > out["feedback_delay"] == 0.08
    assert all(z["re"] < 0 for z in out["design_poles"])


def test_strategy_command_refusals():
    one_line_exit_2(cli("strategy", "--translation", "backward", "--speeds", "1:0.5:3"),
                    "--speeds")
    one_line_exit_2(cli("strategy", "--oscillation", "0.05"), "--frequencies")
    one_line_exit_2(cli("strategy", "--translation", "backward", "--speeds", "0.1:0.2:2",
                        "--controller", "nope"), "multijoint-default")


def test_a_run_that_falls_before_its_steady_part_has_no_hip_fraction(paper):
    body, c, opts = paper
    smap = oscillation_map(body, c.muscles, 0.05, [1.25],
                           **{**opts, "ankle_torque_limit": 60.0})
    run = smap.runs[0]
    assert run.outcome == "fell" and np.isnan(run.hip_fraction) and run.ankle_saturated
    assert smap.transition_frequency is None


def test_sweep_strategy_column_local_and_on_dask(paper):
    """A two-parameter map through the sweep (ankle torque limit × translation size) with
    its hip_fraction column: each row's the single run's, the same on a Dask cluster."""
    distributed = pytest.importorskip("distributed")
    from posturelab.scenarios import Scenario
    from posturelab.studies.sweep import parse_vary, run_sweep

    body, c, _ = paper
    options = pl.RunOptions(duration=2.0, **c.run_options())
    sc = Scenario(name="mj", source="test", body=body, muscles=c.muscles,
                  disturbance=translation_profile(0.3, "backward"), options=options)
    varies = [parse_vary("torque_limit:ankle=40:120:2"), parse_vary("disturbance_scale=0.5:2:3")]
    local = run_sweep(sc, varies, strategy=True)
    names = [name for name, _ in local.columns()]
    assert "hip_fraction" in names and local.units()["hip_fraction"] == "-"
    for r, (limit, scale) in enumerate(local.grid.values):
        single = pl.simulate(body, c.muscles, sc.disturbance.scaled(scale),
                             options=options.replace(torque_limits=(limit, np.inf, np.inf)))
        # a run that fell has no hip fraction (NaN; null in JSON), as in the strategy maps
        expected = float("nan") if single.fell else hip_fraction(single.theta)
        assert local.outcomes.hip_fraction[r] == pytest.approx(expected, abs=1e-6,
                                                               nan_ok=True)
    assert np.isnan(local.outcomes.hip_fraction).any()  # (40 N·m: the larger steps fall)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            remote = run_sweep(sc, varies, client=client, chunk_size=2, strategy=True)
    np.testing.assert_array_equal(local.outcomes.hip_fraction, remote.outcomes.hip_fraction)


def test_scenario_files_name_the_controller(tmp_path):
    """[muscles] controller = "multijoint-default": the design on the file's body, its delay,
    the knee locked; joint_feedback_scale scales it, and is refused without one."""
    from posturelab.scenarios import load_scenario

    good = tmp_path / "mj.toml"
    good.write_text('duration = 1.0\n[muscles]\ncontroller = "multijoint-default"\n'
                    'joint_feedback_scale = 0.5\n[disturbance]\ntype = "ramp-and-hold"\n'
                    'displacement = -0.05\nduration = 0.4\n')
    sc = load_scenario(good)
    design = multijoint_controller(pl.paper_body())
    assert sc.options.knee.mode == "locked" and sc.options.feedback_delay == 0.08
    np.testing.assert_allclose(sc.options.joint_feedback.matrices()[0],
                               0.5 * design.joint_feedback.matrices()[0])
    bad = tmp_path / "bad.toml"
    bad.write_text('duration = 1.0\n[muscles]\ncase = "1"\njoint_feedback_scale = 0.5\n')
    one_line_exit_2(cli("simulate", "--scenario", str(bad)), "muscles.joint_feedback_scale")
    one_line_exit_2(cli("poles", "--controller", "multijoint-default"),
                    "multi-joint controller")
