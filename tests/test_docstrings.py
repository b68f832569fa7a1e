"""The ``>>>`` examples in posturelab's docstrings run and print what they say."""

from __future__ import annotations

import doctest
import importlib
import pkgutil

import numpy as np
import pytest

import posturelab


def _is_public(name: str) -> bool:
    """A module of the documented API: no private part, not the command-line internals."""
    parts = name.split(".")
    return not any(p.startswith("_") for p in parts) and "cli" not in parts[1:2]


def modules_with_examples() -> list[str]:
    """The public modules of posturelab whose source contains a ``>>>`` example."""
    names = []
    for info in pkgutil.walk_packages(posturelab.__path__, "posturelab."):
        if not _is_public(info.name):
            continue
        # the finder that listed the module, not importlib.util.find_spec: importing a
        # former module path (posturelab.body, as conftest does) leaves the module with the
        # former path's spec, which has no origin
        spec = info.module_finder.find_spec(info.name)
        if spec is None or spec.origin is None or not spec.origin.endswith(".py"):
            continue
        with open(spec.origin, encoding="utf-8") as source:
            if ">>>" in source.read():
                names.append(info.name)
    return sorted(names)


MODULES = modules_with_examples()


def test_some_modules_have_examples():
    assert {"posturelab.model.body", "posturelab.model.muscles", "posturelab.linear.analysis",
            "posturelab.linear.delay", "posturelab.simulation.engines"} <= set(MODULES)


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    module = importlib.import_module(name)
    finder = doctest.DocTestFinder(exclude_empty=True)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    # nothing in the examples is random today; one that needs randomness uses this seeded rng
    globs = {"rng": np.random.default_rng(20261122)}
    for test in finder.find(module, name, globs=globs):
        runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed in {name}"
    assert result.attempted > 0, f"no example ran in {name}"
