"""The types of a scenario file, declared once (msgspec): what each key may hold.

:func:`check_types` converts a parsed TOML mapping to :class:`ScenarioFile` in msgspec's
strict mode before any value is used, so that a boolean is never a number
(``duration = true``), a string is never a boolean (``centre_of_pressure = "no"``), a
number is never a list (``stiffness = 5``) and an unknown key is named; the message gives
the key's path (``$.muscles.stiffness[0]``) and what was expected. Ranges, units and the
rules between keys are checked afterwards, by :mod:`posturelab.scenarios`.

:func:`json_schema` is the JSON Schema of the file (``docs/scenario.schema.json``, which a
test regenerates), for editors that check TOML against a schema (Taplo, Even Better TOML).
"""

from __future__ import annotations

from typing import Literal

import msgspec

from ..errors import ScenarioError
from ..simulation.options import REFERENCE_METHODS

__all__ = ["ScenarioFile", "check_types", "json_schema"]


class _Table(msgspec.Struct, forbid_unknown_fields=True, omit_defaults=True):
    pass


class SegmentTable(_Table):
    """One link: mass [kg], length [m], com_distance [m] from its lower joint, inertia
    [kg·m²] about its centre of mass."""

    mass: float
    length: float
    com_distance: float
    inertia: float
    name: str | None = None


class BodyTable(_Table):
    """``[body]``: a preset or the segments, lowest first; gravity [m/s²]."""

    preset: str | None = None
    segments: list[SegmentTable] | None = None
    gravity: float | None = None


class PairTable(_Table):
    """One muscle pair spanning links lo … hi: stiffness [N·m/rad], viscosity [N·m·s/rad],
    active (delayed) gains in the same units."""

    lo: int
    hi: int
    stiffness: float
    name: str | None = None
    viscosity: float | None = None
    one_sided: bool | None = None
    pull_only: bool | None = None
    active_stiffness: float | None = None
    active_viscosity: float | None = None


class MusclesTable(_Table):
    """``[muscles]``: a Table I case, five stiffnesses [N·m/rad], or the pairs."""

    case: str | None = None
    stiffness: list[float] | None = None
    viscosity: list[float] | None = None
    pairs: list[PairTable] | None = None
    viscosity_ratio: float | None = None
    gastrocnemius: Literal["two-sided", "one-sided", "pull-only"] | None = None
    feedback_delay: float | None = None
    active_stiffness: list[float] | None = None
    active_viscosity: list[float] | None = None
    active_viscosity_ratio: float | None = None
    proprioceptive_weight: float | None = None
    visual_weight: float | None = None
    torque_feedback_gain: float | None = None
    torque_feedback_time_constant: float | None = None
    controller: str | None = None
    joint_feedback_scale: float | None = None


class TiltTable(_Table):
    """``[tilt]``: sine, raised-cosine, prts or profile (keys per type in the module notes
    of posturelab.scenarios). Angles [rad], times [s], frequencies [Hz]."""

    type: Literal["sine", "raised-cosine", "prts", "profile"]
    amplitude: float | None = None
    frequency: float | None = None
    phase: float | None = None
    duration: float | None = None
    start: float | None = None
    state_duration: float | None = None
    registers: int | None = None
    taps: list[int] | None = None
    seed: list[int] | None = None
    sequence: str | None = None
    file: str | None = None
    axis_depth: float | None = None


class DisturbanceTable(_Table):
    """``[disturbance]``: one platform motion term (keys per type in posturelab.scenarios).
    Velocities [m/s], accelerations [m/s²], displacement [m], times [s]."""

    type: Literal["none", "velocity-step", "half-sine", "ramp-and-hold", "sum-of-sines",
                  "profile"]
    velocity: float | None = None
    direction: Literal["backward", "forward"] | None = None
    speed: float | None = None
    axis: Literal["x", "y"] | None = None
    peak_acceleration: float | None = None
    duration: float | None = None
    start: float | None = None
    displacement: float | None = None
    amplitudes: list[float] | None = None
    frequencies: list[float] | None = None
    phases: list[float] | None = None
    file: str | None = None


class InitialTable(_Table):
    """``[initial]``: posture [rad], rates [rad/s] before any velocity step."""

    posture: list[float] | None = None
    rates: list[float] | None = None
    rates_from: Literal["upright", "posture"] | None = None


class KneeTable(_Table):
    """``[knee]``: the knee model; stop_angle [rad]."""

    mode: Literal["free", "locked", "stop"] | None = None
    stop_angle: float | None = None


class FootTable(_Table):
    """A base of support: heel and toe [m] relative to the ankle."""

    heel: float
    toe: float


class FallTable(_Table):
    """``[fall]``: max_link_angle [rad]; the foot; centre-of-pressure falls."""

    max_link_angle: float | None = None
    base_of_support: Literal["none", "literature"] | FootTable | None = None
    centre_of_pressure: bool | None = None


class LimitsTable(_Table):
    """``[limits]``: the largest net moment per joint [N·m], ``"inf"`` or ``"none"`` for
    no limit."""

    torque: list[float | Literal["inf", "none"]] | None = None


class SolverTable(_Table):
    """``[solver]``: tolerances [-], [rad, rad/s], output rate [Hz], scipy method, step
    budget [-], wall-clock time limit [s], most switches before a run fails [-]."""

    rtol: float | None = None
    atol: float | None = None
    sample_rate: float | None = None
    method: Literal[REFERENCE_METHODS] | None = None  # type: ignore[valid-type]
    max_steps: int | None = None
    time_limit: float | None = None
    max_switches: int | None = None


class MotorNoiseTable(_Table):
    """``[motor_noise]``: σ per joint [N·m], cutoff [Hz], sample_rate [Hz], seed."""

    standard_deviation: list[float] | float
    cutoff: float | None = None
    sample_rate: float | None = None
    seed: int | None = None


class ScenarioFile(_Table):
    """A scenario file (posturelab.scenarios): duration [s] is required."""

    duration: float
    name: str | None = None
    description: str | None = None
    source: str | None = None
    body: BodyTable | None = None
    muscles: MusclesTable | None = None
    disturbance: DisturbanceTable | list[DisturbanceTable] | None = None
    initial: InitialTable | None = None
    knee: KneeTable | None = None
    fall: FallTable | None = None
    limits: LimitsTable | None = None
    solver: SolverTable | None = None
    tilt: TiltTable | None = None
    visual_tilt: TiltTable | None = None  # the visual scene's (the [tilt] types, no axis_depth)
    motor_noise: MotorNoiseTable | None = None


def check_types(data: dict, origin: str) -> None:
    """Raise ScenarioError, in one line naming the key, unless every key of ``data`` has a
    type :class:`ScenarioFile` allows (msgspec, strict: no bool as a number, no string as
    a bool, no coercion)."""
    try:
        msgspec.convert(data, ScenarioFile, strict=True)
    except msgspec.ValidationError as exc:
        raise ScenarioError(f"{origin}: {_words(str(exc))}") from None


_TYPE_WORDS = {"float": "a number", "int": "an integer", "bool": "true or false",
               "str": "a string", "array": "an array", "object": "a table"}


def _words(text: str) -> str:
    """msgspec's message in a scenario's words: TOML key paths, TOML type names."""
    import re

    text = text.replace("`", "'").replace(" | null", "")
    m = re.fullmatch(r"(.*?)(?: - at '\$\.?(.*)')?", text)
    message, path = (m.group(1), m.group(2) or "") if m else (text, "")
    where = path if path else "the top level"
    table = f"[{path}]" if path else "the top level"
    if (u := re.fullmatch(r"Object contains unknown field '(.*)'", message)):
        return f"unknown key {u.group(1)!r} in {table}"
    if (u := re.fullmatch(r"Object missing required field '(.*)'", message)):
        return f"{table} lacks the required key {u.group(1)!r}"
    if (u := re.fullmatch(r"Expected '(.*)', got '(.*)'", message)):
        want = " or ".join(_TYPE_WORDS.get(w.strip(), w.strip()) for w in u.group(1).split("|"))
        got = {"bool": "a boolean"}.get(u.group(2), _TYPE_WORDS.get(u.group(2), u.group(2)))
        return f"{where} must be {want}, got {got}"
    if (u := re.fullmatch(r"Invalid enum value '(.*)'", message)):
        allowed = _allowed(path)
        return (f"{where} must be one of {', '.join(allowed)}; got {u.group(1)!r}" if allowed
                else f"{where} cannot be {u.group(1)!r}")
    return f"{message} (at {where})" if path else message


def json_schema() -> dict:
    """The JSON Schema of a scenario file (draft 2020-12)."""
    schema = msgspec.json.schema(ScenarioFile)
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "posturelab scenario"
    return schema


def _allowed(path: str) -> list[str]:
    """The literal values the key at ``path`` (``knee.mode``) may take, [] if unknown."""
    import re
    import typing

    kind: object = ScenarioFile
    for part in re.sub(r"\[\d+\]", "", path).split("."):
        struct = _struct_in(kind)
        if struct is None:
            return []
        kind = typing.get_type_hints(struct).get(part)
    values = [v for arg in _args(kind) if typing.get_origin(arg) is Literal
              for v in typing.get_args(arg)]
    return [str(v) for v in values]


def _args(kind) -> list:
    import typing

    if typing.get_origin(kind) is Literal:
        return [kind]
    out = []
    for arg in typing.get_args(kind) or ():
        out += _args(arg) if typing.get_origin(arg) is not Literal else [arg]
    return out


def _struct_in(kind):
    """The Struct class a (possibly optional or listed) annotation holds."""
    import typing

    if isinstance(kind, type) and issubclass(kind, msgspec.Struct):
        return kind
    for arg in typing.get_args(kind) or ():
        found = _struct_in(arg)
        if found is not None:
            return found
    return None
