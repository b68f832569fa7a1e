"""A PRTS identification experiment in silico: simulate, add seeded sensor noise, estimate.

:func:`prts_experiment` applies a periodic tilt (by default posturelab's 80-state PRTS) to the
nonlinear model on the compiled engine for ``discard + cycles`` cycles, adds white sensor
noise of a given standard deviation [rad] to the measured angle (seeded), and estimates the
FRF of that angle to the tilt in the literature's sign (:func:`posturelab.frequency.
estimate_frf`). Motor noise, a seeded random torque inside the loop that adds sway the
stimulus does not explain, is a run option: ``motor_noise=MotorNoise(...)``
(:mod:`posturelab.model.noise`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..simulation.options import RunOptions
from .estimate import FRFEstimate, estimate_frf

__all__ = ["PRTSExperiment", "prts_experiment", "MAX_SENSOR_NOISE", "MAX_RECORD_RATE"]

#: The spawn key of the sensor noise's random stream (see :func:`prts_experiment`).
SENSOR_STREAM = 1

#: Largest sensor noise (standard deviation) on a recorded angle. [rad]
MAX_SENSOR_NOISE = 1.0
#: Highest record rate of a PRTS experiment. [Hz]
MAX_RECORD_RATE = 1e5


@dataclass(frozen=True)
class PRTSExperiment:
    """What :func:`prts_experiment` measured.

    Attributes
    ----------
    estimate : FRFEstimate
    time : numpy.ndarray, shape (S,)
        [s]
    stimulus : numpy.ndarray, shape (S,)
        The tilt α. [rad]
    response : numpy.ndarray, shape (S,)
        The measured angle, noise included (posturelab's sign: forward positive). [rad]
    fell : bool
        The body fell: the record is not usable (``estimate`` is then None).
    """

    estimate: FRFEstimate | None
    time: np.ndarray
    stimulus: np.ndarray
    response: np.ndarray
    fell: bool


def output_choices(n_links: int) -> str:
    """The angles an experiment can record, for a message: ``com_angle or theta1`` on one
    link, ``com_angle, theta1 or theta2`` on two, ``com_angle or theta1 … thetaN`` on more."""
    if n_links == 1:
        return "com_angle or theta1"
    if n_links == 2:
        return "com_angle, theta1 or theta2"
    return f"com_angle or theta1 … theta{n_links}"


def check_output(output, n_links: int) -> None:
    """Refuse an ``output`` that is not com_angle or theta1 … thetaN of an ``n_links`` body,
    in one line naming the choices."""
    if output == "com_angle" or (isinstance(output, str) and output.startswith("theta")
                                 and output[5:].isdigit() and 1 <= int(output[5:]) <= n_links):
        return
    raise ParameterError(f"output must be {output_choices(n_links)}, got {output!r}")


def check_length(cycles: int, discard: int, cycle: float) -> None:
    """Refuse an experiment of ``discard + cycles`` cycles of ``cycle`` [s] longer than the
    longest run (:data:`posturelab.simulation.setup.MAX_DURATION`, 86,400 s), naming both."""
    from ..simulation.setup import MAX_DURATION

    total = cycle * (cycles + discard)
    if total > MAX_DURATION:
        raise ParameterError(f"cycles {cycles} (+ discard {discard}) × the {cycle:g} s cycle = "
                             f"{total:.3g} s exceeds the longest run, {MAX_DURATION:g} s")


def prts_experiment(body, muscles, *, tilt=None, cycles: int = 5, discard: int = 1,
                    sensor_noise: float = 0.0, seed: int = 0, sample_rate: float = 100.0,
                    output: str = "com_angle", bands=None, options: RunOptions | None = None,
                    **run_options: Any) -> PRTSExperiment:
    """Run one seeded PRTS experiment (module notes).

    Parameters
    ----------
    body, muscles
        The model.
    tilt : PRTSTilt, optional
        Default: posturelab's 80-state sequence (``PRTSTilt.named("posturelab-80")``),
        0.035 rad peak to peak.
    cycles, discard : int
        Cycles analysed, and cycles run before them (dropped). [-]
    sensor_noise : float
        Standard deviation of the white noise on the measured angle, >= 0. [rad]
    seed : int
        Of the noise generator.
    sample_rate : float
        [Hz]
    output : {"com_angle", "thetaN"}
        The angle measured.
    bands
        As for :func:`posturelab.frequency.estimate_frf`; default: the tilt's sequence's
        (:func:`posturelab.frequency.bands.sequence_bands`).
    options : RunOptions, optional
        The run's other options (``feedback_delay`` [s], ``proprioceptive_weight`` [-],
        ``motor_noise``, ``knee``, ``fall``, ``torque_limits`` [N·m], …); the experiment sets
        the duration, the tilt and the sample rate. Default: ``RunOptions()``.
    **run_options
        Fields of :class:`~posturelab.simulation.options.RunOptions` by name, replacing
        those of ``options`` (``feedback_delay=0.1``); ``engine`` is the compiled one unless
        given (``engine="reference"``).
    """
    from ..model.tilt import PRTSTilt
    from ..simulation.engines import simulate

    if not isinstance(output, str):
        raise ParameterError(f"output must be com_angle or thetaN, got {output!r}")
    tilt = PRTSTilt.named("posturelab-80", 0.035) if tilt is None else tilt
    if not isinstance(tilt, PRTSTilt):
        raise ParameterError("tilt must be a PRTSTilt (a periodic stimulus)")
    for name, value, least in (("cycles", cycles, 2), ("discard", discard, 0)):
        if isinstance(value, bool) or not isinstance(value, int) or value < least:
            raise ParameterError(f"{name} must be an integer >= {least}, got {value!r}")
    check_length(cycles, discard, tilt.cycle)
    check_output(output, body.n_links)
    from .._validation import float_in_range

    float_in_range("sensor_noise [rad]", sensor_noise, 0.0, MAX_SENSOR_NOISE, unit="rad")
    float_in_range("sample_rate [Hz]", sample_rate, 1.0, MAX_RECORD_RATE, unit="Hz")
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise ParameterError(f"seed must be an integer >= 0, got {seed!r}")
    total = tilt.cycle * (cycles + discard)
    engine = run_options.pop("engine", "compiled")
    run = RunOptions.from_keywords("prts_experiment", **run_options) if options is None \
        else options.replace(**run_options)
    r = simulate(body, muscles, None, options=run.replace(
        duration=total, tilt=tilt, sample_rate=sample_rate, engine=engine))
    t = r.time[:-1] if r.time.size > 1 else r.time
    if output == "com_angle":
        angle = r.com_angle
    elif output.startswith("theta") and output[5:].isdigit() \
            and 1 <= int(output[5:]) <= body.n_links:
        angle = r.theta[:, int(output[5:]) - 1]
    else:
        check_output(output, body.n_links)
    # the sensor's own stream, independent of a motor noise seeded with the same number
    # (MotorNoise draws from default_rng(seed)): a child of the seed's SeedSequence
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(SENSOR_STREAM,)))
    measured = angle[:t.size] + rng.normal(0.0, sensor_noise, t.size)
    stimulus = tilt.angle(t)
    if r.fell:
        return PRTSExperiment(None, t, stimulus, measured, True)
    if bands is None:
        from .bands import sequence_bands

        bands = sequence_bands(tilt)
    est = estimate_frf(stimulus, measured, sample_rate, tilt.cycle, discard_cycles=discard,
                       bands=bands, response_sign=-1)
    return PRTSExperiment(est, t, stimulus, measured, False)
