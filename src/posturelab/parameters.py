"""The parameter vocabulary: every parameter name a command takes, once, with its unit,
bounds and meaning.

A name is ``QUANTITY`` or ``QUANTITY:PAIR`` (``QUANTITY:JOINT`` for a torque limit):
``stiffness:ankle``, ``active_viscosity:gastrocnemius``, ``torque_limit:hip``,
``feedback_delay``. PAIR is a muscle pair of the body in use (the paper's three-link body:
ankle, knee, hip, quadriceps, gastrocnemius; one link: ankle; two links: ankle, hip), JOINT
one of its joints (ankle, knee, hip on three links). On a body with a single pair the
``:PAIR`` may be left out (``active_stiffness`` is ``active_stiffness:ankle`` on one link).
``posturelab sweep --vary``, ``fit --free``, ``fit-frf --free/--per-condition/--bounds``,
``stability-map --x/--y``, the explorer's controls and the scenario files' ``[muscles]``
keys all use these names; output tables name their columns with them verbatim (a colon is
an ordinary character in CSV and Parquet column names).

:data:`QUANTITIES` is the table. :func:`parse_name` splits a name, :func:`resolve` checks a
name against a body's pairs and joints (and a command's quantities) and returns its one
spelling, :func:`check_value` checks a value against the bounds, and :data:`RENAMED`
maps each former spelling to its name: a former spelling is refused with one line naming
the new one. This module imports nothing heavy (the command line's ``--help`` reads it).
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass

from .errors import ParameterError, UnknownParameterError

__all__ = [
    "Quantity",
    "QUANTITIES",
    "MAX_FEEDBACK_DELAY",
    "MAX_TORQUE_FEEDBACK_GAIN",
    "MAX_TORQUE_FEEDBACK_TIME_CONSTANT",
    "TORQUE_FEEDBACK_TIME_CONSTANT",
    "MAX_PAIR_STIFFNESS",
    "MAX_PAIR_VISCOSITY",
    "MAX_VISCOSITY_RATIO",
    "MAX_DISTURBANCE_SCALE",
    "MAX_PLATFORM_SPEED",
    "MAX_TILT",
    "HEIGHT_RANGE",
    "MASS_RANGE",
    "FIT_MAX_GAIN",
    "PAPER_PAIRS",
    "PAPER_JOINTS",
    "RENAMED",
    "renamed",
    "parse_name",
    "resolve",
    "check_value",
    "check_weights",
    "quantity",
    "unit",
    "names_for",
    "markdown_table",
    "RUN_SETTINGS",
    "MAX_DURATION",
    "MAX_TIME_LIMIT",
    "MAX_STEP_BUDGET",
    "MAX_AXIS_DEPTH",
]

#: Largest neural delay of the muscle feedback anywhere in posturelab (simulation, linear
#: analysis, FRF model, fits, scenarios, the command line, the explorer): posturelab's
#: bound, five to ten times the 0.1–0.2 s of human postural feedback. [s]
MAX_FEEDBACK_DELAY = 1.0
#: Torque feedback after Peterka 2002 (J Neurophysiol 88:1097–1118; docs/design.md, "Torque
#: feedback"): the corrective (active) torque fed back positively through K_t/(τ_t s + 1).
#: Largest gain K_t: about three times the 1.70 of PMC5664365 Table 1 (K_F = 0.0018 rad/(N·m)
#: times K_P = 943.9 N·m/rad, the form's static loop gain); posturelab's bound. [-]
MAX_TORQUE_FEEDBACK_GAIN = 5.0
#: Largest time constant τ_t: a filter slower than the longest PRTS cycle by far (Peterka
#: 2018's P18 in balancepy uses the integrator K_t/s, the limit τ_t → ∞); posturelab's
#: bound. [s]
MAX_TORQUE_FEEDBACK_TIME_CONSTANT = 1000.0
#: Smallest τ_t: 1 ms (posturelab's bound, below any physiological filter; τ_t = 1e-9 s
#: made the integration exhaust its step budget). [s]
MIN_TORQUE_FEEDBACK_TIME_CONSTANT = 1e-3
#: The default τ_t: 17.4 s, PMC5664365 Table 1 (τ_F). [s]
TORQUE_FEEDBACK_TIME_CONSTANT = 17.4
#: Largest pair stiffness, intrinsic or active: 10⁵ times a standing adult's mgh. [N·m/rad]
MAX_PAIR_STIFFNESS = 1e8
#: Largest pair viscosity, intrinsic or active. [N·m·s/rad]
MAX_PAIR_VISCOSITY = 1e7
#: Largest viscosity/stiffness ratio (the paper's is 0.25 s): posturelab's bound. [s]
MAX_VISCOSITY_RATIO = 10.0
#: Largest factor on a base experiment's platform motion: posturelab's bound. [-]
MAX_DISTURBANCE_SCALE = 100.0
#: Largest platform velocity step: ten times the fastest perturbation of the field. [m/s]
MAX_PLATFORM_SPEED = 20.0
#: Largest |tilt| of the support surface. [rad]
MAX_TILT = 0.5
#: Standing heights and body masses a body can be scaled to (Winter's table). [m], [kg]
HEIGHT_RANGE = (0.5, 2.5)
MASS_RANGE = (10.0, 300.0)
#: Largest gain a fit searches by default (a search box, inside the bounds). [N·m/rad]
FIT_MAX_GAIN = 1e5
#: The paper's five muscle pairs, in the order of its stiffness arrays.
PAPER_PAIRS: tuple[str, ...] = ("ankle", "knee", "hip", "quadriceps", "gastrocnemius")
#: The joints of the paper's three-link body, in link order.
PAPER_JOINTS: tuple[str, ...] = ("ankle", "knee", "hip")


@dataclass(frozen=True)
class Quantity:
    """One row of the vocabulary.

    Attributes
    ----------
    name : str
        The quantity (the part before ``:``).
    unit : str
        Its unit ("-" for none).
    low, high : float
        The values posturelab accepts, inclusive (``low_open``: ``low`` excluded). [unit]
    meaning : str
        What it is, in one line.
    per : str
        "pair" (``:PAIR`` names a muscle pair), "joint" (``:JOINT`` a joint) or "" (none).
    fit_high : float
        Upper end of a fit's default search interval (at most ``high``). [unit]
    low_open : bool
        Whether ``low`` itself is excluded.
    """

    name: str
    unit: str
    low: float
    high: float
    meaning: str
    per: str = ""
    fit_high: float = math.nan
    low_open: bool = False

    @property
    def form(self) -> str:
        """The name as written: ``stiffness:PAIR``, ``torque_limit:JOINT`` or the bare name."""
        return {"pair": f"{self.name}:PAIR", "joint": f"{self.name}:JOINT"}.get(self.per,
                                                                               self.name)

    def range_text(self) -> str:
        """The accepted interval: ``[0, 1] s``, ``(0, inf] N·m``."""
        unit = "" if self.unit == "-" else f" {self.unit}"
        return f"{'(' if self.low_open else '['}{_g(self.low)}, {_g(self.high)}]{unit}"

    def interval(self) -> str:
        """The accepted interval without the unit: ``[0, 1]``, ``(0, inf]``."""
        return f"{'(' if self.low_open else '['}{_g(self.low)}, {_g(self.high)}]"


def _g(v: float) -> str:
    return "inf" if math.isinf(v) else f"{v:g}"


#: The table: every quantity once.
#: Largest factor on a joint-space controller's gains (model.joint_feedback). [-]
MAX_JOINT_FEEDBACK_SCALE = 10.0

QUANTITIES: dict[str, Quantity] = {q.name: q for q in (
    Quantity("stiffness", "N·m/rad", 0.0, MAX_PAIR_STIFFNESS,
             "a pair's stiffness K: its intrinsic (undelayed) part when it has active gains, "
             "else its whole feedback", "pair", FIT_MAX_GAIN),
    Quantity("viscosity", "N·m·s/rad", 0.0, MAX_PAIR_VISCOSITY,
             "a pair's viscosity L (intrinsic, as stiffness)", "pair", FIT_MAX_GAIN),
    Quantity("active_stiffness", "N·m/rad", 0.0, MAX_PAIR_STIFFNESS,
             "a pair's active (neural) stiffness, delayed by feedback_delay", "pair",
             FIT_MAX_GAIN),
    Quantity("active_viscosity", "N·m·s/rad", 0.0, MAX_PAIR_VISCOSITY,
             "a pair's active viscosity, delayed by feedback_delay", "pair", FIT_MAX_GAIN),
    Quantity("viscosity_ratio", "s", 0.0, MAX_VISCOSITY_RATIO,
             "every pair's viscosity / stiffness (the paper's 0.25 s)", "", 5.0),
    Quantity("active_viscosity_ratio", "s", 0.0, MAX_VISCOSITY_RATIO,
             "every pair's active viscosity / active stiffness", "", 5.0),
    Quantity("feedback_delay", "s", 0.0, MAX_FEEDBACK_DELAY,
             "neural delay τ of the active gains (without any, of every pair's whole "
             "feedback)", "", MAX_FEEDBACK_DELAY),
    Quantity("proprioceptive_weight", "-", 0.0, 1.0,
             "W: under a tilt α the active error of pairs spanning the foot is θ + W·α "
             "(1: relative to the foot, 0: to the vertical)", "", 1.0),
    Quantity("visual_weight", "-", 0.0, 1.0,
             "W_v: under a visual-scene tilt v the active error of pairs spanning the foot "
             "gains W_v·v (Peterka 2002's independent channels; W_p + W_v <= 1, the rest "
             "graviceptive)", "", 1.0),
    Quantity("torque_feedback_gain", "-", 0.0, MAX_TORQUE_FEEDBACK_GAIN,
             "K_t: the active torque fed back positively through K_t/(τ_t s + 1) (Peterka "
             "2002; 0: none; K_t = K_F·K_P of the source's K_F [rad/(N·m)])", "", 3.0),
    Quantity("torque_feedback_time_constant", "s", MIN_TORQUE_FEEDBACK_TIME_CONSTANT,
             MAX_TORQUE_FEEDBACK_TIME_CONSTANT,
             "τ_t of the torque feedback's low-pass filter (default 17.4 s, PMC5664365 "
             "Table 1; at least 1 ms: a faster filter is no filter and stiffens the "
             "integration past its step budget)", "", 200.0),
    Quantity("joint_feedback_scale", "-", 0.0, MAX_JOINT_FEEDBACK_SCALE,
             "factor s on a joint-space controller's gain matrices (multijoint-default: "
             "the LQR design at s = 1)", "", 2.0),
    Quantity("torque_limit", "N·m", 0.0, math.inf,
             "largest net muscle moment at a joint (inf: none)", "joint", low_open=True),
    Quantity("disturbance_scale", "-", 0.0, MAX_DISTURBANCE_SCALE,
             "factor on the base experiment's platform motion (step speed, pulse peak, ramp "
             "displacement, sine amplitudes, measured accelerations); simulate_batch's "
             "per-run factor may also be negative (reversing the motion), each scaled motion "
             "then within its own bounds"),
    Quantity("height", "m", *HEIGHT_RANGE,
             "standing height of a body scaled by Winter's anthropometric table"),
    Quantity("mass", "kg", *MASS_RANGE, "body mass of a body scaled by Winter's table"),
    Quantity("step_speed", "m/s", 0.0, MAX_PLATFORM_SPEED,
             "speed of a platform velocity step (its sign is the direction)", low_open=True),
    Quantity("tilt_amplitude", "rad", 0.0, MAX_TILT,
             "amplitude of a support-surface tilt (a PRTS's peak to peak: up to twice it)"),
)}

#: Former spellings -> (their names, where they were used); PAIR / JOINT stand for any pair
#: or joint name (:func:`renamed` applies it).
RENAMED: dict[str, tuple[str, str]] = {
    "PAIR": ("stiffness:PAIR", "sweep --vary, fit --free, stability-map --x/--y"),
    "active_PAIR": ("active_stiffness:PAIR", "sweep --vary, fit --free, the explorer"),
    "active_viscosity_PAIR": ("active_viscosity:PAIR", "sweep --vary, fit --free, the explorer"),
    "JOINT_torque_limit": ("torque_limit:JOINT", "sweep --vary"),
    "stiffness_PAIR": ("stiffness:PAIR", "the explorer"),
    "stiffness, viscosity, active_stiffness, active_viscosity (no pair, several pairs)": (
        "QUANTITY:PAIR", "fit-frf (meant the first pair), stability-map's delayed map"),
}

_NAME = re.compile(r"[a-z][a-z0-9_]*(?::[a-z][a-z0-9_]*)?")


def quantity(name: str) -> Quantity:
    """The row of ``name`` (``QUANTITY`` or ``QUANTITY:PAIR``); UnknownNameError if none."""
    base = str(name).partition(":")[0].split("#")[0]
    if base not in QUANTITIES:
        raise UnknownParameterError(f"unknown parameter {str(name)!r}; known: "
                               f"{', '.join(q.form for q in QUANTITIES.values())}")
    return QUANTITIES[base]


def unit(name: str) -> str:
    """The unit of a parameter name (a ``#k`` per-condition suffix is ignored)."""
    return quantity(name).unit


def parse_name(text: str) -> tuple[str, str | None]:
    """Split ``QUANTITY[:PAIR]`` into (quantity, pair or None); the quantity must be in the
    table (the pair is not checked: see :func:`resolve`).

    >>> from posturelab.parameters import parse_name
    >>> parse_name("active_stiffness:ankle")
    ('active_stiffness', 'ankle')
    >>> parse_name("feedback_delay")
    ('feedback_delay', None)
    """
    name = str(text).strip().lower()
    if not _NAME.fullmatch(name):
        raise ParameterError(f"a parameter name is QUANTITY or QUANTITY:PAIR (e.g. "
                             f"stiffness:ankle), got {str(text)!r}")
    base, _, part = name.partition(":")
    q = quantity(base)
    if part and not q.per:
        raise ParameterError(f"{base} takes no :PAIR, got {name!r}")
    return base, part or None


def renamed(text: str, pairs: Sequence[str] = PAPER_PAIRS) -> str | None:
    """The name a former spelling now has (:data:`RENAMED`), or None if ``text`` is not one:
    ``active_ankle`` -> ``active_stiffness:ankle``. A bare pair name counts when it is one of
    ``pairs``; the prefixed and suffixed forms whatever the pair or joint."""
    name = str(text).strip().lower()
    if name in QUANTITIES or not re.fullmatch(r"[a-z][a-z0-9_]*", name):
        return None
    if name in pairs:
        return f"stiffness:{name}"
    for prefix, new in (("active_viscosity_", "active_viscosity"), ("stiffness_", "stiffness"),
                        ("active_", "active_stiffness")):
        if name.startswith(prefix) and len(name) > len(prefix):
            return f"{new}:{name.removeprefix(prefix)}"
    if name.endswith("_torque_limit") and len(name) > len("_torque_limit"):
        return f"torque_limit:{name.removesuffix('_torque_limit')}"
    return None


def resolve(text: str, pairs: Sequence[str] = PAPER_PAIRS,
            joints: Sequence[str] = PAPER_JOINTS, *, accepts: Sequence[str] | None = None,
            what: str = "parameter") -> str:
    """The one spelling of a parameter name for a body with these pairs and joints.

    Parameters
    ----------
    text : str
        ``QUANTITY`` or ``QUANTITY:PAIR`` (case and surrounding spaces ignored).
    pairs, joints : sequence of str
        The body's muscle pairs and joints (default: the paper's three-link body).
    accepts : sequence of str, optional
        The quantities the caller takes (default: all of :data:`QUANTITIES`).
    what : str
        How the message names the caller (``"sweep parameter"``, ``"--free"``, ...).

    Returns
    -------
    str
        ``QUANTITY:PAIR``, ``QUANTITY:JOINT`` or ``QUANTITY``; a pair quantity written
        without its pair on a one-pair body gets that pair.

    Raises
    ------
    ParameterError
        A former spelling ("'active_ankle' is now called 'active_stiffness:ankle'"), an
        unknown quantity, pair or joint, a pair quantity without its pair on a body with
        several pairs, or a quantity the caller does not take; one line each.
    """
    name = str(text).strip().lower()
    new = renamed(name, pairs)
    if new is not None and new.partition(":")[2] in (
            joints if new.startswith("torque_limit:") else pairs):
        raise ParameterError(f"{what} {name!r} is now called {new!r}")
    try:
        base, part = parse_name(name)
    except UnknownParameterError:
        known = names_for(pairs, joints, accepts)
        raise UnknownParameterError(f"unknown {what} {str(text).strip()!r}; known: "
                               f"{', '.join(known)}") from None
    q = QUANTITIES[base]
    if accepts is not None and base not in accepts:
        raise ParameterError(f"{what} cannot be {name!r}; it takes "
                             f"{', '.join(QUANTITIES[a].form for a in accepts)}")
    if not q.per:
        return base
    members = tuple(pairs) if q.per == "pair" else tuple(joints)
    kind = q.per
    if part is None:
        if len(members) == 1:
            return f"{base}:{members[0]}"
        raise ParameterError(f"{what} {name!r} needs its {kind}: "
                             f"{', '.join(f'{base}:{m}' for m in members)}")
    if part not in members:
        raise UnknownParameterError(f"unknown {kind} {part!r} in {what} {name!r}; {kind}s: "
                               f"{', '.join(members)}")
    return f"{base}:{part}"


def check_value(name: str, value, field: str | None = None) -> float:
    """``value`` as a float within the bounds of ``name``'s quantity.

    Raises
    ------
    ParameterError
        One line naming the field (``field``, default the name), the value and the range:
        "feedback_delay [s] must be in [0, 1], got 1.5".
    """
    q = quantity(name)
    label = f"{field or name} [{q.unit}]"
    from ._validation import as_number

    v = as_number(label, value, f"a number in {q.interval()}")
    if math.isnan(v) or not (
            (q.low < v if q.low_open else q.low <= v) and v <= q.high):
        raise ParameterError(f"{label} must be in {q.interval()}, got {value!r}")
    return v


def check_weights(proprioceptive_weight, visual_weight,
                  fields: tuple[str, str] = ("proprioceptive_weight", "visual_weight")) -> float:
    """The visual weight W_v [-], each weight within its bounds and W_p + W_v <= 1 (the
    graviceptive weight 1 − W_p − W_v is not negative: Peterka 2002's independent channels);
    ``fields`` are how a message names the two (a file's keys, the command line's flags).

    Raises
    ------
    ParameterError
        One line naming both weights and their sum when it is over 1.
    """
    wp = check_value("proprioceptive_weight", proprioceptive_weight, fields[0])
    wv = check_value("visual_weight", visual_weight, fields[1])
    if wp + wv > 1.0 + 1e-12:
        raise ParameterError(f"{fields[0]} + {fields[1]} [-] must be at most 1 "
                             f"(the rest is graviceptive), got {wp:g} + {wv:g} = {wp + wv:g}")
    return wv


def names_for(pairs: Sequence[str] = PAPER_PAIRS, joints: Sequence[str] = PAPER_JOINTS,
              accepts: Sequence[str] | None = None) -> tuple[str, ...]:
    """Every name of a body with these pairs and joints, in table order (``accepts``: only
    those quantities)."""
    out = []
    for q in QUANTITIES.values():
        if accepts is not None and q.name not in accepts:
            continue
        members = pairs if q.per == "pair" else joints if q.per == "joint" else ()
        out.extend(f"{q.name}:{m}" for m in members) if q.per else out.append(q.name)
    return tuple(out)


def markdown_table() -> str:
    """The table as Markdown (docs/parameters.md holds it; a test compares them)."""
    rows = ["| name | unit | accepted | fit searches | meaning |",
            "|---|---|---|---|---|"]
    for q in QUANTITIES.values():
        fit = f"[{_g(q.low)}, {_g(q.fit_high)}]" if not math.isnan(q.fit_high) else "—"
        rows.append(f"| `{q.form}` | {q.unit} | {q.interval()} | {fit} | {q.meaning} |")
    rows += ["", "| former spelling | name | where |", "|---|---|---|"]
    rows += [f"| `{old}` | `{new}` | {where} |" for old, (new, where) in RENAMED.items()]
    return "\n".join(rows) + "\n"


#: Longest run (a day). [s]
MAX_DURATION = 86_400.0
#: The longest wall-clock time limit a run may ask for (a week). [s]
MAX_TIME_LIMIT = 604_800.0
#: The largest step budget a run may ask for. [-]
MAX_STEP_BUDGET = 10_000_000_000
#: Deepest tilt axis below the ankle. [m]
MAX_AXIS_DEPTH = 1.0

#: The settings of one run that no command varies by name: their units and the values a run
#: accepts (:class:`posturelab.simulation.options.RunOptions` reads its bounds here and, for
#: ``feedback_delay`` and ``proprioceptive_weight``, in :data:`QUANTITIES`).
RUN_SETTINGS: dict[str, Quantity] = {q.name: q for q in (
    Quantity("duration", "s", 0.0, MAX_DURATION, "simulated time", low_open=True),
    Quantity("tilt_axis_depth", "m", 0.0, MAX_AXIS_DEPTH,
             "distance of the tilt axis below the ankle (0: the ankle's own axis)"),
    Quantity("rtol", "-", 1e-14, 1e-1, "relative tolerance of the integrator"),
    Quantity("atol", "rad, rad/s", 1e-16, 1e-1, "absolute tolerance of the integrator"),
    Quantity("sample_rate", "Hz", 1.0, 1e6, "output samples per second"),
    Quantity("time_limit", "s", 0.0, MAX_TIME_LIMIT,
             "wall-clock budget of the integration", low_open=True),
    Quantity("max_steps", "-", 1.0, float(MAX_STEP_BUDGET),
             "step budget: accepted integrator steps before the run stops as failed"),
    Quantity("max_switches", "-", 0.0, math.inf,
             "switches (one-sided pairs, knee stop, saturation) before the run fails"),
)}
