"""posturelab: human standing balance on a moving platform.

Sagittal N-link chains on a translating platform, stabilised by
agonist–antagonist muscle pairs acting as stiffness and viscosity. Starts
from the ankle-strategy paper (three-link biped, Tables I–II, Figs. 3–10)
and goes beyond it. Conventions: :mod:`posturelab.conventions`.
"""

from __future__ import annotations

__version__ = "0.1.0"

from .anthropometry import body_from_anthropometry, lump
from .body import BODY_PRESETS, Body, Segment, get_body, paper_body
from .com import centre_of_gravity, centre_of_gravity_velocity, physiological_state
from .dynamics import (
    angular_acceleration,
    gravity_vector,
    kinetic_energy,
    mass_matrix,
    platform_vector,
    potential_energy,
    state_derivative,
    velocity_step_response,
    velocity_terms,
)
from .errors import ParameterError, PostureLabError, UnknownNameError
from .linear import (
    LinearAnalysis,
    analyse,
    analyse_both_sides,
    disturbance_sensitivity,
    finite_difference_state_matrix,
    state_matrix,
)
from .muscles import (
    STIFFNESS_CASES,
    MusclePair,
    MuscleSet,
    get_stiffness_case,
    joint_torques,
    pair_torques,
    paper_muscles,
)
from .platform import (
    CombinedDisturbance,
    HalfSinePulse,
    MeasuredProfile,
    NoDisturbance,
    RampAndHold,
    SumOfSines,
    VelocityStep,
    read_profile_csv,
)
from .results import DerivedSeries, SimulationResult
from .scenarios import Scenario, builtin_scenario, builtin_scenario_names, load_scenario
from .simulate import (
    FOOT_FROM_LITERATURE,
    BaseOfSupport,
    FallCriteria,
    KneeModel,
    base_of_support_for_height,
    simulate,
)

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
    "STIFFNESS_CASES", "MusclePair", "MuscleSet", "get_stiffness_case", "joint_torques",
    "pair_torques", "paper_muscles",
    "centre_of_gravity", "centre_of_gravity_velocity", "physiological_state",
    "CombinedDisturbance", "HalfSinePulse", "MeasuredProfile", "NoDisturbance", "RampAndHold",
    "SumOfSines", "VelocityStep", "read_profile_csv",
    "SimulationResult", "DerivedSeries", "Scenario", "builtin_scenario",
    "builtin_scenario_names", "load_scenario",
    "FOOT_FROM_LITERATURE", "BaseOfSupport", "FallCriteria", "KneeModel",
    "base_of_support_for_height", "simulate",
]
