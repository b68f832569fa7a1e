"""A negligible feedback delay (τ → 0) behaves as no delay everywhere the delayed root
finder is used: ``rightmost_roots``, ``upright_verdict`` (``poles``, ``simulate``) and the
stacked ``batch_rightmost_root``; before, a delay at or below ~1e-13 s lost every root to
rounding and ``upright_verdict`` raised IndexError."""

from __future__ import annotations

import json

import numpy as np
import pytest

from _cli import run_main

#: The trial's one-link controller: no intrinsic gains, active PD delayed by τ.
ONE_LINK = ("--body", "paper-1link", "--stiffness", "0", "--viscosity", "0",
            "--active-stiffness", "761", "--active-viscosity", "200")


def _roots(capsys, delay: str) -> np.ndarray:
    code, out, err = run_main(capsys, "poles", *ONE_LINK, "--feedback-delay", delay, "--json")
    assert code == 0, err
    v = json.loads(out)["linear_stability"]
    assert v["status"] == "stable"
    return np.array([complex(z["re"], z["im"]) for z in v["sides"][0]["roots"]])


@pytest.mark.parametrize("delay", ["1e-15", "1e-13", "1e-300"])
def test_poles_tiny_delay_is_continuous_with_no_delay(capsys, delay):
    at_zero = _roots(capsys, "0")
    # 1e-4 s is well inside the Chebyshev route: the tiny delay agrees with both ends
    small = _roots(capsys, "1e-4")
    tiny = _roots(capsys, delay)
    assert tiny.shape == at_zero.shape == (2,)
    np.testing.assert_allclose(tiny, at_zero, rtol=1e-9)
    np.testing.assert_allclose(tiny, small, rtol=1e-3)


def test_simulate_tiny_delay_has_a_verdict(capsys, tmp_path):
    code, out, err = run_main(capsys, "simulate", *ONE_LINK, "--feedback-delay", "1e-15",
                              "--tilt", "sine:0.02:0.5", "--duration", "1",
                              "--out", str(tmp_path / "s.csv"))
    assert code == 0, err
    assert "Traceback" not in err


def test_api_and_batch_roots_at_tiny_delay():
    import posturelab as pl
    from posturelab.linear.delay_batch import batch_rightmost_root

    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    r0 = pl.rightmost_roots(body, muscles, 0.0, 4)
    r_tiny = pl.rightmost_roots(body, muscles, 1e-15, 4)
    np.testing.assert_allclose(r_tiny, r0, rtol=1e-9)
    k = np.array([[p.stiffness for p in muscles.pairs]] * 2)
    v = np.array([[p.viscosity for p in muscles.pairs]] * 2)
    b0 = batch_rightmost_root(body, muscles, k, v, delay=0.0)
    b_tiny = batch_rightmost_root(body, muscles, k, v, delay=1e-15)
    np.testing.assert_allclose(b_tiny, b0, rtol=1e-9)
    assert abs(b0[0] - r0[0]) <= 1e-9 * abs(r0[0])


def test_batch_with_mixed_sets_uses_the_poles_where_the_delay_is_negligible():
    """At τ = 1e-9 s a set with gains of 1e5 N·m/rad (rate scale above 1e3/s: τρ > 1e-6)
    takes the Chebyshev route while a soft set takes its τ = 0 poles; both agree with
    rightmost_roots one set at a time."""
    import posturelab as pl
    from posturelab.linear.delay import delayed_system, system_rightmost_roots
    from posturelab.linear.delay_batch import batch_rightmost_root
    from posturelab.model.controllers import get_controller

    body = pl.get_body("paper-1link")
    muscles = get_controller("peterka-2002").muscles(body)
    P = len(muscles.pairs)
    k = np.array([[900.0] * P, [1e5] * P])
    v = 0.25 * k
    batch = batch_rightmost_root(body, muscles, k, v, delay=1e-9)
    from dataclasses import replace

    from posturelab.model.muscles import MuscleSet

    for i in range(2):
        pairs = tuple(replace(p, stiffness=float(k[i, j]), viscosity=float(v[i, j]),
                              active_stiffness=None, active_viscosity=None)
                      for j, p in enumerate(muscles.pairs))
        one = MuscleSet(pairs, muscles.n_links)
        top = system_rightmost_roots(delayed_system(body, one), 1e-9, 1)[0]
        assert abs(batch[i] - top) <= 1e-6 * max(1.0, abs(top)), (i, batch[i], top)
