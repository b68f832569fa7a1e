"""Neural delay of the muscle feedback, against the analytic stability boundary."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import posturelab as pl
from posturelab.model.muscles import MusclePair, MuscleSet


def critical_delay(inertia, load, stiffness, viscosity):
    """Smallest τ at which J s² − mgh + (K + L s) e^{−sτ} = 0 has a root s = iω.

    Imaginary part: L ω cos ωτ = K sin ωτ; modulus: (J ω² + mgh)² = K² + L² ω².
    """
    w = brentq(lambda w: (inertia * w * w + load) ** 2 - stiffness**2 - (viscosity * w) ** 2,
               1e-9, 1e4)
    return math.atan2(viscosity * w, stiffness) / w


@pytest.fixture(scope="module")
def pendulum():
    body = pl.get_body("paper-1link")
    stiffness, viscosity = 1000.0, 100.0
    muscles = MuscleSet((MusclePair("ankle", 0, 1, stiffness, viscosity),), 1)
    tau_c = critical_delay(body.inertia_diagonal[0], body.load_stiffness, stiffness, viscosity)
    return body, muscles, tau_c


@pytest.mark.parametrize("fraction,grows", [(0.85, False), (1.15, True)])
def test_delay_stability_boundary_of_the_inverted_pendulum(pendulum, fraction, grows):
    """Below the analytic critical delay sway decays; above it, it grows."""
    body, muscles, tau_c = pendulum
    r = pl.simulate(body, muscles, None, 15.0, initial_state=[0.01, 0.0],
                    feedback_delay=fraction * tau_c, fall=pl.FallCriteria(math.pi / 2),
                    sample_rate=100)
    early = np.abs(r.theta[r.time < 3, 0]).max()
    late = np.abs(r.theta[r.time > 12, 0]).max()
    assert (late > early) == grows


def test_small_delay_converges_to_no_delay():
    sc = pl.builtin_scenario("paper-backward-case1").replace(duration=0.5, sample_rate=100)
    base = sc.run()
    delayed = sc.run(feedback_delay=5e-4)
    assert np.max(np.abs(delayed.theta - base.theta)) < 2e-3
    assert np.max(np.abs(delayed.theta - base.theta)) > 0


def test_torques_respond_to_the_delayed_state(pendulum):
    """Pair torque at t equals K θ(t − τ) + L θ̇(t − τ) on the output grid."""
    body, muscles, tau_c = pendulum
    tau = 0.05
    r = pl.simulate(body, muscles, None, 2.0, initial_state=[0.02, 0.1], feedback_delay=tau,
                    sample_rate=1000, fall=pl.FallCriteria(math.pi / 2))
    k = int(round(tau * 1000))
    expected = 1000.0 * r.theta[:-k, 0] + 100.0 * r.omega[:-k, 0]
    np.testing.assert_allclose(r.pair_torques[k:, 0], expected, atol=1e-6)
    # before t = τ the muscles respond to the state before the run
    np.testing.assert_allclose(r.pair_torques[:k, 0], 1000.0 * 0.02 + 100.0 * 0.1)


def test_paper_case1_tolerates_only_a_short_delay():
    """The paper's viscous gains on light links: 30 ms of delay topples case 1 backward."""
    sc = pl.builtin_scenario("paper-backward-case1").replace(duration=1.5)
    assert not sc.run(feedback_delay=0.002, sample_rate=100).fell
    assert sc.run(feedback_delay=0.03, sample_rate=100).fell


def test_bad_delay(capsys):
    with pytest.raises(pl.ParameterError, match="feedback_delay"):
        pl.simulate(pl.paper_body(), pl.paper_muscles("1"), None, 1.0, feedback_delay=-0.1)
    from posturelab.cli import main

    assert main(["simulate", "--case", "1", "--feedback-delay", "2"]) == 2
    assert "--feedback-delay" in capsys.readouterr().err
