"""Builds posturelab's compiled simulation engine, a C extension; everything else about the
package is in pyproject.toml.

The extension carries the digest of its sources (PL_SOURCE_HASH), which the package checks at
import against the sources beside it (src/posturelab/simulation/compiled/_sources.py).
"""

import runpy
import sys
from pathlib import Path

from setuptools import Extension, setup

CSRC = Path("src/posturelab/simulation/compiled/csrc")
SOURCES = runpy.run_path("src/posturelab/simulation/compiled/_sources.py")
digest = SOURCES["source_hash"](CSRC)
flags = [] if sys.platform == "win32" else list(SOURCES["COMPILE_FLAGS"])

setup(ext_modules=[Extension(
    "posturelab.simulation.compiled._engine",
    sources=[str(CSRC / "pl_engine.c")],  # includes every other .c file (one unit)
    include_dirs=[str(CSRC)],
    define_macros=[("PL_SOURCE_HASH", f'"{digest}"')],
    extra_compile_args=flags,
)])
