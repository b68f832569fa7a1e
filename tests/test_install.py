"""The compiled engine's staleness check compares what the build recorded with what is
installed: sources beside the package that changed since the build are refused; an
installation without the full source set (as a wheel once carried pl_engine.c alone) is
not checked; the sdist's manifest carries every C source and header.

Building and installing the wheel and the sdist in fresh environments is CI's smoke test
(.ci/run, .ci/smoke.py), not a test here.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from posturelab.simulation.compiled._binding import built_source_files, library
from posturelab.simulation.compiled._sources import (
    CSRC,
    source_files,
    source_hash,
    stale_digest,
)

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture
def sources(tmp_path) -> Path:
    """A copy of the installed C sources."""
    folder = tmp_path / "csrc"
    shutil.copytree(CSRC, folder)
    return folder


def test_the_build_recorded_every_source_file():
    assert built_source_files(library()) == source_files()
    assert {"pl_engine.c", "pl.h", "pl_module.c"} <= set(source_files())


def test_unchanged_sources_are_not_stale(sources):
    assert stale_digest(source_hash(CSRC), source_files(CSRC), sources) == ""


def test_a_changed_source_is_stale(sources):
    built = source_hash(sources)
    (sources / "pl_model.c").write_bytes((sources / "pl_model.c").read_bytes() + b"\n")
    assert stale_digest(built, source_files(CSRC), sources) == source_hash(sources) != built


def test_a_new_source_beside_the_built_ones_is_stale(sources):
    built = source_hash(sources)
    (sources / "pl_new.c").write_text("/* new */\n")
    assert stale_digest(built, source_files(CSRC), sources) not in ("", built)


@pytest.mark.parametrize("kept", [(), ("pl_engine.c",), ("pl_engine.c", "pl.h")])
def test_an_installation_without_the_full_sources_is_not_checked(sources, kept):
    """No sources, or the partial set a wheel carried before MANIFEST.in named them all."""
    built = source_hash(sources)
    for path in sources.iterdir():
        if path.name not in kept:
            path.unlink()
    assert stale_digest(built, source_files(CSRC), sources) == ""


def test_no_source_folder_is_not_checked(tmp_path):
    assert stale_digest("0" * 16, source_files(CSRC), tmp_path / "absent") == ""


def test_an_engine_that_recorded_no_file_list_is_checked_against_any_sources(sources):
    assert stale_digest("0" * 16, [], sources) == source_hash(sources)


def test_the_sdist_manifest_takes_every_c_source_and_header():
    manifest = (ROOT / "MANIFEST.in").read_text()
    csrc = CSRC.relative_to(ROOT).as_posix()
    assert f"recursive-include {csrc} *.c *.h" in manifest


def test_ci_runs_the_readme_test_command_and_the_smoke_test_of_both_artefacts():
    """The README's test command is one line, and .ci/run runs exactly it; .ci/run also
    builds the wheel and the sdist and runs .ci/smoke.py on each."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    commands = [line for block in re.findall(r"```bash\n(.*?)```", readme, re.S)
                for line in block.splitlines() if " pytest" in line]
    assert len(commands) == 1
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    assert commands[0] in ci
    assert "python -m build" in "\n".join(ci) and any("smoke.py" in line for line in ci)
    assert (ROOT / ".ci" / "smoke.py").is_file()
