"""The ankle and hip modes of a run (posturelab.studies.strategy) and the strategy study."""

from __future__ import annotations

import math

import numpy as np
import pytest

import posturelab as pl
from posturelab.errors import ParameterError
from posturelab.studies.strategy import hip_fraction, hip_fraction_study, strategy_modes


def naive_hip_fraction(theta):
    """The definition written out sample by sample."""
    num = den = 0.0
    for row in theta:
        u, w = row[0] - theta[0][0], row[-1] - theta[0][-1]
        a, b = (u + w) / 2, (u - w) / 2
        num += b * b
        den += a * a + b * b
    return 0.0 if den == 0 else num / den


def test_pure_ankle_pure_hip_and_a_mixture():
    t = np.linspace(0, 3, 301)
    s = 0.05 * np.sin(2 * t)
    rigid = np.column_stack([s, 0.3 * s, s])
    assert hip_fraction(rigid) == 0.0
    counter = np.column_stack([s, 0.0 * s, -s])
    assert hip_fraction(counter) == pytest.approx(1.0, abs=1e-15)
    a, b = 0.04 * np.sin(t), 0.01 * np.cos(3 * t) - 0.01
    mixed = np.column_stack([0.1 + a + b, np.zeros_like(t), -0.2 + a - b])
    aa, bb = strategy_modes(mixed)
    np.testing.assert_allclose(aa, a - a[0], atol=1e-15)
    np.testing.assert_allclose(bb, b - b[0], atol=1e-15)
    assert hip_fraction(mixed) == pytest.approx(naive_hip_fraction(mixed.tolist()), rel=1e-12)
    assert math.isnan(hip_fraction(np.zeros((5, 3))))  # nothing moves: 0/0, no strategy
    assert math.isnan(hip_fraction(np.zeros((5, 1))))
    with pytest.raises(ParameterError, match="N >= 2"):
        strategy_modes(np.zeros(5))


def test_a_run_reports_its_hip_fraction():
    r = pl.simulate(pl.paper_body(), pl.paper_muscles("1"), pl.VelocityStep.backward(0.3), 2.0,
                    engine="compiled")
    assert r.hip_fraction == pytest.approx(naive_hip_fraction(r.theta.tolist()), rel=1e-10)
    assert r.summary()["hip_fraction"] == r.hip_fraction
    one = pl.simulate(pl.get_body("paper-1link"),
                      pl.model.muscles.muscles_for(1, [900.0]), pl.VelocityStep.backward(0.3),
                      1.0, engine="compiled")
    assert one.summary()["hip_fraction"] is None


def test_impedance_alone_does_not_switch_to_the_hip_strategy():
    """Without a limit the response is linear in the step size, so the hip fraction does not
    depend on it; with the ankle moment limited to 60 N·m the paper's case 1 gains topple as
    one pendulum: the hip fraction never rises above its linear value before the fall."""
    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    fall = pl.FallCriteria(base_of_support=pl.FOOT_FROM_LITERATURE)
    sizes = np.linspace(0.01, 0.05, 5)
    free = hip_fraction_study(body, muscles, sizes, ankle_torque_limit=1e6, fall=fall)
    assert not free.fell.any()
    assert np.ptp(free.hip_fraction) < 1e-3 * free.hip_fraction.mean()
    limited = hip_fraction_study(body, muscles, np.linspace(0.02, 0.3, 15),
                                 ankle_torque_limit=60.0, fall=fall)
    assert limited.fell.any() and not limited.fell.all()
    assert np.all(limited.peak_ankle_moment <= 60.0 + 1e-9)
    assert limited.hip_fraction[~limited.fell].max() <= free.hip_fraction.mean() + 1e-3
    assert limited.first_above(0.5) is None
    with pytest.raises(ParameterError, match="at least 2 links"):
        hip_fraction_study(pl.get_body("paper-1link"), muscles, sizes, ankle_torque_limit=50.0)
