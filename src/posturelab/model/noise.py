"""Motor noise: a seeded random torque added to the net muscle moment at each joint.

Postural sway that the stimulus does not explain (the "remnant") needs noise inside the
loop; van der Kooij and Peterka (2011, J. Comput. Neurosci. 30:759–778) account for it with
sensory and motor noise sources. posturelab models motor noise as an independent
first-order low-pass (Ornstein–Uhlenbeck) process per joint, sampled exactly
(an AR(1) recursion) at ``sample_rate`` and interpolated between samples by a natural cubic
spline, so the torque is smooth (twice continuously differentiable) and both engines
integrate the same function::

    n[k+1] = a n[k] + sqrt(1 − a²) σ w[k],   a = exp(−2π f_c / f_s),   w[k] ~ N(0, 1)

``n[0] ~ N(0, σ²)``: the process is stationary from the start, with standard deviation σ at
every sample. Without a cutoff the samples are independent (white at f_s, band-limited to
f_s / 2). The noise adds to the joint moment τ_j before any torque limit, as a noise on the
motor command would (sign: that of τ_j, :mod:`posturelab.conventions`).

:class:`MotorNoise` holds validated parameters; :func:`motor_noise_series` realises them over
a run as a :class:`TorqueSeries` (knots and cubic coefficients); :func:`torque_at` evaluates
one (numpy; the compiled engine evaluates the same coefficients in C).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._validation import finite_float, float_in_range
from ..errors import ParameterError

__all__ = ["MotorNoise", "TorqueSeries", "motor_noise_series", "torque_at", "MAX_NOISE_KNOTS",
           "MAX_NOISE_TORQUE"]

#: Most samples one realisation may have (duration × sample_rate). [-]
MAX_NOISE_KNOTS = 10_000_000
#: Largest standard deviation of the motor noise at a joint. [N·m]
MAX_NOISE_TORQUE = 1000.0


@dataclass(frozen=True)
class MotorNoise:
    """Motor noise (module notes): a random joint torque per joint, seeded.

    Parameters
    ----------
    standard_deviation : float or sequence of float
        σ per joint, lowest (ankle) first; a single value is the ankle's and the other
        joints get none; each in [0, :data:`MAX_NOISE_TORQUE`]. [N·m]
    cutoff : float or None
        Corner frequency f_c of the first-order low-pass, in (0, sample_rate / 2); None for
        white samples. [Hz]
    sample_rate : float
        f_s, samples per second of the realisation, in [1, 10000]. [Hz]
    seed : int
        Of the generator (numpy's default, PCG64); the same seed gives the same torque.
    """

    standard_deviation: tuple[float, ...] | float
    cutoff: float | None = None
    sample_rate: float = 100.0
    seed: int = 0
    _sigma: tuple[float, ...] = field(init=False, repr=False, compare=False, default=())

    def __post_init__(self) -> None:
        sd = self.standard_deviation
        values = (sd,) if np.ndim(sd) == 0 else tuple(sd)
        if not values:
            raise ParameterError("motor noise standard_deviation [N·m] needs at least one value")
        sigma = tuple(float_in_range(f"motor noise standard_deviation[{k}] [N·m]", v, 0.0,
                                     MAX_NOISE_TORQUE, unit="N·m")
                      for k, v in enumerate(values))
        rate = float_in_range("motor noise sample_rate [Hz]", self.sample_rate, 1.0, 1e4,
                              unit="Hz")
        cutoff = self.cutoff
        if cutoff is not None:
            cutoff = finite_float("motor noise cutoff [Hz]", cutoff)
            if not 0.0 < cutoff < rate / 2:
                raise ParameterError(f"motor noise cutoff [Hz] must be in (0, {rate / 2:g}) "
                                     f"(half the sample rate), got {cutoff!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, int | np.integer) \
                or self.seed < 0:
            raise ParameterError(f"motor noise seed must be an integer >= 0, got {self.seed!r}")
        object.__setattr__(self, "standard_deviation", sigma if len(sigma) > 1 else sigma[0])
        object.__setattr__(self, "cutoff", cutoff)
        object.__setattr__(self, "sample_rate", rate)
        object.__setattr__(self, "seed", int(self.seed))
        object.__setattr__(self, "_sigma", sigma)

    def per_joint(self, n_joints: int) -> np.ndarray:
        """σ for each of ``n_joints`` joints (zeros after the given ones). [N·m]

        Raises
        ------
        ParameterError
            More values than joints.
        """
        if len(self._sigma) > n_joints:
            raise ParameterError(f"motor noise has {len(self._sigma)} standard deviations but "
                                 f"the body has {n_joints} joints")
        out = np.zeros(n_joints)
        out[:len(self._sigma)] = self._sigma
        return out

    @property
    def max_step(self) -> float:
        """Largest integrator step that resolves the torque: four sample intervals. [s]"""
        return 4.0 / self.sample_rate

    def describe(self) -> str:
        band = f"low-passed at {self.cutoff:g} Hz" if self.cutoff is not None else "white"
        sigma = ", ".join(f"{s:g}" for s in self._sigma)
        return f"motor noise σ = {sigma} N·m ({band}, {self.sample_rate:g} Hz, seed {self.seed})"


@dataclass(frozen=True, eq=False)
class TorqueSeries:
    """A piecewise-cubic joint torque over a run (what :func:`motor_noise_series` returns).

    Attributes
    ----------
    knots : numpy.ndarray, shape (K + 1,)
        Increasing sample times from 0. [s]
    coefficients : numpy.ndarray, shape (K, 4, N)
        Interval k's cubic in ascending powers of t − knots[k], per joint.
        [N·m], [N·m/s], [N·m/s²], [N·m/s³]
    """

    knots: np.ndarray
    coefficients: np.ndarray

    @property
    def samples(self) -> np.ndarray:
        """The torque at the knots, shape (K + 1, N). [N·m]"""
        return torque_at(self, self.knots)


def noise_samples(noise: MotorNoise, n_samples: int, n_joints: int) -> np.ndarray:
    """The AR(1) samples of the module notes, shape (n_samples, n_joints). [N·m]"""
    sigma = noise.per_joint(n_joints)
    rng = np.random.default_rng(noise.seed)
    w = rng.standard_normal((n_samples, n_joints))
    if noise.cutoff is None:
        return w * sigma
    a = math.exp(-2.0 * math.pi * noise.cutoff / noise.sample_rate)
    from scipy.signal import lfilter

    # y[k] = a y[k−1] + sqrt(1 − a²) w[k] with y[0] = w[0] (stationary start)
    y = lfilter([math.sqrt(1.0 - a * a)], [1.0, -a], w[1:], axis=0,
                zi=a * w[:1])[0]
    return np.concatenate([w[:1], y]) * sigma


def motor_noise_series(noise: MotorNoise, duration: float, n_joints: int) -> TorqueSeries:
    """Realise ``noise`` over [0, ``duration``] for a body of ``n_joints`` joints.

    Parameters
    ----------
    noise : MotorNoise
    duration : float
        [s]
    n_joints : int
        [-]

    Returns
    -------
    TorqueSeries
        Knots every 1 / sample_rate from 0 to at least ``duration`` (at least 4).

    Raises
    ------
    ParameterError
        A realisation of more than :data:`MAX_NOISE_KNOTS` samples, or more σ than joints.
    """
    from scipy.interpolate import CubicSpline

    count = max(4, int(math.ceil(duration * noise.sample_rate - 1e-9)) + 1)
    if count > MAX_NOISE_KNOTS:
        raise ParameterError(f"motor noise over {duration:g} s at {noise.sample_rate:g} Hz needs "
                             f"{count:,} samples; at most {MAX_NOISE_KNOTS:,}")
    knots = np.arange(count) / noise.sample_rate
    values = noise_samples(noise, count, n_joints)
    spline = CubicSpline(knots, values, axis=0, bc_type="natural")
    coefficients = np.ascontiguousarray(np.moveaxis(spline.c[::-1], 0, 1))  # (K, 4, N)
    knots.setflags(write=False)
    coefficients.setflags(write=False)
    return TorqueSeries(knots, coefficients)


def torque_at(series: TorqueSeries, t) -> np.ndarray:
    """The torque of ``series`` at times ``t`` (any shape), shape t.shape + (N,); the end
    intervals' cubics carry on outside the knots. [N·m]"""
    t = np.asarray(t, dtype=float)
    k = np.clip(np.searchsorted(series.knots, t, side="right") - 1, 0,
                series.coefficients.shape[0] - 1)
    u = (t - series.knots[k])[..., None]
    c = series.coefficients[k]  # t.shape + (4, N)
    return c[..., 0, :] + u * (c[..., 1, :] + u * (c[..., 2, :] + u * c[..., 3, :]))
