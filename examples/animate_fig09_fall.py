"""A stick-figure animation of the paper's Fig. 9 fall
=====================================================

A GIF of the Fig. 9 run (forward platform motion, case 2: falls). Not run when the
documentation is built.

Usage: python examples/animate_fig09_fall.py [OUTPUT_DIR]   (default: current directory)
"""

import sys
from pathlib import Path

from posturelab.animation import animate

from posturelab.scenarios import builtin_scenario


def main(out_dir: Path) -> Path:
    scenario = builtin_scenario("paper-forward-case2")
    result = scenario.run()
    return animate(result, scenario.body, out_dir / "fig09_fall.gif", fps=25, speed=0.5)


if __name__ == "__main__":
    print(main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")))
