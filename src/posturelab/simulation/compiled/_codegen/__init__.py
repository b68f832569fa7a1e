"""The code generator of the compiled engine (a development tool: it needs sympy).

``python -m posturelab.simulation.compiled._codegen`` rewrites every generated file from the
one statement of the model in :mod:`posturelab.model` (through the symbolic specification of
:mod:`.spec`) and the codes of :mod:`.codes`; a test regenerates each and compares. The
generated files are committed, so that neither the installed package nor its build needs
sympy. Each says so in its first lines.

========================  =====================================================================
``csrc/pl_model.c``       inputs, right-hand side for any N, knee impact, event values
                          (:mod:`.model_c`), torque feedback filters (:mod:`.filters_c`)
``csrc/pl_rhs_small.c``   straight-line right-hand sides for N = 1, 2, 3 (:mod:`.rhs_small`)
``csrc/pl_model.h``       the structs of a run, a batch and the model, the rotation series,
                          the prototypes (:mod:`.headers`)
``csrc/pl_codes.h``       the C enums (:mod:`.codes`)
``csrc/pl_radau.h``       scipy's constants of Radau IIA (:mod:`.radau_c`)
``_layout.py``            the same codes for Python (:mod:`.codes`)
========================  =====================================================================
"""

from __future__ import annotations

import sys
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent
CSRC = PACKAGE / "csrc"
#: The file the small-N generator writes (kept for its own test).
TARGET = CSRC / "pl_rhs_small.c"


def outputs() -> dict[Path, object]:
    """Each generated file and the function that returns its text."""
    from . import codes, headers, model_c, radau_c, rhs_small

    return {CSRC / "pl_model.c": model_c.generate, TARGET: rhs_small.generate,
            CSRC / "pl_model.h": lambda: headers.header(model_c.generate(), rhs_small.generate()),
            CSRC / "pl_codes.h": codes.header,
            CSRC / "pl_radau.h": radau_c.header, PACKAGE / "_layout.py": codes.layout}


def generate() -> str:
    """The text of ``csrc/pl_rhs_small.c``."""
    from . import rhs_small

    return rhs_small.generate()


def main() -> int:
    """Write every generated file."""
    for path, make in outputs().items():
        path.write_text(make(), encoding="utf-8")
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
