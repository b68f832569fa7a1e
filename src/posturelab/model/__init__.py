"""The model: body, muscle pairs, platform motion, equations of motion, kinematics, options
and events.

Everything here is validated immutable parameters (:class:`~.body.Body`,
:class:`~.muscles.MuscleSet`, the disturbances of :mod:`.platform`, the options of
:mod:`.options`) and pure functions over arrays (the equation of motion in
:mod:`.dynamics`, the centre of gravity and pressure in :mod:`.kinematics`). The
linear analysis and both simulators use this one statement of the physics; the
event table of :mod:`.events` serves both simulators, and :mod:`.switched` states the
switched model of a run once (its inputs, right-hand side, event values, what a switch
does, the start): the reference engine evaluates it with numpy, and the compiled engine's
C is generated from the same formulas (``posturelab.simulation.compiled._codegen``). The
public names are exported by :mod:`posturelab` itself. Signs, frames and units:
:mod:`posturelab.conventions`.
"""

from .._lazy import submodule_getattr  # noqa: E402

# The anthropometric body presets (paper-1link, paper-2link, winter-…) register themselves in
# body.BODY_PRESETS when their module is imported. Python runs this file before any module of
# the package, so importing it here makes the presets whole whichever module is imported first,
# without body.py importing anthropometry.py (which imports body.py).
from . import anthropometry  # noqa: E402, F401

__getattr__ = submodule_getattr(__name__, __path__)
