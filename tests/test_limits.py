"""Physiological limits: centre of pressure, ground reaction, torque saturation, recovery."""

import math

import numpy as np
import pytest

import posturelab as pl
from posturelab.model.muscles import MusclePair, MuscleSet
from posturelab.simulation import moments_to_link_torques
from posturelab.studies.recovery import largest_recoverable

FOOT = pl.FOOT_FROM_LITERATURE


def test_centre_of_pressure_equals_cog_at_rest_in_equilibrium():
    """A single link held at rest in a leaning equilibrium (Kθ = m g k sin θ): x_p = x_c."""
    body = pl.get_body("paper-1link")
    theta0 = 0.05
    k_eq = body.load_stiffness * math.sin(theta0) / theta0  # K θ0 = mgh sin θ0
    muscles = MuscleSet((MusclePair("ankle", 0, 1, k_eq, 50.0),), 1)
    r = pl.simulate(body, muscles, None, 0.5, initial_state=[theta0, 0.0], sample_rate=100)
    np.testing.assert_allclose(r.angular_acceleration[0], 0.0, atol=1e-9)
    assert r.centre_of_pressure[0] == pytest.approx(r.cog_position[0, 0], rel=1e-9)
    assert r.ground_reaction[0, 1] == pytest.approx(body.total_mass * body.gravity, rel=1e-9)


def test_ground_reaction_is_rate_of_momentum():
    """F = m (a_platform + a_cog): compare with finite differences of the CoG velocity."""
    body = pl.paper_body()
    r = pl.simulate(body, pl.paper_muscles("1"), pl.HalfSinePulse(-2.0, 0.3, start=0.1), 2.0,
                    sample_rate=2000, rtol=1e-10, atol=1e-12)
    dt = r.time[1] - r.time[0]
    acc_cog = np.gradient(r.cog_velocity, dt, axis=0)
    expected = body.total_mass * (r.platform_acceleration + acc_cog
                                  + np.array([0.0, body.gravity]))
    inner = slice(10, -10)
    # central differences err by O(dt · jump in jerk) next to the pulse's corners: 0.5 N
    # is 1 % of the peak horizontal force
    np.testing.assert_allclose(r.ground_reaction[inner], expected[inner], atol=0.5)


def test_moments_to_link_torques_equals_minus_e_transpose_m():
    muscles = pl.paper_muscles("1")
    rng = np.random.default_rng(3)
    theta, omega = rng.normal(0, 0.1, 3), rng.normal(0, 0.5, 3)
    from posturelab.simulation import joint_crossing_matrix

    m = pl.pair_torques(muscles, theta, omega)
    np.testing.assert_allclose(moments_to_link_torques(m @ joint_crossing_matrix(muscles)),
                               pl.joint_torques(muscles, theta, omega), atol=1e-12)


def test_large_torque_limits_change_nothing():
    sc = pl.builtin_scenario("paper-backward-case1").replace(sample_rate=100)
    free = sc.run()
    body, muscles = sc.body, sc.muscles
    limited = pl.simulate(body, muscles, sc.disturbance, sc.duration,
                          initial_state=sc.initial_state, torque_limits=[1e4, 1e4, 1e4],
                          sample_rate=100, rtol=sc.rtol, atol=sc.atol)  # (the scenario's)
    np.testing.assert_allclose(limited.theta, free.theta, atol=1e-9)


def test_saturated_ankle_never_exceeds_its_limit_and_hip_takes_over():
    """Limiting the ankle moment bounds it, and the hip and knee move more: the ankle
    strategy gives way to a multi-joint one."""
    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    step = pl.VelocityStep.backward(0.5)
    free = pl.simulate(body, muscles, step, 5.0, sample_rate=200)
    lim = pl.simulate(body, muscles, step, 5.0, sample_rate=200,
                      torque_limits=[90.0, math.inf, math.inf])
    assert np.max(np.abs(lim.joint_moments[:, 0])) <= 90.0 + 1e-6
    assert np.max(np.abs(free.joint_moments[:, 0])) > 90.0

    def peak(r, j):
        return np.max(np.abs(np.diff(r.theta, axis=1, prepend=0.0)[:, j]))
    assert peak(lim, 2) > 1.3 * peak(free, 2)  # hip: θ3 − θ2
    assert peak(lim, 0) > 1.3 * peak(free, 0)  # ankle: θ1


def test_bad_torque_limits():
    with pytest.raises(pl.ParameterError, match="torque_limits"):
        pl.simulate(pl.paper_body(), pl.paper_muscles("1"), None, 1.0, torque_limits=[1, 2])
    with pytest.raises(pl.ParameterError, match="torque_limits"):
        pl.simulate(pl.paper_body(), pl.paper_muscles("1"), None, 1.0,
                    torque_limits=[100, -1, 5])


def test_cop_criterion_is_stricter_than_cog():
    """The foot tips (CoP at the toe) at a smaller platform move than the CoG leaves the foot."""
    body, muscles = pl.paper_body(), pl.paper_muscles("1")

    def runner(cop):
        fall = pl.FallCriteria(base_of_support=FOOT, centre_of_pressure=cop)
        return lambda d: pl.simulate(body, muscles, pl.RampAndHold(-d, 0.5), 4.0, fall=fall,
                                     sample_rate=50)

    by_cop = largest_recoverable(runner(True), 0.01, 1.0, tolerance=2e-3)
    by_cog = largest_recoverable(runner(False), 0.01, 1.0, tolerance=2e-3)
    assert by_cop.fell - by_cop.recovered <= 2e-3
    assert "centre of pressure" in by_cop.fall_reason and "toe" in by_cop.fall_reason
    assert by_cop.estimate < by_cog.estimate
    # the boundary brackets: just below recovers, just above falls
    assert not runner(True)(by_cop.recovered).fell
    assert runner(True)(by_cop.fell).fell


def test_fall_detected_at_start():
    """A velocity step whose viscous spike puts the CoP beyond the toe tips the foot at t = 0."""
    fall = pl.FallCriteria(base_of_support=FOOT, centre_of_pressure=True)
    r = pl.simulate(pl.paper_body(), pl.paper_muscles("1"), pl.VelocityStep.backward(0.5), 1.0,
                    fall=fall)
    assert r.fell and r.fall_time == 0.0 and "centre of pressure" in r.fall_reason


def test_recovery_bracket_errors():
    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    fall = pl.FallCriteria(base_of_support=FOOT)

    def run(d):
        return pl.simulate(body, muscles, pl.RampAndHold(-d, 0.5), 2.0, fall=fall,
                           sample_rate=20)
    with pytest.raises(pl.ParameterError, match="recovers"):
        largest_recoverable(run, 0.01, 0.02)
    with pytest.raises(pl.ParameterError, match="low must be"):
        largest_recoverable(run, 0.5, 0.1)
    with pytest.raises(pl.ParameterError, match="base_of_support"):
        pl.FallCriteria(centre_of_pressure=True)


def test_scenario_limits_and_cop(tmp_path):
    from posturelab.scenarios import load_scenario

    p = tmp_path / "s.toml"
    p.write_text('duration = 1\n[muscles]\ncase = "1"\n[limits]\ntorque = [90, "inf", 200]\n'
                 '[fall]\nbase_of_support = "literature"\ncentre_of_pressure = true\n')
    sc = load_scenario(p)
    assert sc.torque_limits == (90.0, math.inf, 200.0)
    assert sc.fall.centre_of_pressure
    assert sc.run(sample_rate=50).status == "completed"
    p.write_text('duration = 1\n[muscles]\ncase = "1"\n[limits]\ntorque = [90, 0, 200]\n')
    with pytest.raises(pl.PostureLabError, match="limits.torque"):
        load_scenario(p)


def test_cli_torque_limits(capsys):
    from posturelab.cli import main

    code = main(["simulate", "--case", "1", "--disturbance", "backward", "--speed", "0.3",
                 "--torque-limits", "90,inf,inf", "--foot", "literature",
                 "--centre-of-pressure", "--json"])
    assert code == 0
    code = main(["simulate", "--case", "1", "--torque-limits", "90,x,inf"])
    err = capsys.readouterr().err
    assert code == 2 and "--torque-limits" in err and len(err.strip().splitlines()) == 1


def test_batch_bisection_equals_one_bisection_per_gain_set():
    """largest_recoverable_batch brackets each gain set exactly where largest_recoverable
    brackets it with simulate_fast and the scaled step (same engine, same midpoints); a set
    that falls at low or recovers at high is reported, not bisected."""
    from posturelab.simulation.compiled import simulate_fast
    from posturelab.studies.recovery import largest_recoverable_batch

    body = pl.paper_body()
    fall = pl.FallCriteria(base_of_support=pl.FOOT_FROM_LITERATURE)
    step = pl.VelocityStep.backward(1.0)
    base = np.asarray(pl.paper_muscles("1").stiffnesses, dtype=float)
    k = np.tile(base, (4, 1))
    k[:, 0] = [400.0, 900.0, 60.0, 3000.0]
    out = largest_recoverable_batch(body, k, 0.25 * k, step, 3.0, 0.1, 1.6, tolerance=0.01,
                                    fall=fall)
    assert out.bracketed.tolist() == [True, True, False, False]
    assert math.isnan(out.recovered[2]) and out.fell[2] == 0.1  # falls even at 0.1
    assert out.recovered[3] == 1.6 and math.isnan(out.fell[3])  # recovers even at 1.6
    for r in (0, 1):
        muscles = pl.paper_muscles(stiffness=k[r], viscosity=0.25 * k[r])

        def run(s, muscles=muscles):
            return simulate_fast(body, muscles, step.scaled(s), 3.0, fall=fall)

        one = largest_recoverable(run, 0.1, 1.6, tolerance=0.01)
        assert (out.recovered[r], out.fell[r]) == (one.recovered, one.fell)
    assert out.recovered[1] > out.recovered[0]
