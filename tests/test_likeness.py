"""The human-likeness distance (posturelab.frequency.likeness), COMTEST's reference shipped as
the preset ``comtest-eyes-closed``, and the likeness commands."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from _cli import cli, one_line_exit_2
from posturelab.errors import ParameterError, UnknownNameError
from posturelab.frequency.likeness import (
    LIKENESS_PRESETS,
    LikenessReference,
    build_likeness_reference,
    likeness,
    likeness_reference,
    likeness_score,
    read_prtsinfo,
)

#: Numbers of COMTEST's reference as printed in github.com/VittorioFreiburg/COMTEST,
#: ANALYSIS/OCTAVE/src/PRTSinfo.m, commit 541da313ba9cfe8de18758f4fcc0c9a261c2d67f
#: (GPL-3.0-or-later): (array, 0-based index as posturelab stores it, value). Sv are the
#: weights, m(1:11) the mean's real parts and m(12:22) its imaginary parts, invSigma Σ⁻¹.
#: Printed to 15 significant digits: tolerance 1e-14 relative.
PRTSINFO_PRINTED = [
    ("Sv", 0, 1.0),
    ("Sv", 1, 0.331373521580086),
    ("Sv", 10, 0.0329904440826550),
    ("m", 0, 2.88966411490562),
    ("m", 10, -0.168961443385927),
    ("m", 11, 1.26308497331590),
    ("m", 21, 0.148596044633691),
    ("invSigma", (0, 0), 1.65555146433233),
    ("invSigma", (0, 1), -0.0743859528674930),
    ("invSigma", (6, 12), -9.37386189298894e-05),
    ("invSigma", (10, 10), 41.3430416535730),
    ("invSigma", (21, 21), 26.4532141380107),
    ("invSigma", (21, 0), 0.202795489299636),
]


def _value(ref: LikenessReference, array: str, index):
    if array == "Sv":
        return ref.weights[index]
    if array == "m":
        B = ref.mean.size
        return ref.mean.real[index] if index < B else ref.mean.imag[index - B]
    return ref.inverse_covariance[index]


@pytest.mark.parametrize("array, index, printed", PRTSINFO_PRINTED)
def test_the_preset_holds_comtests_printed_numbers(array, index, printed):
    ref = likeness_reference("comtest-eyes-closed")
    assert math.isclose(_value(ref, array, index), printed, rel_tol=1e-14)


def test_the_preset_is_comtests_reference_over_the_80_state_bands():
    from posturelab.frequency.bands import PETERKA_BAND_FREQUENCIES

    ref = likeness_reference("comtest-eyes-closed")
    assert ref.mean.size == 11 and ref.inverse_covariance.shape == (22, 22)
    np.testing.assert_allclose(ref.frequency, PETERKA_BAND_FREQUENCIES)
    np.testing.assert_array_equal(ref.inverse_covariance, ref.inverse_covariance.T)
    assert np.linalg.eigvalsh(ref.inverse_covariance).min() > 0
    assert "541da313ba9cfe8de18758f4fcc0c9a261c2d67f" in ref.source
    assert "GPL" in ref.source
    # following the surface reads a phase near 0 at the lowest band (the sign convention)
    assert abs(np.degrees(np.angle(ref.mean[0]))) < 45


def test_the_score_of_the_reference_mean_is_zero():
    ref = likeness_reference("comtest-eyes-closed")
    assert likeness_score(ref.mean, ref) == 0.0
    assert likeness_score(ref.mean / 2.0, ref, scale=2.0) == pytest.approx(0.0, abs=1e-12)


def test_a_hand_computation():
    """Two bands: m = [1 + i, 0.5 − 0.5i], s = [2, 0.5], Σ⁻¹ with one off-diagonal pair.
    H = m + [0.1 + 0.2i, −0.3]: d = [0.1, −0.3, 0.2, 0], S d = [0.2, −0.15, 0.4, 0];
    D² = 2(0.2²) + 2·0.5(0.2)(−0.15) + 1(0.15²) + 1(0.4²) + 3·0 = 0.08 − 0.03 + 0.0225
    + 0.16 = 0.2325."""
    inv = np.array([[2.0, 0.5, 0, 0], [0.5, 1.0, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 3.0]])
    ref = LikenessReference("hand", np.array([0.05, 0.15]), np.array([1 + 1j, 0.5 - 0.5j]),
                            inv, np.array([2.0, 0.5]))
    H = ref.mean + np.array([0.1 + 0.2j, -0.3])
    result = likeness(H, ref)
    assert result.score == pytest.approx(math.sqrt(0.2325), rel=1e-12)
    np.testing.assert_allclose(result.difference, [0.1 + 0.2j, -0.3], atol=1e-15)
    assert likeness_score(H / 4, ref, scale=4.0) == pytest.approx(math.sqrt(0.2325))


def test_an_unknown_preset_lists_the_known_ones():
    with pytest.raises(UnknownNameError, match="known presets: comtest-eyes-closed"):
        likeness_reference("comtest-eyes-open")


def test_the_command_line_knows_the_presets():
    from posturelab.cli.likeness import PRESET_NAMES

    assert tuple(LIKENESS_PRESETS) == PRESET_NAMES


def test_an_frf_over_other_bands_is_refused():
    ref = likeness_reference("comtest-eyes-closed")
    with pytest.raises(ParameterError, match="11 finite values"):
        likeness(np.ones(10), ref)


def test_a_cohorts_reference_has_the_mahalanobis_identity(rng):
    """With weights 1, the squared distances of the cohort's own members to its reference sum
    to (N − 1)·2B exactly (Σ (x − x̄)ᵀ Σ̂⁻¹ (x − x̄) = (N − 1) tr I), and its mean scores 0."""
    B, N = 3, 12
    h = np.array([1.0 + 0.2j, 0.5 - 0.5j, -0.1 - 0.4j])
    cohort = h + 0.2 * (rng.normal(size=(N, B)) + 1j * rng.normal(size=(N, B)))
    ref = build_likeness_reference(list(cohort))
    total = sum(likeness_score(z, ref) ** 2 for z in cohort)
    assert total == pytest.approx((N - 1) * 2 * B, rel=1e-9)
    assert likeness_score(ref.mean, ref) == 0.0
    assert ref.subjects == N and ref.shrinkage == 0.0


def test_too_few_subjects_are_refused_or_shrunk(rng):
    cohort = list(rng.normal(size=(6, 11)) + 1j * rng.normal(size=(6, 11)))
    with pytest.raises(ParameterError, match="give at least 23, or a shrinkage"):
        build_likeness_reference(cohort)
    ref = build_likeness_reference(cohort, shrinkage=0.3)
    assert ref.shrinkage == 0.3 and np.linalg.eigvalsh(ref.inverse_covariance).min() > 0


def test_prtsinfo_is_read_from_ones_own_copy(tmp_path):
    text = ("% a cut-down PRTSinfo.m\nSv=[1,0.5];\nS=diag([Sv,Sv]);\n"
            "m=[2.0,1.0,0.5,-0.25];\ninvSigma=[1,0,0,0;0,2,0,0;0,0,3,0;0,0,0,4];\n")
    (tmp_path / "PRTSinfo.m").write_text(text)
    ref = read_prtsinfo(tmp_path / "PRTSinfo.m")
    np.testing.assert_array_equal(ref.mean, [2.0 + 0.5j, 1.0 - 0.25j])
    np.testing.assert_array_equal(ref.weights, [1.0, 0.5])
    np.testing.assert_array_equal(np.diag(ref.inverse_covariance), [1, 2, 3, 4])


def _write_frf(path, h, f):
    path.write_text(json.dumps({"frequency": list(f),
                                "frf": [{"re": z.real, "im": z.imag} for z in h]}))


def test_the_likeness_commands(tmp_path, rng):
    ref = likeness_reference("comtest-eyes-closed")
    files = []
    for i in range(25):
        path = tmp_path / f"s{i}.json"
        _write_frf(path, ref.mean + 0.3 * (rng.normal(size=11) + 1j * rng.normal(size=11)),
                   ref.frequency)
        files.append(str(path))
    p = cli("likeness", "--data", files[0], "--reference", "comtest-eyes-closed", "--json")
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert out["score"] > 0 and out["reference"] == "comtest-eyes-closed"
    assert "GPL" in out["source"] and len(out["difference"]) == 11
    out_path = tmp_path / "ref.json"
    p = cli("likeness-reference", "--data", *files, "--out", str(out_path))
    assert p.returncode == 0, p.stderr
    mean = tmp_path / "mean.json"
    _write_frf(mean, build_likeness_reference(
        [json_frf(f) for f in files]).mean, ref.frequency)
    p = cli("likeness", "--data", str(mean), "--reference", str(out_path), "--json")
    assert p.returncode == 0, p.stderr
    assert json.loads(p.stdout)["score"] == pytest.approx(0.0, abs=1e-6)
    one_line_exit_2(cli("likeness", "--data", files[0], "--reference", "nope"),
                    "known presets: comtest-eyes-closed")
    one_line_exit_2(cli("likeness-reference", "--data", *files[:5], "--out",
                        str(tmp_path / "r2.json")), "give at least 23")


def json_frf(path):
    obj = json.loads(open(path).read())
    return np.array([z["re"] + 1j * z["im"] for z in obj["frf"]])


def test_a_negative_or_zero_scale_is_refused_in_one_line():
    """The scale is a peak-to-peak amplitude: a negative one would flip the FRF's sign
    silently (the sign belongs to the response sign)."""
    from posturelab.frequency.likeness import likeness, likeness_reference

    ref = likeness_reference("comtest-eyes-closed")
    frf = np.asarray(ref.mean)
    assert likeness(frf, ref, scale=1.0).score == pytest.approx(0.0, abs=1e-9)
    for bad in (-1.0, 0.0):
        with pytest.raises(ParameterError, match="scale"):
            likeness(frf, ref, scale=bad)
