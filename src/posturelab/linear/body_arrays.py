"""The body's parameters as arrays with a set axis (M sets, or 1 shared), for the batched
linear system (:mod:`.system`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import finite_array
from ..errors import ParameterError
from ..model.body import Body, upright_matrices

__all__ = ["BodyArrays"]


@dataclass(frozen=True)
class BodyArrays:
    """Body parameters per parameter set, for sweeps over the body itself.

    Each per-link array has shape (N,) (shared by every set) or (M, N) (one
    row per set); ``gravity`` is a scalar or shape (M,).

    Parameters
    ----------
    masses : array_like, shape (N,) or (M, N)
        Link masses, lowest link first. [kg]
    lengths : array_like, shape (N,) or (M, N)
        Link lengths. [m]
    com_distances : array_like, shape (N,) or (M, N)
        Centre-of-mass distances from each link's lower joint, in [0, length]. [m]
    inertias : array_like, shape (N,) or (M, N)
        Inertias about each centre of mass. [kg·m²]
    gravity : float or array_like, shape (M,)
        Gravitational acceleration, > 0. [m/s²]
    """

    masses: np.ndarray
    lengths: np.ndarray
    com_distances: np.ndarray
    inertias: np.ndarray
    gravity: float | np.ndarray = 9.81

    def __post_init__(self) -> None:
        fields = {}
        for name, unit in (("masses", "kg"), ("lengths", "m"), ("com_distances", "m"),
                           ("inertias", "kg·m²")):
            arr = finite_array(f"{name} [{unit}]", getattr(self, name))
            if arr.ndim not in (1, 2) or arr.shape[-1] < 1:
                raise ParameterError(
                    f"{name} [{unit}] must have shape (N,) or (M, N), got shape {arr.shape}"
                )
            fields[name] = arr
        n_links = {a.shape[-1] for a in fields.values()}
        if len(n_links) != 1:
            raise ParameterError(
                "masses, lengths, com_distances and inertias must have the same number of "
                f"links (last axis), got {sorted(n_links)}"
            )
        for name in ("masses", "lengths", "inertias"):
            if np.any(fields[name] <= 0):
                raise ParameterError(f"{name} must be > 0, got {fields[name].min():g}")
        com = fields["com_distances"]
        if np.any(com < 0) or np.any(com > fields["lengths"]):
            raise ParameterError("com_distances [m] must lie in [0, length] for every link")
        gravity = finite_array("gravity [m/s²]", self.gravity)
        if gravity.ndim > 1 or np.any(gravity <= 0):
            raise ParameterError("gravity [m/s²] must be > 0, a scalar or shape (M,)")
        for name, arr in fields.items():
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        gravity.setflags(write=False)
        object.__setattr__(self, "gravity", gravity)

    @classmethod
    def from_body(cls, body: Body) -> BodyArrays:
        """The parameters of one :class:`~posturelab.model.body.Body`, shared by every set."""
        return cls(body.masses, body.lengths, body.com_distances, body.inertias, body.gravity)

    @property
    def n_links(self) -> int:
        """Number of links N. [-]"""
        return int(self.masses.shape[-1])

    def set_count(self) -> int | None:
        """Number of sets M the per-set arrays describe, or None when all are shared."""
        counts = {a.shape[0] for a in (self.masses, self.lengths, self.com_distances,
                                       self.inertias) if a.ndim == 2}
        if self.gravity.ndim == 1:
            counts.add(self.gravity.shape[0])
        if len(counts) > 1:
            raise ParameterError(f"body arrays disagree on the number of sets: {sorted(counts)}")
        return counts.pop() if counts else None

    def upright_matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """J(0) and g·a per set: shapes (B, N, N) [kg·m²] and (B, N) [N·m/rad], B = M or 1
        (:func:`posturelab.model.body.upright_matrices`)."""
        count = self.set_count()
        size = 1 if count is None else count
        n = self.n_links
        arrays = [np.broadcast_to(a, (size, n)) for a in (self.masses, self.lengths,
                                                           self.com_distances, self.inertias)]
        jac, gravity_torque = upright_matrices(*arrays, np.broadcast_to(self.gravity, (size,)))
        return jac, np.ascontiguousarray(gravity_torque)
