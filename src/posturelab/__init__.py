"""posturelab: human standing balance on a moving platform.

Sagittal N-link chains on a translating platform, stabilised by
agonist–antagonist muscle pairs acting as stiffness and viscosity. Starts
from the ankle-strategy paper (three-link biped, Tables I–II, Figs. 3–10)
and goes beyond it. Conventions: :mod:`posturelab.conventions`.

The names of :data:`PUBLIC_NAMES` are the public API. They, the subpackages and their modules
(``pl.simulate``, ``pl.simulation.compiled``, ``pl.recovery``, ``pl.plots``, …) load
on first attribute access, so that ``import posturelab`` (and so ``posturelab --help``)
stays light: it loads nothing but the error classes, and neither numba, nor scipy,
nor matplotlib, nor the compiled engine.
Former module paths (``posturelab.fast``, ``posturelab.body``, …) still import;
see :mod:`posturelab._compat`.
"""

from __future__ import annotations

import importlib
import sys
import types

from . import _compat
from .errors import ParameterError, PostureLabError, UnknownNameError

__version__ = "0.1.0"

_compat.install()

#: The public API, loaded on first access: module -> the names it gives.
PUBLIC_NAMES: dict[str, tuple[str, ...]] = {
    "posturelab.linear.analysis": ("LinearAnalysis", "analyse", "analyse_both_sides",
                                   "disturbance_sensitivity", "finite_difference_state_matrix",
                                   "state_matrix"),
    "posturelab.linear.delay": ("DelayMargin", "delay_margin", "rightmost_roots"),
    "posturelab.linear.lqr": ("multijoint_controller",),
    "posturelab.linear.verdict": ("UprightVerdict", "upright_verdict"),
    "posturelab.model.anthropometry": ("body_from_anthropometry", "lump"),
    "posturelab.model.body": ("BODY_PRESETS", "Body", "Segment", "get_body", "paper_body"),
    "posturelab.model.dynamics": ("angular_acceleration", "gravity_vector", "kinetic_energy",
                                  "mass_matrix", "platform_vector", "potential_energy",
                                  "state_derivative", "velocity_step_response",
                                  "velocity_terms"),
    "posturelab.model.kinematics": ("centre_of_gravity", "centre_of_gravity_velocity",
                                    "physiological_state"),
    "posturelab.model.joint_feedback": ("JointFeedback",),
    "posturelab.model.muscles": ("STIFFNESS_CASES", "MusclePair", "MuscleSet",
                                 "get_stiffness_case", "joint_torques", "pair_torques",
                                 "paper_muscles"),
    "posturelab.model.platform": ("CombinedDisturbance", "HalfSinePulse", "MeasuredProfile",
                                  "NoDisturbance", "RampAndHold", "SumOfSines", "VelocityStep",
                                  "read_profile_csv"),
    "posturelab.scenarios": ("Scenario", "builtin_scenario", "builtin_scenario_names",
                             "load_scenario"),
    "posturelab.simulation": ("FOOT_FROM_LITERATURE", "BaseOfSupport", "FallCriteria",
                              "KneeModel", "base_of_support_for_height", "simulate"),
    "posturelab.simulation.options": ("RunOptions",),
    "posturelab.simulation.results": ("DerivedSeries", "SimulationResult"),
}
_MODULE_OF_NAME = {name: module for module, names in PUBLIC_NAMES.items() for name in names}


class _Package(types.ModuleType):
    """posturelab itself: an import of the former module path ``posturelab.simulate`` does
    not rebind ``pl.simulate``, which stays the function."""

    def __setattr__(self, name: str, value) -> None:
        if name == "simulate" and isinstance(value, types.ModuleType):
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package

#: Submodules reachable as attributes, loaded on first access: name -> module path.
LAZY_SUBMODULES: dict[str, str] = {
    "cli": "posturelab.cli",
    "conventions": "posturelab.conventions",
    "errors": "posturelab.errors",
    "explore": "posturelab.explore",
    "frequency": "posturelab.frequency",
    "linear": "posturelab.linear",
    "parameters": "posturelab.parameters",
    "model": "posturelab.model",
    "paper": "posturelab.paper",
    "recordings": "posturelab.recordings",
    "scenarios": "posturelab.scenarios",
    "simulation": "posturelab.simulation",
    "studies": "posturelab.studies",
    "viz": "posturelab.viz",
    **{old.removeprefix("posturelab."): new for old, new in _compat.MOVED_MODULES.items()
       if old != "posturelab.simulate"},
}


def __getattr__(name: str):
    """Load a public name or a submodule on first access (``pl.simulate``, ``pl.recovery``,
    ``pl.plots``, ``pl.fast``, …)."""
    if name in _MODULE_OF_NAME:
        value = getattr(importlib.import_module(_MODULE_OF_NAME[name]), name)
    elif name in LAZY_SUBMODULES:
        value = importlib.import_module(LAZY_SUBMODULES[name])
    else:
        raise AttributeError(f"module 'posturelab' has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_MODULE_OF_NAME) | set(LAZY_SUBMODULES))


__all__ = [
    "__version__",
    "body_from_anthropometry", "lump",
    "BODY_PRESETS", "Body", "Segment", "get_body", "paper_body",
    "angular_acceleration", "gravity_vector", "kinetic_energy", "mass_matrix",
    "platform_vector", "potential_energy", "state_derivative", "velocity_step_response",
    "velocity_terms",
    "ParameterError", "PostureLabError", "UnknownNameError",
    "LinearAnalysis", "analyse", "analyse_both_sides", "disturbance_sensitivity",
    "finite_difference_state_matrix", "state_matrix",
    "DelayMargin", "delay_margin", "rightmost_roots", "UprightVerdict", "upright_verdict",
    "STIFFNESS_CASES", "MusclePair", "MuscleSet", "get_stiffness_case", "joint_torques",
    "pair_torques", "paper_muscles",
    "centre_of_gravity", "centre_of_gravity_velocity", "physiological_state",
    "CombinedDisturbance", "HalfSinePulse", "MeasuredProfile", "NoDisturbance", "RampAndHold",
    "SumOfSines", "VelocityStep", "read_profile_csv",
    "SimulationResult", "DerivedSeries", "Scenario", "builtin_scenario",
    "builtin_scenario_names", "load_scenario",
    "FOOT_FROM_LITERATURE", "BaseOfSupport", "FallCriteria", "KneeModel",
    "base_of_support_for_height", "simulate", "RunOptions",
    "multijoint_controller", "JointFeedback",
]
