"""The compiled simulator (posturelab.simulation.compiled) against the reference simulate()
(scipy DOP853).

Nothing here is timed (see benchmarks/bench_simulate.py). Tolerances: the fast
simulator runs at its defaults (rtol 1e-6, atol 1e-9), the reference at
rtol 1e-10, atol 1e-12 (or a scenario's own settings, 1e-8/1e-10). Their
documented agreement is 1e-6 rad in the angles; the runs below agree to about
1e-8 rad, and the tests hold them to 1e-6 rad (angles), 1e-4 rad/s (rates) and
1e-6 s (event times), much tighter than any physical resolution.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import posturelab as pl
from posturelab.errors import ParameterError
from posturelab.model.body import Body, paper_body
from posturelab.model.muscles import MusclePair, MuscleSet, paper_muscles
from posturelab.model.platform import (
    Disturbance,
    HalfSinePulse,
    MeasuredProfile,
    RampAndHold,
    SumOfSines,
    VelocityStep,
    combine,
)
from posturelab.scenarios import builtin_scenario, builtin_scenario_names
from posturelab.simulation import (
    FOOT_FROM_LITERATURE,
    FallCriteria,
    KneeModel,
    simulate,
)
from posturelab.simulation.compiled import BatchResult, simulate_batch, simulate_fast
from posturelab.simulation.derived import derived_series
from posturelab.simulation.setup import prepare_run

THETA_TOL = 1e-6  # [rad]
OMEGA_TOL = 1e-4  # [rad/s]
TIME_TOL = 1e-6  # [s]
PAPER_POSTURE = [0.1, -0.1, 0.1, 0.0, 0.0, 0.0]
REF = {"rtol": 1e-10, "atol": 1e-12}
METHODS = ["RK45", "RK23", "Radau"]  # every compiled integrator is held to the same tolerances


def assert_same_run(fast, ref, theta_tol=THETA_TOL, omega_tol=OMEGA_TOL):
    """Same outcome and the same trajectory on the common sample grid."""
    assert fast.status == ref.status, (fast.message, ref.message)
    assert fast.fell == ref.fell
    if ref.fell:
        assert fast.fall_time == pytest.approx(ref.fall_time, abs=TIME_TOL)
        assert fast.fall_reason == ref.fall_reason
    assert fast.time.shape == ref.time.shape
    np.testing.assert_allclose(fast.time, ref.time, rtol=0, atol=TIME_TOL)
    np.testing.assert_allclose(fast.theta, ref.theta, rtol=0, atol=theta_tol)
    np.testing.assert_allclose(fast.omega, ref.omega, rtol=0, atol=omega_tol)
    assert fast.pair_names == ref.pair_names


def run_both(body, muscles, disturbance, duration, method="RK45", **kwargs):
    fast = simulate_fast(body, muscles, disturbance, duration, method=method, **kwargs)
    ref = simulate(body, muscles, disturbance, duration, **kwargs, **REF)
    return fast, ref


# ---------------------------------------------------------------------------
# Every built-in scenario
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name", builtin_scenario_names())
def test_every_builtin_scenario_matches_the_reference(name, method):
    """Status, fall, fall time and trajectory of each shipped scenario (its own tolerances for
    the reference, the fast defaults for the compiled simulator)."""
    sc = builtin_scenario(name)
    ref = sc.run()
    fast = simulate_fast(
        sc.body, sc.muscles, sc.disturbance, sc.duration, initial_state=sc.initial_state,
        rates_from=sc.rates_from, knee=sc.knee, fall=sc.fall,
        torque_limits=sc.torque_limits, feedback_delay=sc.feedback_delay,
        sample_rate=sc.sample_rate, description=sc.description, method=method,
    )
    assert_same_run(fast, ref)
    assert fast.message == ref.message
    assert fast.description == ref.description


# ---------------------------------------------------------------------------
# Disturbances beyond the velocity step
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("method", METHODS)
def test_half_sine_pulse_from_upright(method):
    """A backward half-sine acceleration pulse (breakpoints at its start and end)."""
    fast, ref = run_both(paper_body(), paper_muscles("1"), HalfSinePulse(-3.0, 0.3, 0.2), 3.0,
                         method)
    assert_same_run(fast, ref)
    np.testing.assert_allclose(fast.platform_acceleration, ref.platform_acceleration, atol=1e-12)
    np.testing.assert_allclose(fast.platform_velocity, ref.platform_velocity, atol=1e-12)


@pytest.mark.parametrize("method", METHODS)
def test_sum_of_sines_horizontal_and_vertical(method):
    """Two sums of sines, one horizontal and one vertical, summed (step capped at max_step)."""
    d = combine(SumOfSines((0.8, 0.5), (0.7, 1.9), (0.3, 1.0)),
                SumOfSines((0.6,), (1.1,), axis="y"))
    fast, ref = run_both(paper_body(), paper_muscles("1"), d, 3.0, method)
    assert_same_run(fast, ref)
    np.testing.assert_allclose(fast.platform_acceleration, ref.platform_acceleration, atol=1e-12)


@pytest.mark.parametrize("method", METHODS)
def test_measured_profile_linear_interpolation(method):
    """A measured profile (x and y, 401 samples): every sample is a breakpoint; zero outside."""
    rng = np.random.default_rng(7)
    t = np.linspace(0.1, 1.1, 401)
    ax = np.cumsum(rng.normal(0.0, 0.4, t.size))
    ay = 0.5 * np.sin(2 * np.pi * t)
    d = MeasuredProfile(t, ax, ay, source="synthetic")
    fast, ref = run_both(paper_body(), paper_muscles("1"), d, 2.0, method,
                         initial_state=PAPER_POSTURE)
    assert_same_run(fast, ref)
    np.testing.assert_allclose(fast.platform_acceleration, ref.platform_acceleration, atol=1e-12)


@pytest.mark.parametrize("method", METHODS)
def test_ramp_and_hold_combined_with_a_velocity_step(method):
    """A combined disturbance: a vertical velocity step (initial rates) plus a ramp-and-hold."""
    d = combine(VelocityStep(0.3, "y"), RampAndHold(-0.08, 0.5, 0.1))
    fast, ref = run_both(paper_body(), paper_muscles("1"), d, 2.0, method,
                         initial_state=PAPER_POSTURE)
    assert_same_run(fast, ref)
    np.testing.assert_allclose(fast.platform_position, ref.platform_position, atol=1e-9)


# ---------------------------------------------------------------------------
# Events and constraints
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("method", METHODS)
def test_one_sided_gastrocnemius_switch_times(method):
    """The real gastrocnemius (acts while θ2 >= 0): from θ2 = −0.1 it is slack, engages as
    the body sways forward and goes slack again near 3.9 s; the switches are located at the
    same times as in the reference."""
    muscles = paper_muscles("1", gastrocnemius="one-sided")
    fast, ref = run_both(paper_body(), muscles, VelocityStep.backward(1.0), 4.5, method,
                         initial_state=PAPER_POSTURE)
    assert_same_run(fast, ref)
    assert len(ref.switch_times) >= 2
    assert len(fast.switch_times) == len(ref.switch_times)
    np.testing.assert_allclose(fast.switch_times, ref.switch_times, atol=TIME_TOL)
    # the pair torque is zero exactly while θ2 < 0
    m_gastro = fast.pair_torques[:, fast.pair_names.index("gastrocnemius")]
    assert np.all(m_gastro[fast.theta[:, 1] < 0] == 0.0)


@pytest.mark.parametrize("method", METHODS)
def test_locked_knee(method):
    """A locked knee (θ2 − θ1 constant, projection form): the constraint holds throughout."""
    fast, ref = run_both(paper_body(), paper_muscles("1"), VelocityStep.backward(0.5), 3.0,
                         method,
                         initial_state=[0.05, 0.05, 0.1, 0.0, 0.0, 0.0],
                         knee=KneeModel("locked"))
    assert_same_run(fast, ref)
    np.testing.assert_allclose(fast.theta[:, 1] - fast.theta[:, 0], 0.0, atol=1e-9)
    np.testing.assert_allclose(fast.omega[:, 1] - fast.omega[:, 0], 0.0, atol=1e-8)


@pytest.mark.parametrize("method", METHODS)
def test_knee_stop_and_base_of_support_fall(method):
    """A hyper-extension stop (the knee hits it: plastic impact, then locked) and a fall when
    the centre of gravity passes the toe (the release is in the lab-ramp-and-hold scenario)."""
    fall = FallCriteria(base_of_support=FOOT_FROM_LITERATURE)
    fast, ref = run_both(paper_body(), paper_muscles("2"), VelocityStep.backward(0.5), 3.0,
                         method,
                         initial_state=[0.05, 0.0, 0.05, 0.0, 0.0, 0.0],
                         knee=KneeModel("stop"), fall=fall)
    assert_same_run(fast, ref)
    assert ref.fell and "centre of gravity" in ref.fall_reason
    assert ref.switch_times
    np.testing.assert_allclose(fast.switch_times, ref.switch_times, atol=TIME_TOL)
    # the state at the fall closes the series, off the grid
    assert fast.time[-1] == pytest.approx(ref.fall_time, abs=TIME_TOL)


@pytest.mark.parametrize("method", METHODS)
def test_fall_already_at_the_start(method):
    """A posture already beyond the limit is a fall at t = 0 (as the reference)."""
    fast, ref = run_both(paper_body(), paper_muscles("1"), None, 1.0, method,
                         initial_state=[1.2, 0.0, 0.0, 0.0, 0.0, 0.0])
    assert fast.fell and fast.fall_time == 0.0 and fast.time.size == 1
    assert fast.message == ref.message
    assert_same_run(fast, ref)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("n_links", [2, 4])
def test_other_chain_lengths_use_the_general_solver(n_links, method):
    """N = 2 and N = 4 (Gaussian elimination instead of the 3×3 closed form)."""
    rng = np.random.default_rng(n_links)
    lengths = rng.uniform(0.3, 0.6, n_links)
    body = Body.from_arrays(rng.uniform(5, 30, n_links), lengths,
                            rng.uniform(0.3, 0.6, n_links) * lengths,
                            rng.uniform(0.2, 2.0, n_links))
    pairs = [MusclePair(f"p{i}", i, i + 1, 1500.0 - 300.0 * i, 0.3 * (1500.0 - 300.0 * i))
             for i in range(n_links)]
    pairs.append(MusclePair("long", 0, n_links, 200.0, 50.0, one_sided=True))
    muscles = MuscleSet(tuple(pairs), n_links)
    x0 = np.concatenate([np.full(n_links, 0.02), np.zeros(n_links)])
    fast, ref = run_both(body, muscles, VelocityStep.backward(0.4), 2.0, method,
                         initial_state=x0)
    assert_same_run(fast, ref)


def test_derived_fields_equal_the_references_assembly():
    """Torques, moments, accelerations, centre of gravity, ground reaction, centre of pressure
    and platform motion: the reference's derived series applied to the fast samples."""
    muscles = paper_muscles("1", gastrocnemius="one-sided")
    d = combine(HalfSinePulse(2.0, 0.4, 0.1), SumOfSines((0.3,), (1.5,), axis="y"))
    fast = simulate_fast(paper_body(), muscles, d, 1.5, initial_state=PAPER_POSTURE,
                         knee=KneeModel("locked"))
    locked = np.ones(fast.time.size, dtype=bool)
    setup = prepare_run(paper_body(), muscles, d, 1.5, initial_state=PAPER_POSTURE,
                        knee=KneeModel("locked"))
    again = derived_series(setup, np.asarray(fast.time), fast.state, locked=locked)
    for name in ("pair_torques", "joint_torques", "joint_moments", "angular_acceleration",
                 "cog_position", "cog_velocity", "ground_reaction", "centre_of_pressure",
                 "platform_acceleration", "platform_velocity", "platform_position"):
        a, b = getattr(fast, name), getattr(again, name)
        assert a.shape == b.shape, name
        np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-10, err_msg=name)


def test_derived_series_are_computed_on_first_access_and_kept():
    """simulate_fast defers the derived series: nothing is computed until one is read, then
    all are computed once and the same arrays come back on every access."""
    fast = simulate_fast(paper_body(), paper_muscles("1"), VelocityStep.backward(0.5), 0.5,
                         initial_state=PAPER_POSTURE)
    assert "_series" not in vars(fast)
    torques = fast.pair_torques
    assert "_series" in vars(fast)
    assert fast.pair_torques is torques
    assert fast.joint_torques.shape == (fast.time.size, 3)
    # U = −EᵀM, from the series just computed
    E = paper_muscles("1").selection_matrix
    np.testing.assert_allclose(fast.joint_torques, -torques @ E, rtol=1e-12, atol=1e-9)
    # a deferred result pickles (for process pools) and computes the same series after
    import pickle

    fresh = simulate_fast(paper_body(), paper_muscles("1"), VelocityStep.backward(0.5), 0.5,
                          initial_state=PAPER_POSTURE)
    again = pickle.loads(pickle.dumps(fresh))
    np.testing.assert_array_equal(again.cog_position, fast.cog_position)


def test_a_result_without_its_derived_series_says_so():
    from posturelab.errors import PostureLabError
    from posturelab.simulation.results import SimulationResult

    bare = SimulationResult(time=np.zeros(1), theta=np.zeros((1, 3)), omega=np.zeros((1, 3)),
                            pair_names=("ankle",), status="completed", message="",
                            fell=False, fall_time=None, fall_reason=None)
    with pytest.raises(PostureLabError, match="derived series"):
        _ = bare.pair_torques
    wrong = SimulationResult(time=np.zeros(1), theta=np.zeros((1, 3)), omega=np.zeros((1, 3)),
                             pair_names=("ankle",), status="completed", message="",
                             fell=False, fall_time=None, fall_reason=None,
                             derived=lambda: 42)
    with pytest.raises(PostureLabError, match="DerivedSeries"):
        _ = wrong.cog_position


def test_batch_refuses_gains_of_the_wrong_shape():
    k = np.asarray(paper_muscles("1").stiffnesses)[None, :]
    with pytest.raises(ParameterError, match=r"shape \(M, 5\)"):
        simulate_batch(paper_body(), k[:, :4], 0.25 * k[:, :4], None, 1.0)


def test_unknown_disturbance_kind_is_refused():
    class Wobble(Disturbance):
        def acceleration(self, t):
            return np.zeros(np.shape(t) + (2,))

    with pytest.raises(ParameterError, match="Wobble"):
        simulate_fast(paper_body(), paper_muscles("1"), Wobble(), 1.0)


# ---------------------------------------------------------------------------
# Batches
# ---------------------------------------------------------------------------


def _gains(rng, m):
    k = np.empty((m, 5))
    k[:, 0] = rng.uniform(400.0, 1500.0, m)
    k[:, 1:] = rng.uniform(0.0, 600.0, (m, 4))
    k[0] = (500.0, 300.0, 300.0, 300.0, 0.0)  # case 2: falls forward
    return k


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("setting", ["paper", "one-sided, knee stop, foot"])
def test_batch_equals_single_runs_bit_for_bit(setting, method):
    """Each batch row is simulate_fast's run with those gains: the same numbers exactly."""
    rng = np.random.default_rng(11)
    stiffness = _gains(rng, 6)
    viscosity = 0.25 * stiffness
    if setting == "paper":
        layout, disturbance, options = paper_muscles("1"), VelocityStep.forward(1.0), {}
    else:
        layout = paper_muscles("1", gastrocnemius="one-sided")
        disturbance = RampAndHold(-0.1, 0.4)
        options = dict(knee=KneeModel("stop"),
                       fall=FallCriteria(base_of_support=FOOT_FROM_LITERATURE))
    options["method"] = method
    batch = simulate_batch(paper_body(), stiffness, viscosity, disturbance, 3.0,
                           PAPER_POSTURE if setting == "paper" else None, muscles=layout,
                           **options)
    serial = simulate_batch(paper_body(), stiffness, viscosity, disturbance, 3.0,
                            PAPER_POSTURE if setting == "paper" else None, muscles=layout,
                            parallel=False, **options)
    assert isinstance(batch, BatchResult) and batch.n_runs == 6
    assert batch.fell.any()
    for r in range(6):
        m = paper_muscles(stiffness=stiffness[r], viscosity=viscosity[r],
                          gastrocnemius="one-sided" if setting != "paper" else "two-sided")
        one = simulate_fast(paper_body(), m, disturbance, 3.0,
                            initial_state=PAPER_POSTURE if setting == "paper" else None,
                            **options)
        assert batch.status[r] == one.status
        assert batch.fell[r] == one.fell
        if one.fell:
            assert batch.fall_time[r] == one.fall_time
        else:
            assert math.isnan(batch.fall_time[r])
        np.testing.assert_array_equal(batch.peak_theta[r], one.max_abs_theta)
        np.testing.assert_array_equal(batch.final_state[r], one.final_state)
        settle = one.settling_time(0.01)
        if settle is None:
            assert math.isnan(batch.settling_time[r])
        else:
            assert batch.settling_time[r] == settle
        assert batch.n_switches[r] == len(one.switch_times)
    for name in ("fell", "fall_time", "peak_theta", "settling_time", "final_state",
                 "status_code", "n_steps"):
        np.testing.assert_array_equal(getattr(batch, name), getattr(serial, name), err_msg=name)


def test_batch_of_a_fall_at_the_start():
    k = np.asarray(paper_muscles("1").stiffnesses)[None, :].repeat(3, axis=0)
    out = simulate_batch(paper_body(), k, 0.25 * k, None, 1.0, [0.0, 1.3, 0.0, 0, 0, 0])
    assert out.fell.all() and np.all(out.fall_time == 0.0)
    np.testing.assert_array_equal(out.final_state[0], [0.0, 1.3, 0.0, 0, 0, 0])


@pytest.mark.parametrize("n_links", [3, 4])
@pytest.mark.parametrize("locked", [False, True])
def test_compiled_right_hand_side_equals_the_numpy_dynamics(n_links, locked):
    """The compiled equations of motion (closed-form 3×3, or elimination for N = 4) equal
    posturelab.model.dynamics at random states, pair activations and platform accelerations."""
    from posturelab.model.dynamics import angular_acceleration, mass_matrix
    from posturelab.simulation.compiled import state_derivative

    rng = np.random.default_rng(3 + n_links)
    lengths = rng.uniform(0.3, 0.6, n_links)
    body = Body.from_arrays(rng.uniform(5, 30, n_links), lengths,
                            rng.uniform(0.3, 0.6, n_links) * lengths,
                            rng.uniform(0.2, 2.0, n_links))
    pairs = tuple(MusclePair(f"p{lo}{hi}", lo, hi, rng.uniform(0, 900), rng.uniform(0, 200))
                  for lo in range(n_links) for hi in range(lo + 1, n_links + 1))
    muscles = MuscleSet(pairs, n_links)
    d = combine(HalfSinePulse(2.5, 0.5, 0.1), SumOfSines((0.7,), (1.3,), axis="y"))
    E = muscles.selection_matrix
    for _ in range(20):
        x = rng.uniform(-0.8, 0.8, 2 * n_links)
        t = rng.uniform(0.0, 1.0)
        active = (rng.uniform(size=len(pairs)) < 0.7).astype(float)
        got = state_derivative(body, muscles, x, active=active, locked=locked,
                               platform_acceleration=tuple(d.acceleration(t)))
        theta, omega = x[:n_links], x[n_links:]
        U = -E.T @ ((muscles.stiffnesses * (E @ theta) + muscles.viscosities * (E @ omega))
                    * active)
        a = d.acceleration(t)
        acc = angular_acceleration(body, theta, omega, U, a[0], a[1])
        if locked:
            C = np.zeros(n_links)
            C[0], C[1] = -1.0, 1.0
            JiC = np.linalg.solve(mass_matrix(body, theta), C)
            acc = acc - JiC * (C @ acc) / (C @ JiC)
        np.testing.assert_allclose(got[:n_links], omega, rtol=0, atol=0)
        np.testing.assert_allclose(got[n_links:], acc, rtol=1e-11, atol=1e-11)


def test_rotated_sines_and_cosines_are_exact_to_rounding():
    """Within a step the integrator rotates sin/cos from the step's start (angle-sum
    formulas and Taylor series for |δ| <= 0.1 rad); beyond that it calls libm."""
    from posturelab.simulation.compiled import rotated_sine_cosine

    rng = np.random.default_rng(5)
    for _ in range(2000):
        base = rng.uniform(-1.2, 1.2)
        theta = base + rng.uniform(-0.12, 0.12)
        s, c = rotated_sine_cosine(theta, base)
        assert abs(s - math.sin(theta)) <= 4e-16 and abs(c - math.cos(theta)) <= 4e-16


def test_step_counts_on_the_stiff_paper_case():
    """Case 1 is stiff (a pole near −554 1/s): the explicit methods are bounded by stability,
    where Bogacki–Shampine's three evaluations per step beat Dormand–Prince's six; Radau's
    steps are set by accuracy and are several times fewer (same accuracy: the scenario
    test above)."""
    sc = builtin_scenario("paper-backward-case1")
    counts = {}
    for method in METHODS:
        out = simulate_batch(sc.body, np.asarray(sc.muscles.stiffnesses)[None, :],
                             np.asarray(sc.muscles.viscosities)[None, :], sc.disturbance,
                             sc.duration, sc.initial_state, method=method)
        counts[method] = int(out.n_steps[0])
    assert counts["RK23"] * 3 < 0.85 * counts["RK45"] * 6
    # the stability bound of RK45: h <= 3.3/554 s, so at least 5 s / 6 ms = 830 steps
    assert counts["RK45"] > 830
    assert counts["Radau"] < counts["RK45"] / 4


def test_radau_follows_the_exact_solution_of_a_very_stiff_pendulum():
    """One link, pair gains putting the poles at −1e5 and −2 1/s (J s² + L s + K − mgh = 0)
    and an initial lean of 1e-6 rad, so that sin θ = θ to 2e-19 rad: the linear solution
    exp(A t) x0 is exact. An explicit method would need about 1e5·5/3.3 = 150,000 steps;
    Radau follows the slow mode in a few hundred, to the tolerance asked for."""
    from scipy.linalg import expm

    from posturelab import get_body

    body = get_body("paper-1link")
    J = float(body.inertia_diagonal[0])
    mgh = float(body.gravity * body.gravity_coefficients[0])
    fast_pole, slow_pole = 1e5, 2.0
    viscosity = J * (fast_pole + slow_pole)
    stiffness = mgh + J * fast_pole * slow_pole
    muscles = MuscleSet((MusclePair("ankle", 0, 1, stiffness, viscosity),), 1)
    x0 = np.array([1e-6, 0.0])
    res = simulate_fast(body, muscles, None, 5.0, initial_state=x0, rtol=1e-6, atol=1e-14,
                        method="Radau")
    assert res.status == "completed"
    A = np.array([[0.0, 1.0], [-(stiffness - mgh) / J, -viscosity / J]])
    exact = np.array([(expm(A * t) @ x0)[0] for t in res.time[::50]])
    np.testing.assert_allclose(res.theta[::50, 0], exact, rtol=0, atol=1e-11)
    out = simulate_batch(body, [[stiffness]], [[viscosity]], None, 5.0, x0, muscles=muscles,
                         rtol=1e-6, atol=1e-14, method="Radau")
    assert out.n_steps[0] < 1000


def test_unknown_method_is_refused():
    with pytest.raises(ParameterError, match="method"):
        simulate_fast(paper_body(), paper_muscles("1"), None, 0.1, method="LSODA")


@pytest.mark.parametrize("disturbance", [
    VelocityStep.backward(1.0),
    MeasuredProfile(np.linspace(0.0, 0.4, 41), 3.0 * np.sin(np.linspace(0.0, np.pi, 41))),
])
def test_batch_disturbance_scale_equals_single_runs_bit_for_bit(disturbance):
    """Run r of a batch with disturbance_scale is the single run with disturbance.scaled(s_r)
    (a hashable step and an unhashable measured profile; repeated and zero factors)."""
    k = np.tile(np.asarray(paper_muscles("1").stiffnesses), (5, 1))
    k[:, 0] = [400.0, 400.0, 900.0, 900.0, 600.0]
    scale = np.array([0.5, 3.0, 0.5, 3.0, 0.0])
    out = simulate_batch(paper_body(), k, 0.25 * k, disturbance, 1.5, PAPER_POSTURE,
                         disturbance_scale=scale)
    for r in range(k.shape[0]):
        one = simulate_fast(paper_body(), paper_muscles(stiffness=k[r], viscosity=0.25 * k[r]),
                            disturbance.scaled(scale[r]), 1.5, initial_state=PAPER_POSTURE)
        assert one.fell == out.fell[r]
        np.testing.assert_array_equal(one.max_abs_theta, out.peak_theta[r])
        np.testing.assert_array_equal(one.final_state, out.final_state[r])
    with pytest.raises(ParameterError, match="disturbance_scale"):
        simulate_batch(paper_body(), k, 0.25 * k, disturbance, 1.5, PAPER_POSTURE,
                       disturbance_scale=[1.0, 2.0])


def test_batch_disturbance_scale_with_a_knee_stop_starts_each_level_as_its_single_run():
    """Whether the knee starts locked at its stop depends on the knee rate after the step,
    which the scale changes (here even its sign): each level starts as its own single run."""
    knee = KneeModel("stop")
    step = VelocityStep.backward(0.3)
    k = np.tile(np.asarray(paper_muscles("1").stiffnesses), (4, 1))
    scale = np.array([-1.0, 1.0, -1.0, 0.5])
    out = simulate_batch(paper_body(), k, 0.25 * k, step, 1.0, None, knee=knee,
                         disturbance_scale=scale)
    for r in range(4):
        one = simulate_fast(paper_body(), paper_muscles("1"), step.scaled(scale[r]), 1.0,
                            knee=knee)
        np.testing.assert_array_equal(one.final_state, out.final_state[r])
        np.testing.assert_array_equal(one.max_abs_theta, out.peak_theta[r])
    empty = simulate_batch(paper_body(), np.zeros((0, 5)), np.zeros((0, 5)), step, 1.0,
                           disturbance_scale=np.zeros(0))
    assert empty.n_runs == 0


@pytest.mark.parametrize("engine", ["reference", "compiled"])
def test_a_knee_at_its_stop_that_the_muscles_pull_off_is_released_at_once(engine):
    """Upright at rest with the knee at its stop (κ = 0) and a forward step: the free knee
    acceleration is negative from t = 0, so the knee flexes instead of being held by the
    stop (before, it stayed locked: the stop pulled)."""
    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    r = pl.simulate(body, muscles, pl.VelocityStep.forward(0.5), 3.0,
                    knee=pl.KneeModel("stop"), engine=engine)
    kappa = r.theta[:, 1] - r.theta[:, 0]
    assert kappa.min() < -0.01 and kappa.max() <= 1e-9
    assert np.all(np.diff(kappa[:50]) < 0)  # it leaves the stop from the first sample
    other = pl.simulate(body, muscles, pl.VelocityStep.forward(0.5), 3.0,
                        knee=pl.KneeModel("stop"),
                        engine="compiled" if engine == "reference" else "reference")
    np.testing.assert_allclose(r.theta, other.theta, atol=1e-6)
