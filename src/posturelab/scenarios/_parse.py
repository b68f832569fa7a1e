"""Reading a scenario file's tables into a :class:`~posturelab.scenarios.Scenario`: the
body, the muscles, the platform motion and the run's
:class:`~posturelab.simulation.options.RunOptions` (each option's key in the file:
:data:`OPTION_KEYS`). The types of every key are checked before, by
:mod:`posturelab.scenarios.schema`; the ranges and the rules between keys here and by the
objects built.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .._validation import finite_array, finite_float
from ..errors import ParameterError, PostureLabError, ScenarioError, UnknownNameError
from ..model.body import Body, Segment, get_body
from ..model.muscles import MusclePair, MuscleSet, paper_muscles
from ..model.noise import MotorNoise
from ..model.options import FOOT_FROM_LITERATURE, BaseOfSupport, FallCriteria, KneeModel
from ..model.platform import (
    Disturbance,
    HalfSinePulse,
    NoDisturbance,
    RampAndHold,
    SumOfSines,
    VelocityStep,
    combine,
    read_profile_csv,
)
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
from ..parameters import check_value
from ..simulation.options import RunOptions
from ._scenario import SCENARIO_DEFAULTS as DEFAULTS
from ._scenario import Scenario

__all__ = ["OPTION_KEYS", "parse_tables", "run_options"]


def _reject(d: dict, allowed, where: str, origin: str) -> None:
    unknown = [k for k in d if k not in allowed]
    if unknown:
        raise ScenarioError(
            f"{origin}: unknown key {unknown[0]!r} in {where}; allowed: {', '.join(allowed)}"
        )


#: Where each run option is written in a scenario file (its TOML key); a message about an
#: option names the key.
OPTION_KEYS: dict[str, str] = {
    "duration": "duration", "initial_state": "initial", "rates_from": "initial.rates_from",
    "knee": "knee", "fall": "fall", "torque_limits": "limits.torque",
    "feedback_delay": "muscles.feedback_delay",
    "proprioceptive_weight": "muscles.proprioceptive_weight",
    "torque_feedback_gain": "muscles.torque_feedback_gain",
    "torque_feedback_time_constant": "muscles.torque_feedback_time_constant", "tilt": "tilt",
    "tilt_axis_depth": "tilt.axis_depth", "motor_noise": "motor_noise",
    "method": "solver.method", "rtol": "solver.rtol", "atol": "solver.atol",
    "sample_rate": "solver.sample_rate", "max_steps": "solver.max_steps",
    "time_limit": "solver.time_limit", "max_switches": "solver.max_switches",
    "description": "description",
}



def run_options(origin: str, **fields) -> RunOptions:
    """The scenario's :class:`RunOptions`; a bad value raises ScenarioError naming its key
    (``solver.max_steps must be an integer in [1, …], got 0``)."""
    try:
        return RunOptions(**fields)
    except ParameterError as exc:
        text = str(exc)
        name = next((k for k in OPTION_KEYS if text.startswith(k + " ")), None)
        if name is not None and OPTION_KEYS[name] != name:
            text = OPTION_KEYS[name] + text[len(name):]
        raise ScenarioError(f"{origin}: {text}") from None


def parse_tables(data: dict, base_dir: Path, origin: str) -> Scenario:
    """A scenario from its tables (types already checked by
    :func:`posturelab.scenarios.schema.check_types`)."""

    duration = finite_float("duration [s]", data["duration"])
    body = _parse_body(data.get("body", {}), origin)
    mt = dict(data.get("muscles", {}))
    preset = _controller(mt, body, origin)
    delay = mt.pop("feedback_delay", 0.0 if preset is None else preset.feedback_delay)
    weight = mt.pop("proprioceptive_weight",
                    1.0 if preset is None else preset.proprioceptive_weight)
    feedback_gain = mt.pop("torque_feedback_gain", DEFAULTS.torque_feedback_gain)
    feedback_lag = mt.pop("torque_feedback_time_constant",
                          DEFAULTS.torque_feedback_time_constant)
    for key, value in (("feedback_delay", delay), ("proprioceptive_weight", weight),
                       ("torque_feedback_gain", feedback_gain),
                       ("torque_feedback_time_constant", feedback_lag)):
        try:  # the parameter table's bounds, before the muscles are built
            check_value(key, value, f"muscles.{key}")
        except ParameterError as exc:
            raise ScenarioError(f"{origin}: {exc}") from None
    muscles, case = (_parse_muscles(mt, body, origin) if preset is None
                     else (preset.muscles(body), None))
    tilt_table = data.get("tilt", {})
    tilt = _parse_tilt(tilt_table, base_dir, origin)
    disturbance = _parse_disturbances(data.get("disturbance"), base_dir, origin)
    nt = data.get("motor_noise", {})
    noise = None if not nt else MotorNoise(nt["standard_deviation"], nt.get("cutoff"),
                                           nt.get("sample_rate", 100.0), nt.get("seed", 0))
    it = data.get("initial", {})
    n = body.n_links
    initial = None
    if "posture" in it or "rates" in it:
        posture = finite_array("initial.posture [rad]", it.get("posture", [0.0] * n), (n,))
        rates = finite_array("initial.rates [rad/s]", it.get("rates", [0.0] * n), (n,))
        initial = np.concatenate([posture, rates])
    kt = data.get("knee", {})
    knee = KneeModel(kt.get("mode", "free"), kt.get("stop_angle", 0.0))
    ft = data.get("fall", {})
    bos_spec = ft.get("base_of_support", "none")
    bos = (None if bos_spec == "none" else FOOT_FROM_LITERATURE if bos_spec == "literature"
           else BaseOfSupport(bos_spec["heel"], bos_spec["toe"], source=origin))
    fall = FallCriteria(ft.get("max_link_angle", math.pi / 3), bos,
                        bool(ft.get("centre_of_pressure", False)))
    torque_limits = None
    if "torque" in data.get("limits", {}):
        values = [math.inf if v in ("inf", "none") else v for v in data["limits"]["torque"]]
        torque_limits = tuple(finite_or_inf("limits.torque [N·m]", v) for v in values)
        if len(torque_limits) != body.n_links:
            raise ScenarioError(f"{origin}: limits.torque needs {body.n_links} values "
                                f"(one per joint), got {len(torque_limits)}")
    st = data.get("solver", {})
    options = run_options(
        origin, duration=duration, initial_state=initial,
        rates_from=it.get("rates_from", DEFAULTS.rates_from), knee=knee, fall=fall,
        torque_limits=torque_limits, feedback_delay=delay, proprioceptive_weight=weight,
        torque_feedback_gain=feedback_gain, torque_feedback_time_constant=feedback_lag,
        tilt=tilt, tilt_axis_depth=tilt_table.get("axis_depth", 0.0), motor_noise=noise,
        method=st.get("method"), rtol=st.get("rtol", DEFAULTS.rtol),
        atol=st.get("atol", DEFAULTS.atol),
        sample_rate=st.get("sample_rate", DEFAULTS.sample_rate),
        max_switches=st.get("max_switches", DEFAULTS.max_switches),
        max_steps=st.get("max_steps"), time_limit=st.get("time_limit"),
        description=str(data.get("description", "")))
    return Scenario(name=str(data.get("name", Path(origin).stem)),
                    source=str(data.get("source", "")), body=body, muscles=muscles,
                    disturbance=disturbance, options=options, case=case)


TILT_KEYS = ("type", "amplitude", "frequency", "phase", "duration", "start", "state_duration",
             "registers", "taps", "seed", "sequence", "file", "axis_depth")


def _parse_tilt(tt: dict, base_dir: Path, origin: str) -> Tilt | None:
    """The [tilt] table (module docstring), or None when there is none."""
    if not tt:
        return None
    kind = tt.get("type")
    allowed = {"sine": ("amplitude", "frequency", "phase"),
               "raised-cosine": ("amplitude", "duration", "start"),
               "prts": ("amplitude", "state_duration", "registers", "taps", "seed",
                        "sequence"),
               "profile": ("file",)}
    if kind not in allowed:
        raise ScenarioError(f"{origin}: tilt.type must be one of {', '.join(allowed)}; "
                            f"got {kind!r}")
    _reject(tt, ("type", "axis_depth", *allowed[kind]), f"tilt (type {kind})", origin)
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
        raise ScenarioError(f"{origin}: tilt: {exc}") from None


def finite_or_inf(name: str, value) -> float:
    """A number > 0, or +inf (no limit)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ScenarioError(f"{name} must be numbers or \"inf\", got {value!r}") from None
    if math.isnan(v) or v <= 0:
        raise ScenarioError(f"{name} must be > 0 (or \"inf\"), got {value!r}")
    return v


def _parse_body(bt: dict, origin: str) -> Body:
    if "preset" in bt and "segments" in bt:
        raise ScenarioError(f"{origin}: [body] takes preset or segments, not both")
    gravity = bt.get("gravity")
    if "segments" in bt:
        segs = bt["segments"]
        if not isinstance(segs, list) or not segs:
            raise ScenarioError(f"{origin}: body.segments must be a non-empty array of tables")
        out = []
        for i, s in enumerate(segs):
            if not isinstance(s, dict):
                raise ScenarioError(f"{origin}: body.segments[{i}] must be a table")
            keys = ("name", "mass", "length", "com_distance", "inertia")
            _reject(s, keys, f"body.segments[{i}]", origin)
            missing = [k for k in keys[1:] if k not in s]
            if missing:
                raise ScenarioError(f"{origin}: body.segments[{i}] lacks {missing[0]!r}")
            out.append(Segment(str(s.get("name", f"link{i + 1}")), s["mass"], s["length"],
                               s["com_distance"], s["inertia"]))
        body = Body(tuple(out), name="scenario")
    else:
        body = get_body(str(bt.get("preset", "paper")))
    if gravity is not None:
        body = body.with_gravity(gravity)
    return body


def _controller(mt: dict, body: Body, origin: str):
    """``[muscles] controller = NAME``: the preset (its gains on this one-link body, its delay
    and weight unless the table gives them), or None."""
    if "controller" not in mt:
        return None
    from ..model.controllers import get_controller

    name = str(mt.pop("controller"))
    try:
        preset = get_controller(name)
    except PostureLabError as exc:
        raise ScenarioError(f"{origin}: muscles.controller: {exc}") from None
    others = [k for k in ("case", "stiffness", "pairs", "viscosity_ratio", "gastrocnemius",
                          "active_stiffness", "active_viscosity", "active_viscosity_ratio")
              if k in mt]
    if others:
        raise ScenarioError(f"{origin}: muscles.{others[0]} cannot be given with "
                            f"muscles.controller {name!r}, which sets every gain")
    if body.n_links != 1:
        raise ScenarioError(f"{origin}: muscles.controller {name!r} is a one-link controller; "
                            f"this body has {body.n_links} links (preset = \"paper-1link\", or "
                            "one segment)")
    return preset


def _parse_muscles(mt: dict, body: Body, origin: str) -> tuple[MuscleSet, str | None]:
    given = [k for k in ("case", "stiffness", "pairs") if k in mt]
    if len(given) != 1:
        raise ScenarioError(f"{origin}: [muscles] needs exactly one of case, stiffness, pairs")
    if "pairs" in mt:
        stray = [k for k in ("active_stiffness", "active_viscosity", "active_viscosity_ratio")
                 if k in mt]
        if stray:
            raise ScenarioError(f"{origin}: muscles.{stray[0]} is for case / stiffness; with "
                                "pairs give active_stiffness and active_viscosity per pair")
        pairs = []
        for i, p in enumerate(mt["pairs"]):
            if not isinstance(p, dict):
                raise ScenarioError(f"{origin}: muscles.pairs[{i}] must be a table")
            keys = ("name", "lo", "hi", "stiffness", "viscosity", "one_sided",
                    "active_stiffness", "active_viscosity", "pull_only")
            _reject(p, keys, f"muscles.pairs[{i}]", origin)
            for k in ("lo", "hi", "stiffness"):
                if k not in p:
                    raise ScenarioError(f"{origin}: muscles.pairs[{i}] lacks {k!r}")
            ratio = finite_float("muscles.viscosity_ratio [s]", mt.get("viscosity_ratio", 0.25))
            visc = p.get("viscosity", ratio * finite_float("stiffness", p["stiffness"]))
            pairs.append(MusclePair(str(p.get("name", f"pair{i + 1}")), p["lo"], p["hi"],
                                    p["stiffness"], visc, bool(p.get("one_sided", False)),
                                    p.get("active_stiffness"), p.get("active_viscosity"),
                                    bool(p.get("pull_only", False))))
        return MuscleSet(tuple(pairs), body.n_links), None
    if body.n_links != 3:
        if "case" in mt:
            raise ScenarioError(f"{origin}: muscles.case is one of the paper's Table I sets of "
                                f"five pairs on 3 links; this body has {body.n_links}: give "
                                "muscles.stiffness (one value per pair, as on the command line) "
                                "or muscles.pairs")
        if mt.get("gastrocnemius", "two-sided") != "two-sided":
            raise ScenarioError(f"{origin}: muscles.gastrocnemius is a pair of the paper's "
                                f"three-link body; this body has {body.n_links} links")
        from ..model.muscles import joint_pair_names, muscles_for

        names = joint_pair_names(body.n_links)
        stiffness = mt["stiffness"]
        if not isinstance(stiffness, list) or len(stiffness) != len(names):
            raise ScenarioError(f"{origin}: muscles.stiffness must have one value per pair of "
                                f"this {body.n_links}-link body ({', '.join(names)}), got "
                                f"{stiffness!r}")
        return muscles_for(
            body.n_links, stiffness, viscosity_ratio=mt.get("viscosity_ratio", 0.25),
            active_stiffness=mt.get("active_stiffness"),
            active_viscosity=mt.get("active_viscosity"),
            active_viscosity_ratio=mt.get("active_viscosity_ratio")), None
    case = mt.get("case")
    return paper_muscles(
        None if case is None else str(case), stiffness=mt.get("stiffness"),
        viscosity_ratio=mt.get("viscosity_ratio", 0.25),
        gastrocnemius=mt.get("gastrocnemius", "two-sided"),
        active_stiffness=mt.get("active_stiffness"), active_viscosity=mt.get("active_viscosity"),
        active_viscosity_ratio=mt.get("active_viscosity_ratio"),
    ), (None if case is None else str(case))


DISTURBANCE_KEYS = {
    "none": (),
    "velocity-step": ("velocity", "direction", "speed", "axis"),
    "half-sine": ("peak_acceleration", "duration", "start", "axis"),
    "ramp-and-hold": ("displacement", "duration", "start", "axis"),
    "sum-of-sines": ("amplitudes", "frequencies", "phases", "axis"),
    "profile": ("file",),
}


def _parse_disturbances(spec, base_dir: Path, origin: str) -> Disturbance:
    if spec is None:
        return NoDisturbance()
    specs = spec if isinstance(spec, list) else [spec]
    return combine(*[_parse_disturbance(s, base_dir, origin, i) for i, s in enumerate(specs)])


def _parse_disturbance(d, base_dir: Path, origin: str, i: int) -> Disturbance:
    if not isinstance(d, dict):
        raise ScenarioError(f"{origin}: [disturbance] must be a table")
    kind = d.get("type")
    if kind not in DISTURBANCE_KEYS:
        raise ScenarioError(f"{origin}: disturbance.type must be one of "
                            f"{', '.join(DISTURBANCE_KEYS)}; got {kind!r}")
    _reject(d, ("type",) + DISTURBANCE_KEYS[kind], f"[disturbance] of type {kind!r}", origin)
    axis = d.get("axis", "x")
    try:
        if kind == "none":
            return NoDisturbance()
        if kind == "velocity-step":
            if "velocity" in d:
                if "direction" in d or "speed" in d:
                    raise ScenarioError(f"{origin}: give velocity, or direction and speed")
                return VelocityStep(d["velocity"], axis)
            direction = d.get("direction")
            speed = d.get("speed", 1.0)
            if direction == "backward":
                return VelocityStep.backward(speed)
            if direction == "forward":
                return VelocityStep.forward(speed)
            raise ScenarioError(f"{origin}: velocity-step needs velocity [m/s] or direction "
                                f"'backward'/'forward'; got direction {direction!r}")
        if kind == "half-sine":
            return HalfSinePulse(_need(d, "peak_acceleration", origin),
                                 _need(d, "duration", origin), d.get("start", 0.0), axis)
        if kind == "ramp-and-hold":
            return RampAndHold(_need(d, "displacement", origin), _need(d, "duration", origin),
                               d.get("start", 0.0), axis)
        if kind == "sum-of-sines":
            return SumOfSines(tuple(_need(d, "amplitudes", origin)),
                              tuple(_need(d, "frequencies", origin)),
                              None if "phases" not in d else tuple(d["phases"]), axis)
        file = Path(str(_need(d, "file", origin)))
        return read_profile_csv(file if file.is_absolute() else base_dir / file)
    except ParameterError as exc:
        raise ScenarioError(f"{origin}: disturbance: {exc}") from None


def _need(d: dict, key: str, origin: str):
    if key not in d:
        raise ScenarioError(f"{origin}: disturbance of type {d.get('type')!r} lacks {key!r}")
    return d[key]
