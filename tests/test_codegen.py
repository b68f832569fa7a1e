"""The compiled engine's generated files: each is what the generator writes now from the one
statement of the model (regenerate them all with
``python -m posturelab.simulation.compiled._codegen``), and each says so in its first lines."""

import pytest

pytest.importorskip("sympy")

from posturelab.simulation.compiled import _codegen  # noqa: E402

OUTPUTS = _codegen.outputs()


@pytest.mark.parametrize("path", list(OUTPUTS), ids=lambda p: p.name)
def test_generated_file_is_up_to_date(path):
    assert path.read_text(encoding="utf-8") == OUTPUTS[path](), (
        f"{path.name} is stale: run python -m posturelab.simulation.compiled._codegen")


@pytest.mark.parametrize("path", list(OUTPUTS), ids=lambda p: p.name)
def test_generated_file_says_so_in_its_first_lines(path):
    head = "\n".join(path.read_text(encoding="utf-8").splitlines()[:3])
    assert "GENERATED, do not edit" in head


def test_every_c_source_is_generated_or_written_by_hand_not_both():
    """The generated C files are the ones the generator lists; no hand-written file says it
    is generated."""
    csrc = _codegen.CSRC
    generated = {p.name for p in OUTPUTS if p.parent == csrc}
    for path in sorted(csrc.iterdir()):
        says = "GENERATED, do not edit" in "\n".join(path.read_text(encoding="utf-8")
                                                      .splitlines()[:3])
        assert says == (path.name in generated), path.name
