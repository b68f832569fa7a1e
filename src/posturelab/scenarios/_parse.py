"""Reading a scenario file's tables into a :class:`~posturelab.scenarios.Scenario`: the
body, the muscles, the platform motion and the run's
:class:`~posturelab.simulation.options.RunOptions` (each option's key in the file:
:data:`OPTION_KEYS`). The types of every key are checked before, by
:mod:`posturelab.scenarios.schema`; the ranges and the rules between keys here and by the
objects built.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from .._validation import finite_array, finite_float
from ..errors import ParameterError, PostureLabError, ScenarioError, UnknownNameError
from ..model.body import Body, Segment, get_body
from ..model.controllers import MULTIJOINT_CONTROLLERS
from ..model.muscles import MusclePair, MuscleSet, paper_muscles
from ..model.noise import MotorNoise
from ..model.options import FOOT_FROM_LITERATURE, BaseOfSupport, FallCriteria, KneeModel
from ..model.tilt import (
    PETERKA_SEED,
    PETERKA_TAPS,
    PRTSTilt,
    RaisedCosineTilt,
    SineTilt,
    Tilt,
    get_prts_sequence,
    read_tilt_csv,
)
from ..parameters import check_value, check_weights
from ..simulation.options import RunOptions
from ._disturbance import _reject, disturbance_from_tables
from ._scenario import SCENARIO_DEFAULTS as DEFAULTS
from ._scenario import Scenario

__all__ = ["OPTION_KEYS", "parse_tables", "run_options", "body_from_table",
           "muscles_from_table", "tilt_from_table", "disturbance_from_tables",
           "motor_noise_from_table", "fall_from_table", "torque_limits_from_table",
           "number_list"]


#: Where each run option is written in a scenario file (its TOML key); a message about an
#: option names the key.
OPTION_KEYS: dict[str, str] = {
    "duration": "duration", "initial_state": "initial", "rates_from": "initial.rates_from",
    "knee": "knee", "fall": "fall", "torque_limits": "limits.torque",
    "feedback_delay": "muscles.feedback_delay",
    "proprioceptive_weight": "muscles.proprioceptive_weight",
    "torque_feedback_gain": "muscles.torque_feedback_gain",
    "torque_feedback_time_constant": "muscles.torque_feedback_time_constant", "tilt": "tilt",
    "joint_feedback": "muscles.controller",
    "visual_weight": "muscles.visual_weight", "visual_tilt": "visual_tilt",
    "tilt_axis_depth": "tilt.axis_depth", "motor_noise": "motor_noise",
    "method": "solver.method", "rtol": "solver.rtol", "atol": "solver.atol",
    "sample_rate": "solver.sample_rate", "max_steps": "solver.max_steps",
    "time_limit": "solver.time_limit", "max_switches": "solver.max_switches",
    "description": "description",
}



def run_options(origin: str, names: Mapping[str, str] | None = None, **fields) -> RunOptions:
    """The scenario's :class:`RunOptions`; a bad value raises ScenarioError naming its key
    (``solver.max_steps must be an integer in [1, …], got 0``), or, from the command line
    (no ``origin``; ``names`` maps keys to flags), a ParameterError naming the flags."""
    import re

    try:
        return RunOptions(**fields)
    except ParameterError as exc:
        text = str(exc)
        name = next((k for k in OPTION_KEYS if text.startswith(k + " ")), None)
        if name is not None and OPTION_KEYS[name] != name:
            text = _name(names, OPTION_KEYS[name]) + text[len(name):]
        if names is not None:  # an option named inside the message: its flag too
            text = re.sub(r"\b(?<![.\-])([a-z]+_[a-z_]+)\b",
                          lambda m: (_name(names, OPTION_KEYS[m[1]]) if m[1] in OPTION_KEYS
                                     else m[1]), text)
        raise _error(origin, text) from None


def parse_tables(data: dict, base_dir: Path, origin: str,
                 names: Mapping[str, str] | None = None) -> Scenario:
    """A scenario from its tables (types already checked by
    :func:`posturelab.scenarios.schema.check_types`, or built by the command line).

    ``origin`` starts each message (the file; empty for the command line, whose messages are
    then ParameterErrors); ``names`` says how the user wrote a key when not as in a scenario
    file (the command line's flags: ``{"muscles.feedback_delay": "--feedback-delay"}``).
    """
    duration = finite_float("duration [s]", data["duration"])
    mt = dict(data.get("muscles", {}))
    feedback_gain = mt.pop("torque_feedback_gain", DEFAULTS.torque_feedback_gain)
    feedback_lag = mt.pop("torque_feedback_time_constant",
                          DEFAULTS.torque_feedback_time_constant)
    visual_weight = mt.pop("visual_weight", DEFAULTS.visual_weight)
    for key, value in (("torque_feedback_gain", feedback_gain),
                       ("torque_feedback_time_constant", feedback_lag),
                       ("visual_weight", visual_weight)):
        try:  # the parameter table's bounds, before the muscles are built
            check_value(key, value, _name(names, f"muscles.{key}"))
        except ParameterError as exc:
            raise _error(origin, str(exc)) from None
    multijoint = _multijoint_name(mt, origin, names)
    body = body_from_table(data.get("body", {}), origin, names,
                           one_link="controller" in mt and multijoint is None)
    joint_feedback, knee_mode = None, "free"
    if multijoint is not None:
        muscles, delay, weight, joint_feedback, knee_mode = _multijoint(mt, body, origin, names)
        case = None
    else:
        muscles, case, delay, weight = muscles_from_table(mt, body, origin, names,
                                                          data.get("body", {}))
    try:
        check_weights(weight, visual_weight, (_name(names, "muscles.proprioceptive_weight"),
                                              _name(names, "muscles.visual_weight")))
    except ParameterError as exc:
        raise _error(origin, str(exc)) from None
    tilt_table = data.get("tilt", {})
    tilt = tilt_from_table(tilt_table, base_dir, origin, names)
    visual = tilt_from_table(data.get("visual_tilt", {}), base_dir, origin, names,
                             "visual_tilt")
    disturbance = disturbance_from_tables(data.get("disturbance"), base_dir, origin, names)
    noise = motor_noise_from_table(data.get("motor_noise", {}), body.n_links, origin, names)
    it = data.get("initial", {})
    n = body.n_links
    initial = None
    if "posture" in it or "rates" in it:
        posture = finite_array(f"{_name(names, 'initial.posture')} [rad]",
                               number_list(it.get("posture", [0.0] * n),
                                           f"{_name(names, 'initial.posture')} [rad]", n),
                               (n,))
        rates = finite_array(f"{_name(names, 'initial.rates')} [rad/s]",
                             number_list(it.get("rates", [0.0] * n),
                                         f"{_name(names, 'initial.rates')} [rad/s]", n), (n,))
        initial = np.concatenate([posture, rates])
    kt = data.get("knee", {})
    knee = KneeModel(kt.get("mode", knee_mode), kt.get("stop_angle", 0.0))
    fall = fall_from_table(data.get("fall", {}), origin, names)
    torque_limits = None
    if "torque" in data.get("limits", {}):
        torque_limits = torque_limits_from_table(data["limits"]["torque"], body.n_links,
                                                 origin, names)
    st = data.get("solver", {})
    options = run_options(
        origin, names, duration=duration, initial_state=initial,
        rates_from=it.get("rates_from", DEFAULTS.rates_from), knee=knee, fall=fall,
        torque_limits=torque_limits, feedback_delay=delay, proprioceptive_weight=weight,
        torque_feedback_gain=feedback_gain, torque_feedback_time_constant=feedback_lag,
        tilt=tilt, tilt_axis_depth=tilt_table.get("axis_depth", 0.0), motor_noise=noise,
        joint_feedback=joint_feedback, visual_tilt=visual, visual_weight=visual_weight,
        method=st.get("method"), rtol=st.get("rtol", DEFAULTS.rtol),
        atol=st.get("atol", DEFAULTS.atol),
        sample_rate=st.get("sample_rate", DEFAULTS.sample_rate),
        max_switches=st.get("max_switches", DEFAULTS.max_switches),
        max_steps=st.get("max_steps"), time_limit=st.get("time_limit"),
        description=str(data.get("description", "")))
    return Scenario(name=str(data.get("name", Path(origin).stem if origin else "")),
                    source=str(data.get("source", "")), body=body, muscles=muscles,
                    disturbance=disturbance, options=options, case=case)


def _multijoint_name(mt: dict, origin: str, names) -> str | None:
    """The name of ``[muscles] controller`` when it is a multi-joint preset, else None."""
    name = str(mt.get("controller", "")).strip().lower()
    if name not in MULTIJOINT_CONTROLLERS and "joint_feedback_scale" in mt:
        raise _error(origin, f"{_name(names, 'muscles.joint_feedback_scale')} scales a "
                     f"multi-joint controller ({_name(names, 'muscles.controller')} "
                     f"{', '.join(MULTIJOINT_CONTROLLERS)}), and none is given")
    return name if name in MULTIJOINT_CONTROLLERS else None


def _multijoint(mt: dict, body: Body, origin: str, names: Mapping[str, str] | None):
    """``[muscles] controller = multijoint-…`` designed for ``body`` with its scale: (muscles,
    delay [s], weight [-], joint feedback, the design's knee mode)."""
    from ..linear.lqr import multijoint_controller

    ctl = _name(names, "muscles.controller")
    name = str(mt.pop("controller"))
    if others := [k for k in GAIN_KEYS if k in mt]:
        raise _error(origin, f"{ctl} sets every gain ({name}); "
                     f"{_name(names, 'muscles.' + others[0])} cannot be given with {ctl}")
    try:
        scale = check_value("joint_feedback_scale", mt.pop("joint_feedback_scale", 1.0),
                            _name(names, "muscles.joint_feedback_scale"))
        design = multijoint_controller(body, name, scale)
        delay, weight = (check_value(k, mt.pop(k, d), _name(names, f"muscles.{k}")) for k, d
                         in (("feedback_delay", design.feedback_delay),
                             ("proprioceptive_weight", 1.0)))
    except PostureLabError as exc:
        raise _error(origin, str(exc)) from None
    return design.muscles, delay, weight, design.joint_feedback, design.knee


def _name(names: Mapping[str, str] | None, key: str) -> str:
    """How the user wrote ``key`` (a scenario file's key, or the flag in ``names``)."""
    return key if names is None else names.get(key, key)


def _error(origin: str, text: str) -> PostureLabError:
    """A ScenarioError naming the file ``origin``; a ParameterError without one (the
    command line, which names its flags)."""
    return ScenarioError(f"{origin}: {text}") if origin else ParameterError(text)


def number_list(value, field: str, n: int | None = None) -> list[float]:
    """Numbers given as a list, or as text ``"a,b,c"`` (the command line's spelling),
    checking their count and finiteness; errors name ``field``."""
    if not isinstance(value, str):
        return list(value)
    parts = [p.strip() for p in value.split(",")]
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise ParameterError(f"{field} must be comma-separated numbers, got {value!r}") from None
    if n is not None and len(values) != n:
        raise ParameterError(f"{field} must have {n} comma-separated values, got {len(values)}")
    for v in values:
        if not math.isfinite(v):
            raise ParameterError(f"{field} must contain finite numbers, got {v}")
    return values


def _one_number(value, field: str) -> float:
    """One number, or its text."""
    return number_list(value, field, 1)[0] if isinstance(value, str) else value


TILT_KEYS = ("type", "amplitude", "frequency", "phase", "duration", "start", "state_duration",
             "registers", "taps", "seed", "sequence", "file", "axis_depth")


def tilt_from_table(tt: dict, base_dir: Path, origin: str = "",
                    names: Mapping[str, str] | None = None, key: str = "tilt") -> Tilt | None:
    """The [tilt] table (module docstring), or None when there is none; the command line's
    ``--tilt`` as this table too; ``key`` "visual_tilt" for the visual scene's table (the
    same types, without axis_depth)."""
    if not tt:
        return None
    where = _name(names, key)
    kind = tt.get("type")
    allowed = {"sine": ("amplitude", "frequency", "phase"),
               "raised-cosine": ("amplitude", "duration", "start"),
               "prts": ("amplitude", "state_duration", "registers", "taps", "seed",
                        "sequence"),
               "profile": ("file",)}
    if kind not in allowed:
        raise _error(origin, f"{key}.type must be one of {', '.join(allowed)}; got {kind!r}")
    _reject(tt, ("type", *(("axis_depth",) if key == "tilt" else ()), *allowed[kind]),
            f"{key} (type {kind})", origin)
    try:
        if kind == "sine":
            return SineTilt(tt.get("amplitude"), tt.get("frequency"), tt.get("phase", 0.0))
        if kind == "raised-cosine":
            return RaisedCosineTilt(tt.get("amplitude"), tt.get("duration"), tt.get("start", 0.0))
        if kind == "prts":
            if "sequence" in tt:  # a named one: its register and state duration
                if set(tt) & {"registers", "taps", "seed"}:
                    raise ScenarioError(f"{origin}: tilt (type prts) takes sequence or a "
                                        "register (registers, taps, seed), not both")
                try:
                    seq = get_prts_sequence(str(tt["sequence"]))
                except UnknownNameError as exc:
                    if not origin:
                        raise
                    raise ScenarioError(f"{origin}: tilt.sequence: {exc}") from None
                return PRTSTilt(tt.get("amplitude"),
                                tt.get("state_duration", seq.state_duration), seq.registers,
                                seq.taps, seq.seed)
            if set(tt) <= {"type", "amplitude"}:
                return PRTSTilt.named("posturelab-80", tt.get("amplitude"))
            return PRTSTilt(tt.get("amplitude"), tt.get("state_duration", 0.25),
                            tt.get("registers", 4), tuple(tt.get("taps", PETERKA_TAPS)),
                            tuple(tt.get("seed", PETERKA_SEED)))
        if "file" not in tt:
            raise ScenarioError(f"{origin}: tilt (type profile) needs file")
        return read_tilt_csv(base_dir / str(tt["file"]))
    except TypeError as exc:
        raise _error(origin, f"{where}: {exc}") from None


def fall_from_table(ft: dict, origin: str = "", names: Mapping[str, str] | None = None,
                    base: FallCriteria | None = None) -> FallCriteria:
    """The [fall] table: max_link_angle [rad], base_of_support ("none", "literature", a
    table {heel, toe} [m] or its text "HEEL,TOE"), centre_of_pressure; a key not given keeps
    ``base``'s (default: the paper's criteria)."""
    base = FallCriteria() if base is None else base
    spec = ft.get("base_of_support")
    if spec is None:
        bos = base.base_of_support
    elif spec == "none":
        bos = None
    elif spec == "literature":
        bos = FOOT_FROM_LITERATURE
    else:
        where = _name(names, "fall.base_of_support")
        if isinstance(spec, str):
            heel, toe = number_list(spec, f"{where} HEEL,TOE [m]", 2)
            spec = {"heel": heel, "toe": toe}
        bos = BaseOfSupport(spec["heel"], spec["toe"], source=origin or where)
    return FallCriteria(ft.get("max_link_angle", base.max_link_angle), bos,
                        bool(ft.get("centre_of_pressure", base.centre_of_pressure)))


def torque_limits_from_table(values, n_joints: int, origin: str = "",
                             names: Mapping[str, str] | None = None) -> tuple:
    """limits.torque: per joint the largest net moment [N·m] both ways, > 0, or "inf" /
    "none" for no limit; or LO:HI (a list [LO, HI]), the moment kept in [LO, HI] with
    LO < 0 < HI (at the ankle HI plantarflexion, toward the toes; LO dorsiflexion, toward the
    heel; -inf / inf for none); or "foot" (the ankle: m g x_heel : m g x_toe from the foot,
    :mod:`posturelab.model.limits`). A list, or its text ``"120,inf,80"`` /
    ``"-40:130,inf,inf"`` / ``"foot,inf,inf"``."""
    where = f"{_name(names, 'limits.torque')} [N·m]"
    if isinstance(values, str):
        values = [v.strip().lower() for v in values.split(",")]
    if len(values) != n_joints:
        raise _error(origin, f"{where} needs {n_joints} values (one per joint), got "
                     f"{len(values)}")

    def number(value, ok, what: str) -> float:
        text = value.strip().lower() if isinstance(value, str) else None
        if text in ("inf", "none", "-inf"):
            v = -math.inf if text == "-inf" else math.inf
        else:
            try:
                v = math.nan if isinstance(value, bool) else float(value)
            except (TypeError, ValueError):
                v = math.nan
        if not ok(v):  # (NaN fails)
            raise _error(origin, f"{where} {what}, got {value!r}")
        return v

    out: list = []
    for j, value in enumerate(values):
        if isinstance(value, str) and value.strip().lower() == "foot":
            if j != 0:
                raise _error(origin, f"{where}: 'foot' is for the ankle (the first joint) only")
            out.append("foot")
            continue
        if isinstance(value, str) and ":" in value:
            value = value.split(":")
        if isinstance(value, (list, tuple)):
            if len(value) != 2:
                raise _error(origin, f"{where} LO:HI needs two numbers, got {value!r}")
            out.append((number(value[0], lambda v: v < 0, "LO (at the ankle dorsiflexion, "
                               "toward the heel) must be in [-inf, 0)"),
                        number(value[1], lambda v: v > 0, "HI (at the ankle plantarflexion, "
                               "toward the toes) must be in (0, inf]")))
            continue
        out.append(number(value, lambda v: v > 0, "must each be in (0, inf] (a number > 0, "
                          "'inf' for no limit, LO:HI or 'foot')"))
    return tuple(out)


def body_from_table(bt: dict, origin: str = "", names: Mapping[str, str] | None = None, *,
                    one_link: bool = False) -> Body:
    """The [body] table: a preset or the segments, or (from the command line's --height and
    --mass, not a file's keys) a height [m] and mass [kg] (Winter's anthropometric table);
    ``one_link`` (a one-link controller): by default the paper's body as one link, and a body
    from height and mass lumped to one link."""
    def name(key: str) -> str:
        return _name(names, f"body.{key}")

    if ("height" in bt) != ("mass" in bt):
        raise _error(origin, f"{name('height')} [m] and {name('mass')} [kg] go together")
    given = [k for k in ("preset", "segments", "height") if k in bt]
    if len(given) > 1:
        raise _error(origin, f"give {name(given[0])} or {name(given[1])}, not both")
    gravity = bt.get("gravity")
    if "segments" in bt:
        segs = bt["segments"]
        if not isinstance(segs, list) or not segs:
            raise _error(origin, "body.segments must be a non-empty array of tables")
        out = []
        for i, s in enumerate(segs):
            if not isinstance(s, dict):
                raise _error(origin, f"body.segments[{i}] must be a table")
            keys = ("name", "mass", "length", "com_distance", "inertia")
            _reject(s, keys, f"body.segments[{i}]", origin)
            missing = [k for k in keys[1:] if k not in s]
            if missing:
                raise _error(origin, f"body.segments[{i}] lacks {missing[0]!r}")
            out.append(Segment(str(s.get("name", f"link{i + 1}")), s["mass"], s["length"],
                               s["com_distance"], s["inertia"]))
        body = Body(tuple(out), name="scenario")
    elif "height" in bt:
        from ..model.anthropometry import body_from_anthropometry
        from ..model.anthropometry import one_link as lumped

        body = body_from_anthropometry(_one_number(bt["height"], f"{name('height')} [m]"),
                                       _one_number(bt["mass"], f"{name('mass')} [kg]"))
        if one_link:
            body = lumped(body)
    else:
        body = get_body(str(bt.get("preset", "paper-1link" if one_link else "paper")))
    if gravity is not None:
        body = body.with_gravity(gravity)
    return body


#: The keys of [muscles] that set a gain (none may be given with a controller preset).
GAIN_KEYS = ("case", "stiffness", "pairs", "viscosity", "viscosity_ratio", "gastrocnemius",
             "active_stiffness", "active_viscosity", "active_viscosity_ratio")


def muscles_from_table(mt: dict, body: Body, origin: str = "",
                       names: Mapping[str, str] | None = None, bt: dict | None = None
                       ) -> tuple[MuscleSet, str | None, float, float]:
    """The [muscles] table on ``body`` (``bt``: its [body] table, for messages): the muscle
    pairs, the Table I case (or None), the feedback delay [s] and the proprioceptive weight
    [-] (a controller preset's unless the table gives them), each checked against the
    parameter table."""
    mt = dict(mt)
    mt.pop("visual_weight", None)  # (a run option: parse_tables reads it)
    preset = _controller(mt, body, origin, names, bt or {})
    delay = mt.pop("feedback_delay", 0.0 if preset is None else preset.feedback_delay)
    weight = mt.pop("proprioceptive_weight",
                    1.0 if preset is None else preset.proprioceptive_weight)
    for key, value in (("feedback_delay", delay), ("proprioceptive_weight", weight)):
        try:  # the parameter table's bounds, before the muscles are built
            value = check_value(key, value, _name(names, f"muscles.{key}"))
        except ParameterError as exc:
            raise _error(origin, str(exc)) from None
        delay, weight = (value, weight) if key == "feedback_delay" else (delay, value)
    muscles, case = (_muscles(mt, body, origin, names) if preset is None
                     else (preset.muscles(body), None))
    return muscles, case, delay, weight


def _controller(mt: dict, body: Body, origin: str, names: Mapping[str, str] | None,
                bt: dict):
    """``[muscles] controller = NAME``: the preset (its gains on this one-link body, its delay
    and weight unless the table gives them), or None."""
    if "controller" not in mt:
        return None
    from ..model.controllers import get_controller

    ctl = _name(names, "muscles.controller")
    name = str(mt.pop("controller"))
    try:
        preset = get_controller(name)
    except PostureLabError as exc:
        raise _error(origin, f"{ctl}: {exc}") from None
    others = [k for k in GAIN_KEYS if k in mt]
    if others:
        raise _error(origin, f"{ctl} sets every gain ({name}); "
                     f"{_name(names, 'muscles.' + others[0])} cannot be given with {ctl}")
    if body.n_links != 1:
        which = (f"{_name(names, 'body.preset')} {bt['preset']}" if "preset" in bt
                 else "this body")
        raise _error(origin, f"{ctl} {name} is a one-link controller (an inverted pendulum "
                     f"about the ankle); {which} has {body.n_links} links: give a one-link "
                     f"body ({_name(names, 'body.preset')} paper-1link), "
                     f"{_name(names, 'body.height')} and {_name(names, 'body.mass')} "
                     "(lumped to one link), or no body")
    return preset


def _muscles(mt: dict, body: Body, origin: str, names: Mapping[str, str] | None
             ) -> tuple[MuscleSet, str | None]:
    def name(key: str) -> str:
        return _name(names, f"muscles.{key}")

    given = [k for k in ("case", "stiffness", "pairs") if k in mt]
    if len(given) != 1:
        choices = ", ".join(name(k) for k in ("case", "stiffness", "pairs", "controller")
                            if names is None or f"muscles.{k}" in names)
        where = "[muscles]" if names is None else "the muscles"
        given_words = f" (given: {', '.join(name(k) for k in given)})" if given else ""
        raise _error(origin, f"{where} need exactly one of {choices}{given_words}"
                     if names is not None else f"{where} needs exactly one of {choices}"
                     f"{given_words}")
    for a, b in (("viscosity", "viscosity_ratio"),
                 ("active_viscosity", "active_viscosity_ratio")):
        if a in mt and b in mt:
            raise _error(origin, f"give {name(a)} or {name(b)}, not both")
    for key in ("viscosity_ratio", "active_viscosity_ratio"):
        ratio = mt.get(key)
        if ratio is not None and not (isinstance(ratio, int | float)
                                      and math.isfinite(ratio) and ratio >= 0):
            raise _error(origin, f"{name(key)} [s] must be a finite number >= 0, got {ratio!r}")
    if "pairs" in mt:
        stray = [k for k in ("viscosity", "active_stiffness", "active_viscosity",
                             "active_viscosity_ratio") if k in mt]
        if stray:
            raise _error(origin, f"muscles.{stray[0]} is for case / stiffness; with "
                         "pairs give active_stiffness and active_viscosity per pair")
        pairs = []
        for i, p in enumerate(mt["pairs"]):
            if not isinstance(p, dict):
                raise _error(origin, f"muscles.pairs[{i}] must be a table")
            keys = ("name", "lo", "hi", "stiffness", "viscosity", "one_sided",
                    "active_stiffness", "active_viscosity", "pull_only")
            _reject(p, keys, f"muscles.pairs[{i}]", origin)
            for k in ("lo", "hi", "stiffness"):
                if k not in p:
                    raise _error(origin, f"muscles.pairs[{i}] lacks {k!r}")
            ratio = finite_float("muscles.viscosity_ratio [s]", mt.get("viscosity_ratio", 0.25))
            visc = p.get("viscosity", ratio * finite_float("stiffness", p["stiffness"]))
            pairs.append(MusclePair(str(p.get("name", f"pair{i + 1}")), p["lo"], p["hi"],
                                    p["stiffness"], visc, bool(p.get("one_sided", False)),
                                    p.get("active_stiffness"), p.get("active_viscosity"),
                                    bool(p.get("pull_only", False))))
        return MuscleSet(tuple(pairs), body.n_links), None
    from ..model.muscles import joint_pair_names, muscles_for

    count = 5 if body.n_links == 3 else len(joint_pair_names(body.n_links))
    units = {"stiffness": "[N·m/rad]", "viscosity": "[N·m·s/rad]",
             "active_stiffness": "[N·m/rad]", "active_viscosity": "[N·m·s/rad]"}
    lists = {key: None if mt.get(key) is None
             else number_list(mt[key], f"{name(key)} {units[key]}", count) for key in units}
    ratio = mt.get("viscosity_ratio", 0.25)
    if body.n_links != 3:
        if "case" in mt:
            raise _error(origin, f"{name('case')} is one of the paper's Table I sets of "
                         f"five pairs on 3 links; this body has {body.n_links}: give "
                         f"{name('stiffness')} (one value per pair) or {name('pairs')}")
        if mt.get("gastrocnemius", "two-sided") != "two-sided":
            raise _error(origin, f"{name('gastrocnemius')} is a pair of the paper's "
                         f"three-link body; this body has {body.n_links} links")
        pair_names = joint_pair_names(body.n_links)
        stiffness = lists["stiffness"]
        if not isinstance(stiffness, list) or len(stiffness) != len(pair_names):
            raise _error(origin, f"{name('stiffness')} must have one value per pair of this "
                         f"{body.n_links}-link body ({', '.join(pair_names)}), got "
                         f"{stiffness!r}")
        return muscles_for(
            body.n_links, stiffness, lists["viscosity"], viscosity_ratio=ratio,
            active_stiffness=lists["active_stiffness"],
            active_viscosity=lists["active_viscosity"],
            active_viscosity_ratio=mt.get("active_viscosity_ratio")), None
    case = mt.get("case")
    return paper_muscles(
        None if case is None else str(case), stiffness=lists["stiffness"],
        viscosity_ratio=ratio, viscosity=lists["viscosity"],
        gastrocnemius=mt.get("gastrocnemius", "two-sided"),
        active_stiffness=lists["active_stiffness"], active_viscosity=lists["active_viscosity"],
        active_viscosity_ratio=mt.get("active_viscosity_ratio"),
    ), (None if case is None else str(case))


def motor_noise_from_table(nt: dict, n_joints: int, origin: str = "",
                           names: Mapping[str, str] | None = None) -> MotorNoise | None:
    """The [motor_noise] table (None when there is none): standard deviation per joint
    [N·m], ankle first, at most one per joint; cutoff [Hz]; sample rate [Hz]; seed."""
    if not nt:
        return None
    where = _name(names, "motor_noise.standard_deviation")
    sigma = nt["standard_deviation"]
    if isinstance(sigma, str | list | tuple):
        sigma = tuple(number_list(sigma, f"{where} [N·m]"))
        if len(sigma) > n_joints:
            raise _error(origin, f"{where} [N·m] takes at most {n_joints} values (one per "
                         f"joint), got {len(sigma)}")
    return MotorNoise(sigma, nt.get("cutoff"), nt.get("sample_rate", 100.0), nt.get("seed", 0))
