"""The compiled engine's steps onto known discontinuities, and its overlapping steps for very
short feedback delays (``docs/simulators.md``).

A PRTS tilt's rate jumps at every state switch, and the delayed feedback feels each jump τ
later (its derivatives 2τ, 3τ, … later): the engine ends a step on each of these times,
takes the inputs just before a stop at a step's end and just after it at the next start,
so a loose tolerance still gives an accurate run. With 0 < τ below
``OVERLAP_BELOW`` (1e-4 s) a step may be longer than τ: the delayed state inside it comes
from its own dense output, iterated; such runs finish and converge to the undelayed run.
"""

from __future__ import annotations

import numpy as np
import pytest

import posturelab as pl
from posturelab.model.controllers import get_controller
from posturelab.model.tilt import PRTSTilt
from posturelab.simulation.compiled import simulate_batch

CASE1 = pl.builtin_scenario("paper-backward-case1")
TIGHT = {"rtol": 1e-9, "atol": 1e-12}


@pytest.fixture(scope="module")
def prts_experiment():
    """One link, intrinsic and delayed active gains (τ = 97 ms), a PRTS tilt for 2 s, and
    the reference engine's run at rtol 1e-10."""
    body = pl.get_body("paper-1link")
    preset = get_controller("icm-pmc5664365")
    muscles = preset.muscles(body)
    tilt = PRTSTilt.named("posturelab-80", 0.035)
    options = {"tilt": tilt, "sample_rate": 100.0, **preset.run_options()}
    reference = pl.simulate(body, muscles, None, 2.0, engine="reference", rtol=1e-10,
                            atol=1e-12, **options)
    return body, muscles, options, reference


@pytest.mark.parametrize("method", ["RK45", "Radau"])
def test_prts_run_at_a_loose_tolerance_is_accurate(prts_experiment, method):
    """At rtol 1e-5 the run is within 5e-8 rad of the reference: no step crosses a switch
    of the PRTS or its echoes (stepping through them gave 3.7e-6 rad with RK45, 7.9e-8 rad
    with Radau)."""
    body, muscles, options, reference = prts_experiment
    run = pl.simulate(body, muscles, None, 2.0, rtol=1e-5, atol=1e-8, method=method, **options)
    assert run.status == "completed"
    np.testing.assert_array_equal(run.time, reference.time)
    assert np.max(np.abs(run.theta - reference.theta)) <= 5e-8


def test_a_switch_the_delayed_jump_fires_happens_at_the_jump():
    """A velocity step felt τ later drives the ankle moment past its limit at t = τ itself,
    in both engines (the compiled one finds the event at the stop, not just before it)."""
    delay = 0.01
    kw = dict(initial_state=CASE1.initial_state, feedback_delay=delay,
              torque_limits=[60.0, np.inf, np.inf], **TIGHT)
    fast = pl.simulate(CASE1.body, CASE1.muscles, pl.VelocityStep.backward(0.25), 0.1, **kw)
    ref = pl.simulate(CASE1.body, CASE1.muscles, pl.VelocityStep.backward(0.25), 0.1,
                      engine="reference", **kw)
    assert ref.switch_times[0] == pytest.approx(delay, abs=1e-12)
    assert fast.switch_times[0] == delay
    assert len(fast.switch_times) == len(ref.switch_times)
    np.testing.assert_allclose(fast.switch_times, ref.switch_times, atol=1e-6)


@pytest.mark.parametrize("method", ["RK45", "Radau"])
@pytest.mark.parametrize("delay", [1e-12, 1e-9, 1e-7])
def test_tiny_delays_finish_and_match_the_undelayed_run(method, delay):
    """Steps longer than τ: a delay of 1e-12 … 1e-7 s finishes within a few thousand steps
    (steps of at most τ would need 1e7 or more) and moves the run by about 0.8 τ rad/s."""
    kw = dict(initial_state=CASE1.initial_state, **TIGHT)
    undelayed = pl.simulate(CASE1.body, CASE1.muscles, CASE1.disturbance, 1.0, **kw)
    run = pl.simulate(CASE1.body, CASE1.muscles, CASE1.disturbance, 1.0, feedback_delay=delay,
                      method=method, max_steps=20_000, **kw)
    assert run.status == "completed", run.message
    assert np.max(np.abs(run.theta - undelayed.theta)) <= 1e-8 + 2.0 * delay
    k = np.asarray(CASE1.muscles.stiffnesses)[None, :]
    batch = simulate_batch(CASE1.body, k, 0.25 * k, CASE1.disturbance, 1.0,
                           CASE1.initial_state, feedback_delay=delay, method=method, **TIGHT)
    assert batch.n_steps[0] < 5_000
    np.testing.assert_array_equal(batch.final_state[0], run.final_state)


def test_overlapping_steps_agree_with_the_method_of_steps():
    """The run's sensitivity to the delay, S(τ) = (θ_τ − θ₀)/τ, is smooth in τ across the
    overlap threshold: S at τ = 9e-5 s (steps longer than τ) is S at 1.1e-4 and 2e-4 s
    (steps of at most τ) extrapolated along their line, to 1e-4 of its size from t = 10 ms
    on (a hundred delays after the step); S itself moves by 1.2e-3 of its size between
    9e-5 and 1.1e-4 s."""
    kw = dict(initial_state=CASE1.initial_state, **TIGHT)
    undelayed = pl.simulate(CASE1.body, CASE1.muscles, CASE1.disturbance, 1.0, **kw)
    after = undelayed.time >= 0.01

    def sensitivity(delay):
        run = pl.simulate(CASE1.body, CASE1.muscles, CASE1.disturbance, 1.0,
                          feedback_delay=delay, **kw)
        return ((run.theta - undelayed.theta) / delay)[after]

    overlapping, near, far = sensitivity(9e-5), sensitivity(1.1e-4), sensitivity(2e-4)
    predicted = near + (near - far) * (1.1e-4 - 9e-5) / (2e-4 - 1.1e-4)
    assert np.max(np.abs(overlapping - predicted)) <= 1e-4 * np.max(np.abs(near))
