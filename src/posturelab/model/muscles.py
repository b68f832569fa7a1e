"""Agonist–antagonist muscle pairs as joint-space stiffness and viscosity.

A co-activated pair is named by the two links it spans, (lo, hi) with
lo < hi and 0 the foot. Its stretch is θ_hi − θ_lo (its row of the matrix E,
paper eq. 4). Pair torques and joint torques (paper Appendix C)::

    M = K_d E Θ + L_d E Θ̇          [N·m]   (one entry per pair)
    U = −Eᵀ M                       [N·m]   (one entry per link)
    K = Eᵀ K_d E,  L = Eᵀ L_d E     (paper eq. 5)

A *one-sided* pair acts only while its stretch is >= 0 (the real
gastrocnemius, which acts while θ2 >= 0); a *two-sided* pair acts always
(the paper's "artificial antagonist").

Two kinds of feedback per pair. The *intrinsic* stiffness and viscosity (``stiffness``,
``viscosity``: the muscles' visco-elasticity) act at once on the stretch relative to the
foot. The *active* (neural) stiffness and viscosity (``active_stiffness``,
``active_viscosity``) act on the state a feedback delay τ earlier. A muscle set with no
active gains at all (every pair's ``None``, the paper's model) reads its pair gains as the
whole feedback: a run's ``feedback_delay`` then delays all of it, as before the split.
:func:`feedback_gains` states the rule once: it gives the (immediate, delayed) gains every
engine uses.

Table I's nine stiffness sets are the presets ``"1" … "7", "6a", "6b"``
(:data:`STIFFNESS_CASES`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from functools import cached_property
from typing import Literal

import numpy as np

from .._validation import finite_array, float_in_range
from ..errors import ParameterError, UnknownNameError
from ..parameters import MAX_PAIR_STIFFNESS, MAX_PAIR_VISCOSITY, check_value

__all__ = [
    "MusclePair",
    "MuscleSet",
    "PAPER_PAIRS",
    "PAPER_PAIR_NAMES",
    "GASTROCNEMIUS_FORMS",
    "STIFFNESS_CASES",
    "TABLE_I_CITATION",
    "DEFAULT_VISCOSITY_RATIO",
    "paper_muscles",
    "get_stiffness_case",
    "joint_pair_names",
    "muscles_for",
]

#: Viscosity as a fraction of stiffness used throughout the paper (Appendix C). [s]
DEFAULT_VISCOSITY_RATIO = 0.25

Gastrocnemius = Literal["two-sided", "one-sided", "pull-only"]

#: The gastrocnemius pair's forms (:func:`paper_muscles`): name -> (one_sided, pull_only) and
#: what it does.
GASTROCNEMIUS_FORMS: dict[str, tuple[bool, bool, str]] = {
    "two-sided": (False, False, "acts for either sign of θ2 (the paper's artificial "
                  "antagonist added; the paper's analysis and Figs. 3–8)"),
    "one-sided": (True, False, "acts only while its stretch θ2 ≥ 0, slack while θ2 < 0 (the "
                  "paper's real gastrocnemius, section V.C)"),
    "pull-only": (True, True, "acts only while θ2 ≥ 0 and its torque k θ2 + l θ̇2 pulls: it "
                  "also goes slack while it would push (a muscle cannot push; beyond the "
                  "paper)"),
}


# Largest pair stiffness [N·m/rad] and viscosity [N·m·s/rad], intrinsic or active: the
# parameter table's (posturelab.parameters)


@dataclass(frozen=True)
class MusclePair:
    """One co-activated agonist–antagonist pair.

    Parameters
    ----------
    name : str
        Label, e.g. ``"ankle"``.
    lo, hi : int
        Links spanned, ``0 <= lo < hi``; 0 is the foot. The stretch is
        θ_hi − θ_lo. [-]
    stiffness : float
        Pair stiffness, the diagonal entry of K_d. [N·m/rad]
    viscosity : float
        Pair viscosity, the diagonal entry of L_d. [N·m·s/rad]
    one_sided : bool
        If true the pair acts only while its stretch is >= 0.
    active_stiffness : float, optional
        Active (neural, delayed) stiffness; None for none. [N·m/rad]
    active_viscosity : float, optional
        Active (neural, delayed) viscosity; None for none (0 if only the active
        stiffness is given). [N·m·s/rad]
    pull_only : bool
        For a one-sided pair: it also goes slack while its torque k s + l ṡ would be
        negative (a muscle pulls, it cannot push), not only while its stretch is. False by
        default: a one-sided pair switches on its stretch only, as the paper's real
        gastrocnemius does (``gastrocnemius="one-sided"``; True is ``"pull-only"``).
        Ignored for a two-sided pair.
    """

    name: str
    lo: int
    hi: int
    stiffness: float
    viscosity: float
    one_sided: bool = False
    active_stiffness: float | None = None
    active_viscosity: float | None = None
    pull_only: bool = False

    def __post_init__(self) -> None:
        label = f"muscle pair {self.name!r}"
        if not (isinstance(self.lo, int | np.integer) and isinstance(self.hi, int | np.integer)):
            raise ParameterError(
                f"{label} lo and hi must be integers, got {self.lo!r}, {self.hi!r}"
            )
        if not 0 <= self.lo < self.hi:
            raise ParameterError(
                f"{label} span must satisfy 0 <= lo < hi, got (lo, hi) = ({self.lo}, {self.hi})"
            )
        object.__setattr__(self, "lo", int(self.lo))
        object.__setattr__(self, "hi", int(self.hi))
        object.__setattr__(self, "stiffness", float_in_range(
            f"{label} stiffness", self.stiffness, 0.0, MAX_PAIR_STIFFNESS, unit="N·m/rad"))
        object.__setattr__(self, "viscosity", float_in_range(
            f"{label} viscosity", self.viscosity, 0.0, MAX_PAIR_VISCOSITY, unit="N·m·s/rad"))
        object.__setattr__(self, "one_sided", bool(self.one_sided))
        if not isinstance(self.pull_only, bool | np.bool_):
            raise ParameterError(f"{label} pull_only must be true or false, got "
                                 f"{self.pull_only!r}")
        object.__setattr__(self, "pull_only", bool(self.pull_only))
        for field, unit in (("active_stiffness", "N·m/rad"), ("active_viscosity", "N·m·s/rad")):
            value = getattr(self, field)
            if value is not None:
                object.__setattr__(self, field, float_in_range(
                    f"{label} {field.replace('_', ' ')}", value, 0.0,
                    MAX_PAIR_STIFFNESS if field == "active_stiffness" else MAX_PAIR_VISCOSITY,
                    unit=unit))

    @property
    def has_active(self) -> bool:
        """The pair has an active (delayed) part."""
        return self.active_stiffness is not None or self.active_viscosity is not None


@dataclass(frozen=True)
class MuscleSet:
    """The muscle pairs acting on an N-link chain.

    Parameters
    ----------
    pairs : sequence of MusclePair
        The pairs, in the order of the rows of E.
    n_links : int
        Number of links N of the chain they act on; every pair needs hi <= N.
    """

    pairs: tuple[MusclePair, ...]
    n_links: int

    def __post_init__(self) -> None:
        pairs = tuple(self.pairs)
        if not isinstance(self.n_links, int | np.integer) or self.n_links < 1:
            raise ParameterError(f"n_links must be an integer >= 1, got {self.n_links!r}")
        names = [p.name for p in pairs]
        if len(set(names)) != len(names):
            raise ParameterError(f"muscle pair names must be unique, got {names}")
        for p in pairs:
            if p.hi > self.n_links:
                raise ParameterError(
                    f"muscle pair {p.name!r} spans link {p.hi}, but the body has "
                    f"{self.n_links} links (allowed hi: 1..{self.n_links})"
                )
        if any(p.has_active for p in pairs) and any(p.one_sided for p in pairs):
            one = next(p.name for p in pairs if p.one_sided)
            raise ParameterError(
                f"muscle pair {one!r} is one-sided: one-sided pairs cannot be combined with "
                "active (delayed) gains (make it two-sided, or give no active gains)"
            )
        object.__setattr__(self, "pairs", pairs)
        object.__setattr__(self, "n_links", int(self.n_links))

    @property
    def names(self) -> list[str]:
        """Pair names in row order."""
        return [p.name for p in self.pairs]

    @cached_property
    def selection_matrix(self) -> np.ndarray:
        """E, shape (P, N): row p is +1 at link hi and −1 at link lo (if lo >= 1). [-]"""
        E = np.zeros((len(self.pairs), self.n_links))
        for r, p in enumerate(self.pairs):
            E[r, p.hi - 1] += 1.0
            if p.lo >= 1:
                E[r, p.lo - 1] -= 1.0
        E.setflags(write=False)
        return E

    @cached_property
    def crossing_matrix(self) -> np.ndarray:
        """C, shape (P, N): C[p, j] = 1 when pair p crosses joint j (0 = ankle, 1 = knee, …). [-]

        Joint j lies between link j (0 = the foot) and link j + 1; the net muscle
        moment at the joints is τ = Cᵀ M.
        """
        crosses = np.zeros((len(self.pairs), self.n_links))
        for r, p in enumerate(self.pairs):
            crosses[r, p.lo:p.hi] = 1.0
        crosses.setflags(write=False)
        return crosses

    @cached_property
    def stiffnesses(self) -> np.ndarray:
        """Diagonal of K_d. [N·m/rad]"""
        return np.array([p.stiffness for p in self.pairs])

    @cached_property
    def viscosities(self) -> np.ndarray:
        """Diagonal of L_d. [N·m·s/rad]"""
        return np.array([p.viscosity for p in self.pairs])

    @cached_property
    def has_active_feedback(self) -> bool:
        """Some pair has active (delayed) gains: the pair gains are then the intrinsic part
        only (undelayed); without any, a feedback delay applies to the whole pair feedback."""
        return any(p.has_active for p in self.pairs)

    @cached_property
    def active_stiffnesses(self) -> np.ndarray:
        """Active (neural) pair stiffness, 0 where none. [N·m/rad]"""
        return np.array([p.active_stiffness or 0.0 for p in self.pairs])

    @cached_property
    def active_viscosities(self) -> np.ndarray:
        """Active (neural) pair viscosity, 0 where none. [N·m·s/rad]"""
        return np.array([p.active_viscosity or 0.0 for p in self.pairs])

    @cached_property
    def spans_foot(self) -> np.ndarray:
        """True for the pairs with lo = 0 (they span the ankle and feel a platform tilt)."""
        return np.array([p.lo == 0 for p in self.pairs], dtype=bool)

    @cached_property
    def one_sided_mask(self) -> np.ndarray:
        """True for pairs that act only while their stretch is >= 0."""
        return np.array([p.one_sided for p in self.pairs], dtype=bool)

    @property
    def pull_only_mask(self) -> np.ndarray:
        """True for one-sided pairs that also go slack while their torque would push."""
        return np.array([p.one_sided and p.pull_only for p in self.pairs], dtype=bool)

    def stiffness_matrix(self, active: np.ndarray | None = None) -> np.ndarray:
        """Joint-space stiffness K = Eᵀ K_d E (paper eq. 5). [N·m/rad]

        Parameters
        ----------
        active : array_like of bool, shape (P,), optional
            Which pairs act; all by default.
        """
        kd = self.stiffnesses if active is None else self.stiffnesses * np.asarray(active)
        E = self.selection_matrix
        return E.T @ (kd[:, None] * E)

    def viscosity_matrix(self, active: np.ndarray | None = None) -> np.ndarray:
        """Joint-space viscosity L = Eᵀ L_d E. [N·m·s/rad]"""
        ld = self.viscosities if active is None else self.viscosities * np.asarray(active)
        E = self.selection_matrix
        return E.T @ (ld[:, None] * E)

    def stretch(self, theta: np.ndarray) -> np.ndarray:
        """Pair stretches E Θ, shape (..., P). [rad]"""
        return np.asarray(theta, dtype=float) @ self.selection_matrix.T

    def active(self, theta: np.ndarray) -> np.ndarray:
        """Which pairs act at posture ``theta``: two-sided always, one-sided while stretch >= 0."""
        return ~self.one_sided_mask | (self.stretch(theta) >= 0.0)

    def with_stiffness(self, **stiffness: float) -> MuscleSet:
        """A copy with some pairs' stiffness replaced (viscosity unchanged), by pair name."""
        unknown = [k for k in stiffness if k not in self.names]
        if unknown:
            raise UnknownNameError(
                f"unknown muscle pair {unknown[0]!r}; known pairs: {', '.join(self.names)}"
            )
        pairs = tuple(replace(p, stiffness=stiffness.get(p.name, p.stiffness))
                      for p in self.pairs)
        return MuscleSet(pairs, self.n_links)

    def with_active_feedback(self, stiffness: Sequence[float] | None,
                             viscosity: Sequence[float] | None = None) -> MuscleSet:
        """A copy with these active (neural, delayed) gains, one per pair in row order, or
        with none (``stiffness=None``, ``viscosity=None``: the paper's model).

        Parameters
        ----------
        stiffness : sequence of float, shape (P,), or None
            Active pair stiffness. [N·m/rad]
        viscosity : sequence of float, shape (P,), optional
            Active pair viscosity; 0 if only ``stiffness`` is given. [N·m·s/rad]
        """
        P = len(self.pairs)
        if stiffness is None and viscosity is None:
            return MuscleSet(tuple(replace(p, active_stiffness=None, active_viscosity=None)
                                   for p in self.pairs), self.n_links)
        k = (np.zeros(P) if stiffness is None
             else np.atleast_1d(finite_array("active stiffness [N·m/rad]", stiffness)))
        v = (np.zeros(P) if viscosity is None
             else np.atleast_1d(finite_array("active viscosity [N·m·s/rad]", viscosity)))
        for label, arr in (("active stiffness [N·m/rad]", k),
                           ("active viscosity [N·m·s/rad]", v)):
            if arr.shape != (P,):
                raise ParameterError(
                    f"{label} must have {P} values (one per pair: {', '.join(self.names)}), "
                    f"got {arr.size}")
        return MuscleSet(tuple(replace(p, active_stiffness=float(k[i]),
                                       active_viscosity=float(v[i]))
                               for i, p in enumerate(self.pairs)), self.n_links)

    def as_two_sided(self) -> MuscleSet:
        """A copy in which every pair acts on both sides (artificial antagonists added)."""
        return MuscleSet(tuple(replace(p, one_sided=False) for p in self.pairs), self.n_links)

    def without_one_sided(self) -> MuscleSet:
        """A copy with the one-sided pairs removed (their inactive side)."""
        return MuscleSet(tuple(p for p in self.pairs if not p.one_sided), self.n_links)


# ---------------------------------------------------------------------------
# The paper's five pairs and Table I
# ---------------------------------------------------------------------------

#: The paper's five pairs (Appendix C, eq. 4; docs/design.md): name -> (lo, hi, description).
PAPER_PAIRS: dict[str, tuple[int, int, str]] = {
    "ankle": (0, 1, "tibialis anterior – soleus; crosses the ankle"),
    "knee": (1, 2, "vasti – short head of hamstring; crosses the knee"),
    "hip": (2, 3, "paraspinals – abdominals; crosses the hip"),
    "quadriceps": (1, 3, "quadriceps – hamstring, two-joint; crosses knee and hip"),
    "gastrocnemius": (0, 2, "gastrocnemius – tibialis, two-joint; crosses ankle and knee"),
}
PAPER_PAIR_NAMES: tuple[str, ...] = tuple(PAPER_PAIRS)

TABLE_I_CITATION = "Ankle-strategy paper, Table I (muscle synergies K for seven experiments)"

#: Table I: pair stiffness [N·m/rad] in the order ankle, knee, hip, quadriceps, gastrocnemius.
STIFFNESS_CASES: dict[str, tuple[float, float, float, float, float]] = {
    "1": (500.0, 300.0, 300.0, 300.0, 300.0),
    "2": (500.0, 300.0, 300.0, 300.0, 0.0),
    "3": (1000.0, 300.0, 300.0, 300.0, 0.0),
    "4": (1000.0, 0.0, 300.0, 300.0, 300.0),
    "5": (1000.0, 0.0, 300.0, 300.0, 0.0),
    "6": (0.0, 0.0, 300.0, 300.0, 1000.0),
    "6a": (0.0, 0.0, 600.0, 300.0, 1000.0),
    "6b": (0.0, 0.0, 300.0, 600.0, 1000.0),
    "7": (1000.0, 0.0, 0.0, 300.0, 1000.0),
}


def get_stiffness_case(case: str) -> tuple[float, ...]:
    """Table I stiffness set ``case`` (ankle, knee, hip, quadriceps, gastrocnemius). [N·m/rad]

    Raises
    ------
    UnknownNameError
        If ``case`` is not in Table I; the message lists the known cases.
    """
    key = str(case).strip().lower().replace("case", "").replace(" ", "")
    try:
        return STIFFNESS_CASES[key]
    except KeyError:
        raise UnknownNameError(
            f"unknown stiffness case {case!r}; known cases (Table I): "
            f"{', '.join(STIFFNESS_CASES)}"
        ) from None


def paper_muscles(
    case: str | None = None,
    *,
    stiffness: Sequence[float] | Mapping[str, float] | None = None,
    viscosity_ratio: float = DEFAULT_VISCOSITY_RATIO,
    viscosity: Sequence[float] | None = None,
    gastrocnemius: Gastrocnemius = "two-sided",
    active_stiffness: Sequence[float] | None = None,
    active_viscosity: Sequence[float] | None = None,
    active_viscosity_ratio: float | None = None,
) -> MuscleSet:
    """The paper's five pairs on the three-link body.

    Give either a Table I ``case`` or five ``stiffness`` values.

    Parameters
    ----------
    case : str, optional
        Table I case: ``"1" … "7", "6a", "6b"``.
    stiffness : sequence of 5 floats or mapping name -> float, optional
        Pair stiffness in the order ankle, knee, hip, quadriceps,
        gastrocnemius (or by name; missing names are 0). [N·m/rad]
    viscosity_ratio : float, optional
        L_d = ratio · K_d when ``viscosity`` is not given; the paper uses 0.25. [s]
    viscosity : sequence of 5 floats, optional
        Per-pair viscosity, overriding ``viscosity_ratio``. [N·m·s/rad]
    gastrocnemius : {"two-sided", "one-sided", "pull-only"}
        ``"two-sided"`` adds the paper's artificial antagonist; ``"one-sided"``
        lets the gastrocnemius act only while θ2 >= 0 (the paper's real pair,
        ``pull_only=False``); ``"pull-only"`` also lets it go slack while its torque
        would push (``pull_only=True``). See :data:`GASTROCNEMIUS_FORMS`.
    active_stiffness : sequence of 5 floats, optional
        Active (neural, delayed) pair stiffness, same order; none by default (the
        paper's model, whose pair gains are then the whole feedback). [N·m/rad]
    active_viscosity : sequence of 5 floats, optional
        Active pair viscosity. [N·m·s/rad]
    active_viscosity_ratio : float, optional
        Active viscosity = ratio × active stiffness instead (default 0 when only the
        active stiffness is given). [s]

    Returns
    -------
    MuscleSet

    Examples
    --------
    >>> import posturelab as pl
    >>> muscles = pl.paper_muscles("1")  # Table I, case 1
    >>> muscles.names
    ['ankle', 'knee', 'hip', 'quadriceps', 'gastrocnemius']
    >>> [float(k) for k in muscles.stiffnesses]  # [N·m/rad]
    [500.0, 300.0, 300.0, 300.0, 300.0]
    >>> [float(v) for v in muscles.viscosities]  # 0.25 s × stiffness [N·m·s/rad]
    [125.0, 75.0, 75.0, 75.0, 75.0]
    """
    if (case is None) == (stiffness is None):
        raise ParameterError("give exactly one of case (Table I) or stiffness (5 values)")
    if case is not None:
        k = np.array(get_stiffness_case(case))
    elif isinstance(stiffness, Mapping):
        unknown = [n for n in stiffness if n not in PAPER_PAIRS]
        if unknown:
            raise UnknownNameError(
                f"unknown muscle pair {unknown[0]!r}; known pairs: {', '.join(PAPER_PAIR_NAMES)}"
            )
        k = np.array([float(stiffness.get(n, 0.0)) for n in PAPER_PAIR_NAMES])
    else:
        k = _five("stiffness [N·m/rad]", stiffness)
    if viscosity is None:
        ratio = check_value("viscosity_ratio", viscosity_ratio)
        v = ratio * k
    else:
        v = _five("viscosity [N·m·s/rad]", viscosity)
    if gastrocnemius not in GASTROCNEMIUS_FORMS:
        raise ParameterError(
            f"gastrocnemius must be one of {', '.join(map(repr, GASTROCNEMIUS_FORMS))}, got "
            f"{gastrocnemius!r}"
        )
    one_sided, pull_only, _ = GASTROCNEMIUS_FORMS[gastrocnemius]
    pairs = tuple(
        MusclePair(name, lo, hi, float(k[i]), float(v[i]),
                   one_sided=(name == "gastrocnemius" and one_sided),
                   pull_only=(name == "gastrocnemius" and pull_only))
        for i, (name, (lo, hi, _)) in enumerate(PAPER_PAIRS.items())
    )
    return _with_active(MuscleSet(pairs, 3), active_stiffness, active_viscosity,
                        active_viscosity_ratio, _five)


def joint_pair_names(n_links: int) -> tuple[str, ...]:
    """Names of the single-joint pairs of an N-link chain (not the paper's three links):
    ``ankle`` for N = 1; ``ankle, hip`` for N = 2 (the ankle–hip model); ``ankle, knee,
    hip, joint4, …`` beyond."""
    if n_links == 1:
        return ("ankle",)
    if n_links == 2:
        return ("ankle", "hip")
    return ("ankle", "knee", "hip") + tuple(f"joint{j}" for j in range(4, n_links + 1))


def muscles_for(n_links: int, stiffness: Sequence[float], viscosity: Sequence[float] | None = None,
                *, viscosity_ratio: float = DEFAULT_VISCOSITY_RATIO,
                active_stiffness: Sequence[float] | None = None,
                active_viscosity: Sequence[float] | None = None,
                active_viscosity_ratio: float | None = None,
                gastrocnemius: Gastrocnemius = "two-sided") -> MuscleSet:
    """The standard pair layout of an N-link body with these gains: the paper's five pairs
    for N = 3, one pair per joint otherwise (:func:`joint_pair_names`), in that order.

    Parameters
    ----------
    n_links : int
        N. [-]
    stiffness, viscosity : sequence of float, shape (P,)
        Intrinsic (or, without active gains, whole) pair gains; viscosity = ratio ×
        stiffness when not given. [N·m/rad], [N·m·s/rad]
    viscosity_ratio : float
        [s]
    active_stiffness, active_viscosity, active_viscosity_ratio
        As for :func:`paper_muscles`. [N·m/rad], [N·m·s/rad], [s]
    gastrocnemius : {"two-sided", "one-sided", "pull-only"}
        N = 3 only (:func:`paper_muscles`).
    """
    if n_links == 3:
        return paper_muscles(stiffness=stiffness, viscosity=viscosity,
                             viscosity_ratio=viscosity_ratio, gastrocnemius=gastrocnemius,
                             active_stiffness=active_stiffness,
                             active_viscosity=active_viscosity,
                             active_viscosity_ratio=active_viscosity_ratio)
    if gastrocnemius != "two-sided":
        raise ParameterError(f"gastrocnemius applies to the paper's three-link body, not "
                             f"{n_links} links")
    names = joint_pair_names(n_links)
    P = len(names)

    def gains(label: str, values) -> np.ndarray:
        arr = np.atleast_1d(finite_array(label, values))
        if arr.shape != (P,):
            raise ParameterError(f"{label} must have {P} values ({', '.join(names)}), got "
                                 f"{arr.size}")
        if np.any(arr < 0):
            raise ParameterError(f"{label} must be >= 0, got {arr[arr < 0][0]:g}")
        return arr

    k = gains("stiffness [N·m/rad]", stiffness)
    v = (check_value("viscosity_ratio", viscosity_ratio) * k if viscosity is None
         else gains("viscosity [N·m·s/rad]", viscosity))
    muscles = MuscleSet(tuple(MusclePair(name, j, j + 1, float(k[j]), float(v[j]))
                              for j, name in enumerate(names)), n_links)
    return _with_active(muscles, active_stiffness, active_viscosity, active_viscosity_ratio,
                        gains)


def _with_active(muscles: MuscleSet, active_stiffness, active_viscosity,
                 active_viscosity_ratio, check) -> MuscleSet:
    """``muscles`` with the active gains given (none: as it is); ``check(label, values)``
    validates a list of one value per pair."""
    if active_stiffness is None and active_viscosity is None:
        if active_viscosity_ratio is not None:
            raise ParameterError("active_viscosity_ratio needs active_stiffness")
        return muscles
    if active_viscosity is not None and active_viscosity_ratio is not None:
        raise ParameterError("give active_viscosity or active_viscosity_ratio, not both")
    P = len(muscles.pairs)
    ka = (np.zeros(P) if active_stiffness is None
          else check("active stiffness [N·m/rad]", active_stiffness))
    if active_viscosity_ratio is not None:
        va = check_value("active_viscosity_ratio", active_viscosity_ratio) * ka
    else:
        va = (np.zeros(P) if active_viscosity is None
              else check("active viscosity [N·m·s/rad]", active_viscosity))
    return muscles.with_active_feedback(ka, va)


def _five(name: str, values) -> np.ndarray:
    arr = np.atleast_1d(finite_array(name, values))
    if arr.shape != (5,):
        raise ParameterError(
            f"{name} must have 5 values (ankle, knee, hip, quadriceps, gastrocnemius), "
            f"got {arr.size}"
        )
    if np.any(arr < 0):
        raise ParameterError(f"{name} must be >= 0, got {arr[arr < 0][0]:g}")
    return arr


#: The torques and gains of a muscle set, stated in :mod:`.feedback` and found here too
#: (loaded on first use, so that what only needs the pairs does not load them).
_FEEDBACK_NAMES = ("pair_torques", "link_torques", "joint_torques", "joint_crossing_matrix",
                   "joint_moments", "moments_to_link_torques", "feedback_gains",
                   "muscle_set_gains", "feedback_pair_torques")


def __getattr__(name: str):
    if name in _FEEDBACK_NAMES:
        from . import feedback

        return getattr(feedback, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
