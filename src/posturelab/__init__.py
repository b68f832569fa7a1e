"""posturelab: human standing balance on a moving platform.

Sagittal N-link chains on a translating platform, stabilised by
agonist–antagonist muscle pairs acting as stiffness and viscosity. Starts
from the ankle-strategy paper (three-link biped, Tables I–II, Figs. 3–10)
and goes beyond it. Conventions: :mod:`posturelab.conventions`.

The names below are the public API. Subpackages and their modules
(``pl.simulation.compiled``, ``pl.recovery``, ``pl.plots``, …) load on first
attribute access, so that ``import posturelab`` stays light: it loads neither
numba, nor scipy's integrators, optimisers or statistics, nor matplotlib.
Former module paths (``posturelab.fast``, ``posturelab.body``, …) still import;
see :mod:`posturelab._compat`.
"""

from __future__ import annotations

import importlib

from . import _compat

__version__ = "0.1.0"

_compat.install()
# The former module posturelab.simulate is loaded before the function of that name is
# bound here, so that a later ``import posturelab.simulate`` cannot rebind ``pl.simulate``.
importlib.import_module("posturelab.simulate")

from .errors import ParameterError, PostureLabError, UnknownNameError  # noqa: E402
from .linear.analysis import (  # noqa: E402
    LinearAnalysis,
    analyse,
    analyse_both_sides,
    disturbance_sensitivity,
    finite_difference_state_matrix,
    state_matrix,
)
from .linear.delay import DelayMargin, delay_margin, rightmost_roots  # noqa: E402
from .linear.verdict import UprightVerdict, upright_verdict  # noqa: E402
from .model.anthropometry import body_from_anthropometry, lump  # noqa: E402
from .model.body import BODY_PRESETS, Body, Segment, get_body, paper_body  # noqa: E402
from .model.dynamics import (  # noqa: E402
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
from .model.kinematics import (  # noqa: E402
    centre_of_gravity,
    centre_of_gravity_velocity,
    physiological_state,
)
from .model.muscles import (  # noqa: E402
    STIFFNESS_CASES,
    MusclePair,
    MuscleSet,
    get_stiffness_case,
    joint_torques,
    pair_torques,
    paper_muscles,
)
from .model.platform import (  # noqa: E402
    CombinedDisturbance,
    HalfSinePulse,
    MeasuredProfile,
    NoDisturbance,
    RampAndHold,
    SumOfSines,
    VelocityStep,
    read_profile_csv,
)
from .scenarios import (  # noqa: E402
    Scenario,
    builtin_scenario,
    builtin_scenario_names,
    load_scenario,
)
from .simulation import (  # noqa: E402
    FOOT_FROM_LITERATURE,
    BaseOfSupport,
    FallCriteria,
    KneeModel,
    base_of_support_for_height,
    simulate,
)
from .simulation.results import DerivedSeries, SimulationResult  # noqa: E402

#: Submodules reachable as attributes, loaded on first access: name -> module path.
LAZY_SUBMODULES: dict[str, str] = {
    "cli": "posturelab.cli",
    "conventions": "posturelab.conventions",
    "errors": "posturelab.errors",
    "linear": "posturelab.linear",
    "model": "posturelab.model",
    "paper": "posturelab.paper",
    "scenarios": "posturelab.scenarios",
    "simulation": "posturelab.simulation",
    "studies": "posturelab.studies",
    "viz": "posturelab.viz",
    **{old.removeprefix("posturelab."): new for old, new in _compat.MOVED_MODULES.items()
       if old != "posturelab.simulate"},
}


def __getattr__(name: str):
    """Load a submodule on first access (``pl.recovery``, ``pl.plots``, ``pl.fast``, …)."""
    path = LAZY_SUBMODULES.get(name)
    if path is None:
        raise AttributeError(f"module 'posturelab' has no attribute {name!r}")
    module = importlib.import_module(path)
    globals()[name] = module
    return module


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(LAZY_SUBMODULES))


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
    "base_of_support_for_height", "simulate",
]
