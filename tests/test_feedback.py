"""Two kinds of feedback per muscle pair: intrinsic (immediate) and active (delayed).

What is checked: the rule of which gains are delayed (posturelab.model.muscles.feedback_gains)
against its statement; a run whose active gains are the pair gains and whose intrinsic gains
are zero is the old all-delayed run bit for bit; with no delay the two parts sum; the torques
are k θ(t) + l θ̇(t) + k_τ θ(t − τ) + l_τ θ̇(t − τ); the engines agree; a batch equals its
single runs; bad input is refused with the field named.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import posturelab as pl
from posturelab.errors import ParameterError
from posturelab.model.muscles import MusclePair, MuscleSet, feedback_gains
from posturelab.simulation.compiled import simulate_batch

TIGHT = {"rtol": 1e-10, "atol": 1e-13}
REF = {"rtol": 1e-10, "atol": 1e-12}
POSTURE = [0.1, -0.1, 0.1, 0.0, 0.0, 0.0]
UPRIGHT_FALL = pl.FallCriteria(math.pi / 2)


def pendulum(stiffness, viscosity, active_stiffness=None, active_viscosity=None):
    pair = MusclePair("ankle", 0, 1, stiffness, viscosity, active_stiffness=active_stiffness,
                      active_viscosity=active_viscosity)
    return pl.get_body("paper-1link"), MuscleSet((pair,), 1)


def test_feedback_gains_follow_the_stated_rule():
    k, v = np.array([500.0, 300.0]), np.array([125.0, 75.0])
    ka, va = np.array([40.0, 0.0]), np.array([4.0, 1.0])
    z = np.zeros(2)
    np.testing.assert_array_equal(feedback_gains(k, v, delay=0.0), [k, v, z, z])
    np.testing.assert_array_equal(feedback_gains(k, v, delay=0.1), [z, z, k, v])
    np.testing.assert_array_equal(feedback_gains(k, v, ka, va, 0.1), [k, v, ka, va])
    np.testing.assert_array_equal(feedback_gains(k, v, ka, va, 0.0), [k + ka, v + va, z, z])
    rows = feedback_gains(np.stack([k, k]), np.stack([v, v]), np.stack([ka, ka]),
                          np.stack([va, va]), np.array([0.0, 0.2]))
    np.testing.assert_array_equal(rows[0], [k + ka, v + va, z, z])
    np.testing.assert_array_equal(rows[1], [k, v, ka, va])


@pytest.mark.parametrize("engine", ["reference", "compiled"])
def test_all_active_feedback_is_the_old_all_delayed_run_bit_for_bit(engine):
    """Intrinsic gains 0 and active gains = the pair gains: the run of the paper's model
    with the same delay, to the last bit."""
    sc = pl.builtin_scenario("paper-backward-case1")
    m = sc.muscles
    split = pl.paper_muscles(stiffness=np.zeros(5), viscosity=np.zeros(5),
                             active_stiffness=m.stiffnesses, active_viscosity=m.viscosities)
    kwargs = dict(initial_state=sc.initial_state, feedback_delay=0.004, sample_rate=200,
                  engine=engine)
    old = pl.simulate(sc.body, m, sc.disturbance, 1.0, **kwargs)
    new = pl.simulate(sc.body, split, sc.disturbance, 1.0, **kwargs)
    np.testing.assert_array_equal(new.theta, old.theta)
    np.testing.assert_array_equal(new.pair_torques, old.pair_torques)
    assert new.status == old.status


@pytest.mark.parametrize("engine", ["reference", "compiled"])
def test_without_a_delay_the_two_parts_sum(engine):
    sc = pl.builtin_scenario("paper-backward-case1")
    k, v = sc.muscles.stiffnesses, sc.muscles.viscosities
    split = pl.paper_muscles(stiffness=0.4 * k, viscosity=0.7 * v, active_stiffness=0.6 * k,
                             active_viscosity=0.3 * v)
    whole = pl.simulate(sc.body, sc.muscles, sc.disturbance, 2.0,
                        initial_state=sc.initial_state, engine=engine)
    parts = pl.simulate(sc.body, split, sc.disturbance, 2.0, initial_state=sc.initial_state,
                        engine=engine)
    np.testing.assert_allclose(parts.theta, whole.theta, rtol=0, atol=1e-9)


@pytest.mark.parametrize("engine", ["reference", "compiled"])
def test_torques_are_intrinsic_now_plus_active_delayed(engine):
    body, muscles = pendulum(300.0, 30.0, 800.0, 60.0)
    tau = 0.05
    r = pl.simulate(body, muscles, None, 2.0, initial_state=[0.02, 0.1], feedback_delay=tau,
                    sample_rate=1000, fall=UPRIGHT_FALL, engine=engine)
    k = int(round(tau * 1000))
    th, om = r.theta[:, 0], r.omega[:, 0]
    expected = 300.0 * th[k:] + 30.0 * om[k:] + 800.0 * th[:-k] + 60.0 * om[:-k]
    np.testing.assert_allclose(r.pair_torques[k:, 0], expected, atol=1e-6)
    before = 300.0 * th[:k] + 30.0 * om[:k] + 800.0 * 0.02 + 60.0 * 0.1
    np.testing.assert_allclose(r.pair_torques[:k, 0], before, atol=1e-9)


@pytest.mark.parametrize("delay", [0.01, 0.05, 0.15])
def test_the_engines_agree_on_intrinsic_plus_delayed_feedback(delay):
    """The paper's body with half its case-1 gains intrinsic and half a delayed active part
    (with the immediate half it stays up at every one of these delays)."""
    sc = pl.builtin_scenario("paper-backward-case1")
    k = sc.muscles.stiffnesses
    muscles = pl.paper_muscles(stiffness=0.5 * k, active_stiffness=0.5 * k,
                               active_viscosity_ratio=0.25)
    kwargs = dict(initial_state=sc.initial_state, feedback_delay=delay, sample_rate=100)
    fast = pl.simulate(sc.body, muscles, sc.disturbance, 1.5, engine="compiled", **kwargs,
                       **TIGHT)
    ref = pl.simulate(sc.body, muscles, sc.disturbance, 1.5, engine="reference", **kwargs,
                      **REF)
    assert fast.status == ref.status == "completed"
    np.testing.assert_allclose(fast.theta, ref.theta, rtol=0, atol=1e-6)


def test_batch_with_active_gains_equals_its_single_runs(rng):
    m = 6
    k = np.tile(np.asarray(pl.paper_muscles("1").stiffnesses), (m, 1))
    ka = rng.uniform(0.0, 400.0, (m, 5))
    delays = np.array([0.0, 0.01, 0.03, 0.1, 0.0, 0.005])
    d = pl.VelocityStep.backward(0.5)
    out = simulate_batch(pl.paper_body(), 0.5 * k, 0.125 * k, d, 1.5, POSTURE,
                         feedback_delay=delays, active_stiffness=ka, active_viscosity=0.3 * ka)
    for r in range(m):
        muscles = pl.paper_muscles(stiffness=0.5 * k[r], viscosity=0.125 * k[r],
                                   active_stiffness=ka[r], active_viscosity=0.3 * ka[r])
        one = pl.simulate(pl.paper_body(), muscles, d, 1.5, initial_state=POSTURE,
                          feedback_delay=float(delays[r]), engine="compiled")
        assert out.fell[r] == one.fell
        np.testing.assert_array_equal(out.final_state[r], np.r_[one.theta[-1], one.omega[-1]])
        np.testing.assert_array_equal(out.peak_theta[r], np.abs(one.theta).max(axis=0))


def test_bad_active_gains_are_refused_naming_the_field():
    with pytest.raises(ParameterError, match="active stiffness .* 5 values"):
        pl.paper_muscles("1", active_stiffness=[1.0, 2.0])
    with pytest.raises(ParameterError, match="active stiffness"):
        MusclePair("ankle", 0, 1, 1.0, 1.0, active_stiffness=-3.0)
    with pytest.raises(ParameterError, match="one-sided"):
        pl.paper_muscles("1", gastrocnemius="one-sided", active_stiffness=[1.0] * 5)
    with pytest.raises(ParameterError, match="active_viscosity_ratio needs"):
        pl.paper_muscles("1", active_viscosity_ratio=0.3)
    with pytest.raises(ParameterError, match="active_stiffness must have the shape"):
        simulate_batch(pl.paper_body(), np.ones((2, 5)), np.ones((2, 5)), None, 1.0,
                       active_stiffness=np.ones((3, 5)))
