"""The rows of a gains array, by name.

The pair gains of a run (:func:`posturelab.model.muscles.feedback_gains`) and the tilt gains
(:func:`posturelab.model.tilt.tilt_pair_gains`) are arrays of shape (..., 4, P): four rows of
one gain per pair, by when the gain acts. Code indexes them with these names, never with a
bare position.
"""

from __future__ import annotations

__all__ = ["IMMEDIATE_STIFFNESS", "IMMEDIATE_VISCOSITY", "DELAYED_STIFFNESS",
           "DELAYED_VISCOSITY", "GAIN_ROWS"]

#: Row of the stiffness acting at once on the state (the intrinsic part). [N·m/rad]
IMMEDIATE_STIFFNESS = 0
#: Row of the viscosity acting at once. [N·m·s/rad]
IMMEDIATE_VISCOSITY = 1
#: Row of the stiffness acting on the state τ earlier (the delayed, active part). [N·m/rad]
DELAYED_STIFFNESS = 2
#: Row of the delayed viscosity. [N·m·s/rad]
DELAYED_VISCOSITY = 3
#: The row names in order.
GAIN_ROWS = ("immediate_stiffness", "immediate_viscosity", "delayed_stiffness",
             "delayed_viscosity")
