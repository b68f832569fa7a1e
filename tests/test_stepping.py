"""Stepping: the extrapolated centre of mass (Hof, Gazendam & Sinke 2005, J Biomech 38:1–8),
the margin of stability, the step-threshold study and its command.

The XCoM is checked on the linear inverted pendulum's closed form; the thresholds against
the published figures of Koushyar et al. 2019 (PLoS ONE 14:e0210049, PMC6338353), typed in
here from its abstract; the population numbers against their sources, typed in here too.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from _cli import cli, one_line_exit_2
from posturelab.errors import ParameterError, UnknownNameError
from posturelab.model.stepping import (
    ankle_moment_cap,
    margin_of_stability,
    pendulum_frequency,
    platform_path_offset,
    xcom,
)
from posturelab.studies.stepping import (
    POPULATIONS,
    PUBLISHED,
    get_population,
    step_threshold,
    step_verdict,
)

# ---- the XCoM on the linear inverted pendulum ---------------------------------------------

#: l = 0.981 m and g = 9.81 m/s² give ω0 = √10 1/s exactly.
LENGTH, GRAVITY = 0.981, 9.81
OMEGA0 = math.sqrt(10.0)
#: Initial conditions: 1 cm in front of the ankle, moving forward at 5 cm/s. [m], [m/s]
X0, V0 = 0.01, 0.05
#: By hand: ξ0 = 0.01 + 0.05/√10 = 0.01 + 0.0158114 = 0.0258114 m.
XI0_BY_HAND = 0.0258114
#: A toe 0.19 m in front of the ankle: b0 = 0.19 − 0.0258114 = 0.1641886 m, and with the
#: centre of pressure held at the ankle ξ = ξ0 e^{ω0 t} reaches the toe at
#: t* = ln(0.19/0.0258114)/√10 = ln(7.361065)/3.1622777 = 1.996206/3.1622777 = 0.631262 s.
TOE, HEEL = 0.19, -0.06
B0_BY_HAND = 0.1641886
T_STAR_BY_HAND = 0.631262


def lip_state(t):
    """x(t), v(t) of ẍ = ω0² x (centre of pressure at the ankle): the closed form."""
    c = X0 + V0 / OMEGA0
    d = X0 - V0 / OMEGA0
    x = 0.5 * (c * np.exp(OMEGA0 * t) + d * np.exp(-OMEGA0 * t))
    v = 0.5 * OMEGA0 * (c * np.exp(OMEGA0 * t) - d * np.exp(-OMEGA0 * t))
    return x, v


def test_pendulum_frequency_is_sqrt_g_over_l():
    assert float(pendulum_frequency(LENGTH, GRAVITY)) == pytest.approx(OMEGA0, rel=1e-12)


def test_xcom_of_the_initial_state_by_hand():
    assert float(xcom(X0, V0, OMEGA0)) == pytest.approx(XI0_BY_HAND, abs=1e-7)
    xi = xcom(X0, V0, OMEGA0)
    assert float(margin_of_stability(xi, HEEL, TOE, side="toe")) == pytest.approx(
        B0_BY_HAND, abs=1e-7)
    # the nearer edge is the heel: 0.0258114 + 0.06 = 0.0858114 m
    assert float(margin_of_stability(xi, HEEL, TOE)) == pytest.approx(0.0858114, abs=1e-7)
    assert float(margin_of_stability(xi, HEEL, TOE, side="heel")) == pytest.approx(
        0.0858114, abs=1e-7)


def test_xcom_of_the_pendulum_grows_as_a_pure_exponential():
    """ξ = x + v/ω0 of the closed-form trajectory is ξ0 e^{ω0 t}: the XCoM carries the
    unstable mode alone (Hof et al. 2005, eq. 7 with p = 0)."""
    t = np.linspace(0.0, 1.0, 101)
    x, v = lip_state(t)
    assert np.allclose(xcom(x, v, OMEGA0), XI0_BY_HAND * np.exp(OMEGA0 * t), atol=1e-7)


def test_the_xcom_reaches_the_toe_when_computed_by_hand_and_before_the_com_does():
    t = np.linspace(0.0, 1.0, 100_001)
    x, v = lip_state(t)
    b = margin_of_stability(xcom(x, v, OMEGA0), HEEL, TOE)
    crossing = t[np.argmax(b < 0.0)]
    assert crossing == pytest.approx(T_STAR_BY_HAND, abs=2e-5)
    assert t[np.argmax(x > TOE)] > crossing + 0.1  # the CoM itself is still over the foot


def test_margin_of_stability_behind_the_heel_and_its_checks():
    assert float(margin_of_stability(-0.08, HEEL, TOE)) == pytest.approx(-0.02)
    assert np.allclose(margin_of_stability([0.0, 0.2], HEEL, TOE), [0.06, -0.01])
    with pytest.raises(ParameterError, match="heel"):
        margin_of_stability(0.0, 0.1, 0.05)
    with pytest.raises(ParameterError, match="side"):
        margin_of_stability(0.0, HEEL, TOE, side="left")
    with pytest.raises(ParameterError, match="com_height"):
        pendulum_frequency(-1.0)


def test_ankle_moment_cap_is_the_smaller_of_strength_and_weight_times_toe():
    assert ankle_moment_cap(300.0, 700.0, 0.2) == pytest.approx(140.0)
    assert ankle_moment_cap(90.0, 700.0, 0.2) == pytest.approx(90.0)
    with pytest.raises(ParameterError, match="strength"):
        ankle_moment_cap(-1.0, 700.0, 0.2)


def test_step_verdict_names_the_side_and_the_time():
    v = step_verdict([0.0, 0.1, 0.2], [0.0, -0.05, -0.07], HEEL, TOE)
    assert v.needs_step and "behind the heel" in v.reason and v.time == pytest.approx(0.2)
    assert v.minimum_margin == pytest.approx(-0.01)
    ok = step_verdict([0.0, 0.1], [0.0, 0.1], HEEL, TOE)
    assert not ok.needs_step and ok.reason == "" and ok.time is None
    fell = step_verdict([0.0, 0.1], [0.0, 0.1], HEEL, TOE, fell=True, fall_reason="x",
                        fall_time=0.1)
    assert fell.needs_step and fell.reason == "fell: x"


# ---- the platform's path still to come ----------------------------------------------------

def ramp_and_hold_offset_closed_form(t, displacement, duration, omega0):
    """Δ(t) for ṗ(s) = (D/T)(1 − cos(2π s/T)) on [0, T], 0 after, by hand:
    ∫_t^T e^{−ω (s−t)} (1 − cos(k s)) ds = (1 − e^{−ω (T−t)})/ω
    − [e^{−ω (s−t)} (k sin(k s) − ω cos(k s))/(ω² + k²)]_t^T, k = 2π/T."""
    w, k = omega0, 2 * np.pi / duration
    t = np.asarray(t, dtype=float)
    decay = np.exp(-w * (duration - t))

    def antiderivative_cos(s, scale):
        return scale * (k * np.sin(k * s) - w * np.cos(k * s)) / (w * w + k * k)

    integral = ((1 - decay) / w
                - (antiderivative_cos(duration, decay) - antiderivative_cos(t, 1.0)))
    velocity = (displacement / duration) * (1 - np.cos(k * t))
    inside = t < duration
    return np.where(inside, velocity / w - (displacement / duration) * integral, 0.0)


def test_platform_path_offset_of_a_ramp_and_hold_against_its_closed_form():
    D, T = -0.12, 0.5
    errors = []
    for n in (2001, 4001):
        t = np.linspace(0.0, 2.0, n)
        v = np.where(t < T, (D / T) * (1 - np.cos(2 * np.pi * t / T)), 0.0)
        got = platform_path_offset(t, v, OMEGA0)
        errors.append(np.max(np.abs(got - ramp_and_hold_offset_closed_form(t, D, T, OMEGA0))))
        # ṗ taken linear between samples: |error| <= h² max|p⃛| / (8 ω0) [m]
        h = t[1] - t[0]
        assert errors[-1] <= h**2 * abs(D / T) * (2 * np.pi / T) ** 2 / (8 * OMEGA0)
    assert errors[1] == pytest.approx(errors[0] / 4, rel=0.05)  # second order
    # at rest before a backward move Δ > 0 (the foot is about to leave backward), with
    # |ṗ| falling Δ takes ṗ's sign (the coming stop), and once stopped Δ = 0
    assert got[0] > 0.01 and got[np.searchsorted(t, 0.45)] < 0 and np.all(got[t > T] == 0.0)


def test_platform_path_offset_of_constant_motion_is_zero_and_of_a_sudden_stop_by_hand():
    t = np.linspace(0.0, 3.0, 31)
    assert np.allclose(platform_path_offset(t, np.full((2, 31), -0.4), OMEGA0), 0.0,
                       atol=1e-15)
    # V until t1 = 1 s then 0 (a ramp over 1 ns): Δ(0) = (V/ω0) e^{−ω0 t1} by hand
    got = platform_path_offset([0.0, 1.0, 1.0 + 1e-9, 3.0], [0.3, 0.3, 0.0, 0.0], OMEGA0)
    assert got[0] == pytest.approx(0.3 / OMEGA0 * math.exp(-OMEGA0), rel=1e-6)
    with pytest.raises(ParameterError, match="increasing"):
        platform_path_offset([0.0, 0.0], [0.0, 0.0], OMEGA0)
    with pytest.raises(ParameterError, match="shapes"):
        platform_path_offset([0.0, 1.0], [0.0], OMEGA0)


@pytest.mark.parametrize("side, stays", [(-1.0, True), (1.0, False)])
def test_xcom_with_the_platform_path_is_the_capture_condition_of_the_pendulum(side, stays):
    """A linear inverted pendulum on a ramp-and-hold platform (lab frame, scipy), its
    centre of pressure held at the toe from t0 on (the most any foot can do against a
    forward fall): started with ξ + Δ 1 mm inside the toe it is driven back behind the toe
    (so a centre of pressure on the foot can stop it), 1 mm outside it falls past the toe
    all the same — the criterion is exact, where ξ alone (the platform-velocity frame)
    misjudges it by Δ(t0)."""
    from scipy.integrate import solve_ivp

    D, T, t0 = -0.15, 0.5, 0.2
    k = 2 * np.pi / T

    def platform(s):
        inside = s < T
        p = np.where(inside, (D / T) * (s - np.sin(k * s) / k), D)
        return p, np.where(inside, (D / T) * (1 - np.cos(k * s)), 0.0)

    offset = float(ramp_and_hold_offset_closed_form(t0, D, T, OMEGA0))
    assert abs(offset) > 0.01  # the check has teeth: Δ(t0) is centimetres
    p0, v0 = platform(t0)
    xi_relative = TOE - offset + side * 1e-3  # ξ relative to the foot
    x_rel = 0.0
    x_lab, v_lab = p0 + x_rel, float(v0) + (xi_relative - x_rel) * OMEGA0

    def rhs(s, y):
        return [y[1], OMEGA0**2 * (y[0] - platform(s)[0] - TOE)]

    sol = solve_ivp(rhs, (t0, 4.0), [x_lab, v_lab], rtol=1e-10, atol=1e-12, dense_output=True)
    end = sol.y[0, -1] - platform(4.0)[0]
    assert bool(end < TOE) == stays and abs(end - TOE) > 0.05


# ---- the population presets: every number with its source ---------------------------------

def test_young_preset_numbers_are_their_sources():
    young = get_population("young")
    # 'Muscular performances at the ankle joint in young and elderly men', HAL
    # inserm-00080421 abstract: plantarflexion 132 N·m (young men)
    assert young.plantarflexion_strength == 132.0
    assert young.ankle_strength == 264.0  # two ankles (posturelab's choice)
    # PMC5664365 Table 1: τ_D = 0.097 s; K_P = 943.9 N·m/rad, K_D = 313.5 N·m·s/rad,
    # K = 40.5 N·m/rad, B = 68.8 N·m·s/rad over m g h = 75 × 9.81 × 0.83 N·m/rad
    mgh = 75 * 9.81 * 0.83
    assert young.feedback_delay == 0.097
    assert young.active_stiffness == pytest.approx(943.9 / mgh, rel=1e-4)
    assert young.active_viscosity == pytest.approx(313.5 / mgh, rel=1e-4)
    assert young.intrinsic_stiffness == pytest.approx(40.5 / mgh, rel=1e-3)
    assert young.intrinsic_viscosity == pytest.approx(68.8 / mgh, rel=1e-3)
    for name in ("plantarflexion_strength", "feedback_delay", "active_stiffness"):
        assert young.provenance_of(name).from_source


def test_older_preset_numbers_are_their_sources_or_labelled_assumptions():
    older = get_population("older")
    # HAL inserm-00080421 abstract: 80 N·m (elderly men)
    assert older.plantarflexion_strength == 80.0
    assert older.provenance_of("plantarflexion_strength").from_source
    # the older delay is posturelab's assumption (young + 20 ms), and says so
    assert older.feedback_delay == pytest.approx(0.117)
    delay = older.provenance_of("feedback_delay")
    assert not delay.from_source and "posturelab" in delay.note
    assert "posturelab's assumption" in older.provenance_text()


def test_every_number_of_every_population_has_a_provenance():
    for pop in POPULATIONS.values():
        named = {name for name, _ in pop.provenance}
        assert named == {"intrinsic_stiffness", "intrinsic_viscosity", "active_stiffness",
                         "active_viscosity", "feedback_delay", "proprioceptive_weight",
                         "plantarflexion_strength", "functional_base_of_support",
                         "forward_share", "stance_lean"}


#: King, Judge & Wolfson 1994 (J Gerontol 49:M258), abstract: "Mean FBOS was .60 ± .07 in
#: subjects under age 60, and .42 ± 12 in subjects 60 and older"; "FL and BL ... 66% and 34%
#: of FBOS"; printed to two digits.
KING_YOUNG, KING_OLDER, KING_FORWARD = 0.60, 0.42, 0.66


def test_functional_feet_are_king_1994s():
    young, older = get_population("young"), get_population("older")
    assert young.functional_base_of_support == pytest.approx(KING_YOUNG, abs=5e-3)
    assert older.functional_base_of_support == pytest.approx(KING_OLDER, abs=5e-3)
    for pop in (young, older):
        assert pop.forward_share == pytest.approx(KING_FORWARD, abs=5e-3)
        assert pop.provenance_of("functional_base_of_support").from_source
        heel, toe = pop.functional_foot(1.75)
        # the span is F × 0.152 H (Winter's foot), 66 % of it in front
        assert toe - heel == pytest.approx(pop.functional_base_of_support * 0.152 * 1.75)
        assert toe / (toe - heel) == pytest.approx(pop.forward_share)
    # the PDS recording's quiet-standing lean, 4.17° (one subject; posturelab's computation)
    assert math.degrees(young.stance_lean) == pytest.approx(4.17, abs=5e-3)


def test_unknown_population_lists_the_known_ones():
    with pytest.raises(UnknownNameError, match="young, older"):
        get_population("middle-aged")


#: Koushyar et al. 2019 (PMC6338353), abstract: "older group (11.8±2.1 cm) vs. the young
#: group (16.2±2.6 cm)", backward; printed to 0.1 cm, so ±0.05 cm.
KOUSHYAR_YOUNG = (0.162, 0.026)
KOUSHYAR_OLDER = (0.118, 0.021)


def test_published_thresholds_are_the_abstracts():
    for key, (mean, sd) in ((("young", "backward"), KOUSHYAR_YOUNG),
                            (("older", "backward"), KOUSHYAR_OLDER)):
        assert PUBLISHED[key].mean == pytest.approx(mean, abs=5e-4)
        assert PUBLISHED[key].sd == pytest.approx(sd, abs=5e-4)
        assert "PMC6338353" in PUBLISHED[key].source


# ---- the study ------------------------------------------------------------------------------

#: The subject: Koushyar et al.'s heights and masses were not available (posturelab's
#: assumption, as in the report).
HEIGHT, MASS = 1.75, 75.0


@pytest.fixture(scope="module")
def thresholds():
    return {p: step_threshold(HEIGHT, MASS, p) for p in ("young", "older")}


def test_both_thresholds_are_within_two_published_sd_and_older_is_below_young(thresholds):
    """Issue 22's check, like for like with Koushyar et al. 2019 (backward): the functional
    foot, the platform's path counted, T = 0.5 s (posturelab's assumption)."""
    young, older = thresholds["young"], thresholds["older"]
    assert abs(young.largest_translation - KOUSHYAR_YOUNG[0]) <= 2 * KOUSHYAR_YOUNG[1]
    assert abs(older.largest_translation - KOUSHYAR_OLDER[0]) <= 2 * KOUSHYAR_OLDER[1]
    assert young.within_two_sd and older.within_two_sd
    assert older.largest_translation < young.largest_translation
    assert young.foot == "functional" and young.criterion == "platform-path"


def test_the_foot_keeps_the_centre_of_pressure_on_it(thresholds):
    """With the ankle limited by the functional foot both ways the centre of pressure stays on
    it but for the vertical force's departure from m g (millimetres: the caps are static)."""
    for r in thresholds.values():
        assert r.cop_overrun <= 0.004
        # (strength left after the stance's tonic moment is above m g × toe: both caps are
        # the foot's)
        weight = r.ankle_moment_cap / r.toe  # m g of the body above the ankles [N]
        assert 0.95 * 75 * 9.81 < weight < 75 * 9.81
        assert r.stance_moment == pytest.approx(
            weight * r.com_height * math.sin(math.radians(4.17)), rel=1e-3)
        assert r.dorsiflexion_cap / r.ankle_moment_cap == pytest.approx(-r.heel / r.toe,
                                                                       rel=1e-12)


def test_the_threshold_is_the_xcom_with_the_planned_path_not_a_stopped_run(thresholds):
    """At the default T the XCoM (with Δ over the platform's whole planned move) decides: the
    run withstood comes within 2 mm of the toe, and the step at the next size is needed late
    in the move, not in the first tens of milliseconds (as when Δ was taken from a run that
    had stopped at a fall, its platform supposed to keep its last velocity)."""
    import re

    for r in thresholds.values():
        assert r.reason.startswith("the XCoM reached") and "in front of the toe" in r.reason
        assert 0.0 <= r.minimum_margin < 0.002
        when = float(re.search(r"at t = ([\d.]+) s", r.reason).group(1))
        assert when > r.feedback_delay + 0.1


def test_the_anatomical_foot_and_the_platform_velocity_frame_are_stricter(thresholds):
    """The alternatives the guide compares: the whole foot from the ankle (the body's centre
    of mass over the ankle) ends in the rebound behind the heel; judging ξ as if the platform
    kept its velocity ends during the move."""
    for name, r in thresholds.items():
        anatomical = step_threshold(HEIGHT, MASS, name, foot="anatomical")
        velocity = step_threshold(HEIGHT, MASS, name, criterion="platform-velocity")
        assert anatomical.largest_translation < r.largest_translation
        assert velocity.largest_translation < r.largest_translation
        assert "behind the heel" in anatomical.reason and anatomical.stance_moment == 0.0
    with pytest.raises(UnknownNameError, match="functional, anatomical"):
        step_threshold(HEIGHT, MASS, foot="flat")
    with pytest.raises(UnknownNameError, match="platform-path, platform-velocity"):
        step_threshold(HEIGHT, MASS, criterion="lab")


def test_the_symmetric_cap_overruns_the_heel_of_the_anatomical_foot():
    """The cap, foot and criterion of before issue 22 (plantarflexion's cap both ways, the
    whole foot, ξ in the platform's current frame): both thresholds within two published SD,
    but the centre of pressure centimetres behind the heel."""
    young, older = (step_threshold(HEIGHT, MASS, p, heel_limit=False, foot="anatomical",
                                   criterion="platform-velocity")
                    for p in ("young", "older"))
    assert young.within_two_sd and older.within_two_sd
    assert older.largest_translation < young.largest_translation
    assert min(young.cop_overrun, older.cop_overrun) > 0.02
    assert young.dorsiflexion_cap == young.ankle_moment_cap


def test_a_threshold_says_what_happened(thresholds):
    r = thresholds["young"]
    assert r.smallest_stepping - r.largest_translation <= 1e-3 + 1e-12
    assert r.reason.startswith("the XCoM reached") or r.reason.startswith("fell")
    assert r.minimum_margin >= 0.0
    assert r.peak_velocity == pytest.approx(2 * r.largest_translation / r.move_duration)
    assert r.ankle_moment_cap <= r.ankle_strength
    d = r.to_dict()
    assert d["largest_translation"] == r.largest_translation
    assert d["within_two_sd"] is r.within_two_sd is (
        abs(r.largest_translation - KOUSHYAR_YOUNG[0]) <= 2 * KOUSHYAR_YOUNG[1])


def test_the_guide_prints_the_thresholds_computed(thresholds):
    """docs/guide/stepping.rst's table of thresholds is what the study computes (to its
    printed 0.1 cm)."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "guide" / "stepping.rst"
            ).read_text(encoding="utf-8")
    for name in ("young", "older"):
        row = next(line for line in text.splitlines()
                   if line.startswith(f"{name} ") and "±" in line)
        printed = float(row.split()[1]) / 100.0
        assert thresholds[name].largest_translation == pytest.approx(printed, abs=5e-4)
        assert row.split()[5] == ("yes" if thresholds[name].within_two_sd else "no")


@pytest.mark.parametrize("duration", [0.3, 0.65, 0.8])
def test_the_comparison_holds_for_other_move_durations(duration):
    """The protocol's T = 0.5 s is posturelab's assumption: from 0.3 to 0.8 s the thresholds
    are within two published SD, older below young (at 0.9 s the older one ends in the
    rebound, under its band: docs/guide/stepping.rst)."""
    from dataclasses import replace

    from posturelab.studies.stepping import PROTOCOL

    protocol = replace(PROTOCOL, move_duration=duration)
    young, older = (step_threshold(HEIGHT, MASS, p, protocol=protocol).largest_translation
                    for p in ("young", "older"))
    assert abs(young - KOUSHYAR_YOUNG[0]) <= 2 * KOUSHYAR_YOUNG[1]
    assert abs(older - KOUSHYAR_OLDER[0]) <= 2 * KOUSHYAR_OLDER[1]
    assert older < young


def test_reference_engine_finds_the_same_threshold(thresholds):
    """A feature of both engines: the reference engine (numpy model, scipy) brackets the
    same threshold to the search's 1 mm."""
    ref = step_threshold(HEIGHT, MASS, "young", engine="reference")
    assert ref.largest_translation == pytest.approx(
        thresholds["young"].largest_translation, abs=1e-3)


def test_gallery_example_draws_both_populations(tmp_path):
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "step_threshold_vs_duration.py"
    spec = importlib.util.spec_from_file_location("step_threshold_vs_duration", path)
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    values = example.thresholds(np.array([0.5]))
    assert set(values) == {"young", "older"} and values["older"][0] < values["young"][0]
    figure = example.main(tmp_path)
    assert figure.exists() and figure.stat().st_size > 10_000


def test_threshold_falls_with_the_delay():
    values = [step_threshold(HEIGHT, MASS, "young", feedback_delay=d).largest_translation
              for d in (0.0, 0.05, 0.097, 0.15, 0.2)]
    assert all(b <= a for a, b in zip(values[:-1], values[1:], strict=True)), values
    assert values[-1] < values[0]


def test_threshold_rises_with_ankle_strength_until_the_foot_binds():
    """Below m g × toe plus the stance's tonic moment the strength binds (Koushyar et al.'s
    finding: plantarflexion strength matters); above it the foot does."""
    values = [step_threshold(HEIGHT, MASS, "young", ankle_strength=s).largest_translation
              for s in (60.0, 80.0, 100.0, 120.0, 200.0, 300.0)]
    assert all(b >= a for a, b in zip(values[:-1], values[1:], strict=True)), values
    assert values[-1] > values[0]


def test_no_step_up_to_the_largest_translation_is_said():
    from dataclasses import replace

    from posturelab.studies.stepping import PROTOCOL

    r = step_threshold(HEIGHT, MASS, "young", protocol=replace(PROTOCOL, largest=0.02))
    assert r.largest_translation == pytest.approx(0.02) and math.isinf(r.smallest_stepping)
    assert r.reason == "" and r.to_dict()["smallest_stepping"] is None


def test_forward_has_no_published_figure():
    r = step_threshold(HEIGHT, MASS, "young", "forward")
    assert r.published_mean is None and r.within_two_sd is None
    assert r.largest_translation > 0.0


def test_bad_study_input_is_refused():
    with pytest.raises(ParameterError, match="height"):
        step_threshold(-1.0, MASS)
    with pytest.raises(ParameterError, match="mass"):
        step_threshold(HEIGHT, 0.0)
    with pytest.raises(UnknownNameError, match="backward, forward"):
        step_threshold(HEIGHT, MASS, "young", "sideways")
    with pytest.raises(ParameterError, match="feedback_delay"):
        step_threshold(HEIGHT, MASS, "young", feedback_delay=-0.1)
    with pytest.raises(ParameterError, match="cop_criterion must be True or False"):
        step_threshold(HEIGHT, MASS, cop_criterion="no")
    with pytest.raises(ParameterError, match="position"):
        xcom("0.1", 0.1, 3.0)
    with pytest.raises(ParameterError, match="platform_velocity"):
        platform_path_offset([0.0, 1.0], ["a", "b"], 3.0)


# ---- the command ------------------------------------------------------------------------

def test_cli_prints_one_json_object_with_the_threshold():
    import json

    p = cli("step-threshold", "--height", "1.75", "--mass", "75", "--population", "older",
            "--direction", "backward", "--json")
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert 0.0 < out["largest_translation"] < 0.6
    assert out["units"]["largest_translation"] == "m"
    assert out["population"] == "older" and "PMC6338353" in out["published_source"]


@pytest.mark.parametrize("args, words", [
    (("--height", "-1.7", "--mass", "75"), ("height", "-1.7")),
    (("--height", "1.7", "--mass", "75", "--population", "middle"), ("young, older",)),
    (("--height", "1.7", "--mass", "75", "--direction", "up"), ("backward, forward",)),
    (("--height", "1.7"), ("--mass",)),
    (("--height", "1.75", "--mass", "75", "--ankle-strength", "20"),
     ("ankle_strength", "20", "51 N·m")),
    (("--height", "2.5", "--mass", "300"), ("young population's ankle strength", "264")),
    (("--height", "1.7", "--mass", "75", "--foot", "flat"), ("--foot", "functional")),
    (("--height", "1.7", "--mass", "75", "--translation", "sideways"),
     ("--translation", "backward, forward")),
])
def test_cli_bad_input_is_one_line_exit_2(args, words):
    one_line_exit_2(cli("step-threshold", *args), *words)
