"""Pack a run's set-up into the plain arrays the compiled kernels take (layouts in
:mod:`._layout`)."""

from __future__ import annotations

import math

import numpy as np

from ...errors import ParameterError
from ...model.body import Body
from ...model.platform import Disturbance, NoDisturbance
from ..setup import RunSetup
from ._layout import (
    DIST_ROW,
    DIST_SAMPLES,
    DIST_SINE,
    DIST_TERM_FIELDS,
    DIST_WINDOWED_SINE,
    F_ATOL,
    F_DURATION,
    F_HEEL,
    F_MAX_ANGLE,
    F_MAX_STEP,
    F_RTOL,
    F_SETTLE_TOL,
    F_STOP_ANGLE,
    F_TIME_LIMIT,
    F_TOE,
    I_KNEE_MODE,
    I_LOCKED0,
    I_MAX_STEPS,
    I_MAX_SWITCHES,
    I_USE_BOS,
    I_USE_COP,
    KNEE_FREE,
    KNEE_LOCKED,
    KNEE_STOP,
    N_FPAR,
    N_IPAR,
    TILT_PPOLY,
    TILT_RAISED_COSINE,
    TILT_ROW,
    TILT_SINE,
    TILT_TERM_FIELDS,
    body_size,
)

_KINDS = {"windowed-sine": DIST_WINDOWED_SINE, "sine": DIST_SINE}


def readonly(arr) -> np.ndarray:
    """A C-contiguous float or int array the kernels may not write (one compiled form)."""
    out = np.ascontiguousarray(arr)
    if out.flags.writeable:
        out = out.copy() if out is arr else out
        out.setflags(write=False)
    return out


def encode_disturbance(disturbance: Disturbance | None) -> np.ndarray:
    """``dp``: the disturbance's :class:`~posturelab.model.platform.Primitive` terms packed."""
    d = NoDisturbance() if disturbance is None else disturbance
    try:
        terms = d.primitives()
    except NotImplementedError:
        raise ParameterError(
            f"the compiled engine cannot run a disturbance of type {type(d).__name__}: it "
            "defines no primitives() (see posturelab.model.platform); use engine='reference'"
        ) from None
    rows: list[list[float]] = []
    profiles: list[tuple[int, np.ndarray]] = []
    for q in terms:
        if q.kind == "samples":
            time, ax, ay = (np.asarray(a, dtype=float) for a in q.samples)
            rows.append([DIST_SAMPLES, 0, -1.0, float(time.size), 0.0, 0.0])
            profiles.append((len(rows) - 1, np.concatenate([time, ax, ay])))
        elif q.kind in DIST_TERM_FIELDS:
            code = DIST_WINDOWED_SINE if q.kind == "windowed-sine" else DIST_SINE
            row = [code, q.axis, *(getattr(q, f) for f in DIST_TERM_FIELDS[q.kind])]
            rows.append(row + [0.0] * (DIST_ROW - len(row)))
        else:
            raise ParameterError(f"unknown kind of platform motion term {q.kind!r}")
    offset = 1 + DIST_ROW * len(rows)
    for row_index, data in profiles:
        rows[row_index][2] = float(offset)  # where this profile's times start in dp
        offset += data.size
    packed = np.concatenate([[float(len(rows))], np.array(rows, float).ravel()]
                            + [data for _, data in profiles])
    return readonly(packed.astype(float))


def encode_tilt(tilt) -> np.ndarray:
    """``tp``: the tilt's :class:`~posturelab.model.tilt.TiltTerm` terms packed ([0] for none)."""
    if tilt is None:
        return readonly(np.zeros(1))
    rows: list[list[float]] = []
    data: list[tuple[int, np.ndarray]] = []
    for q in tilt.terms():
        if q.kind in TILT_TERM_FIELDS:
            code = TILT_SINE if q.kind == "sine" else TILT_RAISED_COSINE
            row = [code, *(getattr(q, f) for f in TILT_TERM_FIELDS[q.kind])]
            rows.append(row + [0.0] * (TILT_ROW - len(row)))
        elif q.kind == "ppoly":
            knots = np.asarray(q.knots, dtype=float)
            coefficients = np.asarray(q.coefficients, dtype=float)
            rows.append([TILT_PPOLY, -1.0, float(coefficients.shape[0]), q.period, 0.0, 0.0,
                         0.0])
            data.append((len(rows) - 1, np.concatenate([knots, coefficients.ravel()])))
        else:
            raise ParameterError(f"unknown kind of tilt term {q.kind!r}")
    offset = 1 + TILT_ROW * len(rows)
    for row_index, block in data:
        rows[row_index][1] = float(offset)
        offset += block.size
    packed = np.concatenate([[float(len(rows))], np.array(rows, float).ravel()]
                            + [block for _, block in data])
    return readonly(packed)


def encode_motor_noise(series) -> np.ndarray:
    """``mp``: a :class:`~posturelab.model.noise.TorqueSeries` packed ([0] for none)."""
    if series is None:
        return readonly(np.zeros(1))
    K = series.coefficients.shape[0]
    return readonly(np.concatenate([[float(K)], series.knots, series.coefficients.ravel()]))


def body_array(body: Body) -> np.ndarray:
    """``bp``: a_i [kg·m], J_ii [kg·m²], c_ij row-major [kg·m²], g [m/s²], Σm [kg]."""
    n = body.n_links
    bp = np.zeros(body_size(n))
    bp[:n] = body.gravity_coefficients
    bp[n:2 * n] = body.inertia_diagonal
    bp[2 * n:2 * n + n * n] = body.coupling.ravel()
    bp[2 * n + n * n] = body.gravity
    bp[2 * n + n * n + 1] = body.total_mass
    return readonly(bp)


def options(setup: RunSetup, settle_tolerance: float = 0.01) -> tuple[np.ndarray, np.ndarray]:
    """The kernels' scalar options ``fpar`` (floats) and ``ipar`` (int64) of a run."""
    fall, knee = setup.fall, setup.knee
    fpar = np.zeros(N_FPAR)
    fpar[F_MAX_ANGLE] = fall.max_link_angle
    bos = fall.base_of_support
    fpar[F_HEEL] = bos.heel if bos is not None else -math.inf
    fpar[F_TOE] = bos.toe if bos is not None else math.inf
    fpar[F_STOP_ANGLE] = knee.stop_angle
    fpar[F_RTOL] = setup.rtol
    fpar[F_ATOL] = setup.atol
    fpar[F_MAX_STEP] = min(  # the C driver caps it at the run's delay itself
        setup.disturbance.max_step, setup.duration,
        setup.tilt.max_step if setup.tilt is not None else math.inf,
        setup.visual_tilt.max_step if setup.visual_tilt is not None else math.inf,
        setup.motor_noise.max_step if setup.motor_noise is not None else math.inf)
    fpar[F_DURATION] = setup.duration
    fpar[F_SETTLE_TOL] = settle_tolerance
    fpar[F_TIME_LIMIT] = setup.time_limit
    ipar = np.zeros(N_IPAR, dtype=np.int64)
    ipar[I_USE_BOS] = 1 if bos is not None else 0
    ipar[I_USE_COP] = 1 if fall.centre_of_pressure else 0
    ipar[I_KNEE_MODE] = {"free": KNEE_FREE, "locked": KNEE_LOCKED, "stop": KNEE_STOP}[knee.mode]
    ipar[I_MAX_SWITCHES] = setup.max_switches
    ipar[I_LOCKED0] = 1 if setup.locked0 else 0
    ipar[I_MAX_STEPS] = setup.max_steps
    return readonly(fpar), readonly(ipar)


def limits(torque_limits: np.ndarray | None, n: int) -> np.ndarray:
    """Torque limits per joint, inf where none. [N·m]"""
    if torque_limits is None:
        return np.full(n, math.inf)
    return np.asarray(torque_limits, dtype=float)
