"""The digest of the compiled engine's C sources (``csrc/``).

``setup.py`` compiles it into the extension; at import the package compares it with the
sources beside it, so that an editable install whose C sources changed since the build
says so instead of running stale machine code. No imports from posturelab here: the
build runs this file on its own.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

CSRC = Path(__file__).resolve().parent / "csrc"
#: Compiler flags of the build (gcc and clang): C99, optimised, no floating-point contraction
#: (a·b + c rounded twice everywhere, so results are the same on every machine and a batch
#: row equals its single run bit for bit), only the entry points exported.
COMPILE_FLAGS = ("-std=c99", "-O3", "-ffp-contract=off", "-fvisibility=hidden")


def source_hash(folder: Path = CSRC) -> str:
    """A 16-hex-digit digest of every ``*.c`` and ``*.h`` file in ``folder`` (names and bytes);
    '' when there are none (an installation without the sources)."""
    files = sorted([*folder.glob("*.c"), *folder.glob("*.h")])
    if not files:
        return ""
    digest = hashlib.sha256()
    for path in files:
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]
