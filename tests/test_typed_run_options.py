"""The experiments and studies that run many simulations pass the run's options as one typed
:class:`~posturelab.simulation.options.RunOptions` (``options=``), which gives what the same
options by keyword give; a per-gain-set array of largest_recoverable_batch follows the gain
sets still being bisected."""

from __future__ import annotations

import numpy as np
import pytest

import posturelab as pl
from posturelab.errors import ParameterError
from posturelab.model.controllers import get_controller
from posturelab.simulation.options import RunOptions


def test_a_prts_experiment_takes_its_options_as_one_object():
    from posturelab.frequency.experiment import prts_experiment

    body = pl.get_body("paper-1link")
    preset = get_controller("peterka-2002")
    muscles = preset.muscles(body)
    options = RunOptions(feedback_delay=0.12, proprioceptive_weight=0.8)
    typed = prts_experiment(body, muscles, cycles=2, discard=1, sensor_noise=1e-3, seed=5,
                            options=options)
    keywords = prts_experiment(body, muscles, cycles=2, discard=1, sensor_noise=1e-3, seed=5,
                               feedback_delay=0.12, proprioceptive_weight=0.8)
    np.testing.assert_array_equal(typed.response, keywords.response)
    np.testing.assert_array_equal(typed.estimate.frf, keywords.estimate.frf)
    other = prts_experiment(body, muscles, cycles=2, discard=1, sensor_noise=1e-3, seed=5,
                            options=options, feedback_delay=0.15)  # a keyword replaces a field
    assert not np.array_equal(other.response, typed.response)
    with pytest.raises(ParameterError, match="unknown option 'feedback_dealy'"):
        prts_experiment(body, muscles, cycles=2, feedback_dealy=0.1)


def test_a_batch_bisection_follows_per_set_delays_and_shared_options():
    """Each gain set's bracket with its own delay equals that of the set alone at that delay
    (the delays of the sets still open are the ones passed on each round)."""
    from posturelab.studies.recovery import largest_recoverable_batch

    body = pl.paper_body()
    step = pl.VelocityStep.backward(1.0)
    k = np.tile(np.asarray(pl.paper_muscles("1").stiffnesses, dtype=float), (4, 1))
    k[:, 0] = [700.0, 900.0, 1200.0, 60.0]  # the last falls at once: not bisected
    delays = np.array([0.0, 0.02, 0.01, 0.0])
    shared = RunOptions(fall=pl.FallCriteria(base_of_support=pl.FOOT_FROM_LITERATURE))
    batch = largest_recoverable_batch(body, k, 0.25 * k, step, 2.0, 0.05, 1.6,
                                      tolerance=0.05, options=shared, feedback_delay=delays)
    assert batch.bracketed[0] and not batch.bracketed[3]  # only some sets are bisected
    for r in range(4):
        alone = largest_recoverable_batch(body, k[r:r + 1], 0.25 * k[r:r + 1], step, 2.0,
                                          0.05, 1.6, tolerance=0.05, options=shared,
                                          feedback_delay=float(delays[r]))
        np.testing.assert_array_equal(
            [batch.recovered[r], batch.fell[r]], [alone.recovered[0], alone.fell[0]])
