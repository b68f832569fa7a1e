"""Both engines do everything: feedback delay, torque saturation and centre-of-pressure falls
agree between the compiled engine and the reference; batches equal their single runs bit for
bit; the C sources, the generated code and the shared codes are what the package expects.

The reference runs at rtol 1e-10, atol 1e-12, the compiled engine at its defaults (rtol
1e-6, atol 1e-9); nothing here is timed (benchmarks/ does that).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import posturelab as pl
from posturelab.model.muscles import MusclePair, MuscleSet
from posturelab.model.tilt import PRTSTilt, RaisedCosineTilt
from posturelab.simulation import compiled
from posturelab.simulation.compiled import simulate_batch

THETA_TOL = 1e-6  # [rad]
TIME_TOL = 1e-6  # [s]
REF = {"rtol": 1e-10, "atol": 1e-12}
#: A delayed run of the paper's gains oscillates near 90 Hz and amplifies every error (the
#: reference itself moves by 6e-7 rad between rtol 1e-8 and 1e-12 over 1.5 s at τ = 10 ms),
#: so delayed runs are compared with the compiled engine at a tolerance to match.
TIGHT = {"rtol": 1e-10, "atol": 1e-13}
POSTURE = [0.1, -0.1, 0.1, 0.0, 0.0, 0.0]


def both(*args, compiled_tolerances=None, **kwargs):
    fast = pl.simulate(*args, engine="compiled", **kwargs, **(compiled_tolerances or {}))
    ref = pl.simulate(*args, engine="reference", **kwargs, **REF)
    return fast, ref


def assert_agree(fast, ref, theta_tol=THETA_TOL):
    assert fast.status == ref.status, (fast.message, ref.message)
    assert fast.fall_reason == ref.fall_reason
    if ref.fell:
        assert fast.fall_time == pytest.approx(ref.fall_time, abs=TIME_TOL)
    assert fast.time.shape == ref.time.shape
    np.testing.assert_allclose(fast.theta, ref.theta, rtol=0, atol=theta_tol)
    assert len(fast.switch_times) == len(ref.switch_times)
    np.testing.assert_allclose(fast.switch_times, ref.switch_times, rtol=0, atol=TIME_TOL)


# ---------------------------------------------------------------------------
# Feedback delay
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("delay", [0.002, 0.01, 0.03, 0.06])
def test_delayed_runs_of_case_1_agree(delay):
    """Below the delay at which case 1 topples (it recovers at 2 and 10 ms) and above it (it
    falls within 0.2 s at 30 and 60 ms): the same outcome, fall time and trajectory."""
    sc = pl.builtin_scenario("paper-backward-case1")
    fast, ref = both(sc.body, sc.muscles, sc.disturbance, 1.5, initial_state=sc.initial_state,
                     feedback_delay=delay, sample_rate=100, compiled_tolerances=TIGHT)
    assert ref.fell == (delay >= 0.03)
    assert_agree(fast, ref)


@pytest.mark.parametrize("fraction", [0.85, 1.15])
def test_delayed_pendulum_agrees_on_both_sides_of_its_critical_delay(fraction):
    """The inverted pendulum of tests/test_delay.py (critical delay 0.159 s for these gains):
    decaying below it, growing above it, both engines alike."""
    body = pl.get_body("paper-1link")
    muscles = MuscleSet((MusclePair("ankle", 0, 1, 1000.0, 100.0),), 1)
    fast, ref = both(body, muscles, None, 6.0, initial_state=[0.01, 0.0],
                     feedback_delay=fraction * 0.1594, fall=pl.FallCriteria(math.pi / 2),
                     sample_rate=100, compiled_tolerances=TIGHT)
    assert_agree(fast, ref)


def test_delayed_one_sided_pair_switches_at_the_same_times():
    """A one-sided gastrocnemius that responds to the delayed stretch switches where θ2(t − τ)
    crosses 0, in both engines."""
    muscles = pl.paper_muscles("1", gastrocnemius="one-sided")
    fast, ref = both(pl.paper_body(), muscles, pl.VelocityStep.forward(0.4), 2.0,
                     initial_state=[0.0, 0.02, 0.0, 0.0, 0.0, 0.0], feedback_delay=0.004,
                     sample_rate=200, compiled_tolerances=TIGHT)
    assert len(ref.switch_times) >= 1
    assert_agree(fast, ref)


def test_delayed_pair_torques_respond_to_the_delayed_state_on_the_compiled_engine():
    """As tests/test_delay.py checks for the reference: M(t) = K θ(t − τ) + L θ̇(t − τ)."""
    body = pl.get_body("paper-1link")
    muscles = MuscleSet((MusclePair("ankle", 0, 1, 1000.0, 100.0),), 1)
    tau = 0.05
    r = pl.simulate(body, muscles, None, 2.0, initial_state=[0.02, 0.1], feedback_delay=tau,
                    sample_rate=1000, fall=pl.FallCriteria(math.pi / 2), engine="compiled")
    k = int(round(tau * 1000))
    expected = 1000.0 * r.theta[:-k, 0] + 100.0 * r.omega[:-k, 0]
    np.testing.assert_allclose(r.pair_torques[k:, 0], expected, atol=1e-6)
    np.testing.assert_allclose(r.pair_torques[:k, 0], 1000.0 * 0.02 + 100.0 * 0.1)


# ---------------------------------------------------------------------------
# Torque saturation and the centre of pressure
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("limits,speed", [((60.0, 30.0, math.inf), 0.2),
                                          ((60.0, 30.0, math.inf), 0.4),
                                          ((80.0, 50.0, 20.0), 0.4)])
def test_torque_saturation_agrees(limits, speed):
    """Joints that saturate and let go: the same switch times, and while a joint saturates
    its net moment is its limit (to the event hysteresis) in both engines."""
    fast, ref = both(pl.paper_body(), pl.paper_muscles("1"), pl.VelocityStep.backward(speed),
                     3.0, initial_state=[0.02, 0.0, 0.0, 0.0, 0.0, 0.0],
                     torque_limits=limits)
    assert len(ref.switch_times) >= 2
    assert_agree(fast, ref)
    lim = np.asarray(limits)
    for run in (fast, ref):
        assert np.all(np.abs(run.joint_moments) <= lim + 1e-9)
        at_limit = np.isclose(np.abs(run.joint_moments), lim, rtol=0, atol=1e-9)
        assert at_limit[:, 0].any() and at_limit[:, 1].any()


@pytest.mark.parametrize("displacement", [0.10, 0.20, 0.30])
def test_centre_of_pressure_falls_agree(displacement):
    """A backward ramp-and-hold of case 1 with a literature foot: recovered at 10 cm, the foot
    tips (centre of pressure past the toe) at 20 and 30 cm, at the same time in both."""
    fall = pl.FallCriteria(base_of_support=pl.FOOT_FROM_LITERATURE, centre_of_pressure=True)
    fast, ref = both(pl.paper_body(), pl.paper_muscles("1"), pl.RampAndHold(-displacement, 0.5),
                     4.0, fall=fall, sample_rate=200)
    assert ref.fell == (displacement > 0.15)
    if ref.fell:
        assert "centre of pressure" in ref.fall_reason
    assert_agree(fast, ref)


def test_centre_of_pressure_with_saturation_and_delay_together():
    fall = pl.FallCriteria(base_of_support=pl.FOOT_FROM_LITERATURE, centre_of_pressure=True)
    fast, ref = both(pl.paper_body(), pl.paper_muscles("1"), pl.RampAndHold(-0.2, 0.5), 2.0,
                     fall=fall, torque_limits=[70.0, math.inf, math.inf],
                     feedback_delay=0.003, sample_rate=200, compiled_tolerances=TIGHT)
    assert_agree(fast, ref)


# ---------------------------------------------------------------------------
# Batches equal their single runs
# ---------------------------------------------------------------------------


def _single(body, k, d, duration, **kwargs):
    return pl.simulate(body, pl.paper_muscles(stiffness=k, viscosity=0.25 * k), d, duration,
                       engine="compiled", **kwargs)


def assert_row_is_run(out, r, one):
    assert one.fell == out.fell[r]
    np.testing.assert_array_equal(one.max_abs_theta, out.peak_theta[r])
    np.testing.assert_array_equal(one.final_state, out.final_state[r])
    if one.fell:
        assert one.fall_time == out.fall_time[r]


def test_delayed_batch_equals_its_single_runs_bit_for_bit(rng):
    """Per-run delays (none, short, long) and gains: each row is its single run, whichever
    integrator each chooses (Radau without delay, RK45 with)."""
    m = 8
    k = np.tile(np.asarray(pl.paper_muscles("1").stiffnesses), (m, 1))
    k[:, 0] = rng.uniform(400.0, 1200.0, m)
    delays = np.array([0.0, 0.002, 0.01, 0.03, 0.0, 0.005, 0.1, 0.002])
    d = pl.VelocityStep.backward(0.5)
    for parallel in (True, False):
        out = simulate_batch(pl.paper_body(), k, 0.25 * k, d, 1.5, POSTURE,
                             feedback_delay=delays, parallel=parallel, chunk=3)
        for r in range(m):
            one = _single(pl.paper_body(), k[r], d, 1.5, initial_state=POSTURE,
                          feedback_delay=float(delays[r]))
            assert_row_is_run(out, r, one)
    assert out.fell[6] and not out.fell[0]


def test_batch_of_random_gains_equals_its_single_runs_bit_for_bit(rng):
    """Random gains (stiff and soft, falling and recovering): peak angles, the last sample
    and the outcome of every row are those of its single run, to the last bit."""
    m = 40
    k = np.empty((m, 5))
    k[:, 0] = rng.uniform(400.0, 1500.0, m)
    k[:, 1:] = rng.uniform(0.0, 600.0, (m, 4))
    d = pl.VelocityStep.backward(1.0)
    out = simulate_batch(pl.paper_body(), k, 0.25 * k, d, 5.0, POSTURE)
    for r in range(m):
        assert_row_is_run(out, r, _single(pl.paper_body(), k[r], d, 5.0, initial_state=POSTURE))
    assert 0 < out.fell.sum() < m


def test_batch_with_per_run_torque_limits_and_cop_equals_single_runs():
    """Per-run limits (including none), centre-of-pressure falls, and a run whose centre of
    pressure is outside the foot at t = 0."""
    fall = pl.FallCriteria(base_of_support=pl.FOOT_FROM_LITERATURE, centre_of_pressure=True)
    k = np.tile(np.asarray(pl.paper_muscles("1").stiffnesses), (4, 1))
    k[3, 0] = 40000.0  # a huge ankle moment at the flexed start posture: the foot tips at once
    limits = np.array([[math.inf] * 3, [60.0, math.inf, math.inf], [70.0, 30.0, math.inf],
                       [math.inf] * 3])
    d = pl.RampAndHold(-0.2, 0.5)
    start = [0.03, 0.0, 0.0, 0.0, 0.0, 0.0]
    out = simulate_batch(pl.paper_body(), k, 0.25 * k, d, 2.0, start, fall=fall,
                         torque_limits=limits)
    for r in range(4):
        lim = None if np.all(np.isinf(limits[r])) else limits[r]
        one = _single(pl.paper_body(), k[r], d, 2.0, initial_state=start, fall=fall,
                      torque_limits=lim)
        assert_row_is_run(out, r, one)
    assert out.fell[3] and out.fall_time[3] == 0.0


def test_batch_parameters_are_checked_as_single_runs_are():
    k = np.asarray(pl.paper_muscles("1").stiffnesses)[None, :].repeat(2, axis=0)
    with pytest.raises(pl.ParameterError, match="feedback_delay"):
        simulate_batch(pl.paper_body(), k, 0.25 * k, None, 1.0, feedback_delay=[0.01, -1.0])
    with pytest.raises(pl.ParameterError, match="torque_limits"):
        simulate_batch(pl.paper_body(), k, 0.25 * k, None, 1.0,
                       torque_limits=[[10.0, 10.0, 10.0], [10.0, -2.0, 10.0]])
    with pytest.raises(pl.ParameterError, match="feedback_delay"):
        simulate_batch(pl.paper_body(), k, 0.25 * k, None, 1.0, feedback_delay=[0.01] * 3)


# ---------------------------------------------------------------------------
# The engine's sources, generated code and codes
# ---------------------------------------------------------------------------


def test_generated_small_right_hand_sides_are_up_to_date():
    """csrc/pl_rhs_small.c is what _codegen/rhs_small.py writes now (regenerate with
    python -m posturelab.simulation.compiled._codegen)."""
    from posturelab.simulation.compiled import _codegen

    assert _codegen.TARGET.read_text(encoding="utf-8") == _codegen.generate()


@pytest.mark.parametrize("n_links,locked", [(1, False), (2, False), (2, True), (3, False),
                                             (3, True)])
def test_generated_and_general_right_hand_sides_agree(n_links, locked, rng):
    """The straight-line code for N = 1, 2, 3 and the general-N elimination, with saturation
    and delayed moments in play (a 1-link chain has no knee to lock)."""
    lengths = rng.uniform(0.3, 0.6, n_links)
    body = pl.Body.from_arrays(rng.uniform(5, 30, n_links), lengths,
                               rng.uniform(0.3, 0.6, n_links) * lengths,
                               rng.uniform(0.2, 2.0, n_links))
    pairs = tuple(MusclePair(f"p{lo}{hi}", lo, hi, rng.uniform(0, 900), rng.uniform(0, 200))
                  for lo in range(n_links) for hi in range(lo + 1, n_links + 1))
    muscles = MuscleSet(pairs, n_links)
    for _ in range(10):
        kwargs = dict(active=(rng.uniform(size=len(pairs)) < 0.7).astype(float), locked=locked,
                      platform_acceleration=tuple(rng.normal(0, 2, 2)),
                      delayed_moments=rng.normal(0, 30, n_links),
                      saturation=rng.choice([-1.0, 0.0, 1.0], n_links),
                      torque_limits=rng.uniform(10, 100, n_links))
        x = rng.uniform(-0.8, 0.8, 2 * n_links)
        small = compiled.state_derivative(body, muscles, x, **kwargs)
        general = compiled.state_derivative(body, muscles, x, general=True, **kwargs)
        np.testing.assert_allclose(small, general, rtol=1e-12, atol=1e-12)


def test_the_engine_was_built_from_the_sources_beside_it():
    from posturelab.simulation.compiled._binding import library
    from posturelab.simulation.compiled._sources import source_hash

    assert library().pl_source_hash().decode() == source_hash()


def _c_enums() -> dict[str, int]:
    """Every NAME = value (or implicit value) of the enums in csrc/pl.h and pl_codes.h."""
    text = "".join((Path(compiled.__file__).parent / "csrc" / name).read_text()
                   for name in ("pl.h", "pl_codes.h"))
    values: dict[str, int] = {}
    for body in re.findall(r"enum\s*\{([^}]*)\}", text):
        nxt = 0
        for item in body.split(","):
            item = re.sub(r"/\*.*?\*/", "", item).strip()
            if not item:
                continue
            name, _, val = item.partition("=")
            nxt = int(val) if val.strip() else nxt
            values[name.strip()] = nxt
            nxt += 1
    return values


def test_codes_in_python_equal_those_in_the_c_header():
    """_layout.py and model/events.py state the numbers csrc/pl.h states."""
    from posturelab.model import events as ev
    from posturelab.simulation.compiled import _layout as lay

    c = _c_enums()
    for name in ("R_STATUS", "R_N_SAMPLES", "R_FALL_KIND", "R_FALL_INDEX", "R_FALL_TIME",
                 "R_N_SWITCHES", "R_T_REACHED", "R_N_STEPS", "R_N_REJECTED", "R_N_EVALS",
                 "R_LAST_OUTSIDE", "R_ANY_OUTSIDE", "R_FINAL_OUTSIDE", "R_FALL_SAMPLE",
                 "N_RESULT", "F_MAX_ANGLE", "F_HEEL", "F_TOE", "F_STOP_ANGLE", "F_RTOL",
                 "F_ATOL", "F_MAX_STEP", "F_DURATION", "F_SETTLE_TOL", "N_FPAR", "I_USE_BOS",
                 "I_USE_COP", "I_KNEE_MODE", "I_MAX_SWITCHES", "I_LOCKED0", "N_IPAR",
                 "KNEE_FREE", "KNEE_LOCKED", "KNEE_STOP", "DIST_ROW", "DIST_WINDOWED_SINE",
                 "DIST_SINE", "DIST_SAMPLES", "METHOD_RADAU", "METHOD_EXPLICIT", "TILT_ROW",
                 "TILT_SINE", "TILT_RAISED_COSINE", "TILT_PPOLY"):
        assert c[name] == getattr(lay, name), name
    statuses = {"PL_COMPLETED": lay.STATUS_COMPLETED, "PL_FELL": lay.STATUS_FELL,
                "PL_STEP_TOO_SMALL": lay.STATUS_STEP_TOO_SMALL,
                "PL_NONFINITE": lay.STATUS_NONFINITE, "PL_CHATTERING": lay.STATUS_CHATTERING,
                "PL_NO_MEMORY": lay.STATUS_NO_MEMORY}
    for name, value in statuses.items():
        assert c[name] == value, name
    for kind in ev.EVENT_KINDS:
        assert c["EV_" + kind.name.upper().replace("-", "_")] == kind.code, kind.name
    for name in ("ALWAYS", "JOINT_FREE", "JOINT_SATURATED", "PAIR_ACTIVE", "PAIR_SLACK",
                 "KNEE_FREE", "KNEE_LOCKED"):
        assert c["COND_" + name] == getattr(ev, name), name


def test_delayed_tilt_batch_equals_its_single_runs_bit_for_bit(rng):
    """A tilt's corners and their delayed echoes: each row steps onto its own t_k + τ, as its
    single run does (the batch hands the driver the corners; the driver adds each row's echoes)."""
    m = 6
    k = np.tile(np.asarray(pl.paper_muscles("1").stiffnesses), (m, 1))
    k[:, 0] = rng.uniform(600.0, 1200.0, m)
    delays = np.array([0.0, 0.01, 0.03, 0.05, 0.002, 0.03])
    for tilt in (RaisedCosineTilt(amplitude=0.02, start=0.2, duration=0.5),
                 PRTSTilt.named("posturelab-80", amplitude=0.02)):
        _assert_tilt_batch_rows(k, delays, tilt)


def _assert_tilt_batch_rows(k, delays, tilt):
    m = len(delays)
    out = simulate_batch(pl.paper_body(), k, 0.25 * k, None, 1.5, feedback_delay=delays,
                         tilt=tilt)
    for r in range(m):
        one = _single(pl.paper_body(), k[r], None, 1.5, feedback_delay=float(delays[r]),
                      tilt=tilt)
        assert_row_is_run(out, r, one)
