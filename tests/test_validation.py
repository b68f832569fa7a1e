"""Bad input raises ParameterError / UnknownNameError naming the field, the value and
the allowed range (docs/design.md, quality bar)."""

import math
import re

import numpy as np
import pytest

from posturelab.errors import ParameterError, PostureLabError, UnknownNameError
from posturelab.linear import analyse, disturbance_sensitivity, state_matrix
from posturelab.model.body import BODY_PRESETS, Body, Segment, get_body, paper_body
from posturelab.model.muscles import (
    PAPER_PAIR_NAMES,
    STIFFNESS_CASES,
    MusclePair,
    MuscleSet,
    get_stiffness_case,
    paper_muscles,
)

GOOD = {
    "masses": [5.0, 20.0, 40.0],
    "lengths": [0.4, 0.4, 0.6],
    "com_distances": [0.2, 0.25, 0.25],
    "inertias": [0.2, 0.5, 2.0],
}
# Body.from_arrays argument -> the Segment field named in the message
FIELD = {"masses": "mass", "lengths": "length", "com_distances": "com_distance",
         "inertias": "inertia"}


def body_with(field, value, link=1):
    arrays = {k: list(v) for k, v in GOOD.items()}
    arrays[field][link] = value
    return Body.from_arrays(**arrays)


def raises_naming(exc_type, *fragments):
    """pytest.raises whose message must contain every fragment (plain text, case-sensitive)."""
    pattern = "".join(f"(?=.*{re.escape(f)})" for f in fragments)
    return pytest.raises(exc_type, match=re.compile(pattern, re.S))


def test_errors_are_value_and_key_errors():
    """ParameterError is a ValueError, UnknownNameError a KeyError, both PostureLabErrors."""
    assert issubclass(ParameterError, ValueError) and issubclass(ParameterError, PostureLabError)
    assert issubclass(UnknownNameError, KeyError) and issubclass(UnknownNameError, PostureLabError)
    # a KeyError subclass must not quote its message
    assert str(UnknownNameError("unknown x")) == "unknown x"


# ---------------------------------------------------------------------------
# Bodies
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("field", ["masses", "lengths", "inertias"])
@pytest.mark.parametrize("value", [-1.5, 0.0])
def test_nonpositive_mass_length_inertia(field, value):
    """Mass, length and inertia must be > 0; the message names link, field, range and value."""
    with raises_naming(ParameterError, "link2", FIELD[field], "> 0", f"got {value!r}"):
        body_with(field, value)


@pytest.mark.parametrize("value", [-0.01, 0.41, 5.0])
def test_com_distance_outside_link(value):
    """com_distance must lie in [0, length]; the message gives the length and the value."""
    with raises_naming(ParameterError, "link2", "com_distance", "[0, length=0.4]",
                       f"got {value!r}"):
        body_with("com_distances", value)


@pytest.mark.parametrize("value", [0.0, 0.4])
def test_com_distance_at_the_ends_is_allowed(value):
    """The closed interval: COM at either joint is accepted."""
    assert body_with("com_distances", value).com_distances[1] == value


@pytest.mark.parametrize("field", list(GOOD))
@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf],
                         ids=["nan", "inf", "-inf"])
def test_non_finite_body_fields(field, value):
    """NaN and ±inf are rejected in every field, named with the value."""
    with raises_naming(ParameterError, "link2", FIELD[field], "finite", f"got {value!r}"):
        body_with(field, value)


def test_non_numeric_body_field():
    with raises_naming(ParameterError, "mass", "'heavy'"):
        body_with("masses", "heavy")


def test_arrays_of_unequal_length():
    """Every per-link array needs one entry per link."""
    with raises_naming(ParameterError, "inertias", "3 entries", "got 2"):
        Body.from_arrays(GOOD["masses"], GOOD["lengths"], GOOD["com_distances"], [0.2, 0.5])


def test_empty_body():
    with raises_naming(ParameterError, "at least 1 link", "got 0"):
        Body.from_arrays([], [], [], [])


@pytest.mark.parametrize("value", [0.0, -9.81, math.nan, math.inf])
def test_bad_gravity(value):
    with raises_naming(ParameterError, "gravity", f"got {value!r}"):
        paper_body(gravity=value)


def test_segment_direct():
    """Segment validates on its own, too."""
    with raises_naming(ParameterError, "'shank'", "mass", "got -3.0"):
        Segment("shank", -3.0, 0.4, 0.2, 0.1)


def test_unknown_body_preset_lists_known_names():
    with raises_naming(UnknownNameError, "'astronaut'", *sorted(BODY_PRESETS)) as info:
        get_body("astronaut")
    assert "paper" in str(info.value)
    assert get_body("paper").n_links == 3


# ---------------------------------------------------------------------------
# Muscles
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("values", [[500, 300, 300], [1, 2, 3, 4, 5, 6], []],
                         ids=["three", "six", "none"])
def test_stiffness_list_of_wrong_length(values):
    """Five stiffness values (one per paper pair); the message names the pairs."""
    with raises_naming(ParameterError, "stiffness", "5 values", f"got {len(values)}",
                       *PAPER_PAIR_NAMES):
        paper_muscles(stiffness=values)


def test_negative_stiffness_in_list():
    with raises_naming(ParameterError, "stiffness", ">= 0", "-300"):
        paper_muscles(stiffness=[500, 300, -300, 300, 300])


@pytest.mark.parametrize("value", [math.nan, math.inf], ids=["nan", "inf"])
def test_non_finite_stiffness_in_list(value):
    with raises_naming(ParameterError, "stiffness", "finite", repr(value)):
        paper_muscles(stiffness=[500, 300, value, 300, 300])


def test_negative_stiffness_by_name():
    with raises_naming(ParameterError, "'hip'", "stiffness", "[0, 1e+08]", "got -1.0"):
        paper_muscles(stiffness={"ankle": 500.0, "hip": -1.0})
    with raises_naming(ParameterError, "'knee'", "stiffness", "[0, 1e+08]", "got -2.0"):
        paper_muscles("1").with_stiffness(knee=-2.0)


def test_negative_or_non_finite_pair_fields():
    with raises_naming(ParameterError, "'soleus'", "stiffness", "[0, 1e+08]", "got -1.0"):
        MusclePair("soleus", 0, 1, -1.0, 1.0)
    with raises_naming(ParameterError, "'soleus'", "viscosity", "[0, 1e+07]", "got -0.5"):
        MusclePair("soleus", 0, 1, 1.0, -0.5)
    with raises_naming(ParameterError, "'soleus'", "viscosity", "finite", "nan"):
        MusclePair("soleus", 0, 1, 1.0, math.nan)


def test_bad_viscosity_ratio_and_list():
    with raises_naming(ParameterError, "viscosity_ratio", "[0, 10]", "got -0.25"):
        paper_muscles("1", viscosity_ratio=-0.25)
    with raises_naming(ParameterError, "viscosity", "5 values", "got 2"):
        paper_muscles("1", viscosity=[1.0, 2.0])


def test_case_and_stiffness_exclusive():
    with raises_naming(ParameterError, "exactly one"):
        paper_muscles()
    with raises_naming(ParameterError, "exactly one"):
        paper_muscles("1", stiffness=[1, 2, 3, 4, 5])


@pytest.mark.parametrize("case", ["8", "6c", "case 0", ""])
def test_unknown_table_i_case_lists_known_cases(case):
    with raises_naming(UnknownNameError, repr(case), "Table I", *STIFFNESS_CASES):
        get_stiffness_case(case)
    with raises_naming(UnknownNameError, repr(case), *STIFFNESS_CASES):
        paper_muscles(case)


@pytest.mark.parametrize("spelling", ["6A", "case 6a", " 6a "])
def test_table_i_case_spellings(spelling):
    """Case names are forgiving about case, spaces and a 'case' prefix."""
    assert get_stiffness_case(spelling) == (0.0, 0.0, 600.0, 300.0, 1000.0)


def test_unknown_pair_name_lists_known_pairs():
    muscles = paper_muscles("1")
    with raises_naming(UnknownNameError, "'soleus'", *PAPER_PAIR_NAMES):
        muscles.with_stiffness(soleus=100.0)
    with raises_naming(UnknownNameError, "'soleus'", *PAPER_PAIR_NAMES):
        paper_muscles(stiffness={"soleus": 100.0})


@pytest.mark.parametrize("lo,hi", [(1, 1), (2, 1), (-1, 1), (3, 0)])
def test_muscle_pair_needs_lo_below_hi(lo, hi):
    with raises_naming(ParameterError, "'x'", "0 <= lo < hi", f"({lo}, {hi})"):
        MusclePair("x", lo, hi, 100.0, 25.0)


def test_muscle_pair_indices_must_be_integers():
    with raises_naming(ParameterError, "'x'", "integers", "1.5"):
        MusclePair("x", 0, 1.5, 100.0, 25.0)


def test_muscle_pair_beyond_the_body():
    """A pair spanning link 4 on a three-link body names the pair, the link and the range."""
    with raises_naming(ParameterError, "'neck'", "link 4", "3 links", "1..3"):
        MuscleSet((MusclePair("neck", 2, 4, 100.0, 25.0),), 3)


def test_muscle_set_for_another_body():
    muscles = MuscleSet((MusclePair("ankle", 0, 1, 100.0, 25.0),), 2)
    with raises_naming(ParameterError, "2 links", "3"):
        analyse(paper_body(), muscles)
    with raises_naming(ParameterError, "2 links", "3"):
        state_matrix(paper_body(), muscles)


def test_duplicate_pair_names_and_bad_n_links():
    pair = MusclePair("ankle", 0, 1, 100.0, 25.0)
    with raises_naming(ParameterError, "unique", "ankle"):
        MuscleSet((pair, pair), 1)
    with raises_naming(ParameterError, "n_links", ">= 1", "got 0"):
        MuscleSet((), 0)


def test_bad_gastrocnemius_and_one_sided_options():
    with raises_naming(ParameterError, "gastrocnemius", "two-sided", "one-sided", "'both'"):
        paper_muscles("1", gastrocnemius="both")
    with raises_naming(ParameterError, "one_sided", "active", "inactive", "'maybe'"):
        analyse(paper_body(), paper_muscles("1"), one_sided="maybe")


# ---------------------------------------------------------------------------
# Linear analysis
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("posture", [[0.1, -0.1], [0.1, -0.1, 0.1, 0.0], [[0.1, 0.1, 0.1]]],
                         ids=["two", "four", "2d"])
def test_sensitivity_posture_of_wrong_shape(posture):
    with raises_naming(ParameterError, "posture", "(3)", str(np.shape(posture))):
        disturbance_sensitivity(paper_body(), posture)


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf], ids=["nan", "inf", "-inf"])
def test_sensitivity_posture_not_finite(value):
    with raises_naming(ParameterError, "posture", "finite", str(value)):
        disturbance_sensitivity(paper_body(), [0.1, value, 0.1])


def test_sensitivity_posture_not_numeric():
    with raises_naming(ParameterError, "posture", "numeric"):
        disturbance_sensitivity(paper_body(), ["a", "b", "c"])


def test_scalar_instead_of_array():
    with raises_naming(ParameterError, "masses"):
        Body.from_arrays(70.0, [1.0], [0.5], [10.0])
