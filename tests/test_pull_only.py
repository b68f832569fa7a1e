"""Pull-only one-sided pairs: a muscle pulls, it cannot push.

A one-sided pair (the real gastrocnemius) used to switch on its stretch only, so while
stretched and shortening fast its torque k s + l ṡ went negative: it pushed. With
``pull_only`` (the default for one-sided pairs) it also goes slack while that torque would
be negative. Checked against: the stretch-only model (identical until the torque first
crosses 0), the engines against each other, a batch against its single runs, the derived
torques never negative, and a plain reference that integrates T = max(0, k s + l ṡ)
directly (a continuous right-hand side, no events)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import posturelab as pl
from posturelab.model.dynamics import angular_acceleration
from posturelab.simulation.compiled import simulate_batch

POSTURE = np.array([0.1, -0.1, 0.1, 0.0, 0.0, 0.0])


def one_sided(pull: bool) -> pl.MuscleSet:
    m = pl.paper_muscles("1", gastrocnemius="one-sided")
    return pl.MuscleSet(tuple(replace(p, pull_only=pull) for p in m.pairs), 3)


@pytest.mark.parametrize("engine", ["reference", "compiled"])
def test_the_pull_only_gastrocnemius_never_pushes(engine):
    body = pl.paper_body()
    step = pl.VelocityStep.backward(1.0)
    old = pl.simulate(body, one_sided(False), step, 5.0, initial_state=POSTURE, engine=engine)
    new = pl.simulate(body, one_sided(True), step, 5.0, initial_state=POSTURE, engine=engine)
    g = new.pair_names.index("gastrocnemius")
    assert old.pair_torques[:, g].min() < -0.1  # the stretch-only switch lets it push
    assert new.pair_torques[:, g].min() >= 0.0
    # both engage at the same time; the pull-only pair lets go earlier, when its torque
    # reaches 0 and not its stretch, and until then the two runs are the same run
    assert new.switch_times[0] == pytest.approx(old.switch_times[0], abs=1e-9)
    assert new.switch_times[1] < old.switch_times[1] - 0.1
    early = new.time < new.switch_times[1]
    np.testing.assert_allclose(new.theta[early], old.theta[early], atol=1e-9)


def test_the_engines_and_a_batch_agree():
    body = pl.paper_body()
    step = pl.VelocityStep.backward(0.6)
    runs = [pl.simulate(body, one_sided(True), step, 4.0, initial_state=POSTURE, engine=e,
                        rtol=1e-10, atol=1e-12) for e in ("reference", "compiled")]
    np.testing.assert_allclose(runs[1].theta, runs[0].theta, atol=1e-7)
    np.testing.assert_allclose(runs[1].switch_times, runs[0].switch_times, atol=1e-6)
    k = np.tile(pl.paper_muscles("1").stiffnesses, (3, 1)) * np.array([[0.8], [1.0], [1.2]])
    batch = simulate_batch(body, k, 0.25 * k, step, 4.0, POSTURE, muscles=one_sided(True))
    for r in range(3):
        m = pl.MuscleSet(tuple(replace(p, stiffness=k[r, i], viscosity=0.25 * k[r, i])
                               for i, p in enumerate(one_sided(True).pairs)), 3)
        one = pl.simulate(body, m, step, 4.0, initial_state=POSTURE, engine="compiled")
        np.testing.assert_array_equal(one.final_state, batch.final_state[r])


def test_it_is_the_continuous_model_with_the_torque_clipped_at_zero():
    """The events find the corners of T = max(0, k s + l ṡ) (s >= 0) exactly: the same run
    as a plain solve_ivp of that continuous right-hand side, to its tolerance."""
    body = pl.paper_body()
    m = one_sided(True)
    E = m.selection_matrix
    k, lam = m.stiffnesses, m.viscosities
    one = m.one_sided_mask
    step = pl.VelocityStep.backward(1.0)
    r = pl.simulate(body, m, step, 3.0, initial_state=POSTURE, rtol=1e-11, atol=1e-13)
    x0 = r.state[0]

    def rhs(t, x):
        s, sd = E @ x[:3], E @ x[3:]
        torque = k * s + lam * sd
        torque = np.where(one, np.where(s >= 0, np.maximum(torque, 0.0), 0.0), torque)
        acc = angular_acceleration(body, x[:3], x[3:], -torque @ E)
        return np.concatenate([x[3:], acc])

    plain = solve_ivp(rhs, (0, 3.0), x0, t_eval=r.time, rtol=1e-11, atol=1e-13,
                      method="DOP853", max_step=1e-3)
    np.testing.assert_allclose(plain.y.T[:, :3], r.theta, atol=2e-6)
