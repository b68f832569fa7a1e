"""The Python API refuses what is not a number, a missing muscle set and absurd initial
angles at its edge (trial issue 17), with ParameterError naming the field; it used to raise
AttributeError, read '5' as 5 s, and start a run at θ1 = 100 rad that "fell at t = 0"."""

from __future__ import annotations

import numpy as np
import pytest

import posturelab as pl
from posturelab._validation import finite_array, finite_float
from posturelab.errors import ParameterError


@pytest.fixture(scope="module")
def model():
    return pl.paper_body(), pl.paper_muscles("1")


@pytest.mark.parametrize("call", ["analyse", "delay_margin", "upright_verdict"])
def test_missing_muscles_is_a_parameter_error(model, call):
    body, _ = model
    with pytest.raises(ParameterError, match="muscles must be a MuscleSet, got NoneType"):
        getattr(pl, call)(body, None)


@pytest.mark.parametrize("kwargs, field", [
    ({"duration": "5"}, "duration"),
    ({"duration": True}, "duration"),
    ({"duration": 1.0, "feedback_delay": "0.1"}, "feedback_delay"),
    ({"duration": 1.0, "feedback_delay": False}, "feedback_delay"),
    ({"duration": 1.0, "proprioceptive_weight": "1"}, "proprioceptive_weight"),
])
def test_simulate_refuses_strings_and_bools(model, kwargs, field):
    body, muscles = model
    with pytest.raises(ParameterError, match=field) as err:
        pl.simulate(body, muscles, **kwargs)
    assert "(str)" in str(err.value) or "(bool)" in str(err.value)


@pytest.mark.parametrize("delay", ["0.1", True, b"0.1"])
def test_rightmost_roots_refuses_non_numbers(model, delay):
    body, muscles = model
    with pytest.raises(ParameterError, match=r"delay \[s\] must be a finite number"):
        pl.rightmost_roots(body, muscles, delay)


def test_numbers_of_every_numeric_type_still_pass(model):
    from posturelab._validation import as_number

    body, muscles = model
    assert as_number("x", np.float32(0.5)) == 0.5 and as_number("x", np.int64(3)) == 3.0
    assert finite_float("x", 2) == 2.0
    np.testing.assert_array_equal(finite_array("x", [1, 2.5]), [1.0, 2.5])
    run = pl.simulate(body, muscles, duration=np.float64(0.5),
                      initial_state=np.array([0.01, 0, 0, 0, 0, 0]))
    assert run.status != "failed"


@pytest.mark.parametrize("state, words", [
    ([100, 0, 0, 0, 0, 0], "angle 1 must be in [−3.14159, 3.14159] rad, got 100.0"),
    ([0, 0, -4.0, 0, 0, 0], "angle 3 must be in"),
    (["0.1", 0, 0, 0, 0, 0], "must be numeric"),
    ([True, 0, 0, 0, 0, 0], "must be numeric"),
])
def test_initial_state_is_bounded_and_numeric(model, state, words):
    body, muscles = model
    with pytest.raises(ParameterError, match="initial_state") as err:
        pl.simulate(body, muscles, duration=1.0, initial_state=state)
    assert words in str(err.value)


def test_large_initial_rates_are_still_allowed(model):
    """Only the angles are bounded: a rate of 5 rad/s is a hard push, not a posture."""
    body, muscles = model
    run = pl.simulate(body, muscles, duration=0.2, initial_state=[0, 0, 0, 5.0, 0, 0])
    assert run.time[-1] > 0
