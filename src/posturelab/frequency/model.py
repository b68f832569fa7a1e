"""The linearised model's frequency response, exact (the delay as e^{−sτ}, no Padé).

About upright with the platform at rest, for s = 2πi f (conventions.md), the frequency
response of the one linear system
(:meth:`posturelab.linear.system.LinearSystem.frequency_response`):

    Δ(s) Θ(s) = b(s) u(s),   Δ(s) = s² J0 − g A + K_i + s L_i + (K_a + s L_a) e^{−sτ}

with the input u either

* the surface tilt α [rad]: b(s) = −Eᵀ[f ∘ (k_i + s l_i) + W f ∘ (k_a + s l_a) e^{−sτ}],
  f the pairs that span the foot, W the proprioceptive weight; or
* the platform displacement x_d [m]: b(s) = −a s² (a the gravity coefficients: the
  horizontal platform acceleration ẍ_d a); or
* the visual-scene tilt v [rad] (``visual-tilt``): b(s) = −Eᵀ[W_v f ∘ (k_a + s l_a) e^{−sτ}],
  W_v the visual weight: the scene acts through the active feedback only (Peterka 2002,
  J Neurophysiol 88:1097, independent channels). For one link with C(s) = (K_a + s L_a)e^{−sτ}
  the two tilt FRFs are H_α = (K_i + s L_i + W_p C)/D and H_v = W_v C/D,
  D = J s² − mgh + K_i + s L_i + C.

The output is y = c·Θ: the centre-of-mass angle Σ a_i θ_i / Σ a_i (``com_angle``), a link
angle (``theta1`` …) or a joint angle (``ankle_angle`` = θ1, ``knee_angle`` = θ2 − θ1, …).
Tilt FRFs are reported in the literature's sign, H = −y/α, so that a body that follows the
surface (θ = −α: perpendicular to it) has H = 1 (and H = −y/v for the scene, positive
toes-up like the surface: a body that follows the scene has H = 1); translation FRFs are
H = y/x_d [rad/m].
The gains split as :func:`posturelab.model.muscles.feedback_gains` states (without active
gains the whole feedback is delayed, and W applies to it).

With torque feedback (Peterka 2002; docs/design.md, "Torque feedback") the delayed part, in
Δ(s) and in b(s), is multiplied by g(s) = (τ_t s + 1)/(τ_t s + 1 − K_t): the active torque
fed back positively through K_t/(τ_t s + 1)
(:meth:`posturelab.linear.system.LinearSystem.torque_feedback_factor`).
"""

from __future__ import annotations

import numpy as np

from .._validation import finite_array
from ..errors import ParameterError, UnknownNameError
from ..linear.system import INPUTS, linear_system
from ..model.body import Body
from ..model.muscles import MuscleSet
from ..parameters import QUANTITIES, check_value, check_weights

#: Highest frequency a model FRF is taken at. [Hz]
MAX_FREQUENCY = 1e4

__all__ = ["model_frf", "model_frf_batch", "output_vector", "output_names", "INPUTS"]



def output_names(n_links: int) -> tuple[str, ...]:
    """The outputs a body of ``n_links`` has."""
    from ..model.muscles import joint_pair_names

    joints = ("ankle", "knee", "hip") if n_links == 3 else joint_pair_names(n_links)
    return ("com_angle", *(f"theta{i + 1}" for i in range(n_links)),
            *(f"{j}_angle" for j in joints[:n_links]))


def output_vector(body: Body, output: str) -> np.ndarray:
    """c with y = c·Θ for the output named (module notes). [-]"""
    n = body.n_links
    names = output_names(n)
    if output not in names:
        raise UnknownNameError(f"unknown output {output!r}; known outputs: {', '.join(names)}")
    c = np.zeros(n)
    if output == "com_angle":
        a = body.gravity_coefficients
        return a / a.sum()
    if output.startswith("theta"):
        c[int(output[5:]) - 1] = 1.0
        return c
    j = names.index(output) - 1 - n  # joint j lies between links j and j + 1
    c[j] = 1.0
    if j > 0:
        c[j - 1] = -1.0
    return c


def model_frf_batch(body: Body, muscles: MuscleSet, frequencies, stiffness, viscosity,
                    active_stiffness=None, active_viscosity=None, feedback_delay=0.0,
                    proprioceptive_weight=1.0, *, input: str = "tilt",
                    output: str = "com_angle", torque_feedback_gain=0.0,
                    torque_feedback_time_constant=None, visual_weight=0.0) -> np.ndarray:
    """Model FRFs of M parameter sets at F frequencies (module notes).

    Parameters
    ----------
    body : Body
    muscles : MuscleSet
        The pair layout (its gains are not used).
    frequencies : array_like, shape (F,)
        > 0. [Hz]
    stiffness, viscosity : array_like, shape (M, P)
        Pair (intrinsic, or without active gains the whole) gains. [N·m/rad], [N·m·s/rad]
    active_stiffness, active_viscosity : array_like, shape (M, P), optional
        Active (delayed) gains. [N·m/rad], [N·m·s/rad]
    feedback_delay : float or array_like, shape (M,)
        τ. [s]
    proprioceptive_weight : float or array_like, shape (M,)
        W. [-]
    input : {"tilt", "translation", "visual-tilt"}
    output : str
        :func:`output_names`.
    torque_feedback_gain : float or array_like, shape (M,)
        K_t (module notes; 0: none). [-]
    torque_feedback_time_constant : float or array_like, shape (M,), optional
        τ_t (default: the parameter table's 17.4 s). [s]
    visual_weight : float or array_like, shape (M,)
        W_v. Each weight is checked against its range here; W + W_v <= 1 by
        :func:`model_frf` and by a run (a fit may search beyond it, and says so). [-]

    Returns
    -------
    numpy.ndarray of complex, shape (M, F)
        [-] for the tilts, [rad/m] for translation.
    """
    from ..model.checks import check_model

    check_model(body, muscles)
    if input not in INPUTS:
        raise ParameterError(f"input must be one of {', '.join(INPUTS)}, got {input!r}")
    f = finite_array("frequencies [Hz]", frequencies, (None,))
    if f.size == 0 or np.any(f <= 0) or np.any(f > MAX_FREQUENCY):
        raise ParameterError(f"frequencies [Hz] must be in (0, {MAX_FREQUENCY:g}] Hz")
    c = output_vector(body, output)
    P = len(muscles.pairs)
    k = _gains("stiffness [N·m/rad]", stiffness, P)
    M = k.shape[0]
    viscosity = _gains("viscosity [N·m·s/rad]", viscosity, P, M)
    if (active_stiffness is None) != (active_viscosity is None):
        raise ParameterError("give active_stiffness and active_viscosity together")
    if active_stiffness is not None:
        active_stiffness = _gains("active_stiffness [N·m/rad]", active_stiffness, P, M)
        active_viscosity = _gains("active_viscosity [N·m·s/rad]", active_viscosity, P, M)
    tau = np.broadcast_to(np.asarray(feedback_delay, dtype=float), (M,))
    w = np.broadcast_to(np.asarray(proprioceptive_weight, dtype=float), (M,))
    wv = np.broadcast_to(np.asarray(visual_weight, dtype=float), (M,))
    for name, values in (("feedback_delay", tau), ("proprioceptive_weight", w),
                         ("visual_weight", wv)):
        bad = ~((values >= QUANTITIES[name].low) & (values <= QUANTITIES[name].high))
        if np.any(bad):  # the parameter table's bounds (NaN fails too)
            check_value(name, float(values[np.argmax(bad)]))
    system = linear_system(body, muscles, stiffness=k, viscosity=viscosity,
                           active_stiffness=active_stiffness, active_viscosity=active_viscosity,
                           delay=tau, proprioceptive_weight=w, visual_weight=wv,
                           torque_feedback_gain=torque_feedback_gain,
                           torque_feedback_time_constant=torque_feedback_time_constant)
    with np.errstate(all="ignore"):
        H = system.frequency_response(f, input, c)
    if input != "translation":
        H = -H  # the literature's sign: H = −y/α (−y/v)
    if not np.all(np.isfinite(H)):
        raise ParameterError("the model FRF is not finite at some frequency (a resonance "
                             "exactly at it, or gains beyond what the model can take)")
    return H


def _gains(name: str, value, pairs: int, rows: int | None = None) -> np.ndarray:
    """Gains as (M, P), finite and >= 0."""
    if isinstance(value, bool):
        raise ParameterError(f"{name} must be numbers, got {value!r}")
    g = np.atleast_2d(finite_array(name, value))
    if g.ndim != 2 or g.shape[1] != pairs or (rows is not None and g.shape[0] != rows):
        want = f"({rows if rows is not None else 'M'}, {pairs})"
        raise ParameterError(f"{name} must have shape {want}, got {g.shape}")
    if np.any(g < 0):
        raise ParameterError(f"{name} must be >= 0, got {float(g.min()):g}")
    return g


def model_frf(body: Body, muscles: MuscleSet, frequencies, *, input: str = "tilt",
              output: str = "com_angle", feedback_delay: float = 0.0,
              proprioceptive_weight: float = 1.0, torque_feedback_gain: float = 0.0,
              torque_feedback_time_constant: float | None = None,
              visual_weight: float = 0.0) -> np.ndarray:
    """The model FRF of one body and muscle set (its own intrinsic and active gains) at
    ``frequencies`` [Hz]; shape (F,). See :func:`model_frf_batch`."""
    check_value("feedback_delay", feedback_delay)
    check_weights(proprioceptive_weight, visual_weight)
    active = muscles.has_active_feedback
    return model_frf_batch(
        body, muscles, frequencies, muscles.stiffnesses[None], muscles.viscosities[None],
        muscles.active_stiffnesses[None] if active else None,
        muscles.active_viscosities[None] if active else None, feedback_delay,
        proprioceptive_weight, input=input, output=output,
        torque_feedback_gain=torque_feedback_gain,
        torque_feedback_time_constant=torque_feedback_time_constant,
        visual_weight=visual_weight)[0]
