"""The populations, the platform protocol and the published thresholds of the stepping study
(:mod:`posturelab.studies.stepping`), each number with where it comes from.

Every number of a :class:`Population` carries a
:class:`~posturelab.model.controllers.Provenance`: the place in its source and the value as
printed, or that it is posturelab's own assumption (and why).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..errors import lookup
from ..model.controllers import AnkleController, Provenance, get_controller
from ..model.platform import RampAndHold

__all__ = ["Population", "POPULATIONS", "get_population", "PlatformProtocol", "PROTOCOL",
           "PublishedThreshold", "PUBLISHED", "KOUSHYAR_2019", "SIMONEAU_2005", "KING_1994",
           "PDS_2017",
           "LIN_WOOLLACOTT_2002", "LEGS"]

#: The study compared with (its abstract is what posturelab could read; see PROTOCOL).
KOUSHYAR_2019 = ("Koushyar H, Bieryla KA, Nussbaum MA, Madigan ML (2019) Age-related strength "
                 "loss affects non-stepping balance recovery. PLoS ONE 14(1):e0210049, "
                 "doi:10.1371/journal.pone.0210049, PMC6338353")
#: Isometric plantarflexion strength, young and elderly men.
SIMONEAU_2005 = ("Muscular performances at the ankle joint in young and elderly men, HAL "
                 "inserm-00080421 (abstract): maximal isometric plantarflexion 132 N·m (11 "
                 "men, mean 24 y) vs 80 N·m (12 men, mean 77 y); Simoneau, Martin & Van "
                 "Hoecke, J Gerontol A 2005 (authors and journal as posturelab recalls them, "
                 "not checked against the stored record)")
#: Postural response latencies with age (a direction, not a number).
LIN_WOOLLACOTT_2002 = ("Postural muscle responses following changing balance threats in "
                       "young, stable older, and unstable older adults. J Mot Behav 2002 "
                       "34(1):37–44, PMID 11880248 (abstract): longer onset latencies in the "
                       "older groups; Lin & Woollacott (authors as posturelab recalls them)")
#: The functional base of support by age.
KING_1994 = ("King MB, Judge JO, Wolfson L (1994) Functional base of support decreases with "
             "age. J Gerontol 49(6):M258–M263 (abstract; journal and pages as posturelab "
             "recalls them): the anterior–posterior share of the foot's length used in "
             "maximal sustained forward and backward leaning, 0.60 ± 0.07 under 60 years and "
             "0.42 ± 0.12 at 60 and over (113 adults, 20–91 y); forward and backward lean 66 % "
             "and 34 % of it")
#: A quiet-standing recording: where the centre of gravity stands over the ankle.
PDS_2017 = ("dos Santos DA, Fukuchi CA, Fukuchi RK, Duarte M (2017) A data set with kinematic "
            "and ground reaction forces of human balance. PeerJ 5:e3626, "
            "doi:10.7717/peerj.3626 (CC BY 4.0; one subject's 60 s of quiet standing as "
            "redistributed in BMClab/BMC data/postureData.txt): the centre of gravity "
            "4.17 ± 0.27° in front of the lateral malleoli over the 60 s (posturelab's "
            "computation from the recording)")
#: The model's ankle is both legs together: strengths measured on one leg are doubled. [-]
LEGS = 2

_ICM = get_controller("icm-pmc5664365")
_ICM_NUMBERS = ("intrinsic_stiffness", "intrinsic_viscosity", "active_stiffness",
                "active_viscosity", "proprioceptive_weight")


@dataclass(frozen=True)
class Population(AnkleController):
    """A group of subjects: the controller, the delay (the numbers of
    :class:`~posturelab.model.controllers.AnkleController`, each with its provenance) and the
    strength of its ankles.

    Attributes
    ----------
    description : str
    plantarflexion_strength : float
        Maximal isometric plantarflexion moment of one ankle. [N·m]
    functional_base_of_support : float
        F, the share of the foot's length over which the centre of pressure can be held:
        from the quiet-standing centre of pressure, F × share forward and F × (1 − share)
        back (:meth:`functional_foot`). [-]
    forward_share : float
        The forward part of F. [-]
    stance_lean : float
        The centre of gravity's angle in front of the ankle in quiet standing: the tonic
        plantarflexion moment m g l sin(lean) it needs is not available to the
        response. [rad]
    """

    description: str
    plantarflexion_strength: float
    functional_base_of_support: float
    forward_share: float
    stance_lean: float

    @property
    def ankle_strength(self) -> float:
        """Plantarflexion strength of both ankles, :data:`LEGS` × one ankle's. [N·m]"""
        return LEGS * self.plantarflexion_strength

    def provenance_text(self) -> str:
        """Where each number comes from, one phrase per number."""
        return "; ".join(self.provenance_of(name).text(name, getattr(self, name))
                         for name, _ in self.provenance) + "."

    def functional_foot(self, height: float) -> tuple[float, float]:
        """(heel, toe): the functional base of support from the quiet-standing centre of
        pressure, −F (1 − share) L and F share L, with the foot's length L = 0.152 × height
        (Winter 2009, :data:`posturelab.model.options.FOOT_LENGTH_FRACTION_OF_HEIGHT`). [m]"""
        from ..model.options import FOOT_LENGTH_FRACTION_OF_HEIGHT

        span = self.functional_base_of_support * FOOT_LENGTH_FRACTION_OF_HEIGHT * height
        return -(1.0 - self.forward_share) * span, self.forward_share * span


def _icm(field_name: str) -> Provenance:
    """The icm-pmc5664365 preset's provenance of a gain, for both populations."""
    p = _ICM.provenance_of(field_name)
    return Provenance(p.where, p.source_value, p.source_unit,
                      (p.note + "; " if p.note else "") + "the same for both populations "
                      "(posturelab's assumption: no age-specific gains used)")


_FORWARD_SHARE = Provenance(
    "King et al. 1994 abstract, forward lean", 66.0, "% of the functional base of support",
    "read as the forward lean's distance from the quiet-standing centre of pressure, the "
    "backward lean's 34 % the rest (posturelab's reading of the abstract); the same at "
    "every age")
_STANCE_LEAN = Provenance(
    "the PDS recording (dos Santos et al. 2017), one subject", 4.17, "°",
    "the centre of gravity's mean angle in front of the lateral malleoli, taken for both "
    "populations (posturelab's choice: one subject, not a group mean)")

_YOUNG = Population(
    name="young", description="young adults (20–30 y, as in Koushyar et al. 2019)",
    **{k: getattr(_ICM, k) for k in _ICM_NUMBERS},
    feedback_delay=_ICM.feedback_delay,
    plantarflexion_strength=132.0,
    functional_base_of_support=0.60, forward_share=0.66, stance_lean=math.radians(4.17),
    provenance=(
        *((k, _icm(k)) for k in _ICM_NUMBERS),
        ("feedback_delay", _ICM.provenance_of("feedback_delay")),
        ("functional_base_of_support", Provenance(
            "King et al. 1994 abstract, subjects under 60", 0.60, "of foot length",
            "the group mean (± 0.07); Koushyar's young were 20–30 y")),
        ("forward_share", _FORWARD_SHARE),
        ("stance_lean", _STANCE_LEAN),
        ("plantarflexion_strength", Provenance(
            "HAL inserm-00080421 abstract (Simoneau et al. 2005), young men", 132.0, "N·m",
            f"one ankle's maximal isometric plantarflexion; doubled for the two ankles of the "
            f"model's one link ({LEGS} legs: posturelab's choice)")),
    ),
)

#: The older group's delay: the young one plus this. [s] posturelab's assumption.
OLDER_EXTRA_DELAY = 0.020

_OLDER = replace(
    _YOUNG, name="older", description="older adults (70–80 y, as in Koushyar et al. 2019)",
    feedback_delay=_YOUNG.feedback_delay + OLDER_EXTRA_DELAY,
    plantarflexion_strength=80.0, functional_base_of_support=0.42,
    provenance=(
        *((k, _icm(k)) for k in _ICM_NUMBERS),
        ("functional_base_of_support", Provenance(
            "King et al. 1994 abstract, subjects 60 and over", 0.42, "of foot length",
            "the group mean (± 0.12); Koushyar's older were 70–80 y (King: −16 % a decade "
            "after 60, so a 75-year-old may use less)")),
        ("forward_share", _FORWARD_SHARE),
        ("stance_lean", _STANCE_LEAN),
        ("feedback_delay", Provenance(None, note=(
            f"the young delay (PMC5664365 Table 1, τ_D = 0.097 s) plus "
            f"{OLDER_EXTRA_DELAY * 1000:g} ms; older adults' postural responses start later "
            "(J Mot Behav 2002 34:37, PMID 11880248), but the 20 ms is posturelab's"))),
        ("plantarflexion_strength", Provenance(
            "HAL inserm-00080421 abstract (Simoneau et al. 2005), elderly men", 80.0, "N·m",
            f"one ankle's maximal isometric plantarflexion; doubled for the two ankles "
            f"({LEGS} legs: posturelab's choice)")),
    ),
)

#: The populations by name.
POPULATIONS: dict[str, Population] = {"young": _YOUNG, "older": _OLDER}


def get_population(name: str) -> Population:
    """The population ``name``.

    Raises
    ------
    UnknownNameError
        Naming the known populations.
    """
    return lookup(POPULATIONS, name, "population", "known populations")


@dataclass(frozen=True)
class PlatformProtocol:
    """The platform moves of a threshold search and the search itself.

    Attributes
    ----------
    name, citation : str
    move_duration : float
        T: each move is a ramp-and-hold of displacement D over T (one sine cycle of
        acceleration, peak velocity 2D/T, peak acceleration 2πD/T²). [s]
    settle_time : float
        Simulated time after the move. [s]
    increment : float
        Step of the ascending series of displacements. [m]
    tolerance : float
        Width of the final bracket. [m]
    largest : float
        Largest displacement tried. [m]
    """

    name: str
    citation: str
    move_duration: float
    settle_time: float
    increment: float
    tolerance: float
    largest: float

    def disturbance(self, displacement: float) -> RampAndHold:
        """The move of ``displacement`` (signed: negative is backward). [m]"""
        return RampAndHold(displacement, self.move_duration)


#: The protocol compared with. The stored copy of PMC6338353 that posturelab could read holds
#: its abstract only (a backward support-surface displacement; the largest displacement
#: withstood without stepping; 5 young adults of 20–30 y, 6 older adults of 70–80 y); its
#: platform's displacement profile, the participants' heights and masses and how the
#: displacement was increased were not available. The move's shape (a smooth ramp-and-hold),
#: its duration T = 0.5 s and the 1 cm ascending series are posturelab's assumptions.
PROTOCOL = PlatformProtocol(
    name="koushyar-2019-assumed",
    citation=(KOUSHYAR_2019 + "; the move's shape and duration (ramp-and-hold over 0.5 s) "
              "and the 1 cm ascending series are posturelab's assumptions, the paper's "
              "methods not having been available"),
    move_duration=0.5, settle_time=3.0, increment=0.01, tolerance=0.001, largest=0.6,
)


@dataclass(frozen=True)
class PublishedThreshold:
    """A published largest translation without a step.

    Attributes
    ----------
    mean, sd : float
        Group mean and standard deviation as printed. [m]
    n : int
        Subjects in the group. [-]
    source : str
        The citation and where in it.
    """

    mean: float
    sd: float
    n: int
    source: str


#: Published thresholds by (population, direction): Koushyar et al. 2019's abstract,
#: "11.8±2.1 cm" (older) and "16.2±2.6 cm" (young), backward.
PUBLISHED: dict[tuple[str, str], PublishedThreshold] = {
    ("young", "backward"): PublishedThreshold(0.162, 0.026, 5, KOUSHYAR_2019 + ", abstract"),
    ("older", "backward"): PublishedThreshold(0.118, 0.021, 6, KOUSHYAR_2019 + ", abstract"),
}
