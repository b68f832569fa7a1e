"""Named feedback controllers from the literature, with their citations.

A controller preset gives, for a one-link body (the inverted pendulum about the ankle of
the identification literature), the intrinsic and the active (neural, delayed) ankle gains
as fractions of the body's load stiffness mgh [N·m/rad], the feedback delay and the
proprioceptive weight. :meth:`ControllerPreset.muscles` scales the gains to a body;
:meth:`ControllerPreset.run_options` gives ``feedback_delay`` and
``proprioceptive_weight`` for :func:`posturelab.simulate`. The paper's own model is the
intrinsic-only Table I (:func:`posturelab.paper_muscles`).

Parts of a published model that posturelab does not model (activation dynamics, slow
torque feedback) are left out and named in the preset's ``omitted``.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import ParameterError, UnknownNameError
from .body import Body
from .muscles import MusclePair, MuscleSet

__all__ = ["ControllerPreset", "CONTROLLERS", "get_controller"]


@dataclass(frozen=True)
class ControllerPreset:
    """A one-link ankle controller from the literature.

    Attributes
    ----------
    name : str
    citation : str
    intrinsic_stiffness : float
        Intrinsic ankle stiffness / mgh. [-]
    intrinsic_viscosity : float
        Intrinsic ankle viscosity / mgh. [s]
    active_stiffness : float
        Active (neural) stiffness K_P / mgh. [-]
    active_viscosity : float
        Active viscosity K_D / mgh. [s]
    feedback_delay : float
        τ. [s]
    proprioceptive_weight : float
        W. [-]
    omitted : str
        What of the published model is not modelled here.
    """

    name: str
    citation: str
    intrinsic_stiffness: float
    intrinsic_viscosity: float
    active_stiffness: float
    active_viscosity: float
    feedback_delay: float
    proprioceptive_weight: float
    omitted: str = ""

    def muscles(self, body: Body) -> MuscleSet:
        """The ankle pair for ``body`` (one link), gains scaled by its mgh [N·m/rad]."""
        if body.n_links != 1:
            raise ParameterError(
                f"controller {self.name!r} is for a one-link body (an inverted pendulum about "
                f"the ankle); this body has {body.n_links} links: use get_body('paper-1link') "
                "or a one-link body")
        mgh = body.load_stiffness
        pair = MusclePair("ankle", 0, 1, self.intrinsic_stiffness * mgh,
                          self.intrinsic_viscosity * mgh,
                          active_stiffness=self.active_stiffness * mgh,
                          active_viscosity=self.active_viscosity * mgh)
        return MuscleSet((pair,), 1)

    def run_options(self) -> dict:
        """``{"feedback_delay": τ [s], "proprioceptive_weight": W [-]}``."""
        return {"feedback_delay": self.feedback_delay,
                "proprioceptive_weight": self.proprioceptive_weight}


#: The presets by name.
CONTROLLERS: dict[str, ControllerPreset] = {
    "peterka-2002": ControllerPreset(
        name="peterka-2002",
        citation=("Peterka RJ (2002) Sensorimotor integration in human postural control. "
                  "J Neurophysiol 88:1097–1118; independent-channel model, round values "
                  "K_P ≈ 1.35 mgh, K_D ≈ 0.47 mgh·s, τ ≈ 0.15 s as summarised for the "
                  "Peterka 2002 / 2018 models"),
        intrinsic_stiffness=0.0, intrinsic_viscosity=0.0,
        active_stiffness=1.35, active_viscosity=0.47, feedback_delay=0.15,
        proprioceptive_weight=1.0,
        omitted="the slow torque feedback; the passive stiffness (small) is taken as 0",
    ),
    "icm-pmc5664365": ControllerPreset(
        name="icm-pmc5664365",
        citation=("Default parameters of the independent-channel stance model, PMC5664365 "
                  "Table 1 (body J = 66 kg·m², m = 75 kg, h = 0.83 m after Fonteyn et al. "
                  "2010; K = 40.5 N·m/rad, B = 68.8 N·m·s/rad, K_P = 943.9 N·m/rad, "
                  "K_D = 313.5 N·m·s/rad, τ_D = 0.097 s, W_P = 0.8), gains / mgh"),
        intrinsic_stiffness=40.5 / (75 * 9.81 * 0.83),
        intrinsic_viscosity=68.8 / (75 * 9.81 * 0.83),
        active_stiffness=943.9 / (75 * 9.81 * 0.83),
        active_viscosity=313.5 / (75 * 9.81 * 0.83),
        feedback_delay=0.097, proprioceptive_weight=0.8,
        omitted="activation dynamics (16.8 rad/s, damping 0.99) and force feedback",
    ),
}


def get_controller(name: str) -> ControllerPreset:
    """The preset ``name``.

    Raises
    ------
    UnknownNameError
        Naming the known presets.
    """
    try:
        return CONTROLLERS[str(name).strip().lower()]
    except KeyError:
        raise UnknownNameError(f"unknown controller {name!r}; known controllers: "
                               f"{', '.join(CONTROLLERS)}") from None
