"""Which strategy a run uses: the ankle (in-phase) and hip (anti-phase) modes of leg and trunk.

Definition (after Creath et al. 2005, *Neurosci. Lett.* 377:75–80, who found in-phase and
anti-phase coordination of the leg and trunk angles co-existing in quiet and perturbed
stance): with u(t) and w(t) the leg angle θ_1 and the trunk angle θ_N [rad] less their
values at the start,

    ankle mode  a(t) = (u + w)/2     (leg and trunk lean together)
    hip mode    b(t) = (u − w)/2     (they counter-rotate about the hip)

so that u = a + b and w = a − b. The **hip fraction** of a run is Σ b² / (Σ a² + Σ b²) over
its samples (equally spaced in time): 0 for a body that sways as one rigid pendulum, 1 for
pure counter-rotation, and 0 when nothing moves. Creath et al. measured the modes by the
relative phase of leg and trunk over frequency; the hip fraction is our time-domain share of
the anti-phase mode, defined for any run and any N >= 2 (NaN for a one-link body, which has
only the ankle mode). Knee motion (θ_2 of the three-link body) is not part of it.

:func:`hip_fraction_study` asks the paper's question of its Section VII ("the knee and hip
strategies when the ankle torque is limited"): with an ankle torque limit, how the hip
fraction grows with the size of a backward platform translation (a ramp-and-hold of given
displacement), on the compiled engine.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import finite_array, float_in_range
from ..errors import ParameterError
from ..model.kinematics import hip_fraction, strategy_modes  # (defined with the kinematics)
from ..model.limits import limit_entries

__all__ = ["strategy_modes", "hip_fraction", "HipFractionStudy", "hip_fraction_study",
           "CREATH_2005_CITATION", "RUNGE_1999_CITATION", "MAX_STUDY_RUNS",
           "HORAK_NASHNER_1986_CITATION", "StrategyRun", "MAX_SPEED", "MAX_FREQUENCY",
           "oscillation_duration", "lowest_frequency", "StrategyMap", "translation_map",
           "oscillation_map", "translation_profile", "oscillation_profile", "limit_maps",
           "maps_to_dict"]

CREATH_2005_CITATION = (
    "Creath R, Kiemel T, Horak F, Peterka R, Jeka J (2005) A unified view of quiet and "
    "perturbed stance: simultaneous co-existing excitable modes. Neurosci Lett 377:75–80"
)
RUNGE_1999_CITATION = (
    "Runge CF, Shupert CL, Horak FB, Zajac FE (1999) Ankle and hip postural strategies "
    "defined by joint torques. Gait Posture 10:161–170 (backward translations of a flat "
    "surface: hip torques join the ankle's at the faster translations)"
)
HORAK_NASHNER_1986_CITATION = (
    "Horak FB, Nashner LM (1986) Central programming of postural movements: adaptation to "
    "altered support-surface configurations. J Neurophysiol 55:1369–1381 (ramp translations "
    "of the support surface, a few cm, at a range of velocities: ankle strategy for the slow, "
    "hip strategy for the fast and on a short surface)"
)
#: Most runs :func:`hip_fraction_study` accepts. [-]
MAX_STUDY_RUNS = 10_000


@dataclass(frozen=True)
class HipFractionStudy:
    """Hip fraction against the size of a backward translation, with an ankle torque limit.

    Attributes
    ----------
    displacement : numpy.ndarray, shape (K,)
        Backward platform displacement of each run (ramp and hold). [m]
    hip_fraction : numpy.ndarray, shape (K,)
        [-]
    fell : numpy.ndarray of bool, shape (K,)
    peak_ankle_moment : numpy.ndarray, shape (K,)
        Largest |net ankle moment| of the run (at most the limit). [N·m]
    ankle_torque_limit : float
        [N·m]
    ramp_duration : float
        Time of the ramp. [s]
    """

    displacement: np.ndarray
    hip_fraction: np.ndarray
    fell: np.ndarray
    peak_ankle_moment: np.ndarray
    ankle_torque_limit: float
    ramp_duration: float

    def first_above(self, level: float) -> float | None:
        """The smallest displacement of a run that did not fall whose hip fraction exceeds
        ``level`` [-]; None if none does. [m]"""
        ok = (~self.fell) & (self.hip_fraction > level)
        return float(self.displacement[ok][0]) if ok.any() else None


def hip_fraction_study(body, muscles, displacements, *, ankle_torque_limit: float,
                       ramp_duration: float = 0.5, duration: float = 3.0, fall=None,
                       **run_options) -> HipFractionStudy:
    """Run a backward ramp-and-hold of each displacement with the ankle moment limited to
    ``ankle_torque_limit`` and measure each run's hip fraction (compiled engine).

    Parameters
    ----------
    body : Body
        N >= 2 links.
    muscles : MuscleSet
    displacements : array_like, shape (K,)
        Backward displacements, > 0, at most :data:`MAX_STUDY_RUNS` of them. [m]
    ankle_torque_limit : float
        Largest net ankle moment, > 0. [N·m]
    ramp_duration : float
        [s]
    duration : float
        Simulated time of each run. [s]
    fall : FallCriteria, optional
    **run_options
        Passed to :func:`posturelab.simulate` (``initial_state``, ``knee``,
        ``feedback_delay``, …).
    """
    from ..model.platform import RampAndHold
    from ..simulation.engines import simulate

    if body.n_links < 2:
        raise ParameterError("the hip fraction needs a body with at least 2 links")
    d = finite_array("displacements [m]", displacements, (None,))
    if d.size == 0 or d.size > MAX_STUDY_RUNS or np.any(d <= 0):
        raise ParameterError(f"displacements [m] must be 1 … {MAX_STUDY_RUNS:,} values > 0")
    limit = float_in_range("ankle_torque_limit [N·m]", ankle_torque_limit, 1e-6, 1e6)
    limits = np.full(body.n_links, np.inf)
    limits[0] = limit
    fractions, fell, peaks = [], [], []
    for x in d:
        r = simulate(body, muscles, RampAndHold(-float(x), ramp_duration), duration,
                     torque_limits=limits, fall=fall, engine="compiled", **run_options)
        fractions.append(hip_fraction(r.theta))
        fell.append(r.fell)
        peaks.append(float(np.abs(r.joint_moments[:, 0]).max()))
    return HipFractionStudy(d, np.array(fractions), np.array(fell), np.array(peaks), limit,
                            float(ramp_duration))


# ---------------------------------------------------------------------------
# Strategy maps: families of translations (transient and sinusoidal)
# ---------------------------------------------------------------------------


#: The displacement of each transient translation of :func:`translation_map` by default:
#: posturelab's choice of "a few cm" (Horak & Nashner 1986). [m]
DEFAULT_TRANSLATION = 0.06
#: Cycles of a sinusoidal translation left out before its steady part. [-]
SETTLE_CYCLES = 2
#: Cycles of the steady part (at least :data:`MIN_STEADY_TIME`). [-]
STEADY_CYCLES = 3
#: Shortest steady part of a sinusoidal run. [s]
MIN_STEADY_TIME = 4.0
#: Hip fraction above which the hip mode dominates (transition_frequency). [-]
HIP_DOMINATES = 0.5
#: Largest peak speed of a transient translation (:func:`translation_profile`). [m/s]
MAX_SPEED = 10.0
#: Highest frequency of a sinusoidal translation (:func:`oscillation_profile`). [Hz]
MAX_FREQUENCY = 20.0


def oscillation_duration(frequency: float) -> float:
    """Simulated time of one run of :func:`oscillation_map` at ``frequency`` [Hz]:
    :data:`SETTLE_CYCLES` cycles, then :data:`STEADY_CYCLES` and at least
    :data:`MIN_STEADY_TIME`. [s]"""
    return SETTLE_CYCLES / frequency + max(STEADY_CYCLES / frequency, MIN_STEADY_TIME)


def lowest_frequency(sample_rate: float = 1000.0) -> float:
    """The lowest frequency [Hz] whose :func:`oscillation_duration` a run can record at
    ``sample_rate`` [Hz]: floor(duration × rate) + 1 <= the most output samples of a run
    (:data:`posturelab.simulation.options.MAX_OUTPUT_SAMPLES`)."""
    from ..simulation.options import MAX_OUTPUT_SAMPLES

    longest = (MAX_OUTPUT_SAMPLES - 1) / sample_rate  # [s]
    # the slow branch: (SETTLE + STEADY) / f <= longest (there 3/f >= MIN_STEADY_TIME)
    return (SETTLE_CYCLES + STEADY_CYCLES) / longest


def translation_profile(speed: float, direction: str, displacement: float = DEFAULT_TRANSLATION):
    """A transient translation: :class:`~posturelab.model.platform.RampAndHold` of
    ``displacement`` D [m] whose peak velocity 2D/T is ``speed`` [m/s] (T = 2D/speed), backward
    (negative) or forward (after Horak & Nashner 1986's ramp translations, whose size and
    velocities posturelab does not copy)."""
    from ..model.platform import RampAndHold

    if direction not in ("backward", "forward"):
        raise ParameterError(f"translation must be 'backward' or 'forward', got {direction!r}")
    v = float_in_range("speed [m/s]", speed, 0.0, MAX_SPEED, include_low=False)
    d = float_in_range("displacement [m]", displacement, 0.0, 2.0, include_low=False)
    return RampAndHold(-d if direction == "backward" else d, 2.0 * d / v)


def oscillation_profile(amplitude: float, frequency: float):
    """A sinusoidal translation x_d = A sin(2π f t) as its acceleration
    −A (2π f)² sin(2π f t) (:class:`~posturelab.model.platform.SumOfSines`; the platform's mean
    velocity drifts by −A 2π f, which the body does not feel: only ẍ_d enters the model).
    ``amplitude`` A [m], ``frequency`` f [Hz]."""
    from ..model.platform import SumOfSines

    a = float_in_range("amplitude [m]", amplitude, 0.0, 1.0, include_low=False)
    f = float_in_range("frequency [Hz]", frequency, 0.0, MAX_FREQUENCY, include_low=False)
    return SumOfSines((-a * (2 * np.pi * f) ** 2,), (f,))


@dataclass(frozen=True)
class StrategyRun:
    """One run of a strategy map.

    Attributes
    ----------
    value : float
        The family's variable: the speed [m/s] or the frequency [Hz].
    hip_fraction : float
        Over the run (transient) or over its steady part (sinusoidal); NaN for a run that
        fell or failed, or that did not move. [-]
    outcome : str
        "recovered", "fell" or "failed".
    peak_ankle_moment : float
        Largest |net ankle moment|. [N·m]
    ankle_saturated : bool
        The ankle reached its torque limit.
    peak_hip_angle : float
        Largest |θ_N − θ_1| (the hip's joint angle). [rad]
    """

    value: float
    hip_fraction: float
    outcome: str
    peak_ankle_moment: float
    ankle_saturated: bool
    peak_hip_angle: float


@dataclass(frozen=True)
class StrategyMap:
    """Hip fraction across a family of translations.

    Attributes
    ----------
    kind : str
        "translation" or "oscillation".
    variable : str
        "speed" [m/s] or "frequency" [Hz].
    runs : tuple of StrategyRun
    profile : str
        The profile in words, with its source.
    ankle_torque_limit : float
        The ankle's plantarflexion limit (positive moments) [N·m] (inf: none).
    ankle_dorsiflexion_limit : float or None
        The magnitude of its dorsiflexion limit (negative moments) when it differs
        (:mod:`posturelab.model.limits`); None: the same as ``ankle_torque_limit``. [N·m]
    """

    kind: str
    variable: str
    runs: tuple
    profile: str
    ankle_torque_limit: float
    ankle_dorsiflexion_limit: float | None = None

    @property
    def transition_frequency(self) -> float | None:
        """The first value at which the hip mode dominates (hip fraction > 0.5) in a run that
        did not fall; None if none. [Hz] or [m/s]"""
        for r in self.runs:
            if r.outcome == "recovered" and r.hip_fraction > HIP_DOMINATES:
                return r.value
        return None

    def to_dict(self) -> dict:
        """``{"runs": [{"speed" or "frequency": …, "hip_fraction": …, "outcome": …, …}],
        …}`` with units."""
        runs = [{self.variable: r.value, "hip_fraction": r.hip_fraction, "outcome": r.outcome,
                 "peak_ankle_moment": r.peak_ankle_moment,
                 "ankle_saturated": r.ankle_saturated, "peak_hip_angle": r.peak_hip_angle}
                for r in self.runs]
        out = {"runs": runs, "profile": self.profile,
               "ankle_torque_limit": (None if np.isinf(self.ankle_torque_limit)
                                      else self.ankle_torque_limit),
               "units": {self.variable: "m/s" if self.variable == "speed" else "Hz",
                         "hip_fraction": "-", "peak_ankle_moment": "N·m",
                         "peak_hip_angle": "rad", "ankle_torque_limit": "N·m"}}
        if self.ankle_dorsiflexion_limit is not None:
            out["ankle_dorsiflexion_limit"] = (None if np.isinf(self.ankle_dorsiflexion_limit)
                                               else self.ankle_dorsiflexion_limit)
            out["units"]["ankle_dorsiflexion_limit"] = "N·m"
        if self.kind == "oscillation":
            out["transition_frequency"] = self.transition_frequency
        return out


def _run_record(result, value: float, limit: float, start: int = 0,
                lower: float | None = None) -> StrategyRun:
    theta = result.theta
    outcome = ("fell" if result.fell else "recovered" if result.status == "completed"
               else "failed")
    moment = result.joint_moments[:, 0]
    ankle = np.abs(moment)
    peak = float(ankle.max()) if ankle.size else 0.0
    lower = limit if lower is None else lower
    saturated = ankle.size > 0 and bool(
        (np.isfinite(limit) and moment.max() >= limit * (1 - 1e-9))
        or (np.isfinite(lower) and moment.min() <= -lower * (1 - 1e-9)))
    hip = np.abs(theta[:, -1] - theta[:, 0])
    steady = theta[start:]
    # a run that fell (or failed) has no strategy to speak of: NaN (null in JSON), in every
    # map and in sweep --strategy alike
    share = (float(hip_fraction(steady)) if outcome == "recovered" and steady.shape[0] > 1
             else float("nan"))
    return StrategyRun(float(value), share, outcome, peak, saturated,
                       float(hip.max()) if hip.size else 0.0)


def _limits(body, ankle_torque_limit, torque_limits, fall=None
            ) -> tuple[tuple, float, float | None]:
    """The runs' ``torque_limits`` entries, the ankle's plantarflexion limit and the
    magnitude of its dorsiflexion limit if it differs (None), [N·m]; ``ankle_torque_limit``
    a number (both ways), a pair (lower, upper) or "foot" (needs ``fall``'s foot)."""
    from ..model.limits import NEGATIVE, POSITIVE, body_torque_limits

    n = body.n_links
    entries = [np.inf] * n if torque_limits is None else list(limit_entries(torque_limits))
    if ankle_torque_limit is not None:
        entries[0] = (float_in_range("ankle_torque_limit [N·m]", ankle_torque_limit, 1e-6, 1e6)
                      if np.ndim(ankle_torque_limit) == 0 and not isinstance(
                          ankle_torque_limit, str) else limit_entries([ankle_torque_limit])[0])
    bounds = body_torque_limits(entries, body, None if fall is None else fall.base_of_support)
    if bounds is None:
        return tuple(entries), float("inf"), None
    upper, lower = float(bounds[POSITIVE, 0]), float(bounds[NEGATIVE, 0])
    return tuple(entries), upper, None if lower == upper else lower


def translation_map(body, muscles, speeds, *, direction: str = "backward",
                    displacement: float = DEFAULT_TRANSLATION, duration: float = 4.0,
                    ankle_torque_limit: float | None = None, torque_limits=None,
                    progress=None, **run_options) -> StrategyMap:
    """Hip fraction against the speed of a transient translation
    (:func:`translation_profile`), one run per speed.

    Parameters
    ----------
    body : Body
        N >= 2 links.
    muscles : MuscleSet
    speeds : array_like, shape (K,)
        Peak platform speeds, > 0, at most :data:`MAX_STUDY_RUNS`. [m/s]
    direction : {"backward", "forward"}
    displacement : float
        [m]
    duration : float
        Simulated time of each run. [s]
    ankle_torque_limit : float, (lower, upper) or "foot", optional
        The ankle's limit, both ways, per side (lower < 0 < upper: dorsiflexion,
        plantarflexion), or from the foot of ``fall`` (else ``torque_limits``' or none). [N·m]
    torque_limits : sequence, optional
        As :func:`posturelab.simulate`'s. [N·m]
    progress : callable(done, total), optional
    **run_options
        Passed to :func:`posturelab.simulate` (``feedback_delay``, ``joint_feedback``,
        ``knee``, ``fall``, ``engine``, …).
    """
    from ..simulation.engines import simulate

    values = _values("speeds [m/s]", speeds, body)
    limits, limit, lower = _limits(body, ankle_torque_limit, torque_limits,
                                   run_options.get("fall"))
    runs = []
    for i, v in enumerate(values):
        r = simulate(body, muscles, translation_profile(v, direction, displacement), duration,
                     torque_limits=limits, **run_options)
        runs.append(_run_record(r, v, limit, lower=lower))
        if progress is not None:
            progress(i + 1, values.size)
    return StrategyMap("translation", "speed", tuple(runs),
                       f"{direction} ramp-and-hold of {displacement:g} m, peak speed 2D/T "
                       f"(after {HORAK_NASHNER_1986_CITATION})", limit, lower)


def oscillation_map(body, muscles, amplitude: float, frequencies, *,
                    ankle_torque_limit: float | None = None, torque_limits=None,
                    progress=None, **run_options) -> StrategyMap:
    """Hip fraction over the steady part of sinusoidal translations of ``amplitude`` [m]
    (:func:`oscillation_profile`) at each frequency [Hz]: each run lasts
    :data:`SETTLE_CYCLES` + :data:`STEADY_CYCLES` cycles (the steady part at least
    :data:`MIN_STEADY_TIME`), the first :data:`SETTLE_CYCLES` left out. Other arguments as
    :func:`translation_map`."""
    from ..simulation.engines import simulate

    values = _values("frequencies [Hz]", frequencies, body)
    limits, limit, lower = _limits(body, ankle_torque_limit, torque_limits,
                                   run_options.get("fall"))
    runs = []
    for i, f in enumerate(values):
        settle = SETTLE_CYCLES / f
        duration = oscillation_duration(f)
        r = simulate(body, muscles, oscillation_profile(amplitude, f), duration,
                     torque_limits=limits, **run_options)
        start = int(np.searchsorted(r.time, settle))
        runs.append(_run_record(r, f, limit, start, lower))
        if progress is not None:
            progress(i + 1, values.size)
    return StrategyMap("oscillation", "frequency", tuple(runs),
                       f"sinusoidal translation of amplitude {amplitude:g} m, the hip fraction "
                       f"after {SETTLE_CYCLES} cycles", limit, lower)


def _values(name: str, values, body) -> np.ndarray:
    if body.n_links < 2:
        raise ParameterError("the hip fraction needs a body with at least 2 links")
    v = finite_array(name, values, (None,))
    if v.size == 0 or v.size > MAX_STUDY_RUNS or np.any(v <= 0):
        raise ParameterError(f"{name} must be 1 … {MAX_STUDY_RUNS:,} values > 0")
    return v


def limit_maps(make, limits) -> tuple:
    """A two-parameter map: ``make(ankle_torque_limit=L)`` (a :func:`translation_map` or
    :func:`oscillation_map` with its other arguments bound) for each ankle torque limit L in
    ``limits`` [N·m]; one :class:`StrategyMap` per limit."""
    values = finite_array("ankle torque limits [N·m]", limits, (None,))
    if values.size == 0 or values.size > MAX_STUDY_RUNS or np.any(values <= 0):
        raise ParameterError(f"ankle torque limits [N·m] must be 1 … {MAX_STUDY_RUNS:,} values "
                             "> 0")
    return tuple(make(ankle_torque_limit=float(v)) for v in values)


def maps_to_dict(maps) -> dict:
    """Maps over ankle torque limits as one object: every run with its
    ``ankle_torque_limit`` [N·m], and the transition frequency per limit (sinusoidal) as
    ``transition_frequencies``: [{"ankle_torque_limit", "frequency"}] (a single map's
    ``transition_frequency`` is one number or None)."""
    first = maps[0].to_dict()
    runs = [{**run, "ankle_torque_limit": m.ankle_torque_limit}
            for m in maps for run in m.to_dict()["runs"]]
    out = {"runs": runs, "profile": first["profile"], "units": first["units"]}
    if maps[0].kind == "oscillation":
        out["transition_frequencies"] = [{"ankle_torque_limit": m.ankle_torque_limit,
                                        "frequency": m.transition_frequency} for m in maps]
    return out
