"""The events of a run, stated once for both simulators.

A run is integrated in smooth segments. A segment ends where an *event
function* g(t, x) crosses zero in its *direction*: a fall ends the run, a
switch changes the model (a one-sided pair engages or goes slack, a joint
moment saturates or lets go, the knee reaches or leaves its stop) and the
integration restarts. Each engine computes the physical part of g its own way
(the reference from the numpy model functions, the compiled engine in its
kernels); what an event is, its direction, its hysteresis, the order in which
a segment lists its events (which breaks ties) and the words of its message
are stated here, once.

The event function of each kind (θ angles [rad], x_c centre of gravity and
x_p centre of pressure [m], τ_j net muscle moment at joint j [N·m], s_p the
stretch of pair p of the state the muscles respond to [rad], κ = θ2 − θ1 the
knee angle [rad], κ̈_free the knee acceleration with the knee free [rad/s²])::

    LINK_ANGLE        max_link_angle − |θ_i|        falling   (a fall)
    COG_TOE           toe − x_c                      falling   (a fall)
    COG_HEEL          x_c − heel                     falling   (a fall)
    COP_TOE           toe·F_y − τ_ankle              falling   (a fall: the foot tips)
    COP_HEEL          τ_ankle − heel·F_y             falling   (a fall: the foot tips)
    SATURATES         side·τ_j − limit_j − h         rising    (joint j saturates at side ±1)
    LETS_GO           side·τ_j − limit_j + h         falling   (a saturated joint lets go)
    PAIR_SLACKENS     s_p + h                        falling   (an acting one-sided pair)
    PAIR_ENGAGES      s_p − h                        rising    (a slack one-sided pair)
    KNEE_HITS_STOP    κ − stop_angle − h             rising    (a free knee locks)
    KNEE_LEAVES_STOP  κ̈_free + h_release             falling   (a locked knee lets go)
    PAIR_PUSHES       M_p + h_M                      falling   (a pull-only pair would push)
    PAIR_PULLS        min(M_p, k_p s_p) − h_M        rising    (a slack pull-only pair pulls)

The centre-of-pressure events are toe − x_p and x_p − heel multiplied by the vertical
ground reaction F_y [N] (x_p = τ_ankle / F_y): the same sign while the foot is pressed on the
platform, and continuous where F_y passes 0 and x_p runs off to infinity, so that a foot that
unloads within one integrator step still falls where x_p passes the edge.

M_p = k_p s_p + l_p ṡ_p is the torque pair p would have, on the state the muscles respond
to (k_p its stiffness). After PAIR_SLACKENS or PAIR_ENGAGES a pair acts if its stretch is
growing; after PAIR_PUSHES it is slack; after PAIR_PULLS (stretched, and pulling) it acts.

h = :data:`SWITCH_HYSTERESIS` keeps a pair, joint or knee resting exactly at its
switch point from switching back and forth; h_release =
:data:`RELEASE_HYSTERESIS`. The ``offset`` of each kind in :data:`EVENT_KINDS` is
the constant added to the physical part.
"""

from __future__ import annotations

import operator
from dataclasses import dataclass

import numpy as np

__all__ = [
    "SWITCH_HYSTERESIS",
    "RELEASE_HYSTERESIS",
    "TORQUE_HYSTERESIS",
    "EventKind",
    "EVENT_KINDS",
    "EVENT_DIRECTION",
    "EVENT_OFFSET",
    "EVENT_ENDS_RUN",
    "EventSlots",
    "event_slots",
    "segment_events",
    "fall_message",
    "JOINT_NAMES",
]

#: A one-sided pair switches when its stretch passes 0 by this much, a joint moment
#: saturates when it passes its limit by this much and lets go this far inside it, and the
#: knee stop engages this far past its angle: far below any physical resolution. [rad], [N·m]
SWITCH_HYSTERESIS = 1e-12
#: A pull-only pair goes slack when its torque falls this far below 0 and acts again this far
#: above: wider than the integrators' noise on a torque of tens of N·m (rtol 1e-8), so that
#: a torque grazing 0 does not chatter. [N·m]
TORQUE_HYSTERESIS = 1e-6
#: The knee stop lets go when the free knee acceleration pulls away by more than this. [rad/s²]
RELEASE_HYSTERESIS = 1e-9

# Codes (shared with the compiled kernels, which receive them as numbers)
LINK_ANGLE = 0
COG_TOE = 1
COG_HEEL = 2
COP_TOE = 3
COP_HEEL = 4
SATURATES = 5
LETS_GO = 6
PAIR_SLACKENS = 7
PAIR_ENGAGES = 8
KNEE_HITS_STOP = 9
KNEE_LEAVES_STOP = 10
PAIR_PUSHES = 11
PAIR_PULLS = 12


@dataclass(frozen=True)
class EventKind:
    """One kind of event.

    Attributes
    ----------
    code : int
        Its number (the index into :data:`EVENT_KINDS`). [-]
    name : str
        A short name.
    ends_run : bool
        True for a fall (the run stops), False for a switch (it restarts).
    direction : int
        +1: fires when g rises through 0; −1: when it falls through 0. [-]
    offset : float
        The constant added to the physical part of g (the hysteresis). [unit of g]
    message : str
        What happened, as a format string; fields ``link`` (1-based), ``limit`` [rad],
        ``toe``, ``heel`` [m], ``joint`` (a name).
    """

    code: int
    name: str
    ends_run: bool
    direction: int
    offset: float
    message: str


def _fall(code: int, name: str, message: str) -> EventKind:
    """A fall: its g falls through 0 (no hysteresis) and the run stops."""
    return EventKind(code, name, True, -1, 0.0, message)


def _switch(code: int, name: str, direction: int, hysteresis: float, message: str) -> EventKind:
    """A switch: it fires once its g has passed 0 by ``hysteresis`` in ``direction`` (the
    offset −direction × hysteresis), and the run restarts."""
    return EventKind(code, name, False, direction, -direction * hysteresis, message)


#: Every kind of event, indexed by its code.
EVENT_KINDS: tuple[EventKind, ...] = (
    _fall(LINK_ANGLE, "link-angle", "link {link} angle passed ±{limit:.3g} rad"),
    _fall(COG_TOE, "cog-toe", "centre of gravity passed the toe ({toe:.3f} m)"),
    _fall(COG_HEEL, "cog-heel", "centre of gravity passed the heel ({heel:.3f} m)"),
    _fall(COP_TOE, "cop-toe", "centre of pressure passed the toe ({toe:.3f} m): the foot tips"),
    _fall(COP_HEEL, "cop-heel",
          "centre of pressure passed the heel ({heel:.3f} m): the foot tips"),
    _switch(SATURATES, "saturates", 1, SWITCH_HYSTERESIS, "the {joint} moment reached its limit"),
    _switch(LETS_GO, "lets-go", -1, SWITCH_HYSTERESIS,
            "the {joint} moment came back inside its limit"),
    _switch(PAIR_SLACKENS, "pair-slackens", -1, SWITCH_HYSTERESIS, "a one-sided pair went slack"),
    _switch(PAIR_ENGAGES, "pair-engages", 1, SWITCH_HYSTERESIS, "a one-sided pair engaged"),
    _switch(KNEE_HITS_STOP, "knee-hits-stop", 1, SWITCH_HYSTERESIS,
            "the knee reached its hyper-extension stop"),
    _switch(KNEE_LEAVES_STOP, "knee-leaves-stop", -1, RELEASE_HYSTERESIS, "the knee left its stop"),
    _switch(PAIR_PUSHES, "pair-pushes", -1, TORQUE_HYSTERESIS,
            "a pull-only pair would have pushed: it went slack"),
    _switch(PAIR_PULLS, "pair-pulls", 1, TORQUE_HYSTERESIS, "a slack pull-only pair pulls again"),
)

#: Direction of each kind, by code (+1 rising, −1 falling). [-]
EVENT_DIRECTION = np.array([k.direction for k in EVENT_KINDS], dtype=np.int64)
#: Constant part of each kind's event function, by code. [unit of g]
EVENT_OFFSET = np.array([k.offset for k in EVENT_KINDS], dtype=float)
#: 1 for the kinds that end the run (falls), by code. [-]
EVENT_ENDS_RUN = np.array([1 if k.ends_run else 0 for k in EVENT_KINDS], dtype=np.int64)
for _a in (EVENT_DIRECTION, EVENT_OFFSET, EVENT_ENDS_RUN):
    _a.setflags(write=False)

#: Names of the joints in messages, lowest first (joint j is below link j + 1).
JOINT_NAMES = ("ankle", "knee", "hip")


# Conditions under which an event slot is part of a segment (codes shared with the kernels)
ALWAYS = 0
JOINT_FREE = 1
JOINT_SATURATED = 2
PAIR_ACTIVE = 3
PAIR_SLACK = 4
KNEE_FREE = 5
KNEE_LOCKED = 6
#: The conditions' names, by code.
CONDITION_NAMES = ("ALWAYS", "JOINT_FREE", "JOINT_SATURATED", "PAIR_ACTIVE", "PAIR_SLACK",
                   "KNEE_FREE", "KNEE_LOCKED")

#: When each condition holds, stated once for both engines (the C is generated from it):
#: condition -> (the segment's switch it reads, at the slot's index unless "locked";
#: the comparison; the value compared with; whether the comparison is negated). [-]
SLOT_CONDITIONS = {
    ALWAYS: (None, None, None, False),
    JOINT_FREE: ("saturation", operator.eq, 0.0, False),
    JOINT_SATURATED: ("saturation", operator.ne, 0.0, False),
    PAIR_ACTIVE: ("active", operator.gt, 0.0, False),
    PAIR_SLACK: ("active", operator.gt, 0.0, True),
    KNEE_FREE: ("locked", None, None, True),
    KNEE_LOCKED: ("locked", None, None, False),
}


#: The kinds whose side is the joint's saturation at the segment's start (a joint lets go
#: from the side it is saturated at); every other kind keeps its slot's side.
SIDE_IS_SATURATION = frozenset({LETS_GO})


def slot_on(condition: int, index: int, saturation, active, locked) -> bool:
    """Whether a slot with ``condition`` (at joint or pair ``index``) is part of a segment
    that starts with joint ``saturation`` (N,), pairs ``active`` (P,) and the knee
    ``locked`` (:data:`SLOT_CONDITIONS`)."""
    switch, compare, value, negated = SLOT_CONDITIONS[condition]
    if switch is None:
        return True
    held = {"saturation": saturation, "active": active}.get(switch)
    on = bool(locked) if held is None else bool(compare(held[index], value))
    return on != negated


@dataclass(frozen=True)
class EventSlots:
    """Every event a run can have, in the order that breaks ties, with when each applies.

    A smooth segment's events are the slots whose condition holds at its start
    (:func:`segment_events`). Arrays of equal length S.

    Attributes
    ----------
    kind : numpy.ndarray of int64
        Event code. [-]
    index : numpy.ndarray of int64
        The link, joint or pair it concerns. [-]
    side : numpy.ndarray
        +1 or −1 for a joint saturating at +limit or −limit, else 0 (a joint letting go
        takes the side it is saturated at). [-]
    condition : numpy.ndarray of int64
        ALWAYS, JOINT_FREE or JOINT_SATURATED (joint ``index``), PAIR_ACTIVE or PAIR_SLACK
        (pair ``index``), KNEE_FREE or KNEE_LOCKED. [-]
    """

    kind: np.ndarray
    index: np.ndarray
    side: np.ndarray
    condition: np.ndarray

    def __len__(self) -> int:
        return int(self.kind.size)


def event_slots(n_links: int, base_of_support: bool, centre_of_pressure: bool,
                limited: np.ndarray, one_sided: np.ndarray, knee_stop: bool,
                pull_only: np.ndarray | None = None) -> EventSlots:
    """The event slots of a run, in tie-breaking order.

    Falls first (every link angle, then the centre of gravity past the toe and the heel,
    then the centre of pressure), then each limited joint (saturating either way while
    free, letting go while saturated), then each one-sided pair (going slack while acting,
    engaging while slack), then the knee stop (reached while free, left while locked).

    Parameters
    ----------
    n_links : int
        N. [-]
    base_of_support, centre_of_pressure : bool
        Whether the centre of gravity, and the centre of pressure, may leave a foot.
    limited : array_like of bool, shape (N,)
        Joints with a finite torque limit.
    one_sided : array_like of bool, shape (P,)
        One-sided pairs.
    knee_stop : bool
        The knee has a hyper-extension stop.
    pull_only : array_like of bool, shape (P,), optional
        One-sided pairs that also switch on the sign of their torque (none by default).
    """
    rows: list[tuple[int, int, float, int]] = [(LINK_ANGLE, i, 0.0, ALWAYS)
                                               for i in range(n_links)]
    if base_of_support:
        rows += [(COG_TOE, 0, 0.0, ALWAYS), (COG_HEEL, 0, 0.0, ALWAYS)]
        if centre_of_pressure:
            rows += [(COP_TOE, 0, 0.0, ALWAYS), (COP_HEEL, 0, 0.0, ALWAYS)]
    for j in np.nonzero(np.asarray(limited, dtype=bool))[0]:
        rows += [(SATURATES, int(j), 1.0, JOINT_FREE), (SATURATES, int(j), -1.0, JOINT_FREE),
                 (LETS_GO, int(j), 0.0, JOINT_SATURATED)]
    one_sided = np.asarray(one_sided, dtype=bool)
    pull = (np.zeros(one_sided.shape, bool) if pull_only is None
            else np.asarray(pull_only, dtype=bool) & one_sided)
    for p in np.nonzero(one_sided)[0]:
        rows += [(PAIR_SLACKENS, int(p), 0.0, PAIR_ACTIVE),
                 (PAIR_ENGAGES, int(p), 0.0, PAIR_SLACK)]
        if pull[p]:
            rows += [(PAIR_PUSHES, int(p), 0.0, PAIR_ACTIVE),
                     (PAIR_PULLS, int(p), 0.0, PAIR_SLACK)]
    if knee_stop:
        rows += [(KNEE_HITS_STOP, 1, 0.0, KNEE_FREE), (KNEE_LEAVES_STOP, 1, 0.0, KNEE_LOCKED)]
    kind, index, side, cond = zip(*rows, strict=True)
    slots = EventSlots(np.array(kind, np.int64), np.array(index, np.int64),
                       np.array(side, float), np.array(cond, np.int64))
    for arr in (slots.kind, slots.index, slots.side, slots.condition):
        arr.setflags(write=False)
    return slots


def segment_events(slots: EventSlots, saturation: np.ndarray, active: np.ndarray,
                   locked: bool) -> list[tuple[int, int, float]]:
    """The (kind, index, side) of each event of a smooth segment that starts with joint
    saturation ``saturation`` (N,), pairs ``active`` (P,) and the knee ``locked``."""
    out = []
    for k, i, sd, c in zip(slots.kind.tolist(), slots.index.tolist(), slots.side.tolist(),
                           slots.condition.tolist(), strict=True):
        if slot_on(c, i, saturation, active, locked):
            out.append((k, i, float(saturation[i]) if k in SIDE_IS_SATURATION else sd))
    return out


def fall_message(code: int, index: int, *, max_link_angle: float, toe: float = 0.0,
                 heel: float = 0.0) -> str:
    """The reason of a fall of kind ``code`` (link ``index``, 0-based), in words."""
    kind = EVENT_KINDS[code]
    return kind.message.format(link=index + 1, limit=max_link_angle, toe=toe, heel=heel,
                               joint=JOINT_NAMES[index] if index < len(JOINT_NAMES)
                               else f"joint {index + 1}")
