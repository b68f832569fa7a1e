"""Options of a run that belong to the model, not to an engine: the foot, falls, the knee
(joint torque limits: :mod:`.limits`).

Both simulators take these frozen objects (validated on construction) and treat
them the same way; the events that enforce them are stated in :mod:`.events`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from .._validation import float_in_range
from ..errors import ParameterError
from .limits import torque_limit_array  # (its home is .limits; kept importable from here)

__all__ = [
    "BaseOfSupport",
    "FallCriteria",
    "KneeModel",
    "KneeMode",
    "FOOT_FROM_LITERATURE",
    "FOOT_LENGTH_FRACTION_OF_HEIGHT",
    "HEEL_FRACTION_OF_FOOT",
    "base_of_support_for_height",
    "torque_limit_array",
]

KneeMode = Literal["free", "locked", "stop"]

#: Winter (2009), Biomechanics and Motor Control of Human Movement, 4th ed., Fig. 4.1 / Table 4.1:
#: foot length = 0.152 × body height. [-]
FOOT_LENGTH_FRACTION_OF_HEIGHT = 0.152
#: Fraction of the foot length behind the ankle joint (heel side). Our assumption (the ankle
#: joint sits about a quarter of the foot length in front of the heel); configurable. [-]
HEEL_FRACTION_OF_FOOT = 0.25


@dataclass(frozen=True)
class BaseOfSupport:
    """Heel and toe positions relative to the ankle, along x.

    Parameters
    ----------
    heel : float
        Heel position, negative (behind the ankle). [m]
    toe : float
        Toe position, positive (in front of the ankle). [m]
    source : str
        Where the numbers come from.
    """

    heel: float
    toe: float
    source: str = "user"

    def __post_init__(self) -> None:
        heel = float_in_range("base of support heel [m]", self.heel, -1.0, 0.0,
                              include_high=False)
        toe = float_in_range("base of support toe [m]", self.toe, 0.0, 1.0, include_low=False)
        object.__setattr__(self, "heel", heel)
        object.__setattr__(self, "toe", toe)


def base_of_support_for_height(height: float) -> BaseOfSupport:
    """Heel and toe of a foot scaled to body height.

    Foot length 0.152 H (Winter 2009, Table 4.1 / Fig. 4.1, after Drillis and
    Contini); the ankle joint a quarter of the foot length in front of the
    heel (our assumption, stated in :data:`HEEL_FRACTION_OF_FOOT`).

    Parameters
    ----------
    height : float
        Body height H. [m]
    """
    h = float_in_range("height [m]", height, 0.5, 2.5, unit="m")
    foot = FOOT_LENGTH_FRACTION_OF_HEIGHT * h
    return BaseOfSupport(
        -HEEL_FRACTION_OF_FOOT * foot, (1 - HEEL_FRACTION_OF_FOOT) * foot,
        source=f"foot length 0.152 H (Winter 2009) for H = {h:g} m; ankle at 25 % of the foot",
    )


#: A foot for the paper's body, whose link lengths match a stature of about 1.65 m
#: (Winter's leg 0.246 H and thigh 0.245 H give 1.63 m and 1.68 m): heel −0.063 m, toe +0.188 m.
FOOT_FROM_LITERATURE = base_of_support_for_height(1.65)


@dataclass(frozen=True)
class FallCriteria:
    """When a run counts as a fall.

    Parameters
    ----------
    max_link_angle : float
        A fall when any |θ_i| exceeds this. [rad] (default π/3, 60°)
    base_of_support : BaseOfSupport or None
        If given, a fall also when the centre of gravity's horizontal
        projection leaves [heel, toe] (the foot would tip). None (default)
        is the paper's model: the foot never tips.
    centre_of_pressure : bool
        With a base of support, also a fall when the centre of pressure under
        the (massless) foot leaves [heel, toe]: the ankle moment exceeds what
        the ground can react and the foot starts to tip, even while the
        centre of gravity is still above the foot.
    """

    max_link_angle: float = math.pi / 3
    base_of_support: BaseOfSupport | None = None
    centre_of_pressure: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "max_link_angle", float_in_range(
            "max_link_angle [rad]", self.max_link_angle, 0.0, math.pi, include_low=False))
        if self.centre_of_pressure and self.base_of_support is None:
            raise ParameterError("centre_of_pressure needs a base_of_support (heel and toe)")


@dataclass(frozen=True)
class KneeModel:
    """How the knee behaves.

    Parameters
    ----------
    mode : {"free", "locked", "stop"}
        ``free``: the paper's unconstrained model. ``locked``: θ2 − θ1 stays at
        its initial value (θ1 = θ2 for an extended knee; two degrees of freedom
        for three links), as the paper assumes when the knee is extended.
        ``stop``: a hyper-extension stop; when θ2 − θ1 reaches ``stop_angle``
        the knee locks (a plastic impact) and it lets go when the muscles and
        gravity would flex it again.
    stop_angle : float
        Knee angle θ2 − θ1 at the hyper-extension stop (mode ``stop``). [rad]
    """

    mode: KneeMode = "free"
    stop_angle: float = 0.0

    def __post_init__(self) -> None:
        if self.mode not in ("free", "locked", "stop"):
            raise ParameterError(f"knee mode must be 'free', 'locked' or 'stop', got {self.mode!r}")
        object.__setattr__(self, "stop_angle",
                           float_in_range("knee stop_angle [rad]", self.stop_angle, -0.5, 0.5))
