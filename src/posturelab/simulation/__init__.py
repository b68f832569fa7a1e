"""Simulation of the nonlinear chain: one set-up, two engines, one result.

:func:`simulate` is the entry point. The reference engine (:mod:`.reference`,
scipy's ``solve_ivp``) and the compiled engine (:mod:`.compiled`, numba,
imported on first use) integrate the same model with the same events and
return the same :class:`~.results.SimulationResult`.
"""

from .reference import (
    FOOT_FROM_LITERATURE,
    FOOT_LENGTH_FRACTION_OF_HEIGHT,
    HEEL_FRACTION_OF_FOOT,
    BaseOfSupport,
    FallCriteria,
    KneeMode,
    KneeModel,
    base_of_support_for_height,
    initial_state_for,
    joint_crossing_matrix,
    moments_to_link_torques,
    simulate,
)
from .results import DerivedSeries, SimulationResult
