"""How posturelab compiles its kernels with numba: one decorator, a cache that notices any
kernel source change, and per-method specialisation of a kernel written once.

:func:`kernel` is ``numba.njit`` with ``cache=True``, ``error_model="numpy"`` (a
division by zero gives inf/NaN, caught by the callers, instead of raising) and
floating-point contraction only (a·b + c may become one fused multiply-add; no
reassociation, so results are deterministic).

The cache. numba's on-disk cache checks the source file of each function but not
the files of the helpers it calls, so a changed helper in another file would
leave stale machine code in its callers' caches. Every kernel's cache name
therefore carries :data:`SOURCE_HASH`, a digest of every file that holds kernel
code (:data:`KERNEL_SOURCES`): any change to any of them gives every kernel a new
name, and everything is compiled afresh once.

Specialisation. :func:`specialise` compiles a copy of a plain-Python template
with some of its global names bound to other kernels or constants (the
integrator's step, its tableau): the integration loop is written once and each
method compiles only when it is first used, into its own cache entry.
"""

from __future__ import annotations

import hashlib
import types
from pathlib import Path

__all__ = ["kernel", "specialise", "kernel_files", "SOURCE_HASH", "KERNEL_SOURCES", "CONTRACT",
           "skip_blas_probe"]

_ROOT = Path(__file__).resolve().parent

#: Files whose code is compiled (relative to the package), and the folders all of whose
#: modules are. A test checks that every module using this decorator is covered.
KERNEL_SOURCES: tuple[str, ...] = ("_jit.py", "linear")

#: Floating-point contraction only: a·b + c as one fused multiply-add (one rounding).
CONTRACT = frozenset({"contract"})


def kernel_files(root: Path = _ROOT) -> list[Path]:
    """The files :data:`KERNEL_SOURCES` names under ``root`` (the package folder by default):
    each listed file, and the ``*.py`` files directly in each listed folder."""
    files: list[Path] = []
    for rel in KERNEL_SOURCES:
        path = root / rel
        files.extend(sorted(path.glob("*.py")) if path.is_dir() else [path])
    return files


def _source_hash(root: Path = _ROOT) -> str:
    """Digest (12 hex digits) of the path and content of every :func:`kernel_files` of
    ``root``; a missing file counts as empty."""
    digest = hashlib.sha256()
    for path in kernel_files(root):
        digest.update(path.relative_to(root).as_posix().encode())
        digest.update(path.read_bytes() if path.exists() else b"")
    return digest.hexdigest()[:12]


#: Digest of every kernel source file; part of every kernel's cache name.
SOURCE_HASH = _source_hash()


def _options(options: dict) -> dict:
    opts = {"cache": True, "error_model": "numpy", "fastmath": set(CONTRACT)}
    opts.update(options)
    return opts


def kernel(fn=None, **options):
    """``numba.njit`` with posturelab's options and a cache name that carries SOURCE_HASH.

    Use as ``@kernel`` or ``@kernel(parallel=True)``. A kernel is called from other kernels
    only (no Python wrapper is compiled for it) unless ``entry=True``.
    """
    options = _internal(options)
    def wrap(f):
        from numba import njit

        return njit(**_options(options))(_renamed(f, f.__name__, f.__globals__))

    return wrap if fn is None else wrap(fn)


def _renamed(f, name: str, scope: dict):
    """A copy of function f named ``name`` with globals ``scope``; its cache name carries
    SOURCE_HASH (f itself is left as it is)."""
    copy = types.FunctionType(f.__code__, scope, name, f.__defaults__, f.__closure__)
    copy.__qualname__ = f"{name}__{SOURCE_HASH}"
    copy.__module__ = f.__module__
    copy.__doc__ = f.__doc__
    return copy


class _RefuseOnThread:
    """A meta-path finder that refuses one module name to one thread (see skip_blas_probe)."""

    def __init__(self, name: str, thread: int) -> None:
        self.name, self.thread = name, thread

    def find_spec(self, name, path=None, target=None):
        import threading

        if name == self.name and threading.get_ident() == self.thread:
            raise ImportError(f"{name} is not imported for numba's BLAS probe (posturelab)")
        return None


def skip_blas_probe() -> bool:
    """Import numba's array-maths lowering without its BLAS probe; True if it was skipped.

    When numba first compiles or loads a kernel it imports ``numba.np.arraymath``, whose
    module-level ``_check_blas`` imports ``scipy.linalg`` (about 0.2 s) only to decide how
    compiled ``numpy.convolve``/``numpy.correlate`` compute inner products (BLAS or a
    loop). posturelab's kernels use neither (``tests/test_jit.py`` checks the kernel
    sources), and kernels loaded from the cache carry their machine code, so skipping the
    probe changes no result. It is skipped only when neither module is imported yet, by refusing
    ``scipy.linalg`` to this thread for the one import; a later ``import scipy.linalg``
    works as usual. For processes posturelab runs itself (the command line): a program
    that compiles its own ``numpy.convolve`` in the same process should not call this.
    """
    import sys
    import threading

    if "numba.np.arraymath" in sys.modules or "scipy.linalg" in sys.modules:
        return False
    finder = _RefuseOnThread("scipy.linalg", threading.get_ident())
    sys.meta_path.insert(0, finder)
    try:
        import numba.np.arraymath  # noqa: F401
    finally:
        sys.meta_path.remove(finder)
    return True


def _internal(options: dict) -> dict:
    """Options of a kernel that only other kernels call: no CPython or C wrapper."""
    options = dict(options)
    if not options.pop("entry", False):
        options.setdefault("no_cpython_wrapper", True)
        options.setdefault("no_cfunc_wrapper", True)
    return options


def specialise(template, suffix: str, bindings: dict, **options):
    """Compile a copy of ``template`` whose globals ``bindings`` replace (a kernel per method).

    Parameters
    ----------
    template : function
        A plain-Python function written for numba (not itself decorated).
    suffix : str
        Names the copy (its cache entry): ``integrate`` → ``integrate_radau``.
    bindings : dict
        Global name → kernel, constant or array the copy sees instead.
    **options
        Further ``numba.njit`` options (``parallel=True``, ``nogil=True``; ``entry=True``
        for one called from Python).

    Returns
    -------
    numba dispatcher
        Compiled on first call, or loaded from the cache.
    """
    from numba import njit

    options = _internal(options)
    scope = dict(template.__globals__)
    scope.update(bindings)
    return njit(**_options(options))(_renamed(template, f"{template.__name__}_{suffix}", scope))
