"""Builds posturelab's compiled simulation engine, a C extension; everything else about the
package is in pyproject.toml.

The extension carries the digest of its sources (PL_SOURCE_HASH) and their names
(PL_SOURCE_FILES), which the package checks at import against the sources beside it where
they are all installed (src/posturelab/simulation/compiled/_sources.py). The sdist, and so
the wheel, carries every C source and header (MANIFEST.in).
"""

import runpy
import sys
from pathlib import Path

from setuptools import Extension, setup

CSRC = Path("src/posturelab/simulation/compiled/csrc")
SOURCES = runpy.run_path("src/posturelab/simulation/compiled/_sources.py")
digest = SOURCES["source_hash"](CSRC)
names = SOURCES["source_files"](CSRC)
flags = [] if sys.platform == "win32" else list(SOURCES["COMPILE_FLAGS"])

setup(ext_modules=[Extension(
    "posturelab.simulation.compiled._engine",
    sources=[str(CSRC / "pl_engine.c")],  # includes every other .c file (one unit)
    depends=[str(CSRC / name) for name in names],  # rebuilt when any of them changes
    include_dirs=[str(CSRC)],
    define_macros=[("PL_SOURCE_HASH", f'"{digest}"'),
                   ("PL_SOURCE_FILES", f'"{",".join(names)}"')],
    extra_compile_args=flags,
)])
