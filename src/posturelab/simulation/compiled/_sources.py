"""The digest of the compiled engine's C sources (``csrc/``) and the check that the engine
is not stale.

``setup.py`` compiles the digest and the names of the files it covers into the extension.
At import the package compares them with the sources installed beside it, so that an
editable install whose C sources changed since the build says so instead of running stale
machine code. A wheel installs the sources its engine was built from (MANIFEST.in puts
them in the sdist, and so in the wheel), which then agree; an installation without all of
them is not checked (:func:`stale_digest`). No imports from posturelab here: the build
runs this file on its own.
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from pathlib import Path

CSRC = Path(__file__).resolve().parent / "csrc"
#: Compiler flags of the build (gcc and clang): C99, optimised, no floating-point contraction
#: (a·b + c rounded twice everywhere, so results are the same on every machine and a batch
#: row equals its single run bit for bit), only the entry points exported.
COMPILE_FLAGS = ("-std=c99", "-O3", "-ffp-contract=off", "-fvisibility=hidden")


def source_files(folder: Path = CSRC) -> list[str]:
    """The names of the ``*.c`` and ``*.h`` files in ``folder``, sorted; [] when there are
    none or no folder."""
    return sorted(path.name for pattern in ("*.c", "*.h") for path in folder.glob(pattern))


def source_hash(folder: Path = CSRC) -> str:
    """A 16-hex-digit digest of every ``*.c`` and ``*.h`` file in ``folder`` (names and bytes);
    '' when there are none (an installation without the sources)."""
    names = source_files(folder)
    if not names:
        return ""
    digest = hashlib.sha256()
    for name in names:
        digest.update(name.encode())
        digest.update((folder / name).read_bytes())
    return digest.hexdigest()[:16]


def stale_digest(built_hash: str, built_files: Sequence[str], folder: Path = CSRC) -> str:
    """The digest of the sources installed in ``folder`` when it differs from the one the
    engine was built from; '' when they agree or when the check does not apply.

    The check applies only where every file the build digested is installed (an editable
    install, a wheel or an sdist with the full set): a partial set of sources beside the
    engine (as wheels carried before MANIFEST.in named them all) says nothing about the
    build, which is what was installed.

    Parameters
    ----------
    built_hash : str
        The digest compiled into the engine (``pl_source_hash``).
    built_files : sequence of str
        The names of the files it covers (``pl_source_files``); empty for an engine built
        before it recorded them, which is then checked whenever any source is installed.
    folder : Path
        Where the installed sources are (the package's ``csrc/``).
    """
    installed = set(source_files(folder))
    if not installed or not set(built_files) <= installed:
        return ""
    here = source_hash(folder)
    return here if here != built_hash else ""
