"""One verdict about upright: is standing still stable for this body, these gains and this
delay?

Every command and view that says whether upright is stable (``posturelab poles``,
``simulate`` and its ``linear_stability``, ``sweep``, the explorer, the reproduction report)
asks :func:`upright_verdict`, so that they cannot disagree.

Each side is one :class:`~posturelab.linear.system.LinearSystem`; its verdict is that of
its rightmost characteristic roots.

**The delay.** With a feedback delay τ > 0 the verdict is that of the characteristic roots
of the delay equation (:func:`posturelab.linear.delay.rightmost_roots`): the pair gains
are then the whole delayed feedback (no active gains) or the intrinsic part acting at once
and the active gains delayed (:func:`posturelab.model.muscles.feedback_gains`). With
τ = 0 the roots are the poles of :func:`posturelab.analyse`; a delay too small to matter
(τ·ρ ≤ 1e-6, ρ the first-order form's rate scale: :mod:`posturelab.linear.delay`'s notes)
starts from those poles, so the verdict as τ → 0 is continuous with the one at τ = 0.

**One-sided pairs.** Upright is exactly the switching point of a one-sided pair: its
stretch is 0 there, so the model has no derivative at upright and no one linearisation.
The verdict linearises every side of the switch (each one-sided pair engaged or slack; a
pull-only pair has the same two sides at upright, where its stretch and torque are both
0) and states what they imply:

- every side stable → ``"stable"``; every side unstable → ``"unstable"``;
- otherwise ``"depends on the side"``: upright is a switching point of a piecewise-linear
  system, stable on some sides and not on others, and its stability is a question the
  linear model cannot settle (trajectories may settle while the pair is engaged, or
  leave the stable side and fall). The verdict says so rather than picking one side.

A side whose rightmost root lies on the imaginary axis to rounding (|Re s| <=
:data:`MARGINAL` · max(1, |s|), e.g. no damping at all) is ``"marginal"``, neither stable
nor unstable.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, replace
from typing import Literal

from .._validation import float_in_range
from ..errors import ParameterError
from ..model.body import Body
from ..model.muscles import MusclePair, MuscleSet
from .analysis import _check_match
from .system import linear_system

__all__ = ["MARGINAL", "UprightSide", "UprightVerdict", "upright_verdict"]

#: A root with |Re s| at most this times max(1 [1/s], |s|) lies on the imaginary axis. [-]
MARGINAL = 1e-9
#: Most one-sided pairs whose sides are enumerated (2**count linearisations). [-]
MAX_SWITCHING_PAIRS = 6

Status = Literal["stable", "unstable", "marginal"]
VerdictStatus = Literal["stable", "unstable", "marginal", "depends on the side"]


def _status(root: complex) -> Status:
    if abs(root.real) <= MARGINAL * max(1.0, abs(root)):
        return "marginal"
    return "stable" if root.real < 0 else "unstable"


def _fmt_root(z: complex) -> str:
    return f"{z.real:.3g} ± {abs(z.imag):.3g}j" if abs(z.imag) > 0 else f"{z.real:.3g}"


def _stretch_words(pair: MusclePair) -> str:
    """Where the pair's stretch is >= 0, e.g. "θ2 ≥ 0" or "θ3 − θ1 ≥ 0"."""
    return f"θ{pair.hi} ≥ 0" if pair.lo == 0 else f"θ{pair.hi} − θ{pair.lo} ≥ 0"


@dataclass(frozen=True)
class UprightSide:
    """The linearisation about upright on one side of the one-sided pairs' switch.

    Attributes
    ----------
    engaged : tuple of str
        The one-sided pairs acting on this side (all pairs act when there are none).
    slack : tuple of str
        The one-sided pairs slack (removed) on this side.
    status : {"stable", "unstable", "marginal"}
        What the roots of this side say.
    rightmost_root : complex
        The root with the largest real part: its growth rate [1/s] and frequency
        [rad/s]. [1/s]
    roots : tuple of complex
        The 2N rightmost characteristic roots, real part descending (τ = 0: all the
        poles). [1/s]
    """

    engaged: tuple[str, ...]
    slack: tuple[str, ...]
    status: Status
    rightmost_root: complex
    roots: tuple[complex, ...]

    def label(self) -> str:
        """Which side, in words: "gastrocnemius engaged", "gastrocnemius slack", ... ("" when
        there is no switch)."""
        parts = [f"{n} engaged" for n in self.engaged] + [f"{n} slack" for n in self.slack]
        return ", ".join(parts)

    def to_dict(self) -> dict:
        """Plain-Python form; roots as {"re", "im"} [1/s]."""
        return {"engaged": list(self.engaged), "slack": list(self.slack),
                "status": self.status,
                "rightmost_root": {"re": float(self.rightmost_root.real),
                                   "im": float(self.rightmost_root.imag)},
                "roots": [{"re": float(z.real), "im": float(z.imag)} for z in self.roots]}


@dataclass(frozen=True)
class UprightVerdict:
    """Whether upright is stable for a body, its gains and its feedback delay.

    Attributes
    ----------
    status : {"stable", "unstable", "marginal", "depends on the side"}
        The verdict (module notes); "depends on the side" only at the switch of a
        one-sided pair whose sides disagree.
    feedback_delay : float
        τ the roots are for. [s]
    delayed_part : {"none", "all", "active"}
        What τ delays: nothing (τ = 0), the whole pair feedback (no active gains), or
        the active gains only.
    switching_pairs : tuple of str
        The one-sided pairs that switch at upright (empty: one linearisation).
    switching_conditions : tuple of str
        Where each of them is engaged, e.g. "θ2 ≥ 0". [-]
    sides : tuple of UprightSide
        Every side of the switch: the first with every one-sided pair engaged, the last
        with every one slack; one entry without one-sided pairs.
    """

    status: VerdictStatus
    feedback_delay: float
    delayed_part: Literal["none", "all", "active"]
    switching_pairs: tuple[str, ...]
    switching_conditions: tuple[str, ...]
    sides: tuple[UprightSide, ...]

    @property
    def stable(self) -> bool:
        """The linear model says upright is stable (every side stable). [-]"""
        return self.status == "stable"

    @property
    def at_switching_point(self) -> bool:
        """Upright is the switching point of one or more one-sided pairs. [-]"""
        return bool(self.switching_pairs)

    @property
    def rightmost_root(self) -> complex:
        """The rightmost root over every side (the fastest-growing or slowest-decaying
        mode anywhere about upright). [1/s]"""
        return max((s.rightmost_root for s in self.sides), key=lambda z: (z.real, z.imag))

    def side(self, engaged: bool) -> UprightSide:
        """The side with every one-sided pair engaged (``True``) or slack (``False``)."""
        return self.sides[0] if engaged else self.sides[-1]

    def describe(self) -> str:
        """One line: the verdict, the rightmost root(s) [1/s] and τ [s]."""
        delay = f" with τ = {self.feedback_delay:g} s" if self.feedback_delay > 0 else ""
        if not self.switching_pairs:
            (side,) = self.sides
            return (f"{side.status} about upright{delay} (rightmost root "
                    f"{_fmt_root(side.rightmost_root)} 1/s)")
        where = ", ".join(f"{n} ({c})" for n, c in zip(self.switching_pairs,
                                                      self.switching_conditions, strict=True))
        each = "; ".join(f"{s.status} while {s.label()} (rightmost root "
                         f"{_fmt_root(s.rightmost_root)} 1/s)" for s in self.sides)
        if self.status == "depends on the side":
            return (f"depends on the side{delay}: upright is the switching point of {where}; "
                    f"{each}. A switched system: its stability about upright is not settled "
                    "by the linear model")
        return (f"{self.status} about upright{delay} on every side of the switch of {where}: "
                f"{each}")

    def to_dict(self) -> dict:
        """Plain-Python form: status, stable, the rightmost root {"re", "im"} [1/s], τ [s],
        the switching pairs and every side; ``units`` names the units."""
        z = self.rightmost_root
        return {"status": self.status, "stable": self.stable,
                "rightmost_root": {"re": float(z.real), "im": float(z.imag)},
                "feedback_delay": float(self.feedback_delay),
                "delayed_part": self.delayed_part,
                "switching_pairs": list(self.switching_pairs),
                "switching_conditions": list(self.switching_conditions),
                "sides": [s.to_dict() for s in self.sides],
                "description": self.describe(),
                "units": {"rightmost_root": "1/s", "roots": "1/s", "feedback_delay": "s"}}


def _side_muscles(muscles: MuscleSet, engaged: frozenset[str]) -> MuscleSet:
    """``muscles`` with the one-sided pairs in ``engaged`` acting on both sides and the
    other one-sided pairs removed: one side's linear model."""
    pairs = tuple(replace(p, one_sided=False) for p in muscles.pairs
                  if not p.one_sided or p.name in engaged)
    return MuscleSet(pairs, muscles.n_links)


def upright_verdict(body: Body, muscles: MuscleSet, feedback_delay: float = 0.0, *,
                    nodes: int = 40, torque_feedback_gain: float = 0.0,
                    torque_feedback_time_constant: float | None = None,
                    joint_feedback=None, knee: str = "free") -> UprightVerdict:
    """The one verdict about upright for this body, these gains and this delay.

    Parameters
    ----------
    body : Body
    muscles : MuscleSet
        Pair gains (intrinsic, and active if any); one-sided pairs are linearised on
        every side of their switch (module notes).
    feedback_delay : float
        τ, in [0, 10]. [s]
    nodes : int
        Chebyshev intervals of the root computation with a delay
        (:func:`posturelab.linear.delay.rightmost_roots`). [-]
    torque_feedback_gain, torque_feedback_time_constant : float
        Peterka 2002's torque feedback (:func:`posturelab.linear.system.linear_system`;
        gain 0: none): the roots are then those of the first-order form with the filter
        states. [-], [s]
    joint_feedback : JointFeedback, optional
        A joint-space controller (:mod:`posturelab.linear.lqr`); with it, ``knee="locked"``
        takes the roots on the knee constraint (:func:`posturelab.linear.lqr.on_knee`).

    Returns
    -------
    UprightVerdict

    Examples
    --------
    The paper's case 1 with the real, one-sided gastrocnemius: stable while it is
    engaged (the poles of case 1), unstable while it is slack (those of case 2):

    >>> import posturelab as pl
    >>> v = pl.upright_verdict(pl.paper_body(), pl.paper_muscles("1", gastrocnemius="one-sided"))
    >>> v.status
    'depends on the side'
    >>> [s.status for s in v.sides], round(v.side(engaged=False).rightmost_root.real, 3)
    (['stable', 'unstable'], 1.169)
    """
    from .delay import MAX_DELAY_FOR_ROOTS, system_rightmost_roots

    _check_match(body, muscles)
    delay = float_in_range("feedback_delay [s]", feedback_delay, 0.0, MAX_DELAY_FOR_ROOTS,
                           unit="s")
    one_sided = [p for p in muscles.pairs if p.one_sided]
    if len(one_sided) > MAX_SWITCHING_PAIRS:
        raise ParameterError(f"upright_verdict takes at most {MAX_SWITCHING_PAIRS} one-sided "
                             f"pairs (2**k linearisations), got {len(one_sided)}")
    names = [p.name for p in one_sided]
    sides = []
    # every one-sided pair engaged first, every one slack last
    for flags in itertools.product((True, False), repeat=len(names)):
        engaged = tuple(n for n, f in zip(names, flags, strict=True) if f)
        slack = tuple(n for n, f in zip(names, flags, strict=True) if not f)
        side = linear_system(body, _side_muscles(muscles, frozenset(engaged)), inputs=False,
                             torque_feedback_gain=torque_feedback_gain,
                             torque_feedback_time_constant=torque_feedback_time_constant,
                             joint_feedback=joint_feedback)
        if joint_feedback is not None and knee == "locked":
            from .lqr import on_knee

            side = on_knee(side, knee)
        roots = system_rightmost_roots(side, delay, 2 * side.n_links, nodes=nodes)
        top = complex(roots[0])
        sides.append(UprightSide(engaged, slack, _status(top), top,
                                 tuple(complex(z) for z in roots)))
    statuses = {s.status for s in sides}
    status: VerdictStatus = (sides[0].status if len(statuses) == 1
                             else "depends on the side")
    delayed = ("none" if delay == 0 else "active" if muscles.has_active_feedback else "all")
    return UprightVerdict(status, delay, delayed, tuple(names),
                          tuple(_stretch_words(p) for p in one_sided), tuple(sides))

