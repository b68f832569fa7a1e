"""Segments and bodies: validated, immutable parameters of a planar chain of N links.

A :class:`Body` is a chain of N >= 1 rigid links hinged at their ends, standing
on a foot that stays flat on the platform (see :mod:`posturelab.conventions`).
Link 1 is the lowest. Bodies only hold parameters; the physics lives in
:mod:`posturelab.model.dynamics` as pure functions.

Presets
-------
``"paper"``
    Appendix A of the ankle-strategy paper: leg, thigh, torso (65.59 kg).

Use :func:`get_body` or :data:`BODY_PRESETS`; an unknown name raises an
error that lists the known ones.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .._validation import finite_float, positive_float
from ..conventions import STANDARD_GRAVITY
from ..errors import ParameterError, UnknownNameError

__all__ = ["Segment", "Body", "BodyPreset", "BODY_PRESETS", "get_body", "paper_body"]


#: Most links a body may have (the compiled engine's straight-line code covers 1–3; the
#: general code is O(N³) per evaluation). [-]
MAX_LINKS = 12


@dataclass(frozen=True)
class Segment:
    """One rigid link of the chain.

    Parameters
    ----------
    name : str
        Label, e.g. ``"leg"``.
    mass : float
        Mass of the link. [kg]
    length : float
        Distance from the lower to the upper joint. [m]
    com_distance : float
        Distance of the centre of mass from the lower joint, along the link;
        the paper's ``k_i``. Must lie within [0, length]. [m]
    inertia : float
        Moment of inertia about the centre of mass, sagittal axis; the
        paper's ``I_i``. [kg·m²]
    """

    name: str
    mass: float
    length: float
    com_distance: float
    inertia: float

    def __post_init__(self) -> None:
        label = f"segment {self.name!r}"
        object.__setattr__(self, "mass", positive_float(f"{label} mass [kg]", self.mass))
        object.__setattr__(self, "length", positive_float(f"{label} length [m]", self.length))
        inertia = positive_float(f"{label} inertia [kg·m²]", self.inertia)
        object.__setattr__(self, "inertia", inertia)
        com = finite_float(f"{label} com_distance [m]", self.com_distance)
        if not 0.0 <= com <= self.length:
            raise ParameterError(
                f"{label} com_distance [m] must be in [0, length={self.length:g}], got {com!r}"
            )
        object.__setattr__(self, "com_distance", com)


@dataclass(frozen=True)
class Body:
    """A planar chain of N links, lowest first.

    Parameters
    ----------
    segments : sequence of Segment
        The links, from the lowest (link 1, leg) up. N = len(segments) >= 1.
    name : str, optional
        Label of the body.
    citation : str, optional
        Where the numbers come from.
    gravity : float, optional
        Gravitational acceleration, positive. [m/s²]

    Notes
    -----
    The derived arrays follow the N-link closed form of docs/design.md (see
    :mod:`posturelab.model.dynamics`): ``a_i = m_i k_i + (Σ_{j>i} m_j) l_i`` [kg·m],
    the diagonal of J(0) ``I_i + m_i k_i² + (Σ_{j>i} m_j) l_i²`` [kg·m²] and the
    coupling ``c_ij = l_i a_j`` (i < j) [kg·m²].
    """

    segments: tuple[Segment, ...]
    name: str = "custom"
    citation: str = ""
    gravity: float = STANDARD_GRAVITY

    def __post_init__(self) -> None:
        segs = tuple(self.segments)
        if len(segs) < 1:
            raise ParameterError("segments must hold at least 1 link, got 0")
        if len(segs) > MAX_LINKS:
            raise ParameterError(f"a body has at most {MAX_LINKS} links, got {len(segs)}")
        for s in segs:
            if not isinstance(s, Segment):
                raise ParameterError(f"segments must be Segment objects, got {type(s).__name__}")
        object.__setattr__(self, "segments", segs)
        object.__setattr__(self, "gravity", positive_float("gravity [m/s²]", self.gravity))

    # ---- construction -------------------------------------------------
    @classmethod
    def from_arrays(
        cls,
        masses: Sequence[float],
        lengths: Sequence[float],
        com_distances: Sequence[float],
        inertias: Sequence[float],
        *,
        names: Sequence[str] | None = None,
        name: str = "custom",
        citation: str = "",
        gravity: float = STANDARD_GRAVITY,
    ) -> Body:
        """Build a body from per-link arrays (lowest link first).

        Parameters
        ----------
        masses : sequence of float
            Link masses. [kg]
        lengths : sequence of float
            Link lengths. [m]
        com_distances : sequence of float
            Centre-of-mass distances from the lower joint. [m]
        inertias : sequence of float
            Inertias about each centre of mass. [kg·m²]
        names : sequence of str, optional
            Link names; default ``link1 … linkN``.
        """
        labels = ["masses", "lengths", "com_distances", "inertias"]
        arrays = []
        for lab, values in zip(labels, (masses, lengths, com_distances, inertias), strict=True):
            if isinstance(values, str) or np.ndim(values) != 1:
                raise ParameterError(
                    f"{lab} must be a sequence with one value per link, got {values!r}"
                )
            arrays.append(list(values))
        n = len(arrays[0])
        for lab, arr in zip(labels, arrays, strict=True):
            if len(arr) != n:
                raise ParameterError(f"{lab} must have {n} entries (one per link), got {len(arr)}")
        if names is None:
            names = [f"link{i + 1}" for i in range(n)]
        if len(names) != n:
            raise ParameterError(f"names must have {n} entries, got {len(names)}")
        segs = tuple(
            Segment(str(nm), m, l, k, i)
            for nm, m, l, k, i in zip(names, *arrays, strict=True)
        )
        return cls(segs, name=name, citation=citation, gravity=gravity)

    # ---- per-link arrays ------------------------------------------------
    @property
    def n_links(self) -> int:
        """Number of links N. [-]"""
        return len(self.segments)

    @cached_property
    def masses(self) -> np.ndarray:
        """Link masses, lowest first. [kg]"""
        return _ro(np.array([s.mass for s in self.segments]))

    @cached_property
    def lengths(self) -> np.ndarray:
        """Link lengths. [m]"""
        return _ro(np.array([s.length for s in self.segments]))

    @cached_property
    def com_distances(self) -> np.ndarray:
        """Centre-of-mass distances from each link's lower joint (paper's k_i). [m]"""
        return _ro(np.array([s.com_distance for s in self.segments]))

    @cached_property
    def inertias(self) -> np.ndarray:
        """Inertias about each centre of mass (paper's I_i). [kg·m²]"""
        return _ro(np.array([s.inertia for s in self.segments]))

    @cached_property
    def total_mass(self) -> float:
        """Sum of link masses (the foot is massless). [kg]"""
        return float(self.masses.sum())

    @cached_property
    def mass_above(self) -> np.ndarray:
        """For each link i, the mass of all links above it, Σ_{j>i} m_j. [kg]"""
        m = self.masses
        return _ro(np.concatenate([np.cumsum(m[::-1])[::-1][1:], [0.0]]))

    @cached_property
    def gravity_coefficients(self) -> np.ndarray:
        """a_i = m_i k_i + (Σ_{j>i} m_j) l_i, the entries of G and H at 0 / 90°. [kg·m]"""
        return _ro(self.masses * self.com_distances + self.mass_above * self.lengths)

    @cached_property
    def inertia_diagonal(self) -> np.ndarray:
        """J_ii = I_i + m_i k_i² + (Σ_{j>i} m_j) l_i² (posture independent). [kg·m²]"""
        return _ro(
            self.inertias
            + self.masses * self.com_distances**2
            + self.mass_above * self.lengths**2
        )

    @cached_property
    def coupling(self) -> np.ndarray:
        """c_ij = l_min(i,j) a_max(i,j) for i != j, zero on the diagonal. [kg·m²]

        J_ij = c_ij cos(θ_j − θ_i) off the diagonal.
        """
        n = self.n_links
        c = np.zeros((n, n))
        a = self.gravity_coefficients
        l = self.lengths
        for i in range(n):
            for j in range(i + 1, n):
                c[i, j] = c[j, i] = l[i] * a[j]
        return _ro(c)

    @cached_property
    def load_stiffness(self) -> float:
        """mgh = g Σ a_i: the gravitational 'load stiffness' of the straight body
        as an inverted pendulum about the ankle. [N·m/rad]"""
        return float(self.gravity * self.gravity_coefficients.sum())

    @cached_property
    def com_height(self) -> float:
        """Height of the centre of mass above the ankle when upright. [m]"""
        return float(self.gravity_coefficients.sum() / self.total_mass)

    def with_gravity(self, gravity: float) -> Body:
        """A copy of this body under another gravitational acceleration [m/s²]."""
        return Body(self.segments, name=self.name, citation=self.citation, gravity=gravity)

    def describe(self) -> str:
        """A short multi-line table of the body's parameters, with units."""
        lines = [f"{self.name}: {self.n_links} links, {self.total_mass:.2f} kg"]
        lines.append(f"{'link':<8}{'m [kg]':>9}{'l [m]':>8}{'k [m]':>8}{'I [kg·m²]':>11}")
        for s in self.segments:
            lines.append(
                f"{s.name:<8}{s.mass:>9.3f}{s.length:>8.3f}{s.com_distance:>8.3f}{s.inertia:>11.3f}"
            )
        return "\n".join(lines)

    def upright_matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """J(0) [kg·m²], shape (N, N), and g·a [N·m/rad], shape (N,): the inertia matrix and
        gravity's stiffness per link upright (:func:`upright_matrices` of this body)."""
        return upright_matrices(self.masses, self.lengths, self.com_distances, self.inertias,
                                self.gravity)


def upright_matrices(masses, lengths, com_distances, inertias, gravity
                     ) -> tuple[np.ndarray, np.ndarray]:
    """The inertia matrix upright J(0) and gravity's stiffness per link g·a, batched.

    J_ii = I_i + m_i k_i² + (Σ_{j>i} m_j) l_i², J_ij = l_min(i,j) a_max(i,j) for i != j, and
    a_i = m_i k_i + (Σ_{j>i} m_j) l_i (the formulas of :class:`Body`, in the same order).

    Parameters
    ----------
    masses, lengths, com_distances, inertias : array_like, shape (..., N)
        [kg], [m], [m], [kg·m²]
    gravity : float or array_like, shape (...)
        [m/s²]

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        J(0), shape (..., N, N) [kg·m²]; g·a, shape (..., N) [N·m/rad].
    """
    m, l, k, inertia = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (
        masses, lengths, com_distances, inertias)))
    n = m.shape[-1]
    above = np.concatenate([np.cumsum(m[..., ::-1], axis=-1)[..., ::-1][..., 1:],
                            np.zeros(m.shape[:-1] + (1,))], axis=-1)
    a = m * k + above * l
    index = np.arange(n)
    jac = l[..., np.minimum.outer(index, index)] * a[..., np.maximum.outer(index, index)]
    jac[..., index, index] = inertia + m * k**2 + above * l**2
    return jac, np.asarray(gravity, dtype=float)[..., None] * a


def _ro(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


# ---------------------------------------------------------------------------
# Presets
# ---------------------------------------------------------------------------

PAPER_CITATION = (
    "Quantitative Analysis of the Ankle Strategy Under Translational Platform "
    "Disturbance, Appendix A (physical parameters of the three-link biped)"
)


def paper_body(gravity: float = STANDARD_GRAVITY) -> Body:
    """The paper's three-link biped (Appendix A): leg, thigh, torso.

    Masses 5.05 / 18.67 / 41.87 kg, lengths 0.401 / 0.412 / 0.619 m, centre
    of mass 0.21 / 0.26 / 0.24 m from the lower joint, inertias
    0.17 / 0.5 / 2.1 kg·m², g = 9.81 m/s².

    Parameters
    ----------
    gravity : float, optional
        Gravitational acceleration. [m/s²]

    Examples
    --------
    >>> import posturelab as pl
    >>> body = pl.paper_body()
    >>> body.n_links, [s.name for s in body.segments]
    (3, ['leg', 'thigh', 'torso'])
    >>> round(body.total_mass, 2), round(body.load_stiffness, 1)  # [kg], mgh [N·m/rad]
    (65.59, 564.0)
    """
    return Body.from_arrays(
        masses=[5.05, 18.67, 41.87],
        lengths=[0.401, 0.412, 0.619],
        com_distances=[0.21, 0.26, 0.24],
        inertias=[0.17, 0.5, 2.1],
        names=["leg", "thigh", "torso"],
        name="paper",
        citation=PAPER_CITATION,
        gravity=gravity,
    )


@dataclass(frozen=True)
class BodyPreset:
    """A named body with its citation."""

    name: str
    factory: Callable[[], Body]
    citation: str
    description: str


BODY_PRESETS: dict[str, BodyPreset] = {
    "paper": BodyPreset(
        "paper", paper_body, PAPER_CITATION,
        "three-link leg/thigh/torso biped of the ankle-strategy paper, 65.59 kg",
    ),
}


def register_body_preset(preset: BodyPreset) -> None:
    """Add a preset to :data:`BODY_PRESETS` (used by :mod:`posturelab.model.anthropometry`)."""
    BODY_PRESETS[preset.name] = preset


def get_body(name: str) -> Body:
    """Return the preset body called ``name``.

    Raises
    ------
    UnknownNameError
        If ``name`` is not a preset; the message lists the known names.
    """
    try:
        preset = BODY_PRESETS[name]
    except KeyError:
        known = ", ".join(sorted(BODY_PRESETS))
        raise UnknownNameError(f"unknown body preset {name!r}; known presets: {known}") from None
    return preset.factory()
