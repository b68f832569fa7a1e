"""Figures (:mod:`.plots`, functions that draw on a matplotlib Axes) and stick-figure
animation (:mod:`.animation`). Importing either loads matplotlib."""

from .._lazy import submodule_getattr  # noqa: E402

__getattr__ = submodule_getattr(__name__, __path__)
