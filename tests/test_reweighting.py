"""Reweighting across conditions (posturelab.frequency.reweighting, fit-frf --compare): W per
condition against the stimulus amplitude, and a likelihood-ratio test of shared against
per-condition W that finds a difference that is there and not one that is not.

Synthetic experiments: the model's exact FRF at the 11 bands of the 80-state protocol plus
complex normal noise of a stated standard error per band (what a trial's estimate is, to
first order), each seeded; tables carry that standard error, so the fit's error model holds.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import posturelab as pl
from _cli import cli, one_line_exit_2
from posturelab.errors import ParameterError
from posturelab.frequency import FRFTable, estimate_frf, model_frf
from posturelab.frequency.bands import PETERKA_BAND_FREQUENCIES
from posturelab.frequency.reweighting import compare_conditions, stimulus_amplitude
from posturelab.model.controllers import get_controller
from posturelab.model.tilt import PRTSTilt

BODY = pl.get_body("paper-1link")
PRESET = get_controller("icm-pmc5664365")
TRUE = PRESET.muscles(BODY)
FREQ = np.asarray(PETERKA_BAND_FREQUENCIES)
SHARED = ["active_stiffness", "active_viscosity", "feedback_delay"]
#: Peak-to-peak tilts of the two conditions, 1° and 4° (Peterka 2002 used 0.5° … 8°). [rad]
AMPLITUDES = [np.radians(1.0), np.radians(4.0)]
START = {"feedback_delay": 0.1, "proprioceptive_weight": 0.7}


def synthetic(weight: float, rng, relative_se: float = 0.15, dof=None) -> FRFTable:
    """The model FRF with weight W at the bands plus complex noise of standard error
    relative_se·|H| per band (each part relative_se·|H|/√2)."""
    H = model_frf(BODY, TRUE, FREQ, feedback_delay=PRESET.feedback_delay,
                  proprioceptive_weight=weight)
    se = relative_se * np.abs(H)
    noise = se / np.sqrt(2) * (rng.normal(size=H.size) + 1j * rng.normal(size=H.size))
    return FRFTable(FREQ, H + noise, frf_se=se,
                    dof=None if dof is None else np.full(H.size, float(dof)))


def test_a_difference_in_w_is_found_and_an_absent_one_is_not_in_90_percent_of_40_repeats():
    """40 seeded two-condition experiments with W 0.8 at 1° and 0.65 at 4° (15 % noise per
    band): the test is significant (p < 0.05) in at least 90 % of them, and the estimates
    lie on the right sides; 40 with W 0.7 in both: not significant in at least 90 % (a
    test of level 0.05 is expected to pass 95 %)."""
    found = absent = 0
    for seed in range(40):
        rng = np.random.default_rng([20261202, seed])
        differ = compare_conditions(BODY, TRUE, [synthetic(0.8, rng), synthetic(0.65, rng)],
                                    SHARED, amplitudes=AMPLITUDES, **START)
        same = compare_conditions(BODY, TRUE, [synthetic(0.7, rng), synthetic(0.7, rng)],
                                  SHARED, amplitudes=AMPLITUDES, **START)
        assert differ.distribution == same.distribution == "chi2(1)"
        found += int(differ.p_value < 0.05 and differ.estimates[0] > differ.estimates[1])
        absent += int(same.p_value >= 0.05)
    assert found >= 36, found  # (measured 40)
    assert absent >= 36, absent  # (measured 39)


def prts_trial(amplitude: float, weight: float, rng, cycles: int = 4):
    """A PRTS trial's estimate: ``cycles`` 20 s cycles of the model's exact steady response
    to a tilt of ``amplitude`` peak to peak [rad] (through its FRF at every harmonic) plus
    white sensor noise of 0.002 rad, in the surface's sense."""
    L, T = 1000, 20.0
    x = PRTSTilt.named("posturelab-80", amplitude).angle(np.arange(L) * T / L)
    X = np.fft.rfft(x)
    H = np.zeros(X.size, complex)
    H[1:] = model_frf(BODY, TRUE, np.arange(1, X.size) / T,
                      feedback_delay=PRESET.feedback_delay, proprioceptive_weight=weight)
    y = np.tile(np.fft.irfft(H * X, L), cycles) + rng.normal(0.0, 0.002, cycles * L)
    return estimate_frf(np.tile(x, cycles), y, L / T, T)


def test_trials_with_estimated_variances_in_40_repeats():
    """40 seeded pairs of four-cycle trials at 1° and 4° peak to peak, whose variances are
    estimated from the cycles (so the F(1, ν) reference): W 0.8 and 0.6 is significant in at
    least 36 (measured 40), W 0.7 in both is not in at least 36 (measured 38); each
    condition's amplitude is measured from its trial."""
    found = absent = 0
    for seed in range(40):
        rng = np.random.default_rng([7, seed])
        same = compare_conditions(BODY, TRUE, [prts_trial(a, 0.7, rng) for a in AMPLITUDES],
                                  SHARED, **START)
        differ = compare_conditions(BODY, TRUE, [prts_trial(a, w, rng) for a, w in
                                                 zip(AMPLITUDES, (0.8, 0.6), strict=True)],
                                    SHARED, **START)
        assert same.distribution.startswith("F(1, ") and same.denominator_dof >= 20
        absent += int(same.p_value >= 0.05)
        found += int(differ.p_value < 0.05 and differ.estimates[0] > differ.estimates[1])
    np.testing.assert_allclose(differ.amplitudes, AMPLITUDES, rtol=0.02)
    assert found >= 36, found
    assert absent >= 36, absent


def test_the_statistic_is_the_difference_of_the_two_fits_objectives(rng):
    """ΔS = S_shared − S_per-condition ≥ 0, referred to χ²(1); the per-condition W are the
    general fit's, the shared W the restricted fit's, W#k named per condition."""
    from scipy.stats import chi2

    c = compare_conditions(BODY, TRUE, [synthetic(0.8, rng), synthetic(0.6, rng)], SHARED,
                           vision=["closed", "closed"], labels=["1 deg", "4 deg"], **START)
    assert c.general.names[-2:] == ("proprioceptive_weight#1", "proprioceptive_weight#2")
    assert "proprioceptive_weight" in c.restricted.names
    assert c.likelihood_ratio == pytest.approx(c.restricted.objective - c.general.objective)
    assert c.likelihood_ratio > 0 and c.df == 1
    assert c.p_value == pytest.approx(chi2.sf(c.likelihood_ratio, 1))
    np.testing.assert_array_equal(c.estimates, c.general.estimates[-2:])
    assert c.confidence_intervals[0, 0] < c.estimates[0] < c.confidence_intervals[0, 1]
    assert np.isnan(c.amplitudes).all()  # tables do not carry their stimulus
    out = c.to_dict()
    assert out["conditions"][0]["vision"] == "closed" and out["df"] == 1
    assert out["p_value"] == pytest.approx(c.p_value)


def test_estimated_variances_use_the_f_reference_and_no_precision_the_f_test(rng):
    """A table's dof ν gives F(1, ν); a table without standard errors the extra-sum-of-squares
    F test on the residual dof (2·11·2 − 5 = 39)."""
    c = compare_conditions(BODY, TRUE, [synthetic(0.8, rng, dof=40),
                                        synthetic(0.6, rng, dof=40)], SHARED, **START)
    assert c.distribution == "F(1, 40)" and c.p_value < 0.05
    bare = [FRFTable(FREQ, t.frf) for t in (synthetic(0.8, rng, 0.03),
                                            synthetic(0.6, rng, 0.03))]
    c = compare_conditions(BODY, TRUE, bare, SHARED, **START)
    assert c.general.weighting == "relative"
    assert c.distribution == "F(1, 39)" and c.p_value < 0.05


def test_a_trials_amplitude_is_its_peak_to_peak_stimulus():
    """From an estimate of a PRTS trial of 0.035 rad peak to peak: its cycle's range."""
    L, T = 1000, 20.0
    x = PRTSTilt.named("posturelab-80", 0.035).angle(np.arange(L) * T / L)
    X = np.fft.rfft(x)
    H = np.zeros(X.size, complex)
    H[1:] = model_frf(BODY, TRUE, np.arange(1, X.size) / T,
                      feedback_delay=PRESET.feedback_delay, proprioceptive_weight=0.8)
    est = estimate_frf(np.tile(x, 3), np.tile(np.fft.irfft(H * X, L), 3), L / T, T)
    assert stimulus_amplitude(est) == pytest.approx(np.ptp(x), rel=1e-9)
    assert stimulus_amplitude(est) == pytest.approx(0.035, rel=0.02)


@pytest.mark.parametrize("kwargs, needle", [
    ({"data": "one"}, "at least two conditions"),
    ({"vision": ["open", "shut"]}, "must be one of open, closed"),
    ({"amplitudes": [0.01]}, "one value per condition"),
    ({"amplitudes": [0.01, -1.0]}, "must be a number >= 0"),
    ({"parameter": "weight_of_nothing"}, "weight_of_nothing"),
    ({"free": "feedback_delay"}, "must be a list"),
])
def test_bad_comparisons_are_refused(rng, kwargs, needle):
    two = [synthetic(0.8, rng), synthetic(0.6, rng)]
    call = {"data": two, "free": SHARED, **kwargs}
    if call["data"] == "one":
        call["data"] = two[:1]
    with pytest.raises(ParameterError, match=needle):
        compare_conditions(BODY, TRUE, call.pop("data"), call.pop("free"), **call)


def _write_table(path, table: FRFTable) -> str:
    path.write_text(json.dumps({"frequency": table.frequency.tolist(),
                                "frf": [{"re": z.real, "im": z.imag} for z in table.frf],
                                "frf_se": table.frf_se.tolist()}))
    return str(path)


def test_fit_frf_compare_prints_the_test_and_writes_the_table_and_figure(tmp_path, rng):
    a = _write_table(tmp_path / "one_deg.json", synthetic(0.8, rng, 0.05))
    b = _write_table(tmp_path / "four_deg.json", synthetic(0.5, rng, 0.05))
    common = ["fit-frf", "--data", a, "--data", b, "--controller", "icm-pmc5664365",
              "--body", "paper-1link", "--free", ",".join(SHARED), "--feedback-delay", "0.1",
              "--proprioceptive-weight", "0.7"]
    p = cli(*common, "--compare", "proprioceptive_weight", "--amplitudes", "0.01745,0.0698",
            "--vision", "closed,closed", "--compare-out", str(tmp_path / "w.csv"),
            "--compare-plot", str(tmp_path / "w.png"), "--json")
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    rw = out["reweighting"]
    assert rw["p_value"] < 1e-3 and rw["distribution"] == "chi2(1)" and rw["significant"]
    assert [c["amplitude"] for c in rw["conditions"]] == [0.01745, 0.0698]
    assert rw["conditions"][0]["estimate"] > rw["conditions"][1]["estimate"]
    assert [q["name"] for q in out["parameters"]][-2:] == ["proprioceptive_weight#1",
                                                          "proprioceptive_weight#2"]
    rows = (tmp_path / "w.csv").read_text().splitlines()
    assert rows[0].startswith("condition,label,amplitude,vision,estimate") and len(rows) == 3
    assert (tmp_path / "w.png").read_bytes()[:4] == b"\x89PNG"
    p = cli(*common, "--compare", "proprioceptive_weight", "--compare-out",
            str(tmp_path / "w.json"))
    assert p.returncode == 0, p.stderr
    assert "likelihood-ratio test" in p.stdout and "p = " in p.stdout
    assert json.loads((tmp_path / "w.json").read_text())["df"] == 1
    one_line_exit_2(cli(*common, "--amplitudes", "0.01,0.02"), "--amplitudes needs --compare")
    one_line_exit_2(cli(*common, "--compare", "proprioceptive_weight", "--vision", "open"),
                    "--vision gives 1 label(s) for 2 --data")


def test_the_reweighting_figure_has_its_units_and_intervals(rng):
    from posturelab.viz.plots import plot_reweighting

    c = compare_conditions(BODY, TRUE, [synthetic(0.8, rng), synthetic(0.6, rng),
                                        synthetic(0.5, rng)], SHARED,
                           amplitudes=[np.radians(a) for a in (1.0, 2.0, 4.0)],
                           vision=["closed", "closed", "open"], **START)
    fig = plot_reweighting(c)
    ax = fig.axes[0]
    assert ax.get_xlabel() == "stimulus amplitude, peak to peak [deg]"
    assert ax.get_ylabel() == "proprioceptive_weight [-]"
    assert "p = " in ax.get_title() and "chi2(2)" in ax.get_title()
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert sorted(labels) == ["eyes closed", "eyes open", "shared (one value for all)"]


def test_the_fit_hooks_objective_and_a_fixed_model_error(rng):
    """FRFFit.objective is Σ u², the fit error's χ² for known standard errors (no mismatch);
    a model error given is used as given (0: the fit unchanged)."""
    from posturelab.frequency.fit import fit_frf

    data = synthetic(0.7, rng)
    free = [*SHARED, "proprioceptive_weight"]
    plain = fit_frf(BODY, TRUE, data, free, **START)
    assert not plain.mismatch and plain.noise_dof == np.inf
    assert plain.residual_dof == 2 * FREQ.size - len(free)
    assert plain.objective == pytest.approx(plain.fit_error ** 2 * plain.residual_dof)
    fixed = fit_frf(BODY, TRUE, data, free, model_error=0.0, **START)
    np.testing.assert_array_equal(fixed.estimates, plain.estimates)
    wider = fit_frf(BODY, TRUE, data, free, model_error=0.2, **START)
    assert wider.model_error == 0.2 and wider.objective < plain.objective
    assert np.all(wider.standard_errors > plain.standard_errors)


def test_a_model_mismatch_is_carried_into_the_restricted_fit(rng):
    """Data the model cannot follow (a gain ripple of ±10 % across the bands, 1 % noise): the
    general fit allows a model error δ, and the restricted fit is made with the same δ."""
    ripple = 1.0 + 0.1 * np.sin(2 * np.pi * np.log2(FREQ))
    data = []
    for w in (0.7, 0.7):
        t = synthetic(w, rng, 0.01)
        data.append(FRFTable(FREQ, t.frf * ripple, frf_se=t.frf_se))
    c = compare_conditions(BODY, TRUE, data, SHARED, **START)
    assert c.general.mismatch and c.general.model_error > 0.01
    assert c.restricted.model_error == c.general.model_error
    assert 0.0 <= c.likelihood_ratio < 10.0  # (measured 0.05: p 0.82; the W are equal)
