"""The report's finding beyond the ankle: issue 22's targets, stated in its words.

Targets (issue 22): on the paper's body with multijoint-default the hip fraction stays below
0.15 for the slowest backward translations and rises above 0.4 for the fastest recovered; under
a 5 cm sinusoid below 0.15 at 0.1 Hz and above 0.4 at 1.25 Hz; the step thresholds within two
published SD of Koushyar et al. 2019 (PMC6338353, abstract: 16.2 ± 2.6 cm young, 11.8 ± 2.1 cm
older), older below young.
"""

from __future__ import annotations

import math

import pytest

from posturelab.model.body import get_body
from posturelab.paper.beyond_ankle import beyond_ankle_finding

#: Koushyar et al. 2019, abstract, backward; printed to 0.1 cm. [m]
KOUSHYAR = {"young": (0.162, 0.026), "older": (0.118, 0.021)}


@pytest.fixture(scope="module")
def finding():
    return beyond_ankle_finding(get_body("paper"))


def test_the_hip_strategy_emerges_with_speed_and_frequency(finding):
    fractions = finding.translation_hip_fractions
    assert fractions[0] < 0.15
    recovered = [f for f in fractions if math.isfinite(f)]
    assert recovered[-1] > 0.4
    waves = dict(zip(finding.frequencies, finding.oscillation_hip_fractions, strict=True))
    assert waves[0.1] < 0.15 and waves[1.25] > 0.4
    assert finding.transition_frequency is not None and 0.1 < finding.transition_frequency <= 1.25


def test_the_step_thresholds_are_within_two_published_sd(finding):
    models = {name: model for name, model, _, _ in finding.thresholds}
    for name, model, mean, sd in finding.thresholds:
        assert (mean, sd) == pytest.approx(KOUSHYAR[name], abs=5e-4)
        assert abs(model - mean) <= 2 * sd
    assert models["older"] < models["young"]


def test_the_words_carry_the_numbers(finding):
    text = finding.text
    for name, model, mean, sd in finding.thresholds:
        assert f"{name} {model * 100:.1f} cm against {mean * 100:.1f} ± {sd * 100:.1f} cm" in text
    assert f"{finding.translation_hip_fractions[0]:.2f} at 0.05 m/s" in text
    assert "PMC6338353" in text and "multijoint-default" in text
