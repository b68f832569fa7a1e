"""The ``[disturbance]`` table(s) of a scenario → a :class:`~posturelab.model.platform.Disturbance`
(the platform's motion; several tables sum)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from ..errors import ParameterError, ScenarioError
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

__all__ = ["DISTURBANCE_KEYS", "disturbance_from_tables"]

#: The keys each disturbance type takes.
DISTURBANCE_KEYS = {
    "none": (),
    "velocity-step": ("velocity", "direction", "speed", "axis"),
    "half-sine": ("peak_acceleration", "duration", "start", "axis"),
    "ramp-and-hold": ("displacement", "duration", "start", "axis"),
    "sum-of-sines": ("amplitudes", "frequencies", "phases", "axis"),
    "profile": ("file",),
}


def _reject(d: dict, allowed, where: str, origin: str) -> None:
    unknown = [k for k in d if k not in allowed]
    if unknown:
        raise ScenarioError(
            f"{origin}: unknown key {unknown[0]!r} in {where}; allowed: {', '.join(allowed)}"
        )


def disturbance_from_tables(spec, base_dir: Path, origin: str = "",
                            names: Mapping[str, str] | None = None) -> Disturbance:
    """The [disturbance] table, or an array of them (their sum); none when absent."""
    if spec is None:
        return NoDisturbance()
    specs = spec if isinstance(spec, list) else [spec]
    return combine(*[_disturbance(s, base_dir, origin, i) for i, s in enumerate(specs)])


def _disturbance(d, base_dir: Path, origin: str, i: int) -> Disturbance:
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
        if not origin:
            raise
        raise ScenarioError(f"{origin}: disturbance: {exc}") from None


def _need(d: dict, key: str, origin: str):
    if key not in d:
        raise ScenarioError(f"{origin}: disturbance of type {d.get('type')!r} lacks {key!r}")
    return d[key]
