"""The base of every platform disturbance: :class:`Disturbance`, the terms the compiled engine
evaluates (:class:`Primitive`; :class:`ProfileTerm`, the fields it shares with a tilt's terms)
and their formulas, and the platform's bounds. The disturbances themselves are in
:mod:`.platform`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validation import finite_float
from ..errors import ParameterError

__all__ = ["ProfileTerm", "Primitive", "Disturbance", "NoDisturbance", "windowed_sine_formula",
           "sine_formula", "MAX_PLATFORM_ACCELERATION", "MIN_PROFILE_SPACING"]

def _axis(axis: str) -> int:
    if axis not in ("x", "y"):
        raise ParameterError(f"axis must be 'x' (horizontal) or 'y' (vertical), got {axis!r}")
    return 0 if axis == "x" else 1


# MAX_PLATFORM_SPEED [m/s], the largest platform velocity step, is the parameter table's
# (posturelab.parameters).
#: Largest platform acceleration of a profile, pulse, ramp or sum of sines: posturelab's bound
#: (not a source's), the largest velocity step (:data:`MAX_PLATFORM_SPEED`) reached in 20 ms,
#: about 100 g. [m/s²]
MAX_PLATFORM_ACCELERATION = 1000.0
#: Closest two samples of a measured profile may be: a 1 MHz recording (posturelab's bound;
#: closer samples stall the integrator at its smallest step). [s]
MIN_PROFILE_SPACING = 1e-6


def _check_acceleration(name: str, peak: float) -> None:
    """ParameterError unless |``peak``| <= :data:`MAX_PLATFORM_ACCELERATION` [m/s²]."""
    if not abs(peak) <= MAX_PLATFORM_ACCELERATION:
        raise ParameterError(f"{name} must be within ±{MAX_PLATFORM_ACCELERATION:g} m/s², got "
                             f"{peak:g}")


@dataclass(frozen=True)
class ProfileTerm:
    """What a term of a platform acceleration (:class:`Primitive`) and a term of a tilt
    (:class:`~posturelab.model.tilt.TiltTerm`) share, in the form the engines evaluate: its
    kind, a sine's amplitude, frequency and phase, a window's start and duration.

    Attributes
    ----------
    kind : str
        The term's formula (each subclass lists its kinds).
    amplitude : float
        [m/s²] for a platform term, [rad] for a tilt term.
    frequency : float
        [Hz]
    phase : float
        [rad]
    start, duration : float
        The window of a windowed sine, or the ramp of a raised cosine. [s]
    """

    kind: str
    amplitude: float = 0.0
    frequency: float = 0.0
    phase: float = 0.0
    start: float = 0.0
    duration: float = 0.0


@dataclass(frozen=True)
class Primitive(ProfileTerm):
    """One term of a platform acceleration (the fields of :class:`ProfileTerm`, amplitude in
    [m/s²], and these).

    Attributes
    ----------
    kind : {"windowed-sine", "sine", "samples"}
        ``windowed-sine``: a(t) = amplitude · sin(2π · cycles · s) for
        s = (t − start)/duration in [0, 1], zero elsewhere; ``sine``:
        a(t) = amplitude · sin(2π · frequency · t + phase); ``samples``: linear
        interpolation of (time, x, y), zero outside.
    axis : int
        0 horizontal (x), 1 vertical (y); unused for samples (both axes). [-]
    cycles : float
        Sine cycles within the window (½ a half-sine, 1 a ramp-and-hold). [-]
    samples : tuple of numpy.ndarray, optional
        (time [s], x acceleration [m/s²], y acceleration [m/s²]).
    """

    axis: int = 0
    cycles: float = 0.0
    samples: tuple | None = None


def windowed_sine_formula(t, amplitude, duration, start, cycles, xp=np):
    """A windowed sine's acceleration (:class:`Primitive` ``windowed-sine``): amplitude ·
    sin(2π · cycles · s), s = (t − start) / duration in [0, 1], zero outside; over a math
    namespace ``xp`` (numpy, or sympy when the C is generated). [m/s²]"""
    s = (t - start) / duration
    return xp.where((s >= 0) & (s <= 1), amplitude * xp.sin(2 * np.pi * cycles * s), 0.0)


def sine_formula(t, amplitude, frequency, phase, xp=np):
    """A sine's acceleration (:class:`Primitive` ``sine``): amplitude · sin(2π · frequency ·
    t + phase). [m/s²]"""
    return amplitude * xp.sin(2 * np.pi * frequency * t + phase)


class Disturbance:
    """Base class: no velocity change, zero acceleration, no breakpoints."""

    #: (Δẋ_d, Δẏ_d) applied at t = 0. [m/s]
    velocity_change: tuple[float, float] = (0.0, 0.0)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Times where the acceleration profile has a corner. [s]"""
        return ()

    @property
    def max_step(self) -> float:
        """Largest integrator step that resolves the profile (inf if any). [s]"""
        return math.inf

    def acceleration(self, t: np.ndarray | float) -> np.ndarray:
        """Platform acceleration (ẍ_d, ÿ_d) at ``t``, shape (..., 2). [m/s²]"""
        t = np.asarray(t, dtype=float)
        return np.zeros(t.shape + (2,))

    def describe(self) -> str:
        """One-line human description with units."""
        return "no platform motion"

    def primitives(self) -> tuple[Primitive, ...]:
        """The acceleration as a sum of :class:`Primitive` terms (none for the base class,
        which does not move; a subclass that moves and does not define this cannot run on
        the compiled engine)."""
        if type(self) is Disturbance:
            return ()
        raise NotImplementedError(type(self).__name__)

    def scaled(self, factor: float) -> Disturbance:
        """The same motion with every amplitude multiplied by ``factor`` [-].

        The velocity step's speed, a pulse's peak, a ramp's displacement, the
        sines' amplitudes and a measured profile's accelerations scale; times,
        durations and frequencies (and so the breakpoints) do not. A negative
        factor reverses the motion; 0 leaves the platform still. A subclass
        that does not define how it scales is refused.
        """
        raise ParameterError(f"{type(self).__name__} does not define how to scale itself "
                             "(a scaled() method)")


@dataclass(frozen=True)
class NoDisturbance(Disturbance):
    """The platform stays still."""

    def scaled(self, factor: float) -> NoDisturbance:
        finite_float("factor [-]", factor)
        return self

    def primitives(self) -> tuple[Primitive, ...]:
        return ()
