"""The layout of ``src/posturelab``: layers, import cycles, file lengths, a light ``--help``.

The import graph is read from the source (the AST), not from a running interpreter: every
``import`` and ``from ... import`` naming a posturelab module, at module level or inside a
function (the lazy imports that keep start-up light are imports all the same). An import
under ``if TYPE_CHECKING:`` never runs: it counts for the layers (a type from a higher layer
is still a dependency on it) but not for cycles. ``posturelab/__init__.py`` loads its public
names with ``importlib`` on first use; those are not imports in the source, and the façade
itself imports only the foundation, so it sits there.

The rules:

* **Layers.** :data:`LAYERS` states the order once, lowest first. A module may import its
  own layer and those below, never one above, at any level.
* **No cycles.** No two modules import each other, directly or through others, at module
  level or inside functions.
* **Length.** No hand-written Python file over :data:`MAX_LINES` lines; a generated file
  (it says ``GENERATED`` or "do not edit" in its first lines) is exempt.
* **Start-up.** ``posturelab --help`` imports at most :data:`MAX_HELP_MODULES` posturelab
  modules.
"""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

import pytest

SOURCE = Path(__file__).resolve().parents[1] / "src" / "posturelab"

#: The layers, lowest first: each top-level module or subpackage of posturelab (``__init__``
#: is the package's own file, the lazy façade). Within a layer imports go either way (no
#: cycles); between layers only downward.
LAYERS: tuple[tuple[str, ...], ...] = (
    ("errors", "conventions", "_lazy", "_jit", "_progress", "_compat"),  # no posturelab imports
    ("parameters", "_validation", "_files", "_parquet", "_bounds", "__init__"),  # foundation
    ("model",),          # validated parameters and the physics as functions over arrays
    ("linear",),         # the linearisation: poles, delays, batched maps
    ("simulation",),     # both engines, the run set-up, results
    ("scenarios",),      # experiments as data (TOML), run through simulation
    ("studies",),        # sweeps, recovery, identification, strategies
    ("recordings",),     # lab recordings: resampling, C3D, sway from markers and plates
    ("frequency",),      # FRF estimates, model FRFs, fits, PRTS populations (on studies' sweeps)
    ("viz",),            # figures of runs, maps and FRFs
    ("paper", "explore"),  # the reproduction report; the browser explorer
    ("cli", "__main__"),   # the command line: calls the public API
)
#: Longest hand-written Python file. [lines]
MAX_LINES = 600
#: Most posturelab modules ``posturelab --help`` may import. [-]
MAX_HELP_MODULES = 12


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(SOURCE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


MODULES: dict[str, Path] = {_module_name(p): p for p in sorted(SOURCE.rglob("*.py"))}


def _unit(module: str) -> str:
    """The top-level module or subpackage ``module`` belongs to (``__init__`` for the
    package's own file)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def _targets(module: str, is_package: bool, node: ast.ImportFrom) -> list[str]:
    """The posturelab modules an ``from ... import`` names (a submodule when the imported
    name is one, else the module imported from)."""
    if node.level:
        base = module.split(".") if is_package else module.split(".")[:-1]
        base = base[:len(base) - (node.level - 1)]
        source = ".".join(base) + (f".{node.module}" if node.module else "")
    else:
        source = node.module or ""
    if source.split(".")[0] != "posturelab":
        return []
    return [f"{source}.{a.name}" if f"{source}.{a.name}" in MODULES else source
            for a in node.names]


class Import:
    """One import in the source: who, of what, where, and whether at module level and only
    for type checking."""

    def __init__(self, importer: str, imported: str, line: int, module_level: bool,
                 type_checking: bool) -> None:
        self.importer, self.imported, self.line = importer, imported, line
        self.module_level, self.type_checking = module_level, type_checking

    def __repr__(self) -> str:
        where = "module level" if self.module_level else "in a function"
        return (f"{MODULES[self.importer].relative_to(SOURCE.parent)}:{self.line} imports "
                f"{self.imported} ({where}{', TYPE_CHECKING' if self.type_checking else ''})")


def _imports_of(module: str, path: Path) -> list[Import]:
    """Every import of a posturelab module in ``module``'s source."""
    is_package = path.name == "__init__.py"
    found: list[Import] = []

    def visit(node: ast.AST, in_function: bool, type_checking: bool) -> None:
        for child in ast.iter_child_nodes(node):
            inside = in_function or isinstance(
                child, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda)
            checking = type_checking or (isinstance(child, ast.If)
                                         and "TYPE_CHECKING" in ast.unparse(child.test))
            if isinstance(child, ast.ImportFrom):
                names = _targets(module, is_package, child)
            elif isinstance(child, ast.Import):
                names = [a.name for a in child.names if a.name.split(".")[0] == "posturelab"]
            else:
                names = []
            found.extend(Import(module, name, child.lineno, not inside, checking)
                         for name in names if name != module)
            visit(child, inside, checking)

    visit(ast.parse(path.read_text(encoding="utf-8")), False, False)
    return found


IMPORTS = [i for module, path in MODULES.items() for i in _imports_of(module, path)]
LAYER_OF = {unit: k for k, layer in enumerate(LAYERS) for unit in layer}


def test_every_module_is_in_a_layer():
    missing = sorted({_unit(m) for m in MODULES} - set(LAYER_OF))
    assert not missing, f"add these to LAYERS in {Path(__file__).name}: {missing}"
    assert len(LAYER_OF) == sum(len(layer) for layer in LAYERS)  # each named once


def test_the_graph_is_read():
    """The reader finds imports of each kind (a guard against a reader that finds none)."""
    assert any(i.module_level and not i.type_checking for i in IMPORTS)
    assert any(not i.module_level for i in IMPORTS)
    assert any(i.type_checking for i in IMPORTS)
    edge = {(i.importer, i.imported) for i in IMPORTS}
    assert ("posturelab.cli.stability_map", "posturelab.viz.maps") in edge
    assert ("posturelab.simulation.results", "posturelab._files") in edge


def test_no_import_goes_up_a_layer():
    """At any level, TYPE_CHECKING included: a module imports its layer and those below."""
    upward = [i for i in IMPORTS
              if LAYER_OF.get(_unit(i.imported), -1) > LAYER_OF.get(_unit(i.importer), -1)]
    assert not upward, "imports from a lower layer up to a higher one:\n" + "\n".join(
        sorted({f"  {i!r}: {_unit(i.importer)} is below {_unit(i.imported)}" for i in upward}))


def _cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def strong(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(edges[v]):
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(MODULES):
        if v not in index:
            strong(v)
    return found


@pytest.mark.parametrize("module_level_only", [True, False],
                         ids=["module-level imports", "all imports"])
def test_no_import_cycles(module_level_only):
    edges: dict[str, set[str]] = defaultdict(set)
    for i in IMPORTS:
        if i.imported in MODULES and not i.type_checking \
                and (i.module_level or not module_level_only):
            edges[i.importer].add(i.imported)
    cycles = _cycles(edges)
    assert not cycles, "import cycles:\n" + "\n".join(
        "  " + " ↔ ".join(c) + "\n" + "\n".join(sorted({
            f"    {i!r}" for i in IMPORTS if i.importer in c and i.imported in c
            and not i.type_checking and (i.module_level or not module_level_only)}))
        for c in cycles)


def _generated(path: Path) -> bool:
    head = "\n".join(path.read_text(encoding="utf-8").splitlines()[:5])
    return "GENERATED" in head or re.search(r"do not edit", head, re.IGNORECASE) is not None


def test_no_hand_written_python_file_is_longer_than_600_lines():
    long = {str(p.relative_to(SOURCE.parent)): n for p in MODULES.values()
            if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_LINES
            and not _generated(p)}
    assert not long, f"hand-written files over {MAX_LINES} lines: {long}"


def test_help_imports_few_posturelab_modules():
    """``posturelab --help`` as the console script runs it (``posturelab.cli:main``)."""
    code = "import sys; from posturelab.cli import main; sys.exit(main(['--help']))"
    proc = subprocess.run([sys.executable, "-X", "importtime", "-c", code],
                          capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode == 0 and "usage: posturelab" in proc.stdout, proc.stderr[-2000:]
    loaded = sorted({m.group(1) for m in re.finditer(r"\|\s*(posturelab(?:\.[\w.]+)?)\s*$",
                                                     proc.stderr, re.MULTILINE)})
    assert "posturelab.cli" in loaded  # (the import log is read)
    assert len(loaded) <= MAX_HELP_MODULES, loaded
