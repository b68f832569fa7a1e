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

Every number of a preset carries its provenance (:class:`Provenance`, in ``provenance``):
the value as the source prints it, with its unit and where (table or figure), or that it is
posturelab's own assumption. :meth:`ControllerPreset.provenance_text` says it in words;
``--controller``'s help and the reproduction report print it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..errors import ParameterError, lookup
from .body import Body
from .muscles import MusclePair, MuscleSet

__all__ = ["AnkleController", "ControllerPreset", "Provenance", "CONTROLLERS", "get_controller",
           "MultiJointPreset", "MULTIJOINT_CONTROLLERS", "get_multijoint_controller"]


#: The preset fields that carry a number, in print order, with the symbol used in words.
PRESET_NUMBERS = (("intrinsic_stiffness", "K/mgh"), ("intrinsic_viscosity", "B/mgh"),
                  ("active_stiffness", "K_P/mgh"), ("active_viscosity", "K_D/mgh"),
                  ("feedback_delay", "τ"), ("proprioceptive_weight", "W"))


@dataclass(frozen=True)
class Provenance:
    """Where one number of a controller preset comes from.

    Attributes
    ----------
    where : str or None
        The place in the source (e.g. "PMC5664365 Table 1, K_P"); None when the number is
        posturelab's assumption.
    source_value : float or None
        The number as the source prints it (in ``source_unit``); None for an assumption.
    source_unit : str
        Its unit as printed.
    note : str
        How the preset's number follows from it, or why posturelab assumed it.
    """

    where: str | None
    source_value: float | None = None
    source_unit: str = ""
    note: str = ""

    @property
    def from_source(self) -> bool:
        """True when the number is the source's (converted), False for an assumption."""
        return self.where is not None

    def text(self, symbol: str, value: float) -> str:
        """One phrase: the symbol, the preset's value and where it comes from."""
        if not self.from_source:
            return f"{symbol} = {value:.4g}: posturelab's assumption ({self.note})"
        given = ("" if self.source_value is None else
                 f" = {self.source_value:g}{' ' + self.source_unit if self.source_unit else ''}")
        note = f"; {self.note}" if self.note else ""
        return f"{symbol} = {value:.4g}: {self.where}{given}{note}"



@dataclass(frozen=True)
class AnkleController:
    """A named one-link ankle controller: its gains as fractions of the body's load stiffness
    mgh, its delay and proprioceptive weight, each number with its :class:`Provenance`
    (:class:`ControllerPreset`; the stepping study's populations).

    Attributes
    ----------
    name : str
    intrinsic_stiffness : float
        Intrinsic (undelayed) ankle stiffness / mgh. [-]
    intrinsic_viscosity : float
        Intrinsic ankle viscosity / mgh. [s]
    active_stiffness : float
        Active (neural, delayed) stiffness K_P / mgh. [-]
    active_viscosity : float
        Active viscosity K_D / mgh. [s]
    feedback_delay : float
        τ of the active part. [s]
    proprioceptive_weight : float
        W (no effect without a tilt). [-]
    provenance : tuple of (str, Provenance)
        For each numeric field, where it comes from (a keyword).
    """

    name: str
    intrinsic_stiffness: float
    intrinsic_viscosity: float
    active_stiffness: float
    active_viscosity: float
    feedback_delay: float
    proprioceptive_weight: float
    provenance: tuple[tuple[str, Provenance], ...] = field(default=(), kw_only=True)

    def provenance_of(self, field_name: str) -> Provenance:
        """The :class:`Provenance` of one numeric field."""
        return dict(self.provenance)[field_name]

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


@dataclass(frozen=True)
class ControllerPreset(AnkleController):
    """A one-link ankle controller from the literature (the numbers of
    :class:`AnkleController`).

    Attributes
    ----------
    citation : str
    omitted : str
        What of the published model is not modelled here.
    """

    citation: str
    omitted: str = ""

    def provenance_text(self) -> str:
        """Which numbers come from the source (and where) and which are posturelab's, in
        words (one sentence per number)."""
        return "; ".join(self.provenance_of(name).text(symbol, getattr(self, name))
                         for name, symbol in PRESET_NUMBERS) + "."

    def assumed(self) -> tuple[str, ...]:
        """The symbols of the numbers that are posturelab's assumptions."""
        return tuple(symbol for name, symbol in PRESET_NUMBERS
                     if not self.provenance_of(name).from_source)


#: The body of PMC5664365 Table 1 (after Fonteyn et al. 2010): m [kg], h [m], g [m/s²].
PMC5664365_BODY = (75.0, 0.83, 9.81)
_MGH = PMC5664365_BODY[0] * PMC5664365_BODY[2] * PMC5664365_BODY[1]  # [N·m/rad]


def _table1(symbol: str, value: float, unit: str, per_mgh: bool = True) -> Provenance:
    note = (f"divided by the table's m g h = 75 × 9.81 × 0.83 = {_MGH:.2f} N·m/rad"
            if per_mgh else "")
    return Provenance(f"PMC5664365 Table 1, {symbol}", value, unit, note)


def _by_name(*presets) -> dict:
    """The presets keyed by their names."""
    return {p.name: p for p in presets}


#: The paper the round values of the Peterka 2002 / 2018 models are after.
_PETERKA_2002 = ("Peterka RJ (2002) Sensorimotor integration in human postural control. "
                 "J Neurophysiol 88:1097–1118")
#: A round value summarised for the Peterka 2002 / 2018 models that posturelab has not found
#: in a table of :data:`_PETERKA_2002`: posturelab's reading.
_PETERKA_ROUND = "a round value after Peterka 2002, not found in its tables"

#: The presets by name.
CONTROLLERS: dict[str, ControllerPreset] = _by_name(
    ControllerPreset(
        name="peterka-2002",
        citation=(_PETERKA_2002 + "; independent-channel model, round values "
                  "K_P ≈ 1.35 mgh, K_D ≈ 0.47 mgh·s, τ ≈ 0.15 s as summarised for the "
                  "Peterka 2002 / 2018 models (not checked against the paper's tables); "
                  "W = 1 and no intrinsic impedance are posturelab's choices"),
        intrinsic_stiffness=0.0, intrinsic_viscosity=0.0,
        active_stiffness=1.35, active_viscosity=0.47, feedback_delay=0.15,
        proprioceptive_weight=1.0,
        omitted="the slow torque feedback; the passive stiffness (small) is taken as 0",
        provenance=(
            ("intrinsic_stiffness", Provenance(None, note="the passive stiffness, small in "
                                               "the model, taken as 0")),
            ("intrinsic_viscosity", Provenance(None, note="the passive damping taken as 0")),
            ("active_stiffness", Provenance(None, note=_PETERKA_ROUND)),
            ("active_viscosity", Provenance(None, note=_PETERKA_ROUND)),
            ("feedback_delay", Provenance(None, note=_PETERKA_ROUND)),
            ("proprioceptive_weight", Provenance(
                None, note="proprioception only (eyes closed on a level surface); the "
                "source's weights depend on the stimulus amplitude and condition")),
        ),
    ),
    ControllerPreset(
        name="icm-pmc5664365",
        citation=("Default parameters of the independent-channel stance model, PMC5664365 "
                  "Table 1 (body J = 66 kg·m², m = 75 kg, h = 0.83 m after Fonteyn et al. "
                  "2010; K = 40.5 N·m/rad, B = 68.8 N·m·s/rad, K_P = 943.9 N·m/rad, "
                  "K_D = 313.5 N·m·s/rad, τ_D = 0.097 s, W_P = 0.8), gains / mgh"),
        intrinsic_stiffness=40.5 / _MGH,
        intrinsic_viscosity=68.8 / _MGH,
        active_stiffness=943.9 / _MGH,
        active_viscosity=313.5 / _MGH,
        feedback_delay=0.097, proprioceptive_weight=0.8,
        omitted="activation dynamics (16.8 rad/s, damping 0.99) and force feedback",
        provenance=(
            ("intrinsic_stiffness", _table1("K", 40.5, "N·m/rad")),
            ("intrinsic_viscosity", _table1("B", 68.8, "N·m·s/rad")),
            ("active_stiffness", _table1("K_P", 943.9, "N·m/rad")),
            ("active_viscosity", _table1("K_D", 313.5, "N·m·s/rad")),
            ("feedback_delay", _table1("τ_D", 0.097, "s", per_mgh=False)),
            ("proprioceptive_weight", _table1("W_P", 0.8, "", per_mgh=False)),
        ),
    ),
)


def get_controller(name: str) -> ControllerPreset:
    """The preset ``name``; an unknown name raises UnknownNameError listing the known ones."""
    return lookup(CONTROLLERS, name, "controller", "known controllers")


@dataclass(frozen=True)
class MultiJointPreset:
    """A multi-joint controller for an N-link body, designed rather than tuned: the weights of
    an LQR design (:mod:`posturelab.linear.lqr`, Bryson's rule) and the pairs acting beside it.

    Attributes
    ----------
    name : str
    citation : str
    angle_limit : float
        θ_max of Bryson's rule, every link. [rad]
    rate_limit : float
        ω_max, every link. [rad/s]
    ankle_effort_centre_of_pressure : float
        The ankle's τ_max is m g times this: the centre of pressure's reach in front of the
        ankle. [m]; None: the foot of :data:`posturelab.model.options.FOOT_FROM_LITERATURE`.
    other_effort_factor : float
        Every other joint's τ_max is this times the ankle's. [-]
    intrinsic_stiffness : tuple of 3 float
        The intrinsic stiffness of the ankle's, the middle joints' (knee, …) and the top
        joint's (hip) pair / (the body's m g h). [-]
    intrinsic_viscosity : tuple of 3 float
        Their viscosity / m g h, in the same order. [s]
    feedback_delay : float
        τ of the controller. [s]
    knee : {"free", "locked"}
        The knee the design assumes (and the runs should use). [-]
    joint_angle_limit : float
        φ_max of Bryson's rule on each joint angle above the ankle (the hip's θ3 − θ_leg):
        a weight that keeps the body straight, the ankle strategy, while the ankle is not
        limited. [rad]
    provenance : tuple of (str, Provenance)
    """

    name: str
    citation: str
    angle_limit: float
    rate_limit: float
    other_effort_factor: float
    intrinsic_stiffness: tuple
    intrinsic_viscosity: tuple
    feedback_delay: float
    ankle_effort_centre_of_pressure: float | None = None
    knee: str = "free"
    joint_angle_limit: float = float("inf")
    provenance: tuple[tuple[str, Provenance], ...] = ()

    def provenance_text(self) -> str:
        """Where each number comes from, in words."""
        def shown(name: str, p: Provenance) -> str:
            value = getattr(self, name)
            if isinstance(value, tuple):
                return f"{name} = {', '.join(f'{v:g}' for v in value)}: {p.note}"
            return p.text(name, value)

        return "; ".join(shown(name, p) for name, p in self.provenance) + "."

    def effort_limits(self, body: Body):
        """τ_max per joint: the ankle's m g x_toe, the others ``other_effort_factor`` times
        it. [N·m]"""
        import numpy as np

        from .options import FOOT_FROM_LITERATURE

        reach = (FOOT_FROM_LITERATURE.toe if self.ankle_effort_centre_of_pressure is None
                 else self.ankle_effort_centre_of_pressure)
        ankle = body.total_mass * body.gravity * reach
        out = np.full(body.n_links, ankle * self.other_effort_factor)
        out[0] = ankle
        return out

    def muscles(self, body: Body) -> MuscleSet:
        """One intrinsic pair per joint (ankle, knee, …, hip: the top joint), gains
        ``intrinsic_stiffness`` × mgh [N·m/rad] and ``intrinsic_viscosity`` × mgh
        [N·m·s/rad]."""
        from .muscles import joint_pair_names

        n, mgh = body.n_links, body.load_stiffness
        names = joint_pair_names(n)

        def part(values, j):
            return values[0] if j == 0 else values[2] if j == n - 1 else values[1]

        return MuscleSet(tuple(MusclePair(nm, j, j + 1, part(self.intrinsic_stiffness, j) * mgh,
                                          part(self.intrinsic_viscosity, j) * mgh)
                               for j, nm in enumerate(names)), n)


_OURS = "posturelab's choice"

#: Multi-joint presets by name.
MULTIJOINT_CONTROLLERS: dict[str, MultiJointPreset] = _by_name(
    MultiJointPreset(
        name="multijoint-default",
        citation=("LQR full-state feedback of the chain about upright after Kuo AD (1995) An "
                  "optimal control model for analyzing human postural balance, IEEE Trans "
                  "Biomed Eng 42:87–101, and Park S, Horak FB, Kuo AD (2004) Postural feedback "
                  "responses scale with biomechanical constraints in human standing, Exp Brain "
                  "Res 154:417–427, doi:10.1007/s00221-003-1674-3 (delayed full-state "
                  "feedback fitted to responses to support translations); weights by "
                  "Bryson's rule (Bryson AE, Ho YC 1975, Applied Optimal Control) with the "
                  "ankle's effort bounded by the foot; every number is posturelab's choice, "
                  "not a fitted value"),
        angle_limit=1.0, rate_limit=float("inf"), other_effort_factor=0.25,
        intrinsic_stiffness=(0.1, 0.1, 0.05), intrinsic_viscosity=(0.05, 0.05, 0.025),
        feedback_delay=0.08,
        knee="locked", joint_angle_limit=float("inf"),
        provenance=(
            ("angle_limit", Provenance(None, note=f"{_OURS}: a cheap-state, costly-effort design "
                                       "(1 rad), so that the undelayed LQR keeps a delay margin "
                                       "above the delay (0.095 s; 0.1 rad gives about 0.03 s)")),
            ("rate_limit", Provenance(None, note=f"{_OURS}: rates not weighted")),
            ("other_effort_factor", Provenance(None, note=f"{_OURS}: the hip's τ_max a quarter "
                                               "of the foot-limited ankle's (larger factors "
                                               "lower the delay margin toward the delay)")),
            ("intrinsic_stiffness", Provenance(None, note=f"{_OURS}: small intrinsic "
                                               "stiffness, 10 % of mgh at ankle and knee, 5 % "
                                               "at the hip")),
            ("intrinsic_viscosity", Provenance(None, note=f"{_OURS}: 5 % and 2.5 % of mgh "
                                               "[s]")),
            ("feedback_delay", Provenance(None, note=f"{_OURS}: 0.08 s, near the ~0.1 s latency "
                                          "of automatic postural responses, below the design's "
                                          "delay margin")),
        ),
    ),
)


def get_multijoint_controller(name: str) -> MultiJointPreset:
    """The multi-joint preset ``name``; an unknown name lists the known ones."""
    return lookup(MULTIJOINT_CONTROLLERS, name, "multi-joint controller")
