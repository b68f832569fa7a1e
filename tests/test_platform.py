"""Platform disturbances: profiles checked against their closed-form integrals."""

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

from posturelab.errors import DataFileError, ParameterError
from posturelab.model.platform import (
    HalfSinePulse,
    MeasuredProfile,
    NoDisturbance,
    RampAndHold,
    SumOfSines,
    VelocityStep,
    combine,
    read_profile_csv,
)


def test_velocity_step_directions():
    assert VelocityStep.backward(1.0).velocity_change == (-1.0, 0.0)
    assert VelocityStep.forward(0.5).velocity_change == (0.5, 0.0)
    assert VelocityStep(0.2, axis="y").velocity_change == (0.0, 0.2)


def test_half_sine_velocity_gain():
    """∫ A sin(πt/T) dt over the pulse = 2AT/π."""
    p = HalfSinePulse(3.0, 0.2, start=0.1)
    t = np.linspace(0, 0.5, 200001)
    v = cumulative_trapezoid(p.acceleration(t)[:, 0], t, initial=0)
    assert v[-1] == pytest.approx(p.velocity_gain, rel=1e-8)
    assert p.breakpoints == (0.1, pytest.approx(0.3))


def test_ramp_and_hold_displacement_and_rest():
    """Acceleration integrates twice to D, with zero velocity at the end."""
    p = RampAndHold(-0.15, 0.5, start=0.2)
    t = np.linspace(0, 1.0, 400001)
    v = cumulative_trapezoid(p.acceleration(t)[:, 0], t, initial=0)
    x = cumulative_trapezoid(v, t, initial=0)
    assert x[-1] == pytest.approx(-0.15, rel=1e-6)
    assert v[-1] == pytest.approx(0.0, abs=1e-9)
    assert np.min(v) == pytest.approx(2 * -0.15 / 0.5, rel=1e-6)  # peak velocity 2D/T


def test_sum_of_sines_and_combine():
    s = SumOfSines((1.0, 0.5), (0.5, 2.0), (0.0, np.pi / 2))
    t = np.array([0.0, 0.25])
    expected = np.sin(2 * np.pi * 0.5 * t) + 0.5 * np.sin(2 * np.pi * 2.0 * t + np.pi / 2)
    np.testing.assert_allclose(s.acceleration(t)[:, 0], expected)
    both = combine(s, HalfSinePulse(1.0, 1.0, axis="y"))
    np.testing.assert_allclose(both.acceleration(t)[:, 1], np.sin(np.pi * t))


def test_measured_profile_interpolates_and_is_zero_outside():
    p = MeasuredProfile([0.0, 1.0, 2.0], [0.0, 2.0, 0.0])
    np.testing.assert_allclose(p.acceleration([-1.0, 0.5, 1.5, 3.0])[:, 0], [0, 1, 1, 0])


def _write(tmp_path, text, name="p.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_read_profile_csv(tmp_path):
    path = _write(tmp_path, "time [s],x_acceleration [m/s^2],y_acceleration\n0,0,0\n0.1,1,0.5\n")
    p = read_profile_csv(path)
    np.testing.assert_allclose(p.time, [0, 0.1])
    np.testing.assert_allclose(p.acceleration_y, [0, 0.5])


@pytest.mark.parametrize("text,needle", [
    ("time,x_acceleration\n0,0\n0.1,nan\n", "NaN"),
    ("time,x_acceleration\n0,0\n0.2,1\n0.1,1\n", "strictly increasing"),
    ("time,x_acceleration\n0,0\n0,1\n", "strictly increasing"),
    ("time,y_acceleration\n0,0\n0.1,1\n", "x_acceleration"),
    ("time,x_acceleration\n0,0\n0.1,abc\n", "not a number"),
    ("time,x_acceleration\n0,0\n", "at least 2 samples"),
])
def test_read_profile_csv_rejects(tmp_path, text, needle):
    with pytest.raises(DataFileError, match=needle):
        read_profile_csv(_write(tmp_path, text))


def test_read_profile_missing_file(tmp_path):
    with pytest.raises(DataFileError, match="cannot read"):
        read_profile_csv(tmp_path / "nope.csv")


@pytest.mark.parametrize("factory,needle", [
    (lambda: HalfSinePulse(1.0, 0.0), "duration"),
    (lambda: HalfSinePulse(float("nan"), 1.0), "peak_acceleration"),
    (lambda: RampAndHold(0.1, -1.0), "duration"),
    (lambda: SumOfSines((1.0,), (0.0,)), "frequencies"),
    (lambda: SumOfSines((1.0, 2.0), (1.0,)), "equal length"),
    (lambda: VelocityStep(1.0, axis="z"), "axis"),
    (lambda: VelocityStep.backward(-1.0), "speed"),
])
def test_bad_disturbance_parameters(factory, needle):
    with pytest.raises(ParameterError, match=needle):
        factory()


@pytest.mark.parametrize("disturbance", [
    VelocityStep.backward(0.8),
    HalfSinePulse(2.0, 0.3, 0.1),
    RampAndHold(0.12, 0.5, 0.05, axis="y"),
    SumOfSines((1.0, 0.5), (1.0, 2.5), (0.0, 0.3)),
    MeasuredProfile([0.0, 0.1, 0.2, 0.4], [0.0, 1.0, -0.5, 0.0], [0.0, 0.2, 0.0, 0.0]),
    combine(HalfSinePulse(2.0, 0.3), VelocityStep.forward(0.5)),
])
@pytest.mark.parametrize("factor", [2.5, -1.0, 0.0])
def test_scaled_multiplies_every_amplitude_and_keeps_the_timing(disturbance, factor):
    """a(t) and the velocity step scale by the factor; breakpoints and max step do not."""
    t = np.linspace(0.0, 0.6, 61)
    scaled = disturbance.scaled(factor)
    np.testing.assert_allclose(scaled.acceleration(t), factor * disturbance.acceleration(t),
                               rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(scaled.velocity_change,
                               factor * np.asarray(disturbance.velocity_change), atol=1e-15)
    assert scaled.breakpoints == disturbance.breakpoints
    assert scaled.max_step == disturbance.max_step


def test_scaled_rejects_a_non_finite_factor():
    with pytest.raises(ParameterError, match="factor"):
        VelocityStep.backward(1.0).scaled(float("nan"))
    with pytest.raises(ParameterError, match="factor"):
        NoDisturbance().scaled(float("inf"))


def test_a_disturbance_that_does_not_define_scaling_is_refused():
    from posturelab.model.platform import Disturbance

    class Custom(Disturbance):
        pass

    with pytest.raises(ParameterError, match="Custom does not define how to scale"):
        Custom().scaled(2.0)
    assert NoDisturbance().scaled(3.0) == NoDisturbance()
