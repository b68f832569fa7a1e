"""``python -m posturelab.simulation.compiled._codegen``: rewrite every generated file."""

import sys

from . import main

sys.exit(main())
