"""Module paths from before the subpackage layout, kept working.

posturelab's modules moved into subpackages (``posturelab.body`` is now
``posturelab.model.body``, ``posturelab.fast`` is ``posturelab.simulation.compiled``,
…). :data:`MOVED_MODULES` maps each former path to its new one; a finder on
``sys.meta_path`` answers an import of a former path with the very module object
of the new path (no second copy is loaded), and submodules of a moved package
follow it (``posturelab.fast._encode``). The layout itself is in ``docs/develop.md``.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys

#: Former module path -> current module path.
MOVED_MODULES: dict[str, str] = {
    "posturelab.anthropometry": "posturelab.model.anthropometry",
    "posturelab.body": "posturelab.model.body",
    "posturelab.com": "posturelab.model.kinematics",
    "posturelab.dynamics": "posturelab.model.dynamics",
    "posturelab.muscles": "posturelab.model.muscles",
    "posturelab.platform": "posturelab.model.platform",
    "posturelab.batch_linear": "posturelab.linear.batch",
    "posturelab.results": "posturelab.simulation.results",
    "posturelab.simulate": "posturelab.simulation",
    "posturelab.fast": "posturelab.simulation.compiled",
    "posturelab.identify": "posturelab.studies.identification",
    "posturelab.recovery": "posturelab.studies.recovery",
    "posturelab.sweep": "posturelab.studies.sweep",
    "posturelab.compare": "posturelab.paper.compare",
    "posturelab.report": "posturelab.paper.report",
    "posturelab.plots": "posturelab.viz.plots",
    "posturelab.animation": "posturelab.viz.animation",
}


def current_name(name: str) -> str | None:
    """The current path of a former module path (or of a submodule of one); None if not moved."""
    if name in MOVED_MODULES:
        return MOVED_MODULES[name]
    head, _, tail = name.rpartition(".")
    while head:
        if head in MOVED_MODULES:
            return f"{MOVED_MODULES[head]}.{name[len(head) + 1:]}"
        head, _, _ = head.rpartition(".")
    del tail
    return None


class _MovedModuleFinder:
    """Imports a former path as the module at its current path (a meta path finder and its
    loader; not derived from importlib.abc, whose import loads importlib.resources and
    slows every start-up)."""

    def find_spec(self, fullname, path=None, target=None):  # noqa: D401 - importlib protocol
        if current_name(fullname) is None:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def create_module(self, spec):
        return importlib.import_module(current_name(spec.name))

    def exec_module(self, module) -> None:
        """Nothing to run: the module is the one already imported at its current path."""


def install() -> None:
    """Put the finder first on ``sys.meta_path`` (once), so that a submodule of a moved
    package (``posturelab.fast._encode``) is not found a second time through the new
    package's ``__path__``."""
    if not any(isinstance(f, _MovedModuleFinder) for f in sys.meta_path):
        sys.meta_path.insert(0, _MovedModuleFinder())  # before the path finder
