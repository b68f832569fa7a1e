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
    viscosity_ratio = 0.25               # [s]; or viscosity = [one value per pair]
    gastrocnemius = "two-sided"          # or "one-sided" (θ2 ≥ 0), "pull-only"
    feedback_delay = 0.0                 # neural delay of the muscle feedback [s]
    active_stiffness = [5 values]        # active (neural, delayed) gains [N·m/rad]; with
    active_viscosity = [5 values]        #   pairs = [...], per pair instead [N·m·s/rad]
    active_viscosity_ratio = 0.3         # or the active viscosity as a ratio [s]
    proprioceptive_weight = 1.0          # W of the active error, in [0, 1] [-]
    visual_weight = 0.0                  # W_v of the visual scene's tilt [-]; W + W_v <= 1
                                         #   (the rest graviceptive; Peterka 2002)
    torque_feedback_gain = 0.0           # K_t: the active torque fed back positively
                                         #   through K_t/(τ_t s + 1) (Peterka 2002; needs
                                         #   feedback_delay > 0 and --engine reference) [-]
    torque_feedback_time_constant = 17.4 # τ_t [s] (PMC5664365 Table 1)

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

    [visual_tilt]                        # visual-scene tilt about the ankle axis, positive
    type = "prts"                        #   toes-up like the surface; the [tilt] types
    sequence = "comtest-80"              #   (no axis_depth): acts only through the
    amplitude = 0.035                    #   active feedback, weighted by visual_weight

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
    max_steps = 1000000                  # step budget [-] (default 1e6 + 1e4 per second)
    time_limit = 60.0                    # wall-clock budget [s] (default none)
    max_switches = 10000                 # more switches fail the run (chattering) [-]

Each run option's key is :data:`posturelab.scenarios._parse.OPTION_KEYS`; the options are
:class:`~posturelab.simulation.options.RunOptions`.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

from ..errors import PostureLabError, ScenarioError
from ._scenario import SCENARIO_DEFAULTS, Scenario

__all__ = [
    "Scenario",
    "SCENARIO_DEFAULTS",
    "load_scenario",
    "parse_scenario",
    "builtin_scenario",
    "builtin_scenario_names",
]


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
    types of every key are checked first, by :func:`posturelab.scenarios.schema.check_types`,
    then the values, by :func:`posturelab.scenarios._parse.parse_tables`)."""
    from ._parse import parse_tables
    from .schema import check_types

    if not isinstance(data, dict):
        raise ScenarioError(f"{origin}: a scenario is a table, got {type(data).__name__}")
    check_types(data, origin)
    try:
        return parse_tables(data, base_dir or Path("."), origin)
    except ScenarioError:
        raise
    except PostureLabError as exc:
        raise ScenarioError(f"{origin}: {exc}") from None


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
