"""Start-up stays light, submodules load as attributes, former module paths still import."""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest

import posturelab as pl
from posturelab import _compat

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
