"""The C engine (``_engine``, built by ``setup.py`` from ``csrc/``) seen from Python.

The structs take their fields from ``_layout.py``, generated with ``csrc/pl_model.h`` from
one table; :func:`library` loads the extension once
and checks that it was built from the sources beside it, where they are all installed.
Calls go through ctypes, which releases the GIL for their duration, so batch chunks run in
parallel on Python threads.
"""

from __future__ import annotations

import ctypes
import functools
import importlib.util
import threading

from ...errors import PostureLabError
from ._layout import BATCH_FIELDS, OUT_FIELDS, RUN_FIELDS
from ._sources import stale_digest

_P = ctypes.POINTER
_d = _P(ctypes.c_double)
_i = _P(ctypes.c_int64)


_TYPES = {"i64": ctypes.c_int64, "f64": ctypes.c_double, "*f64": _d, "*i64": _i,
          "*u8": _P(ctypes.c_uint8)}


def _fields(spec: tuple[str, ...], **structs) -> list:
    """ctypes fields from the ``name:type`` list of a struct in ``_layout.py``; ``structs``
    names the struct types it embeds (``run=Run``)."""
    types = {**_TYPES, **structs}
    return [(name, types[kind]) for name, kind in (item.split(":") for item in spec)]


class Run(ctypes.Structure):
    """``pl_run``: one run's inputs."""

    _fields_ = _fields(RUN_FIELDS)


class Out(ctypes.Structure):
    """``pl_out``: where one run's outputs go."""

    _fields_ = _fields(OUT_FIELDS)


class Batch(ctypes.Structure):
    """``pl_batch``: a batch's shared inputs, per-level and per-run arrays, outputs."""

    _fields_ = _fields(BATCH_FIELDS, run=Run)


def pointer(arr, kind=_d):
    """A ctypes pointer to a C-contiguous numpy array's data (None for None)."""
    if arr is None:
        return None
    if not arr.flags.c_contiguous:
        raise ValueError("array must be C-contiguous")
    return arr.ctypes.data_as(kind)


def built_source_files(lib: ctypes.CDLL) -> list[str]:
    """The names of the C sources the engine ``lib`` was built from ([] for a build that did
    not record them)."""
    try:
        recorded = lib.pl_source_files
    except AttributeError:
        return []
    recorded.restype = ctypes.c_char_p
    return [name for name in recorded().decode().split(",") if name]


#: Held while the engine loads: threads that call :func:`library` first at once (a sweep's
#: threads) would otherwise see the extension half imported (its ``__spec__`` not yet set).
_LOADING = threading.Lock()


@functools.cache
def library() -> ctypes.CDLL:
    """The loaded engine, its functions typed."""
    with _LOADING:
        return _load()


def _load() -> ctypes.CDLL:
    """Load the engine and type its functions (:func:`library`, once)."""
    spec = importlib.util.find_spec("posturelab.simulation.compiled._engine")
    if spec is None or spec.origin is None:
        raise PostureLabError(
            "posturelab's compiled engine is not built: reinstall posturelab "
            "(pip install -e . in a source checkout; a C compiler is needed)")
    importlib.import_module("posturelab.simulation.compiled._engine")  # runs its set-up
    lib = ctypes.CDLL(spec.origin)
    lib.pl_source_hash.restype = ctypes.c_char_p
    built = lib.pl_source_hash().decode()
    here = stale_digest(built, built_source_files(lib))
    if here:
        raise PostureLabError(
            f"posturelab's compiled engine was built from other C sources ({built}) than "
            f"those installed ({here}): rebuild it (pip install -e . in a source checkout)")
    lib.pl_run_one.argtypes = [_P(Run), _P(Out)]
    lib.pl_run_one.restype = ctypes.c_int64
    lib.pl_run_batch.argtypes = [_P(Batch), ctypes.c_int64, ctypes.c_int64]
    lib.pl_run_batch.restype = None
    lib.pl_state_derivative.argtypes = [ctypes.c_int64, ctypes.c_int64, _d, _d, _d, _d, _d,
                                        _d, _d, _d, _d, ctypes.c_int64, ctypes.c_int64, _d, _d]
    lib.pl_state_derivative.restype = None
    lib.pl_rotate_value.argtypes = [ctypes.c_double] * 4 + [_d, _d]
    lib.pl_rotate_value.restype = None
    return lib
