"""Submodules of a posturelab package reachable as attributes (``pl.model.tilt``) without an
import statement, loaded on first access, as they were when every package imported its
modules eagerly. No imports from posturelab here."""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable, Iterable
from types import ModuleType


def submodule_getattr(package: str, path: Iterable[str],
                      fallback: Callable[[str], object] | None = None
                      ) -> Callable[[str], object]:
    """A module-level ``__getattr__`` for ``package`` (its ``__name__``, its ``__path__``):
    an attribute that names a submodule imports it; anything else goes to ``fallback`` or
    raises AttributeError."""
    path = list(path)

    def __getattr__(name: str) -> object:
        if not name.startswith("__") and any(m.name == name
                                              for m in pkgutil.iter_modules(path)):
            module: ModuleType = importlib.import_module(f"{package}.{name}")
            return module
        if fallback is not None:
            return fallback(name)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__
