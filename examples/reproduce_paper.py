"""Regenerate the whole paper as an HTML report
=============================================

Table II, J⁻¹H, Figs. 3–10 and the errata. Not run when the documentation is built.

The same as ``posturelab reproduce --out OUTPUT_DIR``.

Usage: python examples/reproduce_paper.py [OUTPUT_DIR]   (default: ./paper-out)
"""

import sys
from pathlib import Path

from posturelab.report import reproduce_paper


def main(out_dir: Path) -> Path:
    report = reproduce_paper(out_dir, progress=lambda i, n, msg: print(f"[{i}/{n}] {msg}"))
    print(report.summary())
    return report.index_html


if __name__ == "__main__":
    print(main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("paper-out")))
