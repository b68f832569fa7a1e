"""The model: body, muscle pairs, platform motion, equations of motion, kinematics.

Everything here is validated immutable parameters (:class:`Body`,
:class:`MuscleSet`, the disturbances) and pure functions over arrays (the
equation of motion in :mod:`.dynamics`, the centre of gravity in
:mod:`.kinematics`). The linear analysis and both simulators use this one
statement of the physics. Signs, frames and units: :mod:`posturelab.conventions`.
"""

from .anthropometry import body_from_anthropometry, lump
from .body import BODY_PRESETS, Body, BodyPreset, Segment, get_body, paper_body
from .dynamics import (
    angular_acceleration,
    gravity_vector,
    kinetic_energy,
    mass_matrix,
    platform_vector,
    potential_energy,
    state_derivative,
    velocity_step_response,
    velocity_terms,
)
from .kinematics import centre_of_gravity, centre_of_gravity_velocity, physiological_state
from .muscles import (
    DEFAULT_VISCOSITY_RATIO,
    PAPER_PAIR_NAMES,
    PAPER_PAIRS,
    STIFFNESS_CASES,
    TABLE_I_CITATION,
    MusclePair,
    MuscleSet,
    get_stiffness_case,
    joint_torques,
    pair_torques,
    paper_muscles,
)
from .platform import (
    CombinedDisturbance,
    Disturbance,
    HalfSinePulse,
    MeasuredProfile,
    NoDisturbance,
    RampAndHold,
    SumOfSines,
    VelocityStep,
    combine,
    read_profile_csv,
)
