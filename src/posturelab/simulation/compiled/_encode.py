"""Turn posturelab objects into the plain arrays the compiled kernels take."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import ParameterError
from ...model.body import Body
from ...model.events import RELEASE_HYSTERESIS as _RELEASE_HYSTERESIS
from ...model.events import SWITCH_HYSTERESIS as _SWITCH_HYSTERESIS
from ...model.muscles import MuscleSet
from ...model.options import FallCriteria, KneeModel
from ...model.platform import (
    CombinedDisturbance,
    Disturbance,
    HalfSinePulse,
    MeasuredProfile,
    NoDisturbance,
    RampAndHold,
    SumOfSines,
    VelocityStep,
)
from . import _kernels as kern

_AXIS = {"x": 0, "y": 1}


@dataclass(frozen=True)
class EncodedDisturbance:
    """A disturbance packed for the kernels.

    Attributes
    ----------
    packed : numpy.ndarray
        ``dp`` of :mod:`._kernels`: the number of components Q, then Q rows
        (kind, axis, p0, p1, p2), then measured profiles. [s, m/s², Hz, rad]
    breakpoints : tuple of float
        Corners of the acceleration profile. [s]
    max_step : float
        Largest step that resolves the profile (inf if any). [s]
    velocity_change : tuple of float
        (Δẋ_d, Δẏ_d) at t = 0. [m/s]
    """

    packed: np.ndarray
    breakpoints: tuple[float, ...]
    max_step: float
    velocity_change: tuple[float, float]


def _components(d: Disturbance, rows: list, profiles: list) -> None:
    if isinstance(d, CombinedDisturbance):
        for part in d.parts:
            _components(part, rows, profiles)
    elif isinstance(d, NoDisturbance | VelocityStep) or type(d) is Disturbance:
        return  # no acceleration (a velocity step only sets the initial rates)
    elif isinstance(d, HalfSinePulse):
        rows.append([kern.DIST_HALF_SINE, _AXIS[d.axis], d.peak_acceleration, d.duration,
                     d.start])
    elif isinstance(d, RampAndHold):
        rows.append([kern.DIST_RAMP_AND_HOLD, _AXIS[d.axis], d.peak_acceleration, d.duration,
                     d.start])
    elif isinstance(d, SumOfSines):
        for amp, freq, phase in zip(d.amplitudes, d.frequencies, d.phases, strict=True):
            rows.append([kern.DIST_SINE, _AXIS[d.axis], amp, freq, phase])
    elif isinstance(d, MeasuredProfile):
        rows.append([kern.DIST_PROFILE, 0, -1.0, float(d.time.size), 0.0])
        profiles.append((len(rows) - 1, np.concatenate(
            [np.asarray(d.time, float), np.asarray(d.acceleration_x, float),
             np.asarray(d.acceleration_y, float)])))
    else:
        raise ParameterError(
            f"the fast simulator cannot compile a disturbance of type {type(d).__name__}; "
            "use posturelab.simulate.simulate for it (supported: velocity step, half-sine, "
            "ramp-and-hold, sum of sines, measured profile, and their combinations)"
        )


def encode_disturbance(disturbance: Disturbance | None) -> EncodedDisturbance:
    """Pack ``disturbance`` (None: the platform stays still) for the kernels."""
    d = NoDisturbance() if disturbance is None else disturbance
    rows: list = []
    profiles: list = []
    _components(d, rows, profiles)
    offset = 1 + 5 * len(rows)
    for row_index, data in profiles:
        rows[row_index][2] = float(offset)  # where this profile's times start in dp
        offset += data.size
    packed = np.concatenate([[float(len(rows))], np.array(rows, float).ravel()]
                            + [data for _, data in profiles])
    vc = d.velocity_change
    packed = np.ascontiguousarray(packed, dtype=float)
    packed.setflags(write=False)
    return EncodedDisturbance(packed,
                              tuple(float(b) for b in d.breakpoints), float(d.max_step),
                              (float(vc[0]), float(vc[1])))


def model_array(body: Body) -> np.ndarray:
    """``mp`` of :mod:`._kernels` with K = L = 0: a, J_ii, c_ij, K, L, g (SI units)."""
    n = body.n_links
    mp = np.zeros(2 * n + 3 * n * n + 1)
    mp[:n] = body.gravity_coefficients
    mp[n:2 * n] = body.inertia_diagonal
    mp[2 * n:2 * n + n * n] = body.coupling.ravel()
    mp[-1] = body.gravity
    return mp


def pair_layout(muscles: MuscleSet) -> tuple[np.ndarray, np.ndarray]:
    """(E (P, N) [-], one_sided (P,) as 0/1 int64)."""
    return (np.ascontiguousarray(muscles.selection_matrix),
            muscles.one_sided_mask.astype(np.int64))


def crossings(muscles: MuscleSet) -> np.ndarray:
    """(P, N): 1 where pair r crosses joint j (0 = ankle), as in simulate._assemble."""
    crosses = np.zeros((len(muscles.pairs), muscles.n_links))
    for r, p in enumerate(muscles.pairs):
        crosses[r, p.lo:p.hi] = 1.0
    return crosses


def control_arrays(
    body: Body, fall: FallCriteria, knee: KneeModel, *, rtol: float, atol: float,
    max_step: float, duration: float, max_switches: int, locked0: bool,
    settle_tolerance: float, method: str = "Radau",
) -> tuple[np.ndarray, np.ndarray]:
    """The kernels' scalar parameters ``fpar`` (floats) and ``ipar`` (int64)."""
    fpar = np.zeros(kern.N_FPAR)
    fpar[kern.F_GRAVITY] = body.gravity
    fpar[kern.F_TOTAL_MASS] = body.total_mass
    fpar[kern.F_MAX_ANGLE] = fall.max_link_angle
    bos = fall.base_of_support
    fpar[kern.F_HEEL] = bos.heel if bos is not None else -math.inf
    fpar[kern.F_TOE] = bos.toe if bos is not None else math.inf
    fpar[kern.F_STOP_ANGLE] = knee.stop_angle
    fpar[kern.F_RTOL] = rtol
    fpar[kern.F_ATOL] = atol
    fpar[kern.F_MAX_STEP] = max_step
    fpar[kern.F_DURATION] = duration
    fpar[kern.F_SWITCH_HYST] = _SWITCH_HYSTERESIS
    fpar[kern.F_RELEASE_HYST] = _RELEASE_HYSTERESIS
    fpar[kern.F_SETTLE_TOL] = settle_tolerance
    ipar = np.zeros(kern.N_IPAR, dtype=np.int64)
    ipar[kern.I_USE_BOS] = 1 if bos is not None else 0
    ipar[kern.I_KNEE_MODE] = {"free": kern.KNEE_FREE, "locked": kern.KNEE_LOCKED,
                              "stop": kern.KNEE_STOP}[knee.mode]
    ipar[kern.I_MAX_SWITCHES] = max_switches
    ipar[kern.I_LOCKED0] = 1 if locked0 else 0
    ipar[kern.I_METHOD] = {"RK45": kern.METHOD_RK45, "RK23": kern.METHOD_RK23,
                           "Radau": kern.METHOD_RADAU}[method]
    return fpar, ipar
