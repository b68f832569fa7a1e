"""The chain linearised about upright: one batched delayed linear system.

About upright, with the platform level and at rest, M parameter sets of an N-link chain
obey (Appendix B of the paper, with a feedback delay τ)::

    J0 Θ̈ + L_i Θ̇ + S Θ + K_a Θ(t − τ) + L_a Θ̇(t − τ)
        = b0 α + b1 α̇ + b2 α(t − τ) + b3 α̇(t − τ) + h ẍ_d,

    S = K_i − g diag(a),   K_i = Eᵀ diag(k_i) E, …   (E the pairs' selection matrix)

with the pair gains split into an intrinsic part (k_i, l_i: acts at once) and an active
part (k_a, l_a: acts after τ) as :func:`posturelab.model.muscles.feedback_gains` states
for a positive delay (without active gains the whole pair feedback is the delayed part;
with τ = 0, e^{−sτ} = 1 and both parts act at once, as that function sums them). The
inputs are the surface tilt α [rad] (:func:`posturelab.model.tilt.tilt_pair_gains`: the
pairs that span the foot feel it, the active part weighted by the proprioceptive weight
W) and the horizontal platform acceleration ẍ_d [m/s²] (h = −a, the linearised −H(Θ));
and the visual-scene tilt v [rad], which acts only through the active part of the pairs that
span the foot, weighted by the visual weight W_v (:func:`posturelab.model.visual.visual_pair_gains`:
its moments c0 … c3 on v, v̇, v(t − τ), v̇(t − τ) are those of b with the intrinsic part
removed and W_v for W; Peterka 2002's independent channels).

Torque feedback (Peterka 2002, J Neurophysiol 88:1097–1118; docs/design.md): the active
(delayed) torque is fed back positively through the low-pass K_t/(τ_t s + 1), so that the
active torque is g(s) = (τ_t s + 1)/(τ_t s + 1 − K_t) times the delayed PD's: in Δ(s) the
delayed part (K_a + s L_a) e^{−sτ} and in the tilt input the delayed b2, b3 are multiplied
by g(s). In the time domain a filter state Y per link coordinate (a generalised torque
[N·m]) obeys τ_t Ẏ = (K_t − 1) Y + K_t (K_a Θ(t − τ) + L_a Θ̇(t − τ)) and enters the
equation of motion beside the delayed part, so that the first-order form has 3N states.

:class:`LinearSystem` holds these matrices for M sets (an axis of length 1 is shared by
every set); :func:`linear_system` builds it once from a body and a muscle set (its own
gains, or arrays of gains for a batch). Everything linear derives from it, as
python-control derives poles and frequency responses from one ``StateSpace``: the state
matrix and poles (:mod:`.analysis`), the characteristic matrix Δ(s), the rightmost roots
(:func:`posturelab.linear.delay.system_rightmost_roots`) and the delay margins
(:func:`posturelab.linear.margins.delay_margins`; :mod:`.delay`, :mod:`.delay_batch`), the verdict
about upright (:mod:`.verdict`), the batched maps (:mod:`.batch`, whose compiled kernels
take the matrices of :meth:`LinearSystem.without_delay`) and the model FRFs
(:mod:`posturelab.frequency.model`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from .._validation import finite_array
from ..errors import ParameterError
from ..model.body import Body
from ..model.gains import (
    DELAYED_STIFFNESS,
    DELAYED_VISCOSITY,
    IMMEDIATE_STIFFNESS,
    IMMEDIATE_VISCOSITY,
)
from ..model.muscles import MuscleSet, feedback_gains
from ..model.tilt import tilt_pair_gains
from ..model.visual import visual_pair_gains
from .body_arrays import BodyArrays

__all__ = ["BodyArrays", "LinearSystem", "linear_system", "sorted_poles", "OneSided",
           "INPUTS", "with_joint_feedback", "link_torque_matrix"]

OneSided = Literal["active", "inactive"]

#: Inputs of :meth:`LinearSystem.frequency_response`: the surface tilt α [rad], the
#: horizontal platform displacement x_d [m] and the visual-scene tilt v [rad].
INPUTS = ("tilt", "translation", "visual-tilt")

#: Sets per evaluation of a frequency response (bounds the memory of one call). [-]
_FRF_CHUNK = 32_768


def _sets(*arrays: np.ndarray) -> int:
    """The number of sets M of arrays whose first axis is 1 (shared) or M."""
    counts = {a.shape[0] for a in arrays if a is not None} - {1}
    if len(counts) > 1:
        raise ParameterError(f"the system's arrays disagree on the number of sets: "
                             f"{sorted(counts)}")
    return counts.pop() if counts else 1


def _pick(arr: np.ndarray | None, index) -> np.ndarray | None:
    """Rows ``index`` of a per-set array (a shared array of one row stays as it is)."""
    if arr is None or arr.shape[0] == 1:
        return arr
    return arr[index]


@dataclass(frozen=True, eq=False)
class LinearSystem:
    """The chain linearised about upright for M parameter sets (module notes).

    Every array's first axis is the set axis, of length M or 1 (shared by every set).

    Attributes
    ----------
    inertia : numpy.ndarray, shape (M or 1, N, N)
        J0, the inertia matrix upright. [kg·m²]
    stiffness : numpy.ndarray, shape (M or 1, N, N)
        S = K_i − g diag(a): the immediate pair stiffness and gravity's negative
        stiffness. [N·m/rad]
    viscosity : numpy.ndarray, shape (M or 1, N, N)
        L_i, the immediate pair viscosity. [N·m·s/rad]
    delayed_stiffness : numpy.ndarray, shape (M or 1, N, N)
        K_a, acting on Θ(t − τ). [N·m/rad]
    delayed_viscosity : numpy.ndarray, shape (M or 1, N, N)
        L_a, acting on Θ̇(t − τ). [N·m·s/rad]
    delay : numpy.ndarray, shape (M or 1,)
        τ. [s]
    tilt_input : numpy.ndarray, shape (M or 1, 4, N), or None
        b0 … b3, the moments on α, α̇, α(t − τ), α̇(t − τ); None when built without
        inputs. [N·m/rad], [N·m·s/rad], [N·m/rad], [N·m·s/rad]
    translation_input : numpy.ndarray, shape (M or 1, N)
        h = −a, the moments per unit platform acceleration ẍ_d. [kg·m]
    torque_feedback_gain : numpy.ndarray, shape (M or 1,), or None
        K_t of the torque feedback (module notes); None for none. [-]
    torque_feedback_time_constant : numpy.ndarray, shape (M or 1,), or None
        τ_t, > 0 (with the gain). [s]
    visual_input : numpy.ndarray, shape (M or 1, 4, N), or None
        c0 … c3, the moments on v, v̇, v(t − τ), v̇(t − τ) of the visual-scene tilt (the
        active part only); None when built without inputs.
        [N·m/rad], [N·m·s/rad], [N·m/rad], [N·m·s/rad]
    """

    inertia: np.ndarray
    stiffness: np.ndarray
    viscosity: np.ndarray
    delayed_stiffness: np.ndarray
    delayed_viscosity: np.ndarray
    delay: np.ndarray
    tilt_input: np.ndarray | None
    translation_input: np.ndarray
    torque_feedback_gain: np.ndarray | None = None
    torque_feedback_time_constant: np.ndarray | None = None
    visual_input: np.ndarray | None = None

    @property
    def has_torque_feedback(self) -> bool:
        """Whether any set has a torque feedback gain (its filter states then count)."""
        return self.torque_feedback_gain is not None

    @property
    def n_links(self) -> int:
        """N. [-]"""
        return int(self.inertia.shape[-1])

    @property
    def n_sets(self) -> int:
        """M. [-]"""
        return _sets(self.inertia, self.stiffness, self.viscosity, self.delayed_stiffness,
                     self.delayed_viscosity, self.delay, self.tilt_input,
                     self.translation_input, self.torque_feedback_gain,
                     self.torque_feedback_time_constant, self.visual_input)

    def __len__(self) -> int:
        return self.n_sets

    def __getitem__(self, index) -> LinearSystem:
        """The sets ``index`` (an integer array, a slice or an integer) as a system."""
        if isinstance(index, int | np.integer):
            index = slice(int(index), int(index) + 1) if index != -1 else slice(-1, None)
        return LinearSystem(*(_pick(getattr(self, f), index) for f in (
            "inertia", "stiffness", "viscosity", "delayed_stiffness", "delayed_viscosity",
            "delay", "tilt_input", "translation_input", "torque_feedback_gain",
            "torque_feedback_time_constant", "visual_input")))

    def without_delay(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The system at τ = 0, as the matrices of s² J0 + s L + K:
        (J0, L_i + L_a, S + K_a), each with its set axis (M or 1). [kg·m²], [N·m·s/rad],
        [N·m/rad]

        Raises
        ------
        ParameterError
            With torque feedback (its filter makes Δ(s) rational, not a matrix
            polynomial; :meth:`first_order` carries it)."""
        if self.has_torque_feedback:
            raise ParameterError("this analysis does not take torque feedback yet (its "
                                 "filter is not a matrix polynomial); poles, the FRFs and "
                                 "the rightmost roots do")
        return (self.inertia, _add(self.viscosity, self.delayed_viscosity),
                _add(self.stiffness, self.delayed_stiffness))

    def state_matrix(self) -> np.ndarray:
        """A of d[Θ, Θ̇]/dt = A [Θ, Θ̇] at τ = 0, shape (M, 2N, 2N): upper-right block
        [-], lower-left [1/s²], lower-right [1/s]; with torque feedback A0 + A1 of
        :meth:`first_order`, (M, 3N, 3N) over [Θ, Θ̇, Y]."""
        if self.has_torque_feedback:
            A0, A1 = self.first_order()
            return A0 + A1
        jac, damp, load = self.without_delay()
        m, n = self.n_sets, self.n_links
        A = np.zeros((m, 2 * n, 2 * n))
        A[:, :n, n:] = np.eye(n)
        A[:, n:, :n] = np.linalg.solve(np.broadcast_to(jac, (m, n, n)),
                                       -np.broadcast_to(load, (m, n, n)))
        A[:, n:, n:] = -np.linalg.solve(np.broadcast_to(jac, (m, n, n)),
                                        np.broadcast_to(damp, (m, n, n)))
        return A

    def first_order(self) -> tuple[np.ndarray, np.ndarray]:
        """(A0, A1), each (M, 2N, 2N): d/dt [Θ, Θ̇] = A0 x(t) + A1 x(t − τ). [1/s², 1/s]

        With torque feedback each is (M, 3N, 3N) over x = [Θ, Θ̇, Y], Y the filter state
        (module notes): J0 Θ̈ = −S Θ − L_i Θ̇ − Y − K_a Θ(t − τ) − L_a Θ̇(t − τ) and
        τ_t Ẏ = (K_t − 1) Y + K_t (K_a Θ(t − τ) + L_a Θ̇(t − τ)). [N·m/s per state unit]"""
        m, n = self.n_sets, self.n_links
        size = 3 * n if self.has_torque_feedback else 2 * n
        inv = np.broadcast_to(np.linalg.inv(self.inertia), (m, n, n))
        A0 = np.zeros((m, size, size))
        A0[:, :n, n:2 * n] = np.eye(n)
        A0[:, n:2 * n, :n] = -inv @ self.stiffness
        A0[:, n:2 * n, n:2 * n] = -inv @ self.viscosity
        A1 = np.zeros((m, size, size))
        A1[:, n:2 * n, :n] = -inv @ self.delayed_stiffness
        A1[:, n:2 * n, n:2 * n] = -inv @ self.delayed_viscosity
        if self.has_torque_feedback:
            gain = np.broadcast_to(self.torque_feedback_gain, (m,))[:, None, None]
            rate = 1.0 / np.broadcast_to(self.torque_feedback_time_constant, (m,))[:, None, None]
            A0[:, n:2 * n, 2 * n:] = -inv
            A0[:, 2 * n:, 2 * n:] = (gain - 1.0) * rate * np.eye(n)
            A1[:, 2 * n:, :n] = gain * rate * np.broadcast_to(self.delayed_stiffness, (m, n, n))
            A1[:, 2 * n:, n:2 * n] = gain * rate * np.broadcast_to(self.delayed_viscosity,
                                                                    (m, n, n))
        return A0, A1

    def torque_feedback_factor(self, s) -> np.ndarray:
        """g(s) = (τ_t s + 1)/(τ_t s + 1 − K_t) of every set (1 without torque feedback):
        the active torque over the delayed PD's (module notes).

        Parameters
        ----------
        s : complex or array_like, shape (M or 1, ...)
            Its first axis is the set axis. [1/s]

        Returns
        -------
        numpy.ndarray, shape (M or 1, ...)
            [-]
        """
        s = np.asarray(s, dtype=complex)
        if not self.has_torque_feedback:
            return np.ones_like(s)
        extra = (None,) * (s.ndim - 1)
        gain = self.torque_feedback_gain[(slice(None), *extra)]
        lag = self.torque_feedback_time_constant[(slice(None), *extra)] * s + 1.0
        return lag / (lag - gain)

    def poles(self) -> np.ndarray:
        """The poles at τ = 0 of every set, shape (M, 2N) (M, 3N with torque feedback: the
        eigenvalues of :meth:`state_matrix`), real part ascending (as
        :func:`posturelab.linear.sorted_poles`). [1/s]"""
        return sorted_poles(np.linalg.eigvals(self.state_matrix()))

    def characteristic_matrix(self, s, delay=None) -> np.ndarray:
        """Δ(s) = s² J0 + s L_i + S + (K_a + s L_a) e^{−sτ} g(s) of every set (g the torque
        feedback's factor, :meth:`torque_feedback_factor`; 1 without it).

        Parameters
        ----------
        s : complex or array_like, shape (M or 1, ...)
            The Laplace variable; its first axis is the set axis. [1/s]
        delay : float or array_like, shape (M or 1,), optional
            τ instead of the system's own. [s]

        Returns
        -------
        numpy.ndarray, shape (M, ...) + (N, N)
            [N·m/rad]
        """
        s = np.asarray(s, dtype=complex)
        if s.ndim == 0:
            s = s[None]
        tau = self.delay if delay is None else np.atleast_1d(np.asarray(delay, dtype=float))
        extra = (None,) * (s.ndim - 1)
        tau = tau[(slice(None), *extra)]

        def mat(x):
            return x[(slice(None), *extra)]

        z = s[..., None, None]
        delayed = np.exp(-s * tau)
        if self.has_torque_feedback:
            delayed = delayed * self.torque_feedback_factor(s)
        return (z * z * mat(self.inertia) + mat(self.stiffness) + z * mat(self.viscosity)
                + (mat(self.delayed_stiffness) + z * mat(self.delayed_viscosity))
                * delayed[..., None, None])

    def frequency_response(self, frequencies, input: str, output) -> np.ndarray:
        """y(s)/u(s) at s = 2πi f for every set, y = c·Θ.

        Parameters
        ----------
        frequencies : array_like, shape (F,)
            [Hz]
        input : {"tilt", "translation", "visual-tilt"}
            u: the surface tilt α [rad], the horizontal platform displacement x_d [m]
            (the input h ẍ_d = h s² x_d), or the visual-scene tilt v [rad].
        output : array_like, shape (N,)
            c. [-]

        Returns
        -------
        numpy.ndarray of complex, shape (M, F)
            [rad/rad] for the tilts, [rad/m] for translation.
        """
        if input not in INPUTS:
            raise ParameterError(f"input must be one of {', '.join(INPUTS)}, got {input!r}")
        if input != "translation" and self.tilt_input is None:
            raise ParameterError("this system was built without its inputs")
        f = np.asarray(frequencies, dtype=float)
        c = np.asarray(output, dtype=float)
        m = self.n_sets
        parts = [self[lo:lo + _FRF_CHUNK]._response(f, input, c, min(_FRF_CHUNK, m - lo))
                 for lo in range(0, m, _FRF_CHUNK)]
        return parts[0] if len(parts) == 1 else np.concatenate(parts)

    def _response(self, f: np.ndarray, input: str, c: np.ndarray, m: int) -> np.ndarray:
        n = self.n_links
        s = np.broadcast_to((2j * np.pi * f)[None, :], (1, f.size))
        D = self.characteristic_matrix(s)                                  # (M, F, N, N)
        s1 = s[..., None]                                                  # (1, F, 1)
        if input != "translation":
            b = (self.tilt_input if input == "tilt" else self.visual_input)[:, None]  # M,1,4,N
            ex = np.exp(-s * self.delay[:, None])                          # (M, F)
            ex = (ex * self.torque_feedback_factor(s))[..., None]          # (M, F, 1)
            rhs = (b[..., IMMEDIATE_STIFFNESS, :] + s1 * b[..., IMMEDIATE_VISCOSITY, :]
                   + (b[..., DELAYED_STIFFNESS, :] + s1 * b[..., DELAYED_VISCOSITY, :]) * ex)
        else:
            rhs = s1 * s1 * self.translation_input[:, None, :]
        rhs = np.broadcast_to(rhs, (m, f.size, n))
        D = np.broadcast_to(D, (m, f.size, n, n))
        if n == 1:  # a scalar equation: no solve
            theta = rhs / D[..., 0]
        else:
            theta = np.linalg.solve(D, rhs[..., None])[..., 0]
        return theta @ c


def sorted_poles(eigenvalues: np.ndarray) -> np.ndarray:
    """Sort poles by real part ascending; a conjugate pair lists +imag first. [1/s]"""
    ev = np.asarray(eigenvalues, dtype=complex)
    # Round for the sort key only, so conjugates with equal real parts stay together.
    order = np.lexsort((-ev.imag, np.round(ev.real, 9)), axis=-1)
    return np.take_along_axis(ev, order, axis=-1)


def _add(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a + b, leaving out a part that is shared and zero."""
    if b.shape[0] == 1 and not b.any():
        return a
    if a.shape[0] == 1 and not a.any():
        return b
    return a + b


def effective_muscles(muscles: MuscleSet, one_sided: OneSided) -> MuscleSet:
    """The muscle set of one side of a one-sided pair's switch at upright: ``"active"``
    (the pair acts, as two-sided) or ``"inactive"`` (the pair removed)."""
    if one_sided == "active":
        return muscles.as_two_sided()
    if one_sided == "inactive":
        return muscles.without_one_sided()
    raise ParameterError(f"one_sided must be 'active' or 'inactive', got {one_sided!r}")


#: Rows per matrix product in :func:`joint_matrices`: small enough that BLAS runs it on
#: one thread (its threads cost more than they save on products this thin). [-]
_PRODUCT_ROWS = 4096


def joint_matrices(gains: np.ndarray, selection: np.ndarray) -> np.ndarray:
    """Eᵀ diag(g) E for every row g of ``gains`` (M, P): shape (M, N, N). [units of the
    gains]"""
    gains = np.ascontiguousarray(gains, dtype=float)
    P, n = selection.shape
    outer = (selection[:, :, None] * selection[:, None, :]).reshape(P, n * n)
    m = gains.shape[0]
    out = np.empty((m, n * n))
    for lo in range(0, m, _PRODUCT_ROWS):
        np.matmul(gains[lo:lo + _PRODUCT_ROWS], outer, out=out[lo:lo + _PRODUCT_ROWS])
    return out.reshape(m, n, n)


def _joint_or_zero(gains: np.ndarray | None, selection: np.ndarray) -> np.ndarray:
    """:func:`joint_matrices`, or one shared zero matrix when there are no gains."""
    if gains is None:
        n = selection.shape[1]
        return np.zeros((1, n, n))
    return joint_matrices(gains, selection)


def _split(stiffness, viscosity, active_stiffness, active_viscosity) -> list:
    """The gains by when they act for a positive delay, indexed by the rows of
    :mod:`posturelab.model.gains` (None: zero):
    :func:`posturelab.model.muscles.feedback_gains` applied as the linear map it is, its
    matrix read from unit gains (so that a block of many sets costs a few additions)."""
    unit = np.eye(4)
    active = active_stiffness is not None
    weights = feedback_gains(unit[0], unit[1], unit[2] if active else None,
                             unit[3] if active else None, 1.0)  # (4 slots, 4 inputs)
    if not np.isin(weights, (0.0, 1.0)).all():
        raise AssertionError("feedback_gains is expected to place or sum the gains")
    inputs = (stiffness, viscosity, active_stiffness, active_viscosity)
    out = []
    for row in weights:
        terms = [inputs[i] for i in np.flatnonzero(row)]
        total = terms[0] if terms else None
        for term in terms[1:]:
            total = total + term
        out.append(total)
    return out


def _gain_rows(name: str, value, pairs: int) -> np.ndarray:
    """Gains as (M, P), finite and >= 0."""
    arr = finite_array(name, value)
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != pairs:
        raise ParameterError(f"{name} must have shape (M, {pairs}) (one column per muscle "
                             f"pair), got shape {np.shape(value)}")
    if arr.size and arr.min() < 0:
        raise ParameterError(f"{name} must be >= 0, got {arr.min():g}")
    return arr


def _torque_feedback(gain, time_constant) -> tuple[np.ndarray | None, np.ndarray | None]:
    """K_t and τ_t as arrays of shape (M or 1,), checked against the parameter table, or
    (None, None) when every gain is 0 (the system is then exactly the one without)."""
    from ..parameters import QUANTITIES, TORQUE_FEEDBACK_TIME_CONSTANT, check_value

    k = np.atleast_1d(finite_array("torque_feedback_gain [-]", gain))
    t = np.atleast_1d(finite_array("torque_feedback_time_constant [s]",
                                   TORQUE_FEEDBACK_TIME_CONSTANT if time_constant is None
                                   else time_constant))
    for name, values in (("torque_feedback_gain", k), ("torque_feedback_time_constant", t)):
        q = QUANTITIES[name]
        if values.ndim != 1:
            raise ParameterError(f"{name} [{q.unit}] must be a scalar or shape (M,)")
        low_ok = values > q.low if q.low_open else values >= q.low
        bad = ~(low_ok & (values <= q.high))
        if np.any(bad):
            check_value(name, float(values[np.argmax(bad)]))
    if not np.any(k):
        return None, None
    return k, t


def linear_system(body: Body | BodyArrays, muscles: MuscleSet, *, stiffness=None,
                  viscosity=None, viscosity_ratio=None, active_stiffness=None,
                  active_viscosity=None, delay=0.0, proprioceptive_weight=1.0,
                  visual_weight=0.0, one_sided: OneSided = "active", inputs: bool = True,
                  torque_feedback_gain=0.0,
                  torque_feedback_time_constant=None, joint_feedback=None) -> LinearSystem:
    """The chain linearised about upright (module notes), for one or M parameter sets.

    Parameters
    ----------
    body : Body or BodyArrays
        The chain (one body, or per-set parameters).
    muscles : MuscleSet
        The pairs; without gain arrays also their gains (one set), with them the layout
        only.
    stiffness : array_like, shape (M, P) or (P,), optional
        Pair (intrinsic, or without active gains the whole) stiffness. [N·m/rad]
    viscosity : array_like, shape (M, P) or (P,), optional
        Pair viscosity. [N·m·s/rad]
    viscosity_ratio : float or array_like, shape (M,), optional
        Pair viscosity = ratio × pair stiffness, instead of ``viscosity``. [s]
    active_stiffness, active_viscosity : array_like, shape (M, P), optional
        Active (delayed) gains; without them the whole pair feedback is delayed.
        [N·m/rad], [N·m·s/rad]
    delay : float or array_like, shape (M,)
        τ, >= 0. [s]
    proprioceptive_weight : float or array_like, shape (M,)
        W, the weight of the tilt in the active part. [-]
    visual_weight : float or array_like, shape (M,)
        W_v, the weight of the visual-scene tilt in the active part. [-]
    one_sided : {"active", "inactive"}
        How a one-sided pair is linearised at upright (:func:`posturelab.analyse`).
    inputs : bool
        Also build the tilt inputs (a batched map without inputs leaves them out).
    torque_feedback_gain : float or array_like, shape (M,)
        K_t of the torque feedback (module notes), in the parameter table's range; 0 (every
        set): none. [-]
    torque_feedback_time_constant : float or array_like, shape (M,), optional
        τ_t, > 0; by default the parameter table's 17.4 s (PMC5664365 Table 1). [s]
    joint_feedback : JointFeedback, optional
        A joint-space controller (:mod:`posturelab.model.joint_feedback`), added to the
        delayed matrices (:func:`with_joint_feedback`).

    Returns
    -------
    LinearSystem
    """
    from ..model.checks import check_model

    if isinstance(body, Body):
        check_model(body, muscles)
        jac, gravity_torque = body.upright_matrices()
        jac, gravity_torque = jac[None], gravity_torque[None]
        coefficients = body.gravity_coefficients[None]
    elif isinstance(body, BodyArrays):
        if body.n_links != muscles.n_links:
            raise ParameterError(f"muscle set is for {muscles.n_links} links but the body "
                                 f"has {body.n_links}")
        jac, gravity_torque = body.upright_matrices()
        coefficients = BodyArrays(body.masses, body.lengths, body.com_distances,
                                  body.inertias, 1.0).upright_matrices()[1]  # a [kg·m]
    else:
        raise ParameterError(f"body must be a Body or BodyArrays, got {type(body).__name__}")
    muscles = effective_muscles(muscles, one_sided)
    P = len(muscles.pairs)
    if stiffness is None:
        if any(v is not None for v in (viscosity, viscosity_ratio, active_stiffness,
                                       active_viscosity)):
            raise ParameterError("give stiffness with the other gain arrays")
        k, v = muscles.stiffnesses[None], muscles.viscosities[None]
        active = muscles.has_active_feedback
        ka = muscles.active_stiffnesses[None] if active else None
        va = muscles.active_viscosities[None] if active else None
    else:
        k = _gain_rows("stiffness [N·m/rad]", stiffness, P)
        if (viscosity is None) == (viscosity_ratio is None):
            raise ParameterError("give viscosity or viscosity_ratio (one of them)")
        if viscosity is not None:
            v = _gain_rows("viscosity [N·m·s/rad]", viscosity, P)
        else:
            ratio = np.atleast_1d(finite_array("viscosity_ratio [s]", viscosity_ratio))
            v = ratio[:, None] * k
        if (active_stiffness is None) != (active_viscosity is None):
            raise ParameterError("give active_stiffness and active_viscosity together")
        ka = va = None
        if active_stiffness is not None:
            ka = _gain_rows("active_stiffness [N·m/rad]", active_stiffness, P)
            va = _gain_rows("active_viscosity [N·m·s/rad]", active_viscosity, P)
    tau = np.atleast_1d(finite_array("delay [s]", delay))
    if tau.ndim != 1 or np.any(tau < 0):
        raise ParameterError("delay [s] must be >= 0, a scalar or shape (M,)")
    # the split for a positive delay (at τ = 0 the delayed part acts at once: e^0 = 1)
    split = _split(k, v, ka, va)
    E = muscles.selection_matrix
    n = E.shape[1]
    stiff = _joint_or_zero(split[IMMEDIATE_STIFFNESS], E)
    index = np.arange(n)
    stiff = np.array(np.broadcast_to(stiff, (max(stiff.shape[0], jac.shape[0]), n, n)))
    stiff[:, index, index] -= gravity_torque
    tilt = visual = None
    if inputs:
        shape = np.broadcast_shapes(*(g.shape for g in split if g is not None))
        gains = np.stack([np.zeros(shape) if g is None else np.broadcast_to(g, shape)
                          for g in split], axis=-2)
        weight = np.atleast_1d(np.asarray(proprioceptive_weight, dtype=float))
        tilt = -tilt_pair_gains(gains, muscles.spans_foot, tau, weight) @ E
        visual_w = np.atleast_1d(np.asarray(visual_weight, dtype=float))
        visual = -visual_pair_gains(gains, muscles.spans_foot, tau, visual_w) @ E
    feedback_gain, time_constant = _torque_feedback(torque_feedback_gain,
                                                    torque_feedback_time_constant)
    system = LinearSystem(
        inertia=jac, stiffness=stiff, viscosity=_joint_or_zero(split[IMMEDIATE_VISCOSITY], E),
        delayed_stiffness=_joint_or_zero(split[DELAYED_STIFFNESS], E),
        delayed_viscosity=_joint_or_zero(split[DELAYED_VISCOSITY], E), delay=tau,
        tilt_input=tilt, translation_input=-coefficients, torque_feedback_gain=feedback_gain,
        torque_feedback_time_constant=time_constant, visual_input=visual)
    system.n_sets  # noqa: B018 (checks that the arrays agree on M)
    return system if joint_feedback is None else with_joint_feedback(system, joint_feedback)


def link_torque_matrix(n: int) -> np.ndarray:
    """D with U = D τ: the generalised link torques from the joint moments
    (:func:`posturelab.model.feedback.moments_to_link_torques`), shape (N, N). [-]"""
    from ..model.feedback import moments_to_link_torques

    return moments_to_link_torques(np.eye(n)).T


def with_joint_feedback(system: LinearSystem, feedback) -> LinearSystem:
    """``system`` with a joint-space controller τ_ctrl = −F_θ Θ(t − τ) − F_ω Θ̇(t − τ)
    (:class:`posturelab.model.joint_feedback.JointFeedback`, its scale applied): its link
    torques U = D τ_ctrl = −D F Θ(t − τ) − …, so K_a += D F_θ and L_a += D F_ω (at τ = 0
    they act at once, as the engines add them to the immediate gains)."""
    from dataclasses import replace

    from ..model.joint_feedback import joint_gain_rows

    n = system.n_links
    rows = joint_gain_rows(feedback, n, 1.0)  # the delayed rows: −F_θ, −F_ω
    D = link_torque_matrix(n)
    return replace(system,
                   delayed_stiffness=system.delayed_stiffness - D @ rows[DELAYED_STIFFNESS],
                   delayed_viscosity=system.delayed_viscosity - D @ rows[DELAYED_VISCOSITY])
