"""What a fit sees of each condition (private to :mod:`.fit`): the FRF, how its residuals
are whitened (by its variance, its gain and phase errors, or relative), and each band's
statistic as a χ²₂ value. The weighting is stated in :mod:`.fit`'s module notes."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from .estimate import FRFEstimate

__all__ = ["target", "chi2", "SE_FLOOR"]

#: Relative floor of a band's standard error (a noise-free record). [-]
SE_FLOOR = 1e-12


@dataclass(frozen=True)
class _Target:
    """One condition's data as the objective sees them (module notes)."""

    frf: np.ndarray        # Ĥ, (B,)
    kind: str              # "variance", "gain-phase" or "relative"
    sd: np.ndarray         # (2, B): the standard deviations of the two residuals per band
    dof: np.ndarray        # (B,), inf for known standard errors
    cov: np.ndarray | None = None  # (B, B) E[ΔĤ ΔĤ*] when the bands are correlated

    def standardised(self, model: np.ndarray, delta: float) -> np.ndarray:
        """The two residuals per band, whitened, (2, B)."""
        t = self.frf
        if self.kind == "gain-phase":
            g = np.abs(t)
            sd = np.sqrt(self.sd ** 2 + delta ** 2 * np.stack([g ** 2, np.ones_like(g)]))
            return np.stack([(np.abs(model) - g), np.angle(model * np.conj(t))]) / sd
        e = model - t
        if self.cov is not None:  # each part has covariance cov/2
            from scipy.linalg import cholesky, solve_triangular

            V = 0.5 * (self.cov + np.diag(2 * self.sd[0] ** 2 - np.diag(self.cov)
                                          + delta ** 2 * np.abs(t) ** 2))
            try:
                low = cholesky(V, lower=True)
            except np.linalg.LinAlgError:
                raise ParameterError("the bands' covariance is not positive definite"
                                     ) from None
            return np.stack([solve_triangular(low, e.real, lower=True),
                             solve_triangular(low, e.imag, lower=True)])
        sd = np.sqrt(self.sd ** 2 + 0.5 * delta ** 2 * np.abs(t) ** 2)
        return np.stack([e.real, e.imag]) / sd


def target(c, k: int) -> _Target:
    """The :class:`_Target` of condition ``k`` (an FRFEstimate or an FRFTable)."""
    from .table import FRFTable

    if np.all(np.abs(np.asarray(c.frf)) == 0):
        raise ParameterError(f"condition {k + 1}: the FRF is zero at every band (no "
                             "response): there is nothing to fit")
    if isinstance(c, FRFEstimate):
        if not (np.all(np.isfinite(c.frf)) and np.all(np.isfinite(c.frequency))
                and np.all(np.isfinite(c.coherence))):
            raise ParameterError(f"condition {k + 1}: the estimate has a non-finite "
                                 "frequency, FRF or coherence")
        if c.variance.size != c.frf.size or not np.all(np.isfinite(c.variance)):
            raise ParameterError(f"condition {k + 1}: the estimate carries no variance per "
                                 "band (make it with estimate_frf)")
        var = np.maximum(c.variance, (SE_FLOOR * np.abs(c.frf).max()) ** 2)
        sd = np.sqrt(var / 2)
        cov = c.covariance if c.covariance.shape == (c.frf.size,) * 2 else None
        return _Target(c.frf, "variance", np.stack([sd, sd]), np.asarray(c.dof, float), cov)
    if not isinstance(c, FRFTable):
        raise ParameterError(f"condition {k + 1} must be an FRFEstimate or an FRFTable, got "
                             f"{type(c).__name__}")
    dof = np.full(c.frf.size, np.inf) if c.dof is None else np.asarray(c.dof, float)
    floor = SE_FLOOR * np.abs(c.frf).max()
    if c.frf_se is not None:
        sd = np.sqrt(np.maximum(c.frf_se, floor) ** 2 / 2)
        return _Target(c.frf, "variance", np.stack([sd, sd]), dof, c.frf_covariance)
    if c.gain_se is not None:
        sd = np.stack([np.maximum(c.gain_se, floor),
                       np.maximum(np.radians(c.phase_se_deg), SE_FLOOR)])
        return _Target(c.frf, "gain-phase", sd, dof)
    g = np.maximum(np.abs(c.frf), floor)
    return _Target(c.frf, "relative", np.stack([g, g]), np.full(g.size, np.inf))


def chi2(u: np.ndarray, dof: np.ndarray) -> np.ndarray:
    """Each band's statistic as a χ²₂ value of the same probability (module notes)."""
    from scipy.stats import f as fisher

    q = np.sum(u ** 2, axis=0)
    nu = np.where(np.isfinite(dof), dof, 1.0)
    with np.errstate(all="ignore"):
        z = -2.0 * fisher.logsf(q / 2.0, 2, nu)
    return np.where(np.isfinite(dof) & np.isfinite(z), z, q)
