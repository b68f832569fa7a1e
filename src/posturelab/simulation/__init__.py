"""Simulation of the nonlinear chain: one set-up, two engines, one result.

:func:`simulate` is the entry point (:mod:`.engines`). :mod:`.setup` validates a
run and works out what both engines share; the reference engine
(:mod:`.reference`, the numpy model integrated by scipy) and the compiled engine
(:mod:`.compiled`, C, built when posturelab is installed) integrate it with the events of
:mod:`posturelab.model.events` and return a :class:`~.results.SimulationResult`,
whose derived series come from :mod:`.derived`.
"""

from ..model.muscles import joint_crossing_matrix, moments_to_link_torques
from ..model.options import (
    FOOT_FROM_LITERATURE,
    FOOT_LENGTH_FRACTION_OF_HEIGHT,
    HEEL_FRACTION_OF_FOOT,
    BaseOfSupport,
    FallCriteria,
    KneeMode,
    KneeModel,
    base_of_support_for_height,
)
from .engines import ENGINES, simulate
from .results import DerivedSeries, SimulationResult
from .setup import RunSetup, initial_state_for, prepare_run
