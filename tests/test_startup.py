"""Start-up stays light, submodules load as attributes, former module paths still import."""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest

import posturelab as pl
from posturelab import _compat
from posturelab.cli import SUBCOMMAND_HELP, SUBCOMMANDS

HEAVY = ("numba", "scipy.integrate", "scipy.optimize", "scipy.stats", "matplotlib")

PROBE = """
import sys
{code}
print("HEAVY:" + " ".join(m for m in {heavy!r} if m in sys.modules))
"""


def loaded_after(code: str) -> list[str]:
    """Heavy modules loaded by ``code`` in a fresh interpreter."""
    out = subprocess.run([sys.executable, "-c", PROBE.format(code=code, heavy=HEAVY)],
                         capture_output=True, text=True, check=True, timeout=120).stdout
    line = [ln for ln in out.splitlines() if ln.startswith("HEAVY:")][-1]
    return line.removeprefix("HEAVY:").split()


@pytest.mark.parametrize("code", [
    "import posturelab",
    "import posturelab.cli",
    "from posturelab.cli import build_parser; build_parser()",
    "from posturelab.cli import main\ntry:\n    main(['--help'])\nexcept SystemExit:\n    pass",
    "from posturelab.cli import main\nfor c in ('simulate', 'sweep', 'fit', 'stability-map', "
    "'reproduce', 'poles', 'sensitivity'):\n    try:\n        main([c, '--help'])\n"
    "    except SystemExit:\n        pass",
])
def test_start_up_loads_no_heavy_module(code):
    """import posturelab, import posturelab.cli and every --help load none of numba, scipy's
    integrators, optimisers or statistics, or matplotlib."""
    assert loaded_after(code) == []


#: Modules that no --help may load: the compiled engine (its Python package too), numba and
#: its compiler, matplotlib, and any part of scipy.
NOT_AT_HELP = ("posturelab.simulation.compiled", "numba", "llvmlite", "matplotlib", "scipy")
#: At most this many modules in all after `posturelab CMD --help` (a bare `import numpy` loads
#: about 170, the interpreter about 30; every --help loaded 297 before start-up was made lazy,
#: 244-253 for the heaviest commands when this was written) ...
MAX_MODULES_AT_HELP = 280
#: ... and at most this many of posturelab's own (55 before; 5-26 when this was written; 35
#: for sweep once files were split to at most 600 lines: smaller modules, not more code —
#: the heavy libraries above and the total stay the guards).
MAX_POSTURELAB_MODULES_AT_HELP = 36

HELP_PROBE = """
import sys
from posturelab.cli import main
try:
    main({argv!r})
except SystemExit:
    pass
print("MODULES:" + " ".join(sorted(sys.modules)))
"""


def modules_after_help(argv: list[str]) -> list[str]:
    """Every module loaded by ``posturelab ARGV`` in a fresh interpreter."""
    out = subprocess.run([sys.executable, "-c", HELP_PROBE.format(argv=argv)],
                         capture_output=True, text=True, check=True, timeout=120).stdout
    line = [ln for ln in out.splitlines() if ln.startswith("MODULES:")][-1]
    return line.removeprefix("MODULES:").split()


@pytest.mark.parametrize("command", ["", *sorted(SUBCOMMANDS)])
def test_help_loads_few_modules_and_no_engine(command):
    """`posturelab --help` and `posturelab CMD --help` for every CMD load no compiled engine,
    numba, matplotlib or scipy, and few modules (thresholds above)."""
    modules = modules_after_help([command, "--help"] if command else ["--help"])
    heavy = [m for m in modules if any(m == h or m.startswith(h + ".") for h in NOT_AT_HELP)]
    assert heavy == []
    assert len(modules) <= MAX_MODULES_AT_HELP
    assert len([m for m in modules if m.split(".")[0] == "posturelab"]) \
        <= MAX_POSTURELAB_MODULES_AT_HELP


def test_posturelab_help_imports_no_subcommand():
    """`posturelab --help` lists the subcommands from cli.SUBCOMMAND_HELP: it imports none of
    their modules, nor numpy."""
    modules = modules_after_help(["--help"])
    assert [m for m in modules if m.startswith("posturelab.cli.")] == []
    assert "numpy" not in modules


def test_every_subcommand_has_one_help_line():
    assert set(SUBCOMMAND_HELP) == set(SUBCOMMANDS)
    assert all(line and "\n" not in line for line in SUBCOMMAND_HELP.values())


def test_import_posturelab_loads_only_its_error_classes():
    """The public API loads on first use: `import posturelab` runs nothing else of it."""
    out = subprocess.run([sys.executable, "-c", "import sys, posturelab; print(sorted(m for m "
                          "in sys.modules if m.startswith('posturelab')))"],
                         capture_output=True, text=True, check=True, timeout=120).stdout
    assert out.strip() == "['posturelab', 'posturelab._compat', 'posturelab.errors']"


@pytest.mark.parametrize("name", sorted(pl.__all__))
def test_public_names_load_on_first_access(name):
    assert getattr(pl, name) is not None and name in dir(pl)


@pytest.mark.parametrize("name", sorted(pl.LAZY_SUBMODULES))
def test_submodules_are_attributes(name):
    module = getattr(pl, name)
    assert module is importlib.import_module(pl.LAZY_SUBMODULES[name])


def test_unknown_attribute_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'no_such_thing'"):
        _ = pl.no_such_thing


@pytest.mark.parametrize("old,new", sorted(_compat.MOVED_MODULES.items()))
def test_former_module_paths_import_the_same_module(old, new):
    assert importlib.import_module(old) is importlib.import_module(new)


def test_a_submodule_of_a_moved_package_is_not_loaded_twice():
    from posturelab.fast import _encode as old

    from posturelab.simulation.compiled import _encode as new

    assert old is new


def test_simulate_stays_the_function():
    """posturelab.simulate is both a former module path and the function; importing the
    module path does not rebind the function."""
    importlib.import_module("posturelab.simulate")
    assert callable(pl.simulate) and pl.simulate.__module__ == "posturelab.simulation.engines"
    from posturelab.simulate import FallCriteria, simulate

    assert simulate is pl.simulate and FallCriteria is pl.FallCriteria


def test_simulate_stays_the_function_when_the_former_module_is_imported_first():
    code = ("import posturelab.simulate\nimport posturelab as pl\n"
            "print(pl.simulate.__module__, pl.simulate is pl.simulation.simulate)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=120).stdout
    assert out.split() == ["posturelab.simulation.engines", "True"]


def test_every_body_preset_and_dotted_path_works_in_a_fresh_process():
    """In a fresh interpreter (nothing else imported first): every body preset is known
    (the anthropometric ones register themselves when model.body loads) and the dotted paths
    the README and docs use reach their modules without an import statement."""
    import subprocess
    import sys

    code = """
import posturelab as pl
names = sorted(pl.BODY_PRESETS)
assert names == ["paper", "paper-1link", "paper-2link", "winter-1.75m-75kg"], names
assert all(pl.get_body(n).n_links >= 1 for n in names)
assert pl.model.tilt.PRTSTilt.named("peterka-2002-242", 0.03).registers == 5
assert callable(pl.linear.delay_batch.delay_stability_map)
assert callable(pl.scenarios.schema.json_schema)
assert "peterka-2002" in pl.model.controllers.CONTROLLERS
assert callable(pl.frequency.model_frf_batch) and callable(pl.frequency.fit.fit_frf)
assert pl.parameters.MAX_FEEDBACK_DELAY == 1.0
print("ok")
"""
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       timeout=120)
    assert p.returncode == 0 and p.stdout.strip() == "ok", p.stderr[-2000:]
