"""A simulated PRTS experiment's sensor noise and a motor noise given the same seed are
independent streams (they were once the same draws, scaled, which inflated the band
variance of a simulated experiment by 1.6–2× at high frequency)."""

from __future__ import annotations

import numpy as np

import posturelab as pl
from posturelab.frequency.experiment import prts_experiment
from posturelab.model.muscles import muscles_for
from posturelab.model.noise import MotorNoise, noise_samples
from posturelab.model.tilt import PRTSTilt


def test_sensor_noise_of_an_experiment_is_not_its_motor_noise():
    body = pl.get_body("paper-1link")
    muscles = muscles_for(1, [1.3 * 9.81 * body.segments[0].mass
                                 * body.segments[0].com_distance])
    tilt = PRTSTilt.named("posturelab-80", amplitude=0.01)
    correlations = []
    for seed in range(4):
        kwargs = dict(tilt=tilt, cycles=2, discard=0, seed=seed, sample_rate=100.0)
        clean = prts_experiment(body, muscles, **kwargs)
        noisy = prts_experiment(body, muscles, sensor_noise=1e-3, **kwargs)
        sensor = (noisy.response - clean.response) / 1e-3
        motor = noise_samples(MotorNoise(1.0, None, seed=seed), sensor.size, 1)[:, 0]
        correlations.append(np.corrcoef(sensor, motor)[0, 1])
    # independent streams: each correlation ~ N(0, 1/n) (n = 4,000: sd 0.016); equal draws: 1
    assert np.max(np.abs(correlations)) < 5.0 / np.sqrt(sensor.size)
