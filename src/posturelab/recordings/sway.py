"""The body's centre-of-mass sway angle about the ankle from markers or force plates.

Each function returns ``com_angle`` [rad] in posturelab's convention
(docs/conventions.md): the angle from the vertical through the ankle to the body's centre
of mass (feet excluded, as in the model), positive leaning forward. Positions are given in
the sagittal plane as ``forward`` and ``up`` coordinates [m]; which lab axis is forward is
declared by the caller (``posturelab convert --forward``), never guessed.

Three methods:

``segments``
    Winter's (2009) segment table (Dempster's data, Table 4.1; the table posturelab ships
    in ``data/bmc_bsp`` and uses in :mod:`posturelab.model.anthropometry`): the centres of
    mass of both legs (ankle–knee markers, at 0.567 of the length from the ankle), both
    thighs (knee–hip, 0.567 from the knee) and head-arms-trunk (hip–shoulder, 0.626 from the
    hip), weighted by their mass fractions 2 × 0.0465, 2 × 0.100 and 0.678. The subject's
    mass cancels from the angle and the lengths come from the markers, so height and mass
    are not needed. On markers placed on the model's joints this reproduces the model's
    centre of mass exactly (tests/test_recordings.py: to 1e-12 rad).
``two-marker``
    Hip and shoulder markers only (the common minimal set: sway measured at hip and shoulder
    level): the same table with the knee taken on the ankle–hip line (legs and thighs one
    segment, centre of mass at the fraction :func:`lower_body_fraction` of ankle–hip).
    **This reduction is posturelab's own**: searches of the literature (for a hip–shoulder
    or sacrum-marker estimate of the CoM sway angle with a published error) found no source
    to cite, so no published error is given; the error below is our measurement. Its error
    comes from the knee's flexion: on a simulated PRTS trial of a three-link Winter body
    (knee angle 0.011 rad RMS, sway 0.085 rad RMS) 0.42 % of the sway's RMS
    (tests/test_recordings.py); it grows with the knee's motion, and is nil for a body
    straight from ankle to shoulder (tests/test_recordings_hostile.py). When only forward
    positions of hip and shoulder are recorded, their heights above the ankle come from
    the subject's height by Winter's Fig. 4.1 (after Drillis & Contini 1966: greater
    trochanter 0.530 H, shoulder 0.818 H, lateral malleolus 0.039 H).
``cop``
    Force plates only: the inverted-pendulum relation between the centre of pressure and
    the centre of mass, ẍ_G = ω₀² (x_G − x_P) with ω₀² = m g h / I_A (m the body's mass,
    h its centre-of-mass height above the ankle, I_A its moment of inertia about the
    ankle), applied in the frequency domain: X_G(f) = X_P(f) ω₀² / (ω₀² + (2πf)²) — the
    low-pass filter method of Caron, Faure & Brenière (1997), "Estimating the centre of
    gravity of the body on the basis of the centre of pressure in standing posture",
    J Biomech 30(11–12):1169–1171, after Brenière (1996). h and I_A come from Winter's table
    scaled to the subject's height and mass (the one-link lump of
    :func:`posturelab.model.anthropometry.body_from_anthropometry`). The mean is removed
    (the ankle's position on the plate is unknown), so the angle is about the mean posture;
    it ignores the body's bending, which a multi-link body has, and assumes the record is
    periodic (whole PRTS cycles: the filter is applied by FFT). On the same simulated
    three-link trial (two whole cycles) its error is 0.70 % of the sway's RMS (tests).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from ..model.anthropometry import WINTER_TABLE

__all__ = ["SwaySpec", "SWAY_METHODS", "LANDMARKS", "AXES", "com_angle_segments",
           "com_angle_two_markers", "com_angle_cop", "lower_body_fraction", "LANDMARK_HEIGHTS",
           "WINTER_SEGMENTS"]

#: The sway methods, with what each needs.
SWAY_METHODS = {
    "segments": "ankle, knee, hip and shoulder markers (Winter 2009 Table 4.1)",
    "two-marker": "hip and shoulder markers (ankle marker or its position; Winter 2009 "
                  "reduced by posturelab, no published validation)",
    "cop": "a force plate's centre of pressure, height and mass (Caron et al. 1997)",
}

#: The landmarks a marker may be named for. [-]
LANDMARKS = ("ankle", "knee", "hip", "shoulder")
#: The landmarks each method needs. [-]
NEEDS = {"segments": LANDMARKS, "two-marker": ("hip", "shoulder"), "cop": ()}
#: Lab axes a marker coordinate may be taken along (a leading - flips it).
AXES = ("x", "y", "z", "-x", "-y", "-z")


@dataclass(frozen=True)
class SwaySpec:
    """How ``com_angle`` is computed from a recording's markers or force plate (what
    ``posturelab convert --sway`` and ``frf --sway`` are given), checked when made.

    Attributes
    ----------
    method : str
        ``segments``, ``two-marker`` or ``cop`` (:data:`SWAY_METHODS`).
    markers : tuple of (str, str)
        (landmark, marker label) pairs: ankle, knee, hip, shoulder.
    plate : int
        The force plate ``cop`` uses (1-based). [-]
    forward, up : str
        The lab axes (x, y, z, a leading - flips) pointing forward and up.
    height, mass : float or None
        The subject's height [m] and mass [kg] (``cop``; ``two-marker`` on forward
        positions only).
    """

    method: str
    markers: tuple[tuple[str, str], ...] = field(default=())
    plate: int = 1
    forward: str = "x"
    up: str = "z"
    height: float | None = None
    mass: float | None = None

    def __post_init__(self) -> None:
        if self.method not in SWAY_METHODS:
            raise ParameterError(f"unknown sway method {self.method!r}; known: "
                                 + ", ".join(SWAY_METHODS))
        for a in (self.forward, self.up):
            if a not in AXES:
                raise ParameterError(f"an axis must be one of {', '.join(AXES)}, got {a!r}")
        if self.forward.lstrip("-") == self.up.lstrip("-"):
            raise ParameterError(f"the forward and up axes must differ, got {self.forward} "
                                 f"and {self.up}")
        for k, _ in self.markers:
            if k not in LANDMARKS:
                raise ParameterError(f"unknown landmark {k!r} in --markers; known: "
                                     + ", ".join(LANDMARKS))
        given = dict(self.markers)
        missing = [n for n in NEEDS[self.method] if n not in given]
        if missing:
            raise ParameterError(f"--sway {self.method} needs the "
                                 f"{', '.join(NEEDS[self.method])} markers (--markers "
                                 f"{'=LABEL,'.join(NEEDS[self.method])}=LABEL or "
                                 f"--{missing[0]}-marker LABEL); {missing[0]} not given")
        if self.method == "cop" and (self.height is None or self.mass is None):
            raise ParameterError("--sway cop needs --height [m] and --mass [kg]")
        if not isinstance(self.plate, int) or self.plate < 1:
            raise ParameterError(f"the force plate must be a number >= 1, got {self.plate!r}")

    def options(self) -> dict:
        """:func:`posturelab.recordings.convert.convert_recording`'s sway options."""
        return {"sway": self.method, "markers": dict(self.markers), "plate": self.plate,
                "forward": self.forward, "up": self.up, "height": self.height,
                "mass": self.mass}


#: Winter (2009) Table 4.1, from posturelab.model.anthropometry.WINTER_TABLE (stated once
#: there): per segment, (mass fraction of both sides together [-], centre of mass from the
#: segment's lower end as a fraction of its length [-], length as a fraction of height [-]).
WINTER_SEGMENTS = {name: (WINTER_TABLE[key][0] * WINTER_TABLE[key][4], WINTER_TABLE[key][2],
                          WINTER_TABLE[key][1])
                   for name, key in (("leg", "leg"), ("thigh", "thigh"), ("hat", "torso"))}
#: Heights of landmarks as fractions of standing height: the lateral malleolus at 0.039 H
#: (Winter 2009 Fig. 4.1, after Drillis & Contini 1966) and the knee, hip (greater
#: trochanter) and shoulder above it by the table's segment lengths (0.285, 0.530 and
#: 0.818 H, as Fig. 4.1 gives them). [-]
LANDMARK_HEIGHTS = dict(zip(("ankle", "knee", "hip", "shoulder"), np.cumsum(
    [0.039, *(WINTER_SEGMENTS[n][2] for n in ("leg", "thigh", "hat"))]).tolist(), strict=True))


def _xz(p, name: str) -> np.ndarray:
    a = np.asarray(p, dtype=float)
    if a.ndim != 2 or a.shape[1] != 2:
        raise ParameterError(f"marker {name} must have shape (samples, 2) [forward, up] "
                             f"[m], got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ParameterError(f"marker {name} has a missing (NaN) sample; fill or resample "
                             "first")
    return a


def _angle(com: np.ndarray, ankle: np.ndarray) -> np.ndarray:
    d = com - ankle
    return np.arctan2(d[:, 0], d[:, 1])


def com_angle_segments(ankle, knee, hip, shoulder) -> np.ndarray:
    """Centre-of-mass sway angle from ankle, knee, hip and shoulder markers (Winter 2009).

    Parameters
    ----------
    ankle, knee, hip, shoulder : array_like, shape (S, 2)
        Marker positions, forward and up. [m]

    Returns
    -------
    numpy.ndarray, shape (S,)
        ``com_angle``, positive leaning forward. [rad]
    """
    a, k, h, s = (_xz(p, n) for p, n in ((ankle, "ankle"), (knee, "knee"), (hip, "hip"),
                                         (shoulder, "shoulder")))
    (ml, cl, _), (mt, ct, _), (mh, ch, _) = (WINTER_SEGMENTS[n] for n in ("leg", "thigh", "hat"))
    com = (ml * (a + cl * (k - a)) + mt * (k + ct * (h - k)) + mh * (h + ch * (s - h))) \
        / (ml + mt + mh)
    return _angle(com, a)


def lower_body_fraction() -> float:
    """Centre of mass of both legs and thighs together along ankle–hip, from the ankle, as a
    fraction of the ankle–hip length, with Winter's segment lengths (leg 0.246 H, thigh
    0.245 H) on a straight knee. [-]"""
    (ml, cl, leg), (mt, ct, thigh) = WINTER_SEGMENTS["leg"], WINTER_SEGMENTS["thigh"]
    return float((ml * cl * leg + mt * (leg + ct * thigh)) / ((ml + mt) * (leg + thigh)))


def com_angle_two_markers(hip, shoulder, ankle=None, *, height: float | None = None
                          ) -> np.ndarray:
    """Centre-of-mass sway angle from hip and shoulder markers (two segments, Winter 2009).

    Parameters
    ----------
    hip, shoulder : array_like, shape (S, 2) or (S,)
        Marker positions, forward and up [m]; or forward positions only (then ``height`` is
        needed and the heights come from Winter's Fig. 4.1 fractions).
    ankle : array_like, shape (S, 2) or (S,) or (2,), optional
        The ankle's position (forward, up) or forward position [m] (default 0, and
        0.039 H up when only forward positions are given).
    height : float, optional
        The subject's standing height [m], for forward-only positions.

    Returns
    -------
    numpy.ndarray, shape (S,)
        ``com_angle``, positive leaning forward. [rad]
    """
    hip_a, sh_a = np.asarray(hip, dtype=float), np.asarray(shoulder, dtype=float)
    if hip_a.ndim == 1:
        if height is None:
            raise ParameterError("--height is required for --sway two-marker from forward "
                                 "positions only (the subject's height in 0.5 … 2.5 m)")
        if not 0.5 <= float(height) <= 2.5:
            raise ParameterError("two-marker sway from forward positions only needs the "
                                 f"subject's height in 0.5 … 2.5 m, got {float(height):g}")
        hgt = float(height)
        ax = np.zeros_like(hip_a) if ankle is None else np.broadcast_to(
            np.asarray(ankle, dtype=float), hip_a.shape)
        lengths = [(LANDMARK_HEIGHTS["hip"] - LANDMARK_HEIGHTS["ankle"]) * hgt,
                   (LANDMARK_HEIGHTS["shoulder"] - LANDMARK_HEIGHTS["hip"]) * hgt]
        dx1, dx2 = hip_a - ax, sh_a - hip_a
        for d, n, ln in ((dx1, "hip", lengths[0]), (dx2, "shoulder", lengths[1])):
            if np.any(np.abs(d) >= ln):
                raise ParameterError(f"the {n} marker moves further than its segment's "
                                     f"length ({ln:.3g} m for height {hgt:g} m): check the "
                                     "units and the ankle position")
        a = np.stack([ax, np.zeros_like(ax)], axis=1)
        h = a + np.stack([dx1, np.sqrt(lengths[0] ** 2 - dx1 ** 2)], axis=1)
        s = h + np.stack([dx2, np.sqrt(lengths[1] ** 2 - dx2 ** 2)], axis=1)
    else:
        h, s = _xz(hip_a, "hip"), _xz(sh_a, "shoulder")
        a = np.zeros_like(h) if ankle is None else np.broadcast_to(
            np.asarray(ankle, dtype=float), h.shape)
    (ml, _, _), (mt, _, _), (mh, ch, _) = (WINTER_SEGMENTS[n] for n in ("leg", "thigh", "hat"))
    cl = lower_body_fraction()
    com = ((ml + mt) * (a + cl * (h - a)) + mh * (h + ch * (s - h))) / (ml + mt + mh)
    return _angle(com, a)


def pendulum_frequency(height: float, mass: float, gravity: float = 9.81) -> tuple[float, float]:
    """ω₀² = m g h / I_A [1/s²] and h [m] of the subject lumped to one link (Winter 2009)."""
    from ..model.anthropometry import body_from_anthropometry, one_link

    body = one_link(body_from_anthropometry(height, mass, gravity=gravity))
    m, k, inertia = (float(body.masses[0]), float(body.com_distances[0]),
                     float(body.inertias[0]))
    return m * gravity * k / (inertia + m * k * k), k


def com_angle_cop(cop, rate: float, *, height: float, mass: float,
                  gravity: float = 9.81) -> np.ndarray:
    """Centre-of-mass sway angle from the centre of pressure (Caron et al. 1997).

    Parameters
    ----------
    cop : array_like, shape (S,)
        Forward position of the centre of pressure, uniformly sampled. [m]
    rate : float
        Sample rate. [Hz]
    height, mass : float
        The subject's standing height [m] and mass [kg].
    gravity : float
        [m/s²]

    Returns
    -------
    numpy.ndarray, shape (S,)
        ``com_angle`` about the mean posture (mean removed), positive forward. [rad]
    """
    p = np.asarray(cop, dtype=float)
    if p.ndim != 1 or p.size < 8 or not np.all(np.isfinite(p)):
        raise ParameterError("the centre of pressure must be a finite series of at least 8 "
                             "samples [m]")
    w0sq, h = pendulum_frequency(height, mass, gravity)
    x = p - p.mean()
    f = np.fft.rfftfreq(x.size, 1.0 / float(rate))
    xg = np.fft.irfft(np.fft.rfft(x) * w0sq / (w0sq + (2 * np.pi * f) ** 2), n=x.size)
    return np.arctan2(xg, h)
