"""Simulation of the nonlinear chain: one set-up, two engines, one result.

:func:`simulate` is the entry point (:mod:`.engines`). :mod:`.setup` validates a
run and works out what both engines share; the reference engine
(:mod:`.reference`, the numpy model integrated by scipy) and the compiled engine
(:mod:`.compiled`, C, built when posturelab is installed) integrate it with the events of
:mod:`posturelab.model.events` and return a :class:`~.results.SimulationResult`,
whose derived series come from :mod:`.derived`.
"""

import importlib

from .._lazy import submodule_getattr

#: The names this package gives, loaded on first access (so that importing one of its
#: modules, e.g. for a constant a --help needs, does not load the engines): module -> names.
NAMES: dict[str, tuple[str, ...]] = {
    "posturelab.model.muscles": ("joint_crossing_matrix", "moments_to_link_torques"),
    "posturelab.model.options": ("FOOT_FROM_LITERATURE", "FOOT_LENGTH_FRACTION_OF_HEIGHT",
                                 "HEEL_FRACTION_OF_FOOT", "BaseOfSupport", "FallCriteria",
                                 "KneeMode", "KneeModel", "base_of_support_for_height"),
    "posturelab.simulation.engines": ("ENGINES", "simulate"),
    "posturelab.simulation.options": ("RunOptions",),
    "posturelab.simulation.results": ("DerivedSeries", "SimulationResult"),
    "posturelab.simulation.setup": ("RunSetup", "initial_state_for", "prepare_run"),
}
_MODULE_OF_NAME = {name: module for module, names in NAMES.items() for name in names}
__all__ = sorted(_MODULE_OF_NAME)


def _name(name: str):
    if name not in _MODULE_OF_NAME:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(_MODULE_OF_NAME[name]), name)
    globals()[name] = value
    return value


__getattr__ = submodule_getattr(__name__, __path__, _name)


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_MODULE_OF_NAME))
