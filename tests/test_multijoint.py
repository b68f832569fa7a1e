"""The multi-joint controller: the LQR design, its closed loop against the linear design
(poles, delay margin), both engines on it, the preset."""

from __future__ import annotations

import numpy as np
import pytest

import posturelab as pl
from posturelab.errors import ParameterError, UnknownNameError
from posturelab.linear.lqr import (
    bryson_weights,
    closed_loop_check,
    design_matrices,
    lqr_joint_feedback,
    multijoint_controller,
)
from posturelab.linear.system import linear_system
from posturelab.model.controllers import get_multijoint_controller
from posturelab.model.joint_feedback import JointFeedback, joint_gain_rows
from posturelab.model.options import KneeModel
from posturelab.model.platform import RampAndHold
from posturelab.simulation.setup import model_response, prepare_run


@pytest.fixture(scope="module")
def controller():
    return multijoint_controller(pl.paper_body())


def _free_design(body):
    """An LQR on the free three-link chain (no knee constraint) with the preset's pairs."""
    preset = get_multijoint_controller("multijoint-default")
    muscles = preset.muscles(body)
    Q, R = bryson_weights(3, 0.2, 1.0, [120.0, 240.0, 240.0])
    return muscles, lqr_joint_feedback(body, muscles, Q, R)


def _nonlinear_state_matrix(body, muscles, feedback, step=1e-6):
    """Central differences of the nonlinear model's right-hand side (the run set-up's
    model_response, no delay) at upright, with the controller."""
    n = body.n_links
    setup = prepare_run(body, muscles, None, pl.RunOptions(joint_feedback=feedback,
                                                           duration=1.0))

    def f(x):
        _, acc = model_response(setup, 0.0, x, x, setup.active0, False, None)
        return np.concatenate([x[n:], acc])

    A = np.zeros((2 * n, 2 * n))
    for j in range(2 * n):
        e = np.zeros(2 * n)
        e[j] = step
        A[:, j] = (f(e) - f(-e)) / (2 * step)
    return A


def test_nonlinear_closed_loop_has_the_designed_poles(body):
    muscles, feedback = _free_design(body)
    A, B, _ = design_matrices(linear_system(body, muscles, inputs=False))
    F = np.hstack(feedback.matrices())
    designed = np.sort_complex(np.linalg.eigvals(A - B @ F))
    numeric = np.sort_complex(np.linalg.eigvals(_nonlinear_state_matrix(body, muscles, feedback)))
    assert np.all(designed.real < 0)
    np.testing.assert_allclose(numeric, designed, rtol=1e-5, atol=1e-5)


def test_the_gain_minimises_the_quadratic_cost(body):
    """J(F) = x0ᵀ P_F x0 with P_F from the closed loop's Lyapunov equation: the LQR gain's cost
    is below that of perturbed gains (each stabilising)."""
    from scipy.linalg import solve_continuous_lyapunov

    muscles, feedback = _free_design(body)
    A, B, _ = design_matrices(linear_system(body, muscles, inputs=False))
    Q, R = bryson_weights(3, 0.2, 1.0, [120.0, 240.0, 240.0])
    F = np.hstack(feedback.matrices())

    def cost(G):
        Acl = A - B @ G
        assert np.all(np.linalg.eigvals(Acl).real < 0)
        P = solve_continuous_lyapunov(Acl.T, -(Q + G.T @ R @ G))
        return np.trace(P)

    best = cost(F)
    rng = np.random.default_rng(7)
    for _ in range(5):
        assert cost(F + 0.02 * np.abs(F).max() * rng.standard_normal(F.shape)) > best


def test_preset_closed_loop_poles_and_delay_margin(controller):
    check = controller.check()
    np.testing.assert_allclose(np.sort_complex(check.poles_without_delay),
                               np.sort_complex(check.design_poles), rtol=1e-9, atol=1e-9)
    assert np.all(check.design_poles.real < 0)
    assert check.delay_margin > controller.feedback_delay
    assert check.stable_at_delay


def _late_sway(body, controller, delay):
    options = {**controller.run_options(), "feedback_delay": delay}
    r = pl.simulate(body, controller.muscles, RampAndHold(-0.002, 0.4), 12.0, **options)
    theta = r.theta
    return (np.abs(theta[r.time > 9.0]).max(), np.abs(theta[(r.time > 1.0) & (r.time < 4.0)]).max())


def test_delay_margin_against_the_nonlinear_runs(body, controller):
    """A small translation dies away a little below the delay margin and grows a little above."""
    margin = controller.check().delay_margin
    late, early = _late_sway(body, controller, 0.9 * margin)
    assert late < 0.2 * early
    late, early = _late_sway(body, controller, 1.1 * margin)
    assert late > early


def test_engines_agree_on_the_controller(body, controller):
    """With the ankle limited to 60 N·m (the unlimited run peaks near 170 N·m) the ankle
    saturates and lets go at events: both engines alike, the reported moment the
    controller's with the limit applied."""
    options = {**controller.run_options(), "torque_limits": (60.0, np.inf, np.inf)}
    runs = [pl.simulate(body, controller.muscles, RampAndHold(-0.06, 0.3), 3.0, engine=e,
                        **options) for e in ("compiled", "reference")]
    assert runs[0].status == runs[1].status == "completed"
    for r in runs:
        assert np.abs(r.joint_moments[:, 0]).max() == pytest.approx(60.0, rel=1e-9)
    np.testing.assert_allclose(runs[0].theta, runs[1].theta, atol=2e-6)
    unlimited = pl.simulate(body, controller.muscles, RampAndHold(-0.06, 0.3), 3.0,
                            **controller.run_options())
    assert np.abs(unlimited.joint_moments[:, 0]).max() > 100.0


def test_reported_moments_include_the_controller(body, controller):
    """The run's joint moments are the pairs' plus the controller's −F_θ Θ(t − τ) −
    F_ω Θ̇(t − τ), the delayed state read from the run's own samples."""
    r = pl.simulate(body, controller.muscles, RampAndHold(-0.02, 0.5), 2.0, engine="reference",
                    **controller.run_options())
    k, v = controller.joint_feedback.matrices()
    tau = controller.feedback_delay
    n = body.n_links
    late = r.time >= tau + 0.5
    past = np.column_stack([np.interp(r.time[late] - tau, r.time, r.state[:, j])
                            for j in range(2 * n)])
    pairs = r.pair_torques[late] @ controller.muscles.crossing_matrix
    expected = pairs - past[:, :n] @ k.T - past[:, n:] @ v.T
    np.testing.assert_allclose(r.joint_moments[late][:, [0, 2]], expected[:, [0, 2]],
                               atol=0.05)


def test_engines_agree_without_delay(body):
    muscles, feedback = _free_design(body)
    runs = [pl.simulate(body, muscles, RampAndHold(-0.05, 0.5), 2.0, engine=e,
                        joint_feedback=feedback) for e in ("compiled", "reference")]
    np.testing.assert_allclose(runs[0].theta, runs[1].theta, atol=2e-6)


def test_scale_multiplies_the_gains(controller):
    k, v = controller.joint_feedback.matrices()
    k2, v2 = controller.joint_feedback.scaled(0.5).matrices()
    np.testing.assert_allclose(k2, 0.5 * k)
    np.testing.assert_allclose(v2, 0.5 * v)
    rows = joint_gain_rows(controller.joint_feedback, 3, 0.08)
    np.testing.assert_allclose(rows[2], -k)
    assert not rows[0].any()


def test_joint_feedback_is_checked():
    with pytest.raises(ParameterError, match="square"):
        JointFeedback(((1.0, 2.0),), ((1.0, 2.0),))
    with pytest.raises(ParameterError, match="joint_feedback_scale"):
        JointFeedback(((1.0,),), ((1.0,),), scale=-1.0)
    with pytest.raises(ParameterError, match="joint feedback is for 1 links"):
        pl.simulate(pl.paper_body(), pl.paper_muscles("1"), None, 0.1,
                    joint_feedback=JointFeedback(((1.0,),), ((1.0,),)))


def test_preset_carries_its_citation_and_unknown_names_list_the_known():
    preset = get_multijoint_controller("multijoint-default")
    assert "Kuo" in preset.citation and "Park" in preset.citation
    assert "posturelab's" in preset.provenance_text()
    with pytest.raises(UnknownNameError, match="multijoint-default"):
        get_multijoint_controller("nope")


def test_locked_knee_design_leaves_the_knee_row_empty(controller):
    k, v = controller.joint_feedback.matrices()
    assert not k[1].any() and not v[1].any()
    assert controller.run_options()["knee"] == KneeModel("locked")
    check = closed_loop_check(pl.paper_body(), controller.muscles, controller.joint_feedback,
                              0.0, "locked")
    assert check.delay_margin == pytest.approx(controller.check().delay_margin)


def test_the_controller_scale_is_swept_and_fitted(body, controller, tmp_path):
    """A run made with the gains at 0.8 of the design gives back 0.8 when joint_feedback_scale
    is fitted from its angles; a sweep over the factor gives each row the single run's
    outcome."""
    from posturelab.scenarios import Scenario
    from posturelab.studies._sweep_grid import sweep_grid
    from posturelab.studies.identification import fit_stiffness
    from posturelab.studies.sweep import VaryRange, run_sweep

    options = pl.RunOptions(duration=2.0, **controller.run_options())
    sc = Scenario(name="mj", source="test", body=body, muscles=controller.muscles,
                  disturbance=RampAndHold(-0.05, 0.4), options=options)
    truth = pl.simulate(body, controller.muscles, sc.disturbance, options=options.replace(
        joint_feedback=controller.joint_feedback.scaled(0.8)))
    t, theta = truth.time[::20], truth.theta[::20]
    # (the controller's own pairs stay as they are: no pair gain is free)
    fit = fit_stiffness(sc, t, theta, free=["joint_feedback_scale"])
    assert fit.parameter_names == ("joint_feedback_scale",)
    assert fit.estimates[0] == pytest.approx(0.8, rel=1e-4)

    varies = [VaryRange("joint_feedback_scale", 0.5, 1.5, 3),
              VaryRange("torque_limit:ankle", 40.0, 120.0, 2)]
    grid = sweep_grid(sc, varies)
    table = run_sweep(sc, varies)
    for r, (scale, limit) in enumerate(grid.values):
        single = pl.simulate(body, controller.muscles, sc.disturbance, options=options.replace(
            joint_feedback=controller.joint_feedback.scaled(scale),
            torque_limits=(limit, np.inf, np.inf)))
        assert table.outcomes.fell[r] == single.fell
        np.testing.assert_allclose(table.outcomes.peak_theta[r],
                                   np.abs(single.theta).max(axis=0), rtol=1e-3, atol=1e-5)
