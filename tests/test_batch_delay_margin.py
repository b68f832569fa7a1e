"""Batched delay margins (posturelab.linear.margins) against the single-set delay_margin
(Chen–Gu–Nett, one set at a time), and the one-link closed form against the delay pencil.

The single-set method and the batched one share only the linear system's matrices: the
crossings come from different eigenvalue problems (the first-order Kronecker pencil of
size 8N² against the second-order one of size 2N²).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import posturelab as pl
from posturelab.errors import ParameterError
from posturelab.linear import BatchDelayMargin, batch_delay_margin, linear_system
from posturelab.linear.delay import delay_margin
from posturelab.linear.margins import _one_link, _pencil, delay_margins
from posturelab.model.muscles import MusclePair, MuscleSet

RTOL = 1e-8


def assert_same_margin(batch: BatchDelayMargin, i: int, single) -> None:
    assert bool(batch.stable_without_delay[i]) == single.stable_without_delay, i
    if not single.stable_without_delay:
        assert math.isnan(batch.delay_margin[i]) and math.isnan(batch.crossing_frequency[i])
    elif math.isinf(single.delay_margin):
        assert math.isinf(batch.delay_margin[i]) and math.isnan(batch.crossing_frequency[i])
    else:
        assert batch.delay_margin[i] == pytest.approx(single.delay_margin, rel=RTOL), i
        assert batch.crossing_frequency[i] == pytest.approx(single.crossing_frequency,
                                                            rel=RTOL), i


@pytest.mark.parametrize("active", [False, True])
def test_three_link_margins_equal_the_single_set_ones(rng, active):
    body, layout = pl.paper_body(), pl.paper_muscles("1")
    m = 40
    k = rng.uniform(0.0, 1500.0, (m, 5))
    ka = rng.uniform(0.0, 1500.0, (m, 5))
    gains = dict(stiffness=k, viscosity=0.25 * k)
    if active:
        gains.update(active_stiffness=ka, active_viscosity=0.3 * ka)
    out = batch_delay_margin(body, layout, **gains)
    assert len(out) == m
    for i in range(m):
        extra = dict(active_stiffness=ka[i], active_viscosity=0.3 * ka[i]) if active else {}
        muscles = pl.paper_muscles(stiffness=k[i], viscosity=0.25 * k[i], **extra)
        assert_same_margin(out, i, delay_margin(body, muscles))
    assert out.stable_without_delay.any()
    assert np.isfinite(out.delay_margin).any()


def test_two_and_four_link_margins_equal_the_single_set_ones(rng):
    for n in (2, 4):
        body = pl.get_body(f"paper-{n}link") if n == 2 else pl.Body.from_arrays(
            [5.0, 15.0, 20.0, 25.0], [0.4, 0.4, 0.3, 0.5], [0.2, 0.2, 0.15, 0.25],
            [0.1, 0.4, 0.3, 1.5])
        spans = [(lo, hi) for hi in range(1, n + 1) for lo in range(hi)]
        layout = MuscleSet(tuple(MusclePair(f"p{j}", lo, hi, 1.0, 1.0)
                                 for j, (lo, hi) in enumerate(spans)), n)
        m = 12
        k = rng.uniform(0.0, 2.0, (m, len(spans))) * body.load_stiffness
        v = rng.uniform(0.05, 0.4, (m, len(spans))) * k
        out = batch_delay_margin(body, layout, stiffness=k, viscosity=v)
        for i in range(m):
            muscles = MuscleSet(tuple(MusclePair(f"p{j}", lo, hi, k[i, j], v[i, j])
                                      for j, (lo, hi) in enumerate(spans)), n)
            assert_same_margin(out, i, delay_margin(body, muscles))


def test_one_link_margins_equal_the_single_set_ones(rng):
    body = pl.get_body("paper-1link")
    m = 60
    ki = rng.uniform(0.0, 300.0, (m, 1))
    ka = rng.uniform(0.0, 3.0, (m, 1)) * body.load_stiffness
    la = rng.uniform(0.0, 600.0, (m, 1))
    layout = MuscleSet((MusclePair("ankle", 0, 1, 1.0, 1.0),), 1)
    out = batch_delay_margin(body, layout, stiffness=ki, viscosity=0.1 * ki,
                             active_stiffness=ka, active_viscosity=la)
    for i in range(m):
        muscles = MuscleSet((MusclePair("ankle", 0, 1, ki[i, 0], 0.1 * ki[i, 0],
                                        active_stiffness=ka[i, 0],
                                        active_viscosity=la[i, 0]),), 1)
        assert_same_margin(out, i, delay_margin(body, muscles))
    assert 0 < out.stable_without_delay.sum() < m


def test_the_one_link_closed_form_equals_the_delay_pencil(rng):
    body = pl.get_body("paper-1link")
    m = 500
    k = rng.uniform(0.5, 4.0, (m, 1)) * body.load_stiffness
    layout = MuscleSet((MusclePair("ankle", 0, 1, 1.0, 1.0),), 1)
    system = linear_system(body, layout, stiffness=0.2 * k, viscosity=0.02 * k,
                           active_stiffness=k, active_viscosity=rng.uniform(0.0, 0.5, (m, 1)) * k,
                           inputs=False)
    mats = (system.inertia, system.stiffness, system.viscosity, system.delayed_stiffness,
            system.delayed_viscosity)
    closed = _one_link(*(np.broadcast_to(x, (m, 1, 1))[:, 0, 0] for x in mats))
    pencil = _pencil(m, *mats)
    finite = np.isfinite(closed[0])
    assert finite.sum() > m // 2
    np.testing.assert_array_equal(np.isfinite(pencil[0]), finite)
    np.testing.assert_allclose(pencil[0][finite], closed[0][finite], rtol=1e-10)
    np.testing.assert_allclose(pencil[1][finite], closed[1][finite], rtol=1e-10)


def test_the_delayed_pendulum_margin_is_its_closed_form():
    """J θ̈ − mgh θ + K θ(t − τ) + L θ̇(t − τ) = 0 crosses where (J ω² + mgh)² = K² + L² ω²,
    at τ = atan2(L ω, K)/ω (written here, not from the module)."""
    body = pl.get_body("paper-1link")
    J, mgh = body.inertia_diagonal[0], body.load_stiffness
    k = np.array([[1000.0], [700.0], [2000.0]])
    v = np.array([[100.0], [300.0], [50.0]])
    out = batch_delay_margin(body, MuscleSet((MusclePair("ankle", 0, 1, 1.0, 1.0),), 1),
                             stiffness=k, viscosity=v)
    for i in range(3):
        K, L = k[i, 0], v[i, 0]
        b = 2 * J * mgh - L * L
        u = (-b + math.sqrt(b * b - 4 * J * J * (mgh * mgh - K * K))) / (2 * J * J)
        w = math.sqrt(u)
        assert out.crossing_frequency[i] == pytest.approx(w, rel=1e-12)
        assert out.delay_margin[i] == pytest.approx(math.atan2(L * w, K) / w, rel=1e-12)


def test_one_set_from_the_muscles_and_the_system_method():
    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    out = batch_delay_margin(body, muscles)
    single = delay_margin(body, muscles)
    assert_same_margin(out, 0, single)
    again = delay_margins(linear_system(body, muscles))
    np.testing.assert_array_equal(again.delay_margin, out.delay_margin)


def test_result_is_frozen_and_says_its_units():
    body = pl.get_body("paper-1link")
    layout = MuscleSet((MusclePair("ankle", 0, 1, 1.0, 1.0),), 1)
    k = np.array([[300.0], [1000.0], [1000.0]])  # below mgh; delayed; intrinsic only
    out = batch_delay_margin(body, layout, stiffness=k, viscosity=0.1 * k,
                             active_stiffness=np.array([[0.0], [900.0], [0.0]]),
                             active_viscosity=np.array([[0.0], [250.0], [0.0]]))
    d = out.to_dict()
    assert d["units"] == {"delay_margin": "s", "crossing_frequency": "rad/s",
                          "stable_without_delay": "-"}
    assert d["delay_margin"][0] is None and d["delay_margin"][2] == "infinite"
    assert isinstance(d["delay_margin"][1], float) and d["crossing_frequency"][2] is None
    assert d["stable_without_delay"] == [False, True, True]
    with pytest.raises(ValueError):
        out.delay_margin[0] = 1.0


def test_bad_gains_raise_parameter_error():
    body, layout = pl.paper_body(), pl.paper_muscles("1")
    with pytest.raises(ParameterError, match=r"shape \(M, 5\)"):
        batch_delay_margin(body, layout, stiffness=np.ones((3, 4)), viscosity_ratio=0.2)
    with pytest.raises(ParameterError, match="viscosity"):
        batch_delay_margin(body, layout, stiffness=np.ones((3, 5)))
    with pytest.raises(ParameterError, match=">= 0"):
        batch_delay_margin(body, layout, stiffness=-np.ones((3, 5)), viscosity_ratio=0.2)


def test_a_body_per_set(rng):
    from posturelab.linear.system import BodyArrays

    body = pl.paper_body()
    scale = rng.uniform(0.8, 1.2, (6, 1))
    arrays = BodyArrays(body.masses * scale, body.lengths, body.com_distances, body.inertias)
    k = np.tile(pl.paper_muscles("1").stiffnesses, (6, 1))
    out = batch_delay_margin(arrays, pl.paper_muscles("1"), stiffness=k, viscosity_ratio=0.25)
    for i in range(6):
        one = pl.Body.from_arrays(arrays.masses[i], body.lengths, body.com_distances,
                                  body.inertias, gravity=float(arrays.gravity))
        assert_same_margin(out, i, delay_margin(one, pl.paper_muscles("1")))
