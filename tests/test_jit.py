"""posturelab._jit: every numba module is in the digest, the digest follows every covered
file, and each kernel's cache name carries it (so a changed helper recompiles its callers).
"""

import re
import shutil
from pathlib import Path

import pytest

from posturelab import _jit

PACKAGE = Path(_jit.__file__).resolve().parent

#: A line that imports numba (at module level or inside a function).
NUMBA_IMPORT = re.compile(r"^\s*(import numba\b|from numba\b).*$", re.MULTILINE)
#: numba imports that compile nothing (compile events, configuration): a module whose only
#: numba imports are these holds no kernel code and need not be in the digest.
NON_COMPILING = re.compile(r"^\s*from numba(\.core)? import (event|config)$")
#: A line that imports the kernel decorator (a module that compiles with it).
JIT_IMPORT = re.compile(r"^\s*from (\.+|posturelab\.)_jit import|^\s*import posturelab\._jit",
                        re.MULTILINE)
#: An import of _jit's helper that compiles nothing (the command line's kernel loading).
NON_COMPILING_JIT = re.compile(r"^\s*from (\.+|posturelab\.)_jit import skip_blas_probe$")


def numba_modules(*, compiling: bool = True) -> list[str]:
    """Package-relative paths of the modules that import numba or posturelab._jit (with
    ``compiling``, other than only for NON_COMPILING parts)."""
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        imports = [m.group(0) for m in NUMBA_IMPORT.finditer(text)]
        jit = [line for line in text.splitlines() if JIT_IMPORT.match(line)]
        if compiling:
            imports = [line for line in imports if not NON_COMPILING.match(line)]
            jit = [line for line in jit if not NON_COMPILING_JIT.match(line)]
        if imports or jit:
            found.append(path.relative_to(PACKAGE).as_posix())
    return found


def copy_covered(root: Path) -> None:
    """Copy every file that _jit.KERNEL_SOURCES names into ``root`` (same layout)."""
    for path in _jit.kernel_files(PACKAGE):
        target = root / path.relative_to(PACKAGE)
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(path, target)


def test_every_numba_module_is_covered_by_the_digest():
    covered = {p.relative_to(PACKAGE).as_posix() for p in _jit.kernel_files(PACKAGE)}
    modules = numba_modules()
    assert "linear/_batch_kernels.py" in modules and "_jit.py" in modules  # the grep works
    # cli/_common.py imports numba.core.event and _jit.skip_blas_probe only (load_compiled
    # listens for compiles)
    assert "cli/_common.py" in numba_modules(compiling=False)
    missing = [m for m in modules if m not in covered]
    assert missing == [], f"modules using numba outside _jit.KERNEL_SOURCES: {missing}"


def test_digest_of_a_copy_equals_source_hash(tmp_path):
    copy_covered(tmp_path)
    assert _jit._source_hash(tmp_path) == _jit._source_hash() == _jit.SOURCE_HASH


def test_digest_changes_when_any_covered_file_changes(tmp_path):
    copy_covered(tmp_path)
    files = _jit.kernel_files(tmp_path)
    assert len(files) >= 3
    seen = {_jit._source_hash(tmp_path)}
    for path in files:
        original = path.read_bytes()
        path.write_bytes(original + b"\n# changed\n")
        changed = _jit._source_hash(tmp_path)
        assert changed not in seen, f"editing {path.relative_to(tmp_path)} kept the digest"
        seen.add(changed)
        path.write_bytes(original)
        assert _jit._source_hash(tmp_path) == _jit.SOURCE_HASH


def test_digest_changes_when_a_kernel_file_is_added_or_removed(tmp_path):
    copy_covered(tmp_path)
    folder = next(tmp_path / rel for rel in _jit.KERNEL_SOURCES if (tmp_path / rel).is_dir())
    extra = folder / "_new_kernels.py"
    extra.write_text("x = 1\n")
    assert _jit._source_hash(tmp_path) != _jit.SOURCE_HASH
    extra.unlink()
    (folder / "batch.py").unlink()
    assert _jit._source_hash(tmp_path) != _jit.SOURCE_HASH


def test_kernel_cache_names_carry_the_source_hash():
    from numba.core.dispatcher import Dispatcher

    from posturelab.linear import _batch_kernels

    kernels = {name: obj for name, obj in vars(_batch_kernels).items()
               if isinstance(obj, Dispatcher)}
    assert "batch_kernel" in kernels and "_aberth" in kernels
    for name, dispatcher in kernels.items():
        assert dispatcher.py_func.__qualname__ == f"{name}__{_jit.SOURCE_HASH}"
        # numba names the on-disk cache entry after that qualname
        assert f".{name}__{_jit.SOURCE_HASH}-" in dispatcher._cache._impl.filename_base
    # only the entry point has a Python wrapper
    assert not kernels["batch_kernel"].targetoptions.get("no_cpython_wrapper", False)
    assert kernels["_aberth"].targetoptions["no_cpython_wrapper"]


def test_kernel_and_specialise_name_their_copies():
    def template(x):
        return x + 1.0

    compiled = _jit.kernel(entry=True, cache=False)(template)  # no cache file for a test
    assert compiled.py_func.__qualname__ == f"template__{_jit.SOURCE_HASH}"
    assert compiled(1.0) == 2.0
    special = _jit.specialise(template, "plus", {}, entry=True)
    assert special.py_func.__qualname__ == f"template_plus__{_jit.SOURCE_HASH}"
    assert template.__qualname__.endswith("template")  # the original is left as it is


@pytest.mark.parametrize("options", [{}, {"nogil": True}])
def test_internal_kernels_get_no_wrappers(options):
    internal = _jit._internal(options)
    assert internal["no_cpython_wrapper"] and internal["no_cfunc_wrapper"]
    assert "entry" not in _jit._internal({**options, "entry": True})
    assert "no_cpython_wrapper" not in _jit._internal({**options, "entry": True})


#: numpy functions whose compiled form depends on numba's BLAS probe (numba.np.arraymath's
#: _HAVE_BLAS), which the command line skips (_jit.skip_blas_probe).
BLAS_PROBED = re.compile(r"\bnp\.(convolve|correlate)\b")


def test_no_kernel_depends_on_the_skipped_blas_probe():
    used = [p.relative_to(PACKAGE).as_posix() for p in _jit.kernel_files(PACKAGE)
            if p.exists() and BLAS_PROBED.search(p.read_text(encoding="utf-8"))]
    assert used == []


def test_skip_blas_probe_leaves_scipy_linalg_importable():
    """In a fresh interpreter: the probe is skipped (scipy.linalg not imported, numba's
    flag False), the kernels give the map, and ``import scipy.linalg`` still works."""
    import subprocess
    import sys

    code = (
        "import sys\n"
        "from posturelab import _jit\n"
        "assert _jit.skip_blas_probe() is True\n"
        "assert 'scipy.linalg' not in sys.modules\n"
        "import numba.np.arraymath as a\n"
        "assert a._HAVE_BLAS is False\n"
        "assert _jit.skip_blas_probe() is False  # once only\n"
        "from posturelab.linear.batch import stability_map\n"
        "m = stability_map(('stiffness:ankle', 0, 2000), ('stiffness:gastrocnemius', 0, 1000), 3)\n"
        "print(repr(m.max_real_part.tolist()))\n"
        "import scipy.linalg\n"
        "assert scipy.linalg.cython_blas is not None\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    from posturelab.linear.batch import stability_map

    here = stability_map(("stiffness:ankle", 0, 2000), ("stiffness:gastrocnemius", 0, 1000), 3)
    assert proc.stdout.strip() == repr(here.max_real_part.tolist())
