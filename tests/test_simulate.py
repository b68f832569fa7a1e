"""Nonlinear simulation: the paper's runs, and checks independent of the integrator."""

import math

import numpy as np
import pytest

import posturelab as pl
from posturelab.model.muscles import MusclePair, MuscleSet
from posturelab.model.platform import HalfSinePulse, MeasuredProfile, RampAndHold, VelocityStep
from posturelab.scenarios import builtin_scenario
from posturelab.simulation import (
    FOOT_FROM_LITERATURE,
    BaseOfSupport,
    FallCriteria,
    KneeModel,
    initial_state_for,
    simulate,
)

PAPER_POSTURE = [0.1, -0.1, 0.1]


@pytest.fixture(scope="module")
def backward_case1():
    return builtin_scenario("paper-backward-case1").run()


def test_backward_case1_recovers_figs_3_to_7(backward_case1):
    """Section V.B / Fig. 3: case 1 backward recovers: every |θ| < 1e-2 rad at 5 s."""
    r = backward_case1
    assert r.status == "completed" and not r.fell
    assert r.time[-1] == pytest.approx(5.0)
    assert np.all(np.abs(r.theta[-1]) < 1e-2)


def test_backward_initial_state_is_the_papers(backward_case1):
    """Section V.B: initial state [0.1, −0.1, 0.1, 2.5580, −0.0654, 0.0027] (printed digits)."""
    np.testing.assert_allclose(backward_case1.state[0],
                               [0.1, -0.1, 0.1, 2.5580, -0.0654, 0.0027], atol=5e-5)


def test_forward_case2_falls_fig_9():
    """Fig. 9: without the gastrocnemius (case 2) the forward run falls; the time is reported."""
    r = builtin_scenario("paper-forward-case2").run()
    assert r.fell and r.status == "fell"
    assert r.fall_time is not None and 0.5 < r.fall_time < 3.0
    assert "link" in r.fall_reason
    assert r.time[-1] <= r.fall_time + 1e-9
    # the run stops where a link passes the limit
    assert np.max(np.abs(r.theta[-1])) == pytest.approx(math.pi / 3, abs=5e-3)


def test_forward_case3_recovers_more_slowly_than_case1_fig_10():
    """Fig. 10: case 3 recovers, but is farther from upright at 5 s than case 1 (Fig. 8)."""
    r1 = builtin_scenario("paper-forward-case1").run()
    r3 = builtin_scenario("paper-forward-case3").run()
    assert not r1.fell and not r3.fell
    d1 = np.linalg.norm(r1.theta[-1])
    d3 = np.linalg.norm(r3.theta[-1])
    assert d3 > 10 * d1
    # and it is recovering: the slow mode (erratum 1, pole −0.092 1/s) decays
    assert np.linalg.norm(r3.theta[-1]) < np.linalg.norm(r3.theta[r3.time.searchsorted(2.0)])


def test_energy_conserved_without_muscles():
    """Zero gains and no viscosity: kinetic + potential energy constant to 1e-8 over 2 s."""
    body = pl.paper_body().with_gravity(0.5)  # slow the fall so the chain stays up for 2 s
    muscles = MuscleSet((MusclePair("ankle", 0, 1, 0.0, 0.0),), 3)
    r = simulate(body, muscles, None, 2.0, initial_state=[0.02, -0.01, 0.03, 0.1, -0.2, 0.3],
                 fall=FallCriteria(math.pi), rtol=1e-12, atol=1e-12)
    assert r.status == "completed"
    energy = pl.kinetic_energy(body, r.theta, r.omega) + pl.potential_energy(body, r.theta)
    assert np.max(np.abs(energy - energy[0])) / abs(energy[0]) < 1e-8
    assert np.ptp(pl.kinetic_energy(body, r.theta, r.omega)) > 1e-3  # something moved


def test_mirror_symmetry_forward_backward_from_upright():
    """Two-sided muscles, upright start: a forward step is the mirror image of a backward one."""
    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    b = simulate(body, muscles, VelocityStep.backward(0.5), 3.0, sample_rate=200)
    f = simulate(body, muscles, VelocityStep.forward(0.5), 3.0, sample_rate=200)
    np.testing.assert_allclose(f.theta, -b.theta, atol=1e-9)
    np.testing.assert_allclose(f.pair_torques, -b.pair_torques, atol=1e-6)


def test_measured_profile_sampled_from_half_sine_matches():
    """A CSV-like profile sampled at 1 kHz from the built-in half-sine gives the same run."""
    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    pulse = HalfSinePulse(-2.0, 0.3, start=0.1)
    t = np.arange(0.0, 0.5 + 1e-9, 1e-3)
    profile = MeasuredProfile(t, pulse.acceleration(t)[:, 0])
    a = simulate(body, muscles, pulse, 2.0, sample_rate=100)
    b = simulate(body, muscles, profile, 2.0, sample_rate=100)
    assert np.max(np.abs(a.theta)) > 0.01
    np.testing.assert_allclose(b.theta, a.theta, atol=2e-6)


def test_trajectories_converge_as_tolerances_tighten():
    """Errors against a 1e-12 reference shrink as rtol tightens (1e-4 → 1e-6 → 1e-8)."""
    sc = builtin_scenario("paper-backward-case1").replace(duration=2.0, sample_rate=100)
    ref = sc.run(rtol=1e-12, atol=1e-13)
    errors = [np.max(np.abs(sc.run(rtol=tol, atol=tol * 1e-2).theta - ref.theta))
              for tol in (1e-4, 1e-6, 1e-8)]
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 1e-7


def test_one_sided_gastrocnemius_switches_exactly_at_theta2_zero():
    """The real gastrocnemius, switching on its stretch only (pull_only=False), engages /
    goes slack as θ2 crosses 0, located as an event (tests/test_pull_only.py: the default,
    which also lets go when its torque would push)."""
    from dataclasses import replace

    body = pl.paper_body()
    muscles = pl.paper_muscles("1", gastrocnemius="one-sided")
    muscles = pl.MuscleSet(tuple(replace(p, pull_only=False) for p in muscles.pairs), 3)
    r = simulate(body, muscles, VelocityStep.backward(1.0), 5.0,
                 initial_state=PAPER_POSTURE + [0, 0, 0])
    assert len(r.switch_times) >= 1
    # θ2 at each switch is 0 (interpolate the trajectory's zero crossing)
    for ts in r.switch_times:
        i = np.searchsorted(r.time, ts)
        th2 = np.interp(ts, r.time[i - 1:i + 1], r.theta[i - 1:i + 1, 1])
        assert abs(th2) < 1e-5
    g = r.pair_torques[:, r.pair_names.index("gastrocnemius")]
    slack = r.theta[:, 1] < -1e-6
    assert np.all(g[slack] == 0.0)
    assert np.any(g[~slack] != 0.0)


def test_one_sided_equals_two_sided_while_theta2_positive():
    """Until θ2 first goes negative, one- and two-sided gastrocnemius runs are identical."""
    body = pl.paper_body()
    x0 = [0.05, 0.05, 0.05, 0.2, 0.2, 0.2]
    a = simulate(body, pl.paper_muscles("1"), None, 0.3, initial_state=x0, sample_rate=100)
    b = simulate(body, pl.paper_muscles("1", gastrocnemius="one-sided"), None, 0.3,
                 initial_state=x0, sample_rate=100)
    assert np.all(a.theta[:, 1] > 0)
    np.testing.assert_allclose(a.theta, b.theta, atol=1e-10)


def test_base_of_support_fall():
    """With a literature foot the paper's forward case 1 run falls: the CoG passes the heel."""
    sc = builtin_scenario("paper-forward-case1")
    r = sc.run(fall=FallCriteria(base_of_support=FOOT_FROM_LITERATURE))
    assert r.fell and "heel" in r.fall_reason
    assert r.cog_position[-1, 0] == pytest.approx(FOOT_FROM_LITERATURE.heel, abs=1e-4)
    assert FOOT_FROM_LITERATURE.heel == pytest.approx(-0.25 * 0.152 * 1.65)


def test_knee_locked_keeps_theta1_equal_theta2():
    """Knee locked (the paper's assumption when extended): θ1 = θ2 throughout."""
    body = pl.paper_body()
    r = simulate(body, pl.paper_muscles("2"), VelocityStep.backward(0.3), 3.0,
                 knee=KneeModel("locked"))
    assert np.max(np.abs(r.theta[:, 1] - r.theta[:, 0])) < 1e-9
    assert np.max(np.abs(r.theta[:, 0])) > 1e-2


def test_knee_locked_equals_two_link_chain():
    """A locked knee is a two-link chain whose lower link merges leg and thigh (limit case)."""
    body = pl.paper_body()
    m, l, k, inertia = body.masses, body.lengths, body.com_distances, body.inertias
    m12 = m[0] + m[1]
    com12 = (m[0] * k[0] + m[1] * (l[0] + k[1])) / m12
    i12 = (inertia[0] + m[0] * (k[0] - com12) ** 2 + inertia[1] + m[1] * (l[0] + k[1] - com12) ** 2)
    two = pl.Body.from_arrays([m12, m[2]], [l[0] + l[1], l[2]], [com12, k[2]], [i12, inertia[2]])
    three_m = MuscleSet((MusclePair("ankle", 0, 1, 900, 200), MusclePair("hip", 2, 3, 300, 60)), 3)
    two_m = MuscleSet((MusclePair("ankle", 0, 1, 900, 200), MusclePair("hip", 1, 2, 300, 60)), 2)
    x3 = [0.05, 0.05, -0.02, 0.1, 0.1, 0.0]
    x2 = [0.05, -0.02, 0.1, 0.0]
    a = simulate(body, three_m, None, 2.0, initial_state=x3, knee=KneeModel("locked"),
                 sample_rate=100, rtol=1e-10, atol=1e-12)
    b = simulate(two, two_m, None, 2.0, initial_state=x2, sample_rate=100, rtol=1e-10,
                 atol=1e-12)
    np.testing.assert_allclose(a.theta[:, [0, 2]], b.theta, atol=1e-8)


def test_knee_stop_never_hyperextends():
    """With a hyper-extension stop at 0 the knee angle θ2 − θ1 never exceeds 0."""
    r = builtin_scenario("lab-ramp-and-hold").run()
    assert np.max(r.theta[:, 1] - r.theta[:, 0]) <= 1e-9
    assert len(r.switch_times) >= 1


def test_rates_from_posture_uses_exact_sensitivity():
    """Erratum 5: rates_from='posture' gives −J⁻¹H at the flexed posture times Δẋ_d."""
    body = pl.paper_body()
    x0 = initial_state_for(body, VelocityStep.backward(1.0), PAPER_POSTURE + [0, 0, 0],
                           rates_from="posture")
    np.testing.assert_allclose(x0[3:], pl.disturbance_sensitivity(body, PAPER_POSTURE), rtol=1e-12)


def test_ramp_and_hold_moves_platform_by_displacement():
    """Ramp-and-hold: the platform ends displaced by D with zero velocity."""
    r = simulate(pl.paper_body(), pl.paper_muscles("1"), RampAndHold(-0.1, 0.4), 1.0)
    assert r.platform_position[-1, 0] == pytest.approx(-0.1, abs=1e-5)
    assert r.platform_velocity[-1, 0] == pytest.approx(0.0, abs=1e-5)


def test_vertical_acceleration_acts_like_gravity():
    """Erratum 3: a constant upward platform acceleration ÿ acts as gravity g + ÿ."""
    from posturelab.model.platform import SumOfSines

    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    x0 = [0.05, 0.0, -0.05, 0, 0, 0]
    heavy = simulate(body.with_gravity(body.gravity + 1.0), muscles, None, 1.0, initial_state=x0,
                     sample_rate=100)
    # a very slow sine ≈ constant 1 m/s² upward over 1 s (sin(π/2 + 2π·0.001·t) ≈ 1)
    lifted = simulate(body, muscles, SumOfSines((1.0,), (1e-6,), (math.pi / 2,), axis="y"), 1.0,
                      initial_state=x0, sample_rate=100)
    np.testing.assert_allclose(lifted.theta, heavy.theta, atol=1e-8)


def test_failed_run_is_reported_not_raised():
    """A run that cannot proceed reports status 'failed' with a message."""
    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    r = simulate(body, muscles, VelocityStep.backward(1.0), 1.0, method="RK23", rtol=1e-3,
                 atol=1e-6, max_switches=0, initial_state=PAPER_POSTURE + [0, 0, 0])
    assert r.status in ("completed", "failed")  # no one-sided pair: no switch, completes
    m1 = pl.paper_muscles("1", gastrocnemius="one-sided")
    r = simulate(body, m1, VelocityStep.backward(1.0), 5.0, max_switches=0,
                 initial_state=PAPER_POSTURE + [0, 0, 0])
    assert r.status == "failed" and "switches" in r.message and not r.success


@pytest.mark.parametrize("kwargs,field", [
    ({"duration": -1.0}, "duration"),
    ({"duration": float("nan")}, "duration"),
    ({"rtol": 0.0}, "rtol"),
    ({"sample_rate": 0.0}, "sample_rate"),
    ({"initial_state": [0.0] * 5}, "initial_state"),
    ({"initial_state": [0.0, 0.0, float("nan"), 0, 0, 0]}, "initial_state"),
])
def test_bad_simulation_input(kwargs, field):
    args = {"duration": 1.0} | kwargs
    duration = args.pop("duration")
    with pytest.raises(pl.ParameterError, match=field):
        simulate(pl.paper_body(), pl.paper_muscles("1"), None, duration, **args)


def test_bad_base_of_support():
    with pytest.raises(pl.ParameterError, match="heel"):
        BaseOfSupport(0.1, 0.2)
    with pytest.raises(pl.ParameterError, match="toe"):
        BaseOfSupport(-0.1, -0.05)
