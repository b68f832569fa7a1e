"""Delay margins with Peterka 2002's torque feedback (posturelab.linear.delay and .margins).

Three independent routes to the same margin: the single-set Chen–Gu–Nett pencil of the
3N-state first-order form (filter states included), the batched delay pencil of the
quasi-polynomial det(d A + n B e^{−sτ}) (the cubic in ω² for one link), and the rightmost
roots of the delayed system (spectral discretisation + Newton) just below and just above
the margin. For one link a closed form: with K_t = 2, |d(iω)| = |n(iω)| at every ω, so the
crossing frequency is that without the filter and the delay moves by arg g(iω)/ω.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import posturelab as pl
from _cli import cli, one_line_exit_2
from posturelab.linear import batch_delay_margin
from posturelab.linear.delay import delay_margin, delayed_system, system_rightmost_roots
from posturelab.linear.margins import delay_margins
from posturelab.model.controllers import get_controller

RTOL = 1e-8
FILTERS = [(0.3, 17.4), (0.8, 5.0), (1.2, 17.4), (2.0, 40.0)]


def _one_link():
    body = pl.get_body("paper-1link")
    return body, get_controller("peterka-2002").muscles(body)


@pytest.mark.parametrize("gain, lag", FILTERS)
@pytest.mark.parametrize("links", [1, 3])
def test_margin_by_three_routes(links, gain, lag):
    """Chen–Gu–Nett (3N states) = the delay pencil to 1e-8; the rightmost root is in the
    left half-plane at 0.99 τ_m and in the right at 1.01 τ_m, as the crossing's direction
    says."""
    body, muscles = _one_link() if links == 1 else (pl.paper_body(), pl.paper_muscles("1"))
    single = delay_margin(body, muscles, torque_feedback_gain=gain,
                          torque_feedback_time_constant=lag)
    system = delayed_system(body, muscles, torque_feedback_gain=gain,
                            torque_feedback_time_constant=lag)
    assert system.first_order()[0].shape[-1] == 3 * links
    batch = delay_margins(system)
    assert single.stable_without_delay and math.isfinite(single.delay_margin)
    assert batch.delay_margin[0] == pytest.approx(single.delay_margin, rel=RTOL)
    assert batch.crossing_frequency[0] == pytest.approx(single.crossing_frequency, rel=RTOL)
    tau = single.delay_margin
    below = system_rightmost_roots(system, 0.99 * tau, 1)[0]
    above = system_rightmost_roots(system, 1.01 * tau, 1)[0]
    assert below.real < 0 < above.real, (below, above)
    assert single.crossings[0].direction == 1  # Re ds/dτ > 0 with the filter's factor
    assert abs(above.imag) == pytest.approx(single.crossing_frequency, rel=0.05)


def test_one_link_closed_form_at_gain_two():
    """K_t = 2: (1 − K_t)² = 1, so |Â(iω)| = |B̂(iω)| ⇔ |A(iω)| = |B(iω)|: the crossing
    frequency is the unfiltered one, and e^{−iωτ} = −A/(B g) gives τ = τ_0 + arg g(iω)/ω
    (mod 2π/ω), arg g = atan(τ_t ω) − atan2(τ_t ω, 1 − K_t)."""
    body, muscles = _one_link()
    plain = delay_margin(body, muscles)
    omega = plain.crossing_frequency
    for lag in (1.0, 2.0, 17.4, 100.0):  # (at 0.5 s it is unstable without delay)
        shift = math.atan(lag * omega) - math.atan2(lag * omega, -1.0)
        expected = (plain.delay_margin + shift / omega) % (2 * math.pi / omega)
        out = batch_delay_margin(body, muscles, torque_feedback_gain=2.0,
                                 torque_feedback_time_constant=lag)
        assert out.crossing_frequency[0] == pytest.approx(omega, rel=1e-9)
        assert out.delay_margin[0] == pytest.approx(expected, rel=1e-9)


def test_a_vanishing_gain_leaves_the_margin():
    body, muscles = _one_link()
    plain = delay_margin(body, muscles).delay_margin
    tiny = batch_delay_margin(body, muscles, torque_feedback_gain=1e-9).delay_margin[0]
    assert tiny == pytest.approx(plain, rel=1e-6)


@pytest.mark.parametrize("links", [1, 3])
def test_batched_filters_equal_the_single_set_ones(rng, links):
    """Per-set gains and filters (some sets unstable without delay) against one set at a
    time."""
    if links == 1:
        body, layout = _one_link()
        k = rng.uniform(0.0, 3.0, (16, 1)) * body.load_stiffness
        ka = rng.uniform(0.0, 2.0, (16, 1)) * body.load_stiffness
    else:
        body, layout = pl.paper_body(), pl.paper_muscles("1")
        k = rng.uniform(0.0, 1500.0, (16, 5))
        ka = rng.uniform(0.0, 1500.0, (16, 5))
    gain = rng.uniform(0.0, 2.5, 16)
    lag = rng.uniform(0.5, 40.0, 16)
    gains = dict(stiffness=k, viscosity=0.25 * k, active_stiffness=ka,
                 active_viscosity=0.3 * ka)
    out = batch_delay_margin(body, layout, **gains, torque_feedback_gain=gain,
                             torque_feedback_time_constant=lag)
    found = 0
    for i in range(16):
        muscles = _muscles(layout, k[i], ka[i])
        single = delay_margin(body, muscles, torque_feedback_gain=gain[i],
                              torque_feedback_time_constant=lag[i])
        assert bool(out.stable_without_delay[i]) == single.stable_without_delay, i
        if not single.stable_without_delay:
            assert math.isnan(out.delay_margin[i])
        elif math.isinf(single.delay_margin):
            assert math.isinf(out.delay_margin[i])
        else:
            found += 1
            assert out.delay_margin[i] == pytest.approx(single.delay_margin, rel=RTOL), i
    assert found >= 3


def _muscles(layout, k, ka):
    from dataclasses import replace

    from posturelab.model.muscles import MuscleSet

    pairs = tuple(replace(p, stiffness=float(k[j]), viscosity=0.25 * float(k[j]),
                          active_stiffness=float(ka[j]), active_viscosity=0.3 * float(ka[j]))
                  for j, p in enumerate(layout.pairs))
    return MuscleSet(pairs, layout.n_links)


def test_delay_margin_command_takes_the_filter():
    p = cli("delay-margin", "--controller", "peterka-2002", "--torque-feedback-gain", "2",
            "--torque-feedback-time-constant", "1", "--json")
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    body, muscles = _one_link()
    expected = delay_margin(body, muscles, torque_feedback_gain=2.0,
                            torque_feedback_time_constant=1.0)
    assert out["delay_margin"] == pytest.approx(expected.delay_margin, rel=1e-12)
    assert out["torque_feedback"] == {"gain": 2.0, "time_constant": 1.0}
    assert out["units"]["torque_feedback"] == {"gain": "-", "time_constant": "s"}
    text = cli("delay-margin", "--case", "1", "--torque-feedback-gain", "0.5")
    assert text.returncode == 0, text.stderr
    assert "torque feedback K_t = 0.5, τ_t = 17.4 s" in text.stdout
    one_line_exit_2(cli("delay-margin", "--torque-feedback-gain", "9"),
                    "--torque-feedback-gain", "9")


@pytest.mark.parametrize("name, tau, m", [("paper-1link", 0.15, 300),
                                          pytest.param("paper-2link", 0.05, 120,
                                                       marks=pytest.mark.slow)])
def test_margins_split_the_batched_rightmost_roots(rng, name, tau, m):
    """D-subdivision by brute force: random sets (gains, K_t in [0, 2.5], τ_t in
    [0.5, 40] s), their rightmost roots at one delay τ (delay_batch, 16 Chebyshev
    intervals): every set whose margin exceeds τ by 2 % has its rightmost root in the left
    half-plane, and every set whose margin is 2 % below τ in the right (all agree: no
    stability switch back among them)."""
    from posturelab.linear.delay_batch import batch_rightmost_root
    from posturelab.model.muscles import MusclePair, MuscleSet

    body = pl.get_body(name)
    if name == "paper-1link":
        layout = _one_link()[1]
    else:
        layout = MuscleSet(tuple(MusclePair(p, lo, lo + 1, 1.0, 1.0, active_stiffness=1.0,
                                            active_viscosity=1.0)
                                 for p, lo in (("ankle", 0), ("hip", 1))), 2)
    pairs = len(layout.pairs)
    k = rng.uniform(0.0, 1.0, (m, pairs)) * body.load_stiffness
    ka = rng.uniform(0.0, 2.5, (m, pairs)) * body.load_stiffness
    la = rng.uniform(0.05, 0.5, (m, pairs)) * ka
    filters = dict(torque_feedback_gain=rng.uniform(0.0, 2.5, m),
                   torque_feedback_time_constant=rng.uniform(0.5, 40.0, m))
    out = batch_delay_margin(body, layout, stiffness=k, viscosity=0.1 * k,
                             active_stiffness=ka, active_viscosity=la, **filters)
    roots = batch_rightmost_root(body, layout, k, 0.1 * k, ka, la, tau, nodes=16, **filters)
    clear = out.stable_without_delay & (np.abs(out.delay_margin - tau) > 0.02 * tau)
    assert clear.sum() >= m // 2
    stable = roots.real[clear] < 0
    np.testing.assert_array_equal(stable, out.delay_margin[clear] > tau)
    assert 0 < stable.sum() < clear.sum()
