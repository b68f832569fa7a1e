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
    COP_TOE           toe − x_p                      falling   (a fall: the foot tips)
    COP_HEEL          x_p − heel                     falling   (a fall: the foot tips)
    SATURATES         side·τ_j − limit_j − h         rising    (joint j saturates at side ±1)
    LETS_GO           side·τ_j − limit_j + h         falling   (a saturated joint lets go)
    PAIR_SLACKENS     s_p + h                        falling   (an acting one-sided pair)
    PAIR_ENGAGES      s_p − h                        rising    (a slack one-sided pair)
    KNEE_HITS_STOP    κ − stop_angle − h             rising    (a free knee locks)
    KNEE_LEAVES_STOP  κ̈_free + h_release             falling   (a locked knee lets go)

h = :data:`SWITCH_HYSTERESIS` keeps a pair, joint or knee resting exactly at its
switch point from switching back and forth; h_release =
:data:`RELEASE_HYSTERESIS`. The ``offset`` of each kind in :data:`EVENT_KINDS` is
the constant added to the physical part.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "SWITCH_HYSTERESIS",
    "RELEASE_HYSTERESIS",
    "EventKind",
    "EVENT_KINDS",
    "EVENT_DIRECTION",
    "EVENT_OFFSET",
    "EVENT_ENDS_RUN",
    "segment_events",
    "max_segment_events",
    "fall_message",
    "JOINT_NAMES",
]

#: A one-sided pair switches when its stretch passes 0 by this much, a joint moment
#: saturates when it passes its limit by this much and lets go this far inside it, and the
#: knee stop engages this far past its angle: far below any physical resolution. [rad], [N·m]
SWITCH_HYSTERESIS = 1e-12
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


#: Every kind of event, indexed by its code.
EVENT_KINDS: tuple[EventKind, ...] = (
    EventKind(LINK_ANGLE, "link-angle", True, -1, 0.0,
              "link {link} angle passed ±{limit:.3g} rad"),
    EventKind(COG_TOE, "cog-toe", True, -1, 0.0, "centre of gravity passed the toe ({toe:.3f} m)"),
    EventKind(COG_HEEL, "cog-heel", True, -1, 0.0,
              "centre of gravity passed the heel ({heel:.3f} m)"),
    EventKind(COP_TOE, "cop-toe", True, -1, 0.0,
              "centre of pressure passed the toe ({toe:.3f} m): the foot tips"),
    EventKind(COP_HEEL, "cop-heel", True, -1, 0.0,
              "centre of pressure passed the heel ({heel:.3f} m): the foot tips"),
    EventKind(SATURATES, "saturates", False, 1, -SWITCH_HYSTERESIS,
              "the {joint} moment reached its limit"),
    EventKind(LETS_GO, "lets-go", False, -1, SWITCH_HYSTERESIS,
              "the {joint} moment came back inside its limit"),
    EventKind(PAIR_SLACKENS, "pair-slackens", False, -1, SWITCH_HYSTERESIS,
              "a one-sided pair went slack"),
    EventKind(PAIR_ENGAGES, "pair-engages", False, 1, -SWITCH_HYSTERESIS,
              "a one-sided pair engaged"),
    EventKind(KNEE_HITS_STOP, "knee-hits-stop", False, 1, -SWITCH_HYSTERESIS,
              "the knee reached its hyper-extension stop"),
    EventKind(KNEE_LEAVES_STOP, "knee-leaves-stop", False, -1, RELEASE_HYSTERESIS,
              "the knee left its stop"),
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


def max_segment_events(n_links: int, n_pairs: int) -> int:
    """Largest number of events a segment can list. [-]"""
    return n_links + 4 + 2 * n_links + n_pairs + 1


def segment_events(n_links, base_of_support, centre_of_pressure, limited, saturation,
                   one_sided, active, knee_stop, locked, kind, index, side):
    """List the events of a smooth segment, in the order that breaks ties; return how many.

    Written for numpy arrays in plain loops, so that the compiled engine runs this very
    function (compiled) and the reference engine runs it as Python.

    Parameters
    ----------
    n_links : int
        N. [-]
    base_of_support, centre_of_pressure : bool
        Whether the centre of gravity, and the centre of pressure, may leave a foot.
    limited : numpy.ndarray of int, shape (N,)
        1 for a joint with a finite torque limit. [-]
    saturation : numpy.ndarray, shape (N,)
        0 for a free joint, ±1 for one saturated at +limit or −limit. [-]
    one_sided : numpy.ndarray of int, shape (P,)
        1 for a one-sided pair. [-]
    active : numpy.ndarray, shape (P,)
        1 for a pair that acts, 0 for a slack one. [-]
    knee_stop : bool
        The knee has a hyper-extension stop.
    locked : bool
        The knee is at its stop (locked) now.
    kind, index, side : numpy.ndarray of int64, int64, float64
        Filled with each event's code, its link / joint / pair index and its side (±1
        for a saturation, else 0); at least :func:`max_segment_events` long.

    Returns
    -------
    int
        The number of events listed.
    """
    m = 0
    for i in range(n_links):  # falls: every link angle, then the foot
        kind[m] = LINK_ANGLE
        index[m] = i
        side[m] = 0.0
        m += 1
    if base_of_support:
        for code in (COG_TOE, COG_HEEL):
            kind[m] = code
            index[m] = 0
            side[m] = 0.0
            m += 1
        if centre_of_pressure:
            for code in (COP_TOE, COP_HEEL):
                kind[m] = code
                index[m] = 0
                side[m] = 0.0
                m += 1
    for j in range(n_links):  # a free limited joint saturates either way; a saturated one lets go
        if limited[j]:
            if saturation[j] == 0.0:
                for s in (1.0, -1.0):
                    kind[m] = SATURATES
                    index[m] = j
                    side[m] = s
                    m += 1
            else:
                kind[m] = LETS_GO
                index[m] = j
                side[m] = saturation[j]
                m += 1
    for p in range(one_sided.size):
        if one_sided[p]:
            kind[m] = PAIR_SLACKENS if active[p] > 0.0 else PAIR_ENGAGES
            index[m] = p
            side[m] = 0.0
            m += 1
    if knee_stop:
        kind[m] = KNEE_LEAVES_STOP if locked else KNEE_HITS_STOP
        index[m] = 1
        side[m] = 0.0
        m += 1
    return m


def fall_message(code: int, index: int, *, max_link_angle: float, toe: float = 0.0,
                 heel: float = 0.0) -> str:
    """The reason of a fall of kind ``code`` (link ``index``, 0-based), in words."""
    kind = EVENT_KINDS[code]
    return kind.message.format(link=index + 1, limit=max_link_angle, toe=toe, heel=heel,
                               joint=JOINT_NAMES[index] if index < len(JOINT_NAMES)
                               else f"joint {index + 1}")
