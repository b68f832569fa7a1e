"""Signs, frames, units and state order, stated once.

Every other module follows these conventions; docstrings refer here.

Units
-----
SI throughout: lengths [m], masses [kg], time [s], angles [rad], angular
rates [rad/s], torques [N·m], stiffness [N·m/rad], viscosity [N·m·s/rad],
accelerations [m/s²].

Frames and signs
----------------
* ``x`` is forward (the direction the subject faces), ``y`` is up.
* Link angles ``theta[i]`` are *absolute*: measured from the vertical, positive
  when the link leans forward (toward +x).
* Link 1 (index 0 in arrays) is the lowest (leg / shank); link N the highest
  (torso / head-arms-trunk). The foot is link "0": flat on the platform,
  ``theta_0 = 0``, and is not a degree of freedom.
* Joint angles are relative: ankle = θ1, knee = θ2 − θ1, hip = θ3 − θ2.
  A positive knee angle is knee flexion in this sagittal chain only in the
  sense of the difference of absolute angles; no anatomical sign is implied.
* The platform position is ``(x_d(t), y_d(t))``. A *backward* platform
  motion has ẋ_d < 0 and makes the body sway *forward* (θ̇ > 0).

State
-----
The state vector is ``[θ1 … θN, θ̇1 … θ̇N]`` (angles first, then rates). Time
is the first axis of every time series.

Equation of motion (paper eq. 1, corrected for y up, see ``errata``)
--------------------------------------------------------------------
    J(Θ) Θ̈ + B(Θ, Θ̇) Θ̇ − (g + ÿ_d) G(Θ) + ẍ_d H(Θ) = U

A sudden change of platform velocity Δẋ_d gives ΔΘ̇ = −J(Θ)⁻¹ H(Θ) Δẋ_d.

Muscle pairs
------------
A pair spanning links (lo, hi), lo < hi, with 0 the foot, has stretch
θ_hi − θ_lo (its row of E). Pair torque M = K_d E Θ + L_d E Θ̇ (positive M
resists positive stretch); joint-space torque U = −Eᵀ M.
"""

from __future__ import annotations

#: Standard gravity used by the paper (Appendix A). [m/s²]
STANDARD_GRAVITY: float = 9.81

#: Names of the entries of the state vector for an N-link chain.
def state_names(n_links: int) -> list[str]:
    """Column names of the state vector: ``theta1..thetaN, omega1..omegaN``.

    Parameters
    ----------
    n_links : int
        Number of links N. [-]

    Returns
    -------
    list of str
        ``["theta1", …, "thetaN", "omega1", …, "omegaN"]``; angles in [rad],
        rates in [rad/s].
    """
    return [f"theta{i + 1}" for i in range(n_links)] + [f"omega{i + 1}" for i in range(n_links)]


#: Units of the state entries, in state order.
def state_units(n_links: int) -> list[str]:
    """Units of the state entries, in state order: ``rad`` then ``rad/s``."""
    return ["rad"] * n_links + ["rad/s"] * n_links
