"""Anthropometric scaling (Winter 2009 Table 4.1) and lumping links."""

import numpy as np
import pytest

import posturelab as pl
from posturelab.model.anthropometry import WINTER_TABLE, body_from_anthropometry, lump
from posturelab.model.muscles import MusclePair, MuscleSet
from posturelab.simulation import KneeModel, simulate


def test_winter_body_mass_and_lengths():
    """Winter Table 4.1: 2 legs + 2 thighs + HAT = 0.971 M; lengths 0.246/0.245/0.288 H."""
    b = body_from_anthropometry(1.80, 80.0)
    assert b.total_mass == pytest.approx(0.971 * 80.0)
    np.testing.assert_allclose(b.lengths, np.array([0.246, 0.245, 0.288]) * 1.80)
    assert b.masses[0] == pytest.approx(2 * 0.0465 * 80.0)
    assert b.com_distances[2] == pytest.approx(0.626 * 0.288 * 1.80)


def test_centre_of_mass_height_is_physiological():
    """Sanity bound: the chain's CoM is 0.55–0.62 H above the floor (ankle height 0.039 H).

    Measured whole-body values are 0.55–0.57 H; Dempster's leg/thigh/HAT without the feet
    gives 0.60 H. Putting a CoM at the wrong end of its segment moves it out of this band.
    """
    h = 1.75
    b = body_from_anthropometry(h, 70.0)
    assert 0.55 * h < b.com_height + 0.039 * h < 0.62 * h


def test_scaling_laws():
    """Mass scales a_i and J linearly; height scales a_i ∝ H and J ∝ H²."""
    b1 = body_from_anthropometry(1.6, 60.0)
    b2 = body_from_anthropometry(3.2 / 2 * 1.25, 120.0)
    ratio_h = b2.lengths[0] / b1.lengths[0]
    np.testing.assert_allclose(b2.gravity_coefficients / b1.gravity_coefficients, 2.0 * ratio_h)
    np.testing.assert_allclose(b2.inertia_diagonal / b1.inertia_diagonal, 2.0 * ratio_h**2)


def test_bad_anthropometry():
    with pytest.raises(pl.ParameterError, match="height"):
        body_from_anthropometry(0.1, 70)
    with pytest.raises(pl.ParameterError, match="mass"):
        body_from_anthropometry(1.7, float("nan"))
    with pytest.raises(pl.UnknownNameError, match="winter"):
        body_from_anthropometry(1.7, 70, table="nasa")


def test_lump_equals_locked_knee_simulation():
    """A lumped leg+thigh link behaves exactly like the three-link body with the knee locked."""
    body = pl.paper_body()
    two = lump(body, [[1, 2], [3]])
    three_m = MuscleSet((MusclePair("ankle", 0, 1, 900, 200), MusclePair("hip", 2, 3, 300, 60)), 3)
    two_m = MuscleSet((MusclePair("ankle", 0, 1, 900, 200), MusclePair("hip", 1, 2, 300, 60)), 2)
    a = simulate(body, three_m, None, 1.5, initial_state=[0.04, 0.04, -0.03, 0.2, 0.2, 0],
                 knee=KneeModel("locked"), sample_rate=100, rtol=1e-10, atol=1e-12)
    b = simulate(two, two_m, None, 1.5, initial_state=[0.04, -0.03, 0.2, 0], sample_rate=100,
                 rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(a.theta[:, [0, 2]], b.theta, atol=1e-8)


def test_one_link_lump_is_the_inverted_pendulum():
    """paper-1link: J = I_total about the ankle, a = m h; poles from (J s² + L s + K − mgh) = 0."""
    b = pl.get_body("paper-1link")
    paper = pl.paper_body()
    assert b.total_mass == pytest.approx(paper.total_mass)
    assert b.gravity_coefficients[0] == pytest.approx(paper.gravity_coefficients.sum())
    stiffness, viscosity = 1000.0, 250.0
    res = pl.analyse(b, MuscleSet((MusclePair("ankle", 0, 1, stiffness, viscosity),), 1))
    j = b.inertia_diagonal[0]
    roots = np.roots([j, viscosity, stiffness - b.load_stiffness])
    np.testing.assert_allclose(np.sort_complex(res.poles), np.sort_complex(roots), rtol=1e-10)


def test_lump_rejects_bad_groups():
    with pytest.raises(pl.ParameterError, match="consecutive"):
        lump(pl.paper_body(), [[1, 3], [2]])


def test_presets_listed_with_citations():
    for name in ("paper", "paper-1link", "paper-2link", "winter-1.75m-75kg"):
        assert pl.BODY_PRESETS[name].citation
        assert pl.get_body(name).n_links in (1, 2, 3)
    assert set(WINTER_TABLE) == {"leg", "thigh", "torso"}
