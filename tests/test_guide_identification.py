"""The identification guide's Python runs as written (as the README's does, test_readme)."""

import re
import subprocess
import sys
import textwrap
from pathlib import Path

GUIDE = Path(__file__).resolve().parents[1] / "docs" / "guide" / "identification.rst"


def guide_python() -> str:
    """The guide's ``.. code-block:: python`` blocks, in order, as one program."""
    text = GUIDE.read_text(encoding="utf-8")
    blocks = re.findall(r"\.\. code-block:: python\n\n((?:(?:   .*)?\n)+)", text)
    return "\n".join(textwrap.dedent(b) for b in blocks)


def test_the_identification_guide_python_runs(tmp_path):
    code = guide_python()
    assert "fit_stiffness(" in code and "fit_frf(" in code
    check = ("\nassert fit.names == ('active_stiffness:ankle', 'active_viscosity:ankle', "
             "'feedback_delay'), fit.names\n")
    p = subprocess.run([sys.executable, "-c", code + check], cwd=tmp_path, capture_output=True,
                       text=True, timeout=600)
    assert p.returncode == 0, p.stderr
