"""Linear analysis about upright stance: state matrix, poles, modes, sensitivity.

Linearising eq. 1 about Θ = 0, Θ̇ = 0 with the platform at rest (paper
Appendix B)::

    J(0) Θ̈ − g ∂G/∂Θ(0) Θ = −K Θ − L Θ̇

so the state matrix of x = [Θ, Θ̇] is::

    A = [[0, I], [J(0)⁻¹ (g diag(a) − K), −J(0)⁻¹ L]]

A one-sided pair is not differentiable at upright (its stretch is 0 there).
:func:`analyse` takes ``one_sided="active"`` (default: the side where the pair
acts, stretch >= 0, the same as two-sided) or ``"inactive"`` (the pair
removed); :func:`analyse_both_sides` gives both.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import finite_array
from ..model.body import Body
from ..model.dynamics import mass_matrix, platform_vector, state_derivative
from ..model.muscles import MuscleSet, feedback_pair_torques, muscle_set_gains
from .system import OneSided, effective_muscles, linear_system, sorted_poles

__all__ = [
    "LinearAnalysis",
    "state_matrix",
    "finite_difference_state_matrix",
    "sorted_poles",
    "analyse",
    "analyse_both_sides",
    "disturbance_sensitivity",
]

def _effective(muscles: MuscleSet, one_sided: OneSided) -> MuscleSet:
    return effective_muscles(muscles, one_sided)


def state_matrix(body: Body, muscles: MuscleSet, one_sided: OneSided = "active") -> np.ndarray:
    """Analytic state matrix A (2N × 2N) of the chain linearised about upright.

    Parameters
    ----------
    body : Body
        The chain.
    muscles : MuscleSet
        Pairs acting on it (``muscles.n_links`` must equal ``body.n_links``).
    one_sided : {"active", "inactive"}
        How a one-sided pair is linearised at upright (see module notes).

    Returns
    -------
    numpy.ndarray, shape (2N, 2N)
        d[Θ, Θ̇]/dt = A [Θ, Θ̇]; upper-right block [-], lower-left [1/s²],
        lower-right [1/s]. (:meth:`posturelab.linear.system.LinearSystem.state_matrix`
        without delay.)
    """
    _check_match(body, muscles)
    return linear_system(body, muscles, one_sided=one_sided, inputs=False).state_matrix()[0]


def finite_difference_state_matrix(
    body: Body, muscles: MuscleSet, step: float = 1e-6, one_sided: OneSided = "active"
) -> np.ndarray:
    """State matrix from central differences of the *nonlinear* model at upright.

    An independent cross-check of :func:`state_matrix` (it uses only
    :func:`posturelab.model.dynamics.state_derivative` and the pair torques).

    Parameters
    ----------
    step : float
        Perturbation of each state entry. [rad] or [rad/s]
    """
    _check_match(body, muscles)
    m = _effective(muscles, one_sided)
    n = body.n_links

    gains = muscle_set_gains(m, 0.0)

    def f(x: np.ndarray) -> np.ndarray:
        u = -feedback_pair_torques(m, gains, x, x) @ m.selection_matrix
        return state_derivative(body, x, u)

    A = np.zeros((2 * n, 2 * n))
    for j in range(2 * n):
        e = np.zeros(2 * n)
        e[j] = step
        A[:, j] = (f(e) - f(-e)) / (2 * step)
    return A


@dataclass(frozen=True)
class LinearAnalysis:
    """Poles and modes of the chain linearised about upright.

    Attributes
    ----------
    poles : numpy.ndarray of complex, shape (2N,)
        Eigenvalues of the state matrix, real part ascending. [1/s]
    stable : bool
        True when every pole has a negative real part.
    max_real_part : float
        Largest real part among the poles; the growth rate of the slowest-
        decaying (or fastest-growing) mode. [1/s]
    natural_frequencies : numpy.ndarray, shape (2N,)
        |λ| for each pole. [rad/s]
    damping_ratios : numpy.ndarray, shape (2N,)
        −Re(λ)/|λ| for each pole; negative for an unstable mode. [-]
    state_matrix : numpy.ndarray, shape (2N, 2N)
        The matrix A whose eigenvalues are the poles. [mixed, see state_matrix]
    pair_names : tuple of str
        Muscle pair names, in the order of the stiffness arrays.
    pair_stiffness : numpy.ndarray, shape (P,)
        Stiffness of each pair. [N·m/rad]
    pair_stiffness_fraction_of_load : numpy.ndarray, shape (P,)
        Pair stiffness divided by the body's load stiffness mgh = g Σ a_i. [-]
    load_stiffness : float
        mgh = g Σ a_i of the body. [N·m/rad]
    one_sided : str
        How one-sided pairs were linearised: "active" or "inactive".
    """

    poles: np.ndarray
    stable: bool
    max_real_part: float
    natural_frequencies: np.ndarray
    damping_ratios: np.ndarray
    state_matrix: np.ndarray
    pair_names: tuple[str, ...]
    pair_stiffness: np.ndarray
    pair_stiffness_fraction_of_load: np.ndarray
    load_stiffness: float
    one_sided: str = "active"

    def to_dict(self) -> dict:
        """Plain-Python summary: poles as {"re", "im"} [1/s], stable, stiffness [N·m/rad]."""
        return {
            "poles": [{"re": float(p.real), "im": float(p.imag)} for p in self.poles],
            "stable": bool(self.stable),
            "max_real_part": float(self.max_real_part),
            "pair_names": list(self.pair_names),
            "pair_stiffness": [float(x) for x in self.pair_stiffness],
            "pair_stiffness_fraction_of_load": [
                float(x) for x in self.pair_stiffness_fraction_of_load
            ],
            "load_stiffness": float(self.load_stiffness),
        }


def analyse(body: Body, muscles: MuscleSet, one_sided: OneSided = "active") -> LinearAnalysis:
    """Linear stability of the chain about upright.

    Parameters
    ----------
    body : Body
    muscles : MuscleSet
    one_sided : {"active", "inactive"}
        Which side of a one-sided pair to linearise (see module notes).

    Returns
    -------
    LinearAnalysis

    Examples
    --------
    Table II, case 3 (erratum 1: the slowest pole is −0.092 1/s, not the printed −0.90):

    >>> import posturelab as pl
    >>> res = pl.analyse(pl.paper_body(), pl.paper_muscles("3"))
    >>> res.stable
    True
    >>> [round(float(p), 3) for p in res.poles.real]  # [1/s]
    [-575.405, -90.564, -3.641, -2.948, -2.948, -0.092]
    """
    A = state_matrix(body, muscles, one_sided)
    poles = sorted_poles(np.linalg.eigvals(A))
    mag = np.abs(poles)
    with np.errstate(invalid="ignore", divide="ignore"):
        zeta = np.where(mag > 0, -poles.real / np.where(mag > 0, mag, 1.0), np.nan)
    load = body.load_stiffness
    used = _effective(muscles, one_sided)
    return LinearAnalysis(
        poles=poles,
        stable=bool(np.all(poles.real < 0.0)),
        max_real_part=float(poles.real.max()),
        natural_frequencies=mag,
        damping_ratios=zeta,
        state_matrix=A,
        pair_names=tuple(used.names),
        pair_stiffness=used.stiffnesses.copy(),
        pair_stiffness_fraction_of_load=used.stiffnesses / load,
        load_stiffness=load,
        one_sided=one_sided,
    )


def analyse_both_sides(body: Body, muscles: MuscleSet) -> tuple[LinearAnalysis, LinearAnalysis]:
    """Linearisations on both sides of the one-sided pairs' switch: (active, inactive).

    For a muscle set with no one-sided pair both entries are the same analysis.
    """
    active = analyse(body, muscles, "active")
    if not muscles.one_sided_mask.any():
        return active, active
    return active, analyse(body, muscles, "inactive")


def disturbance_sensitivity(body: Body, posture: np.ndarray | None = None) -> np.ndarray:
    """Disturbance-severity vector J(Θ)⁻¹ H(Θ) (paper section VI).

    A sudden platform velocity change Δẋ_d changes the link rates by
    −J⁻¹H Δẋ_d; entry i measures how hard a horizontal platform disturbance
    drives link i.

    Parameters
    ----------
    body : Body
    posture : array_like, shape (N,), optional
        Link angles at which to evaluate; upright by default. [rad]

    Returns
    -------
    numpy.ndarray, shape (N,)
        J⁻¹H. [rad/m] (rate change [rad/s] per platform velocity change [m/s])

    Examples
    --------
    The paper's body upright, and at its flexed initial posture (erratum 5):

    >>> import posturelab as pl
    >>> [round(float(v), 4) for v in pl.disturbance_sensitivity(pl.paper_body())]  # [rad/m]
    [2.558, -0.0654, 0.0027]
    >>> [round(float(v), 3) for v in pl.disturbance_sensitivity(pl.paper_body(),
    ...                                                         [0.1, -0.1, 0.1])]
    [2.268, 0.291, -0.071]
    """
    from ..model.checks import check_model

    check_model(body)
    if posture is None:
        posture = np.zeros(body.n_links)
    posture = finite_array("posture [rad]", posture, (body.n_links,))
    return np.linalg.solve(mass_matrix(body, posture), platform_vector(body, posture))


def _check_match(body: Body, muscles: MuscleSet) -> None:
    from .._validation import expect_type
    from ..model.checks import check_model

    expect_type("muscles", muscles, MuscleSet)  # (check_model lets None through)
    check_model(body, muscles)
