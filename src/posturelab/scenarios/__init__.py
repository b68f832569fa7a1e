"""Scenario files (TOML) and the paper's experiments as built-in scenarios.

A scenario names everything one simulation needs: body, muscle pairs (or a
Table I case), disturbance, duration, initial state, knee model, fall
criteria and solver settings. Unknown keys are rejected with the key named.

Schema (every table optional except where noted; units in brackets)::

    name = "paper-backward-case1"
    description = "..."
    source = "Figs. 3–7"
    duration = 5.0                       # [s] (required)

    [body]
    preset = "paper"                     # or: segments = [{name, mass, length,
                                         #                  com_distance, inertia}, ...]
    gravity = 9.81                       # [m/s²]

    [muscles]
    controller = "peterka-2002"          # a one-link controller preset (its gains, delay
                                         # and weight) instead of the gains below; or
    case = "1"                           # Table I; or stiffness = [one value per pair]
                                         # [N·m/rad] (the paper's five on 3 links, ankle on
                                         # 1, ankle and hip on 2, as --stiffness); or
                                         # pairs = [{name, lo, hi, stiffness, viscosity,
                                         #   one_sided}] (lo, hi: the links the pair spans,
                                         #   0 the foot: the ankle pair is lo = 0, hi = 1)
    viscosity_ratio = 0.25               # [s]
    gastrocnemius = "two-sided"          # or "one-sided" (θ2 ≥ 0), "pull-only"
    feedback_delay = 0.0                 # neural delay of the muscle feedback [s]
    active_stiffness = [5 values]        # active (neural, delayed) gains [N·m/rad]; with
    active_viscosity = [5 values]        #   pairs = [...], per pair instead [N·m·s/rad]
    active_viscosity_ratio = 0.3         # or the active viscosity as a ratio [s]
    proprioceptive_weight = 1.0          # W of the active error, in [0, 1] [-]

    [tilt]                               # support-surface tilt, positive toes-up
    type = "sine"                        # sine | raised-cosine | prts | profile
    # sine: amplitude [rad], frequency [Hz], phase [rad]
    # raised-cosine: amplitude [rad], duration [s], start [s]
    # prts: amplitude [rad] peak to peak; sequence = "posturelab-80" (default: posturelab's
    #       own 80-state, 20 s one), "comtest-80" or "peterka-2002-242"; or a register:
    #       registers, taps, seed (taps and seed one digit 0-2 per register: taps =
    #       [1, 1, 0, 0], seed = [1, 0, 0, 0]); state_duration [s]
    # profile: file = "tilt.csv" with columns time [s] and tilt [rad]
    axis_depth = 0.0                     # the tilt axis this far below the ankle [m]

    [motor_noise]                        # a seeded random torque on each joint's moment
    standard_deviation = [2.0]           # σ per joint, ankle first [N·m]
    cutoff = 1.0                         # first-order low-pass corner [Hz] (omit: white)
    sample_rate = 100.0                  # [Hz]
    seed = 0

    [disturbance]                        # or [[disturbance]] several, summed
    type = "velocity-step"               # velocity-step | half-sine | ramp-and-hold |
                                         # sum-of-sines | profile | none
    velocity = -1.0                      # velocity-step [m/s]; or direction =
                                         # "backward"/"forward" and speed [m/s]
    axis = "x"                           # x (horizontal) or y (vertical)
    # half-sine: peak_acceleration [m/s²], duration [s], start [s]
    # ramp-and-hold: displacement [m], duration [s], start [s]
    # sum-of-sines: amplitudes [m/s²], frequencies [Hz], phases [rad]
    # profile: file = "profile.csv" (relative to the scenario file)

    [initial]
    posture = [0.1, -0.1, 0.1]           # [rad]
    rates = [0.0, 0.0, 0.0]              # [rad/s], before any velocity step
    rates_from = "upright"               # where J⁻¹H is evaluated for a velocity step

    [knee]
    mode = "free"                        # free | locked | stop
    stop_angle = 0.0                     # [rad]

    [fall]
    max_link_angle = 1.0471975511965976  # [rad]
    base_of_support = "none"             # none | literature | {heel = -0.06, toe = 0.19} [m]
    centre_of_pressure = false           # also fall when the CoP leaves the foot (it tips)

    [limits]
    torque = [120.0, "inf", "inf"]       # largest net moment at ankle, knee, hip [N·m]

    [solver]
    rtol = 1e-8
    atol = 1e-10
    sample_rate = 1000.0                 # [Hz]
    method = "Radau"                     # default: the engine's own (DOP853 on the reference)
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._validation import finite_array, finite_float, reject_unknown_keys
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

if TYPE_CHECKING:  # (the simulation loads when a scenario is read or run: --help stays light)
    from ..simulation.results import SimulationResult

__all__ = [
    "Scenario",
    "load_scenario",
    "parse_scenario",
    "builtin_scenario",
    "builtin_scenario_names",
]


@dataclass(frozen=True)
class Scenario:
    """Everything one simulation needs.

    Attributes
    ----------
    name : str
    description : str
    source : str
        The paper figure or lab protocol it reproduces.
    body : Body
    muscles : MuscleSet
    disturbance : Disturbance
    duration : float
        [s]
    initial_state : numpy.ndarray or None
        ``[Θ, Θ̇]`` before any velocity step. [rad], [rad/s]
    rates_from : str
        "upright" or "posture" (see :func:`posturelab.simulate.initial_state_for`).
    knee : KneeModel
    fall : FallCriteria
    rtol, atol : float
        Integrator tolerances. [-], [rad, rad/s]
    sample_rate : float
        [Hz]
    method : str or None
        The integrator (``solver.method``); None (the default) for the engine's own:
        DOP853 on the reference engine, Radau or RK45 on the compiled one
        (:func:`posturelab.simulate`). The compiled engine has Radau, RK45 and RK23 only.
    case : str or None
        The Table I case, when the muscles come from one.
    torque_limits : tuple of float or None
        Largest net muscle moment per joint (ankle, knee, hip, …); inf for
        none. [N·m]
    feedback_delay : float
        Neural delay of the muscle feedback. [s]
    tilt : Tilt or None
        Support-surface tilt (:mod:`posturelab.model.tilt`).
    proprioceptive_weight : float
        W of the active part's error for pairs that span the foot. [-]
    tilt_axis_depth : float
        Distance of the tilt axis below the ankle. [m]
    motor_noise : MotorNoise or None
        A seeded random joint torque (:mod:`posturelab.model.noise`). [N·m]
    max_steps : int or None
        The step budget of a run (None: :func:`posturelab.simulation.setup.default_step_budget`).
        [-]
    time_limit : float or None
        The wall-clock budget of a run; None for none. [s]
    """

    name: str
    description: str
    source: str
    body: Body
    muscles: MuscleSet
    disturbance: Disturbance
    duration: float
    initial_state: np.ndarray | None
    rates_from: str
    knee: KneeModel
    fall: FallCriteria
    rtol: float = 1e-8
    atol: float = 1e-10
    sample_rate: float = 1000.0
    method: str | None = None
    case: str | None = None
    torque_limits: tuple[float, ...] | None = None
    feedback_delay: float = 0.0
    tilt: Tilt | None = None
    proprioceptive_weight: float = 1.0
    tilt_axis_depth: float = 0.0
    motor_noise: MotorNoise | None = None
    max_steps: int | None = None
    time_limit: float | None = None

    def run(self, *, engine: str = "compiled", **overrides: Any) -> SimulationResult:
        """Simulate this scenario; keyword ``overrides`` replace fields first.

        ``engine="compiled"`` (the default; ``"fast"`` is its former name) runs the C
        engine, ``engine="reference"`` the numpy model integrated by scipy; both at the
        scenario's tolerances and with its ``solver.method`` (the engine's own integrator
        when it names none; :func:`posturelab.simulate`).

        Raises
        ------
        ParameterError
            ``solver.method`` names an integrator the engine does not have (the compiled
            engine has Radau, RK45 and RK23).
        """
        from ..simulation.engines import engine_name, simulate

        name = engine_name(engine)
        sc = self.replace(**overrides) if overrides else self
        return simulate(
            sc.body, sc.muscles, sc.disturbance, sc.duration,
            initial_state=sc.initial_state, rates_from=sc.rates_from, knee=sc.knee,
            fall=sc.fall, torque_limits=sc.torque_limits,
            feedback_delay=sc.feedback_delay, rtol=sc.rtol, atol=sc.atol,
            sample_rate=sc.sample_rate, description=sc.description,
            method=sc.method_for(name), engine=name, tilt=sc.tilt,
            proprioceptive_weight=sc.proprioceptive_weight, tilt_axis_depth=sc.tilt_axis_depth,
            motor_noise=sc.motor_noise, max_steps=sc.max_steps, time_limit=sc.time_limit,
        )

    def method_for(self, engine: str) -> str | None:
        """The scenario's ``solver.method`` for ``engine`` (None: the engine's own).

        Raises
        ------
        ParameterError
            The compiled engine and a method it does not have (it has Radau, RK45, RK23).
        """
        from ..simulation.engines import engine_name

        if engine_name(engine) == "compiled" and self.method is not None:
            from ..simulation.compiled import METHODS

            if self.method not in METHODS:
                raise ParameterError(
                    f"scenario {self.name!r}: solver.method {self.method!r} runs on the "
                    f"reference engine only; the compiled engine integrates with "
                    f"{', '.join(METHODS)} (choose one of those, or run the reference engine: "
                    "engine='reference', --engine reference)")
        return self.method

    def replace(self, **changes: Any) -> Scenario:
        """A copy with some fields changed; unknown field names are rejected."""
        fields = set(self.__dataclass_fields__)
        reject_unknown_keys("Scenario.replace()", changes, fields)
        return replace(self, **changes)


TOP_KEYS = ("name", "description", "source", "duration", "body", "muscles", "disturbance",
            "initial", "knee", "fall", "limits", "solver", "tilt", "motor_noise")


def load_scenario(path: str | Path) -> Scenario:
    """Read a scenario TOML file.

    Raises
    ------
    ScenarioError
        Malformed TOML, an unknown key (named), or a bad value (field named).
    """
    from .._files import MAX_SCENARIO_BYTES, read_text

    path = Path(path)
    text = read_text(path, "scenario", max_bytes=MAX_SCENARIO_BYTES, error=ScenarioError)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"scenario {str(path)!r} is not valid TOML: {exc}") from None
    except RecursionError:
        raise ScenarioError(f"scenario {str(path)!r} is nested too deeply to be a "
                            "scenario") from None
    return parse_scenario(data, base_dir=path.parent, origin=str(path))


def parse_scenario(data: dict, base_dir: Path | None = None, origin: str = "scenario") -> Scenario:
    """Build a :class:`Scenario` from a parsed TOML mapping (see the module schema; the
    types of every key are checked first, by :func:`posturelab.scenarios.schema.check_types`)."""
    from .schema import check_types

    if not isinstance(data, dict):
        raise ScenarioError(f"{origin}: a scenario is a table, got {type(data).__name__}")
    check_types(data, origin)
    try:
        return _parse(data, base_dir or Path("."), origin)
    except ScenarioError:
        raise
    except PostureLabError as exc:
        raise ScenarioError(f"{origin}: {exc}") from None


def _table(data: dict, key: str, allowed: tuple[str, ...], origin: str) -> dict:
    value = data.get(key, {})
    if not isinstance(value, dict):
        raise ScenarioError(f"{origin}: [{key}] must be a table")
    _reject(value, allowed, f"[{key}]", origin)
    return value


def _reject(d: dict, allowed, where: str, origin: str) -> None:
    unknown = [k for k in d if k not in allowed]
    if unknown:
        raise ScenarioError(
            f"{origin}: unknown key {unknown[0]!r} in {where}; allowed: {', '.join(allowed)}"
        )


def _parse(data: dict, base_dir: Path, origin: str) -> Scenario:
    from ..simulation.setup import check_step_budget, check_time_limit

    _reject(data, TOP_KEYS, "the top level", origin)
    if "duration" not in data:
        raise ScenarioError(f"{origin}: missing required key 'duration' [s]")
    duration = finite_float("duration [s]", data["duration"])
    if duration <= 0:
        raise ScenarioError(f"{origin}: duration [s] must be > 0, got {duration:g}")

    body = _parse_body(_table(data, "body", ("preset", "segments", "gravity"), origin), origin)
    mt = _table(data, "muscles", ("case", "stiffness", "pairs", "viscosity_ratio",
                                  "gastrocnemius", "feedback_delay", "active_stiffness",
                                  "active_viscosity", "active_viscosity_ratio",
                                  "proprioceptive_weight", "controller"), origin)
    mt = dict(mt)
    preset = _controller(mt, body, origin)
    delay = finite_float("muscles.feedback_delay [s]", mt.pop(
        "feedback_delay", 0.0 if preset is None else preset.feedback_delay))
    weight = finite_float("muscles.proprioceptive_weight [-]", mt.pop(
        "proprioceptive_weight", 1.0 if preset is None else preset.proprioceptive_weight))
    for key, value in (("feedback_delay", delay), ("proprioceptive_weight", weight)):
        try:  # the parameter table's bounds
            check_value(key, value, f"muscles.{key}")
        except ParameterError as exc:
            raise ScenarioError(f"{origin}: {exc}") from None
    muscles, case = (_parse_muscles(mt, body, origin) if preset is None
                     else (preset.muscles(body), None))
    tilt_table = _table(data, "tilt", TILT_KEYS, origin)
    tilt = _parse_tilt(tilt_table, base_dir, origin)
    depth = finite_float("tilt.axis_depth [m]", tilt_table.get("axis_depth", 0.0))
    disturbance = _parse_disturbances(data.get("disturbance"), base_dir, origin)
    nt = _table(data, "motor_noise", ("standard_deviation", "cutoff", "sample_rate", "seed"),
                origin)
    noise = None
    if nt:
        if "standard_deviation" not in nt:
            raise ScenarioError(f"{origin}: [motor_noise] needs standard_deviation [N·m]")
        noise = MotorNoise(nt["standard_deviation"], nt.get("cutoff"),
                           nt.get("sample_rate", 100.0), nt.get("seed", 0))

    it = _table(data, "initial", ("posture", "rates", "rates_from"), origin)
    n = body.n_links
    initial = None
    if "posture" in it or "rates" in it:
        posture = finite_array("initial.posture [rad]", it.get("posture", [0.0] * n), (n,))
        rates = finite_array("initial.rates [rad/s]", it.get("rates", [0.0] * n), (n,))
        initial = np.concatenate([posture, rates])
    rates_from = it.get("rates_from", "upright")
    if rates_from not in ("upright", "posture"):
        raise ScenarioError(f"{origin}: initial.rates_from must be 'upright' or 'posture', "
                            f"got {rates_from!r}")

    kt = _table(data, "knee", ("mode", "stop_angle"), origin)
    knee = KneeModel(kt.get("mode", "free"), kt.get("stop_angle", 0.0))

    ft = _table(data, "fall", ("max_link_angle", "base_of_support", "centre_of_pressure"),
                origin)
    bos_spec = ft.get("base_of_support", "none")
    if bos_spec == "none":
        bos = None
    elif bos_spec == "literature":
        bos = FOOT_FROM_LITERATURE
    elif isinstance(bos_spec, dict):
        _reject(bos_spec, ("heel", "toe"), "fall.base_of_support", origin)
        if "heel" not in bos_spec or "toe" not in bos_spec:
            raise ScenarioError(f"{origin}: fall.base_of_support needs heel and toe [m]")
        bos = BaseOfSupport(bos_spec["heel"], bos_spec["toe"], source=origin)
    else:
        raise ScenarioError(f"{origin}: fall.base_of_support must be 'none', 'literature' or "
                            f"{{heel = …, toe = …}}, got {bos_spec!r}")
    fall = FallCriteria(ft.get("max_link_angle", math.pi / 3), bos,
                        bool(ft.get("centre_of_pressure", False)))
    lt = _table(data, "limits", ("torque",), origin)
    torque_limits = None
    if "torque" in lt:
        values = [math.inf if v in ("inf", "none") else v for v in lt["torque"]]
        torque_limits = tuple(finite_or_inf("limits.torque [N·m]", v) for v in values)
        if len(torque_limits) != body.n_links:
            raise ScenarioError(f"{origin}: limits.torque needs {body.n_links} values "
                                f"(one per joint), got {len(torque_limits)}")

    st = _table(data, "solver", ("rtol", "atol", "sample_rate", "method", "max_steps",
                                 "time_limit"), origin)
    method = st.get("method")
    if method is not None and method not in ("DOP853", "RK45", "RK23", "Radau", "BDF", "LSODA"):
        raise ScenarioError(f"{origin}: solver.method must be one of DOP853, RK45, RK23, Radau, "
                            f"BDF, LSODA; got {method!r}")
    return Scenario(
        name=str(data.get("name", Path(origin).stem)),
        description=str(data.get("description", "")),
        source=str(data.get("source", "")),
        body=body, muscles=muscles, disturbance=disturbance, duration=duration,
        initial_state=initial, rates_from=rates_from, knee=knee, fall=fall,
        rtol=finite_float("solver.rtol", st.get("rtol", 1e-8)),
        atol=finite_float("solver.atol", st.get("atol", 1e-10)),
        sample_rate=finite_float("solver.sample_rate [Hz]", st.get("sample_rate", 1000.0)),
        method=method, case=case, torque_limits=torque_limits, feedback_delay=delay,
        tilt=tilt, proprioceptive_weight=weight, tilt_axis_depth=depth, motor_noise=noise,
        max_steps=_budget(origin, st.get("max_steps"),
                          lambda v: check_step_budget(v, duration)),
        time_limit=_budget(origin, st.get("time_limit"), check_time_limit),
    )


def _budget(origin: str, value, check):
    """A scenario's step budget or time limit checked as a run checks it (``check``), the
    message prefixed with the table; None when none is given."""
    if value is None:
        return None
    try:
        return check(value)
    except ParameterError as exc:
        raise ScenarioError(f"{origin}: solver.{exc}") from None


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


def builtin_scenario_names() -> list[str]:
    """Names of the scenarios shipped with posturelab."""
    from importlib import resources

    root = resources.files(__package__) / "builtin"
    return sorted(p.name[:-5] for p in root.iterdir() if p.name.endswith(".toml"))


def builtin_scenario(name: str) -> Scenario:
    """A shipped scenario by name; an unknown name lists the known ones."""
    from importlib import resources

    from ..errors import UnknownNameError

    names = builtin_scenario_names()
    if name not in names:
        raise UnknownNameError(f"unknown built-in scenario {name!r}; known: {', '.join(names)}")
    res = resources.files(__package__) / "builtin" / f"{name}.toml"
    with resources.as_file(res) as path:
        return load_scenario(path)

from .._lazy import submodule_getattr  # noqa: E402

__getattr__ = submodule_getattr(__name__, __path__)
