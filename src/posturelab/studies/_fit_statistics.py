"""The statistics of a time-domain fit (:func:`posturelab.studies.identification.fit_stiffness`):
whether the model describes the data, which parameters the data determine, the covariance
of the estimates under independent or AR(1) residuals, and the restart points.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

#: Largest |predicted angle| [rad] of a model that "predicts no motion" (an upright run
#: without disturbance stays exactly at 0).
_NO_MOTION = 1e-12
#: A fit describes the data when its residual RMS is at most this fraction of the sway's
#: RMS about upright (at 0.5 it explains three quarters of the sway's mean square; a wrong
#: local minimum or a missing disturbance leaves residuals as large as the sway) ... [-]
_DESCRIBES_FRACTION = 0.5
#: ... or when the residuals look like noise: their RMS at most this multiple of the noise
#: level estimated from successive differences (√(mean(Δr²)/2), the RMS of independent
#: noise; a systematic misfit is smooth and its differences small) ... [-]
_NOISE_MULTIPLE = 2.0
#: ... and the model still accounts for at least this share of the sway's mean square
#: (variance accounted for, VAF = 1 − residual²/sway², RMS about upright): residuals that
#: look like noise only say the model is right when the data are more than noise; fitted
#: to white noise, any model leaves residuals as large as the data (VAF ≈ 0) that look
#: like noise too. At 0.25 the residual RMS is at most √0.75 ≈ 0.87 of the sway's (our
#: threshold, not a published one). [-]
_MIN_VAF_WITH_NOISE = 0.25
#: Seeded restarts after a fit that does not describe the data, and their seed. [-]
_RESTARTS = 8
_RESTART_SEED = 20261202
#: A parameter whose change by its scale moves the angles by less than this fraction of
#: the sway (RMS) is one the data do not depend on. [-]
_NO_EFFECT = 1e-6
#: Singular values of the unit-norm Jacobian columns below this count as a dependence
#: between parameters (exactly dependent columns give ~1e-8 from finite differences). [-]
_DEPENDENT = 1e-4


def _describes(residual: np.ndarray, sway: float, n_links: int) -> bool:
    """Whether residuals (sample-major, ``n_links`` per sample) [rad] are small against the
    sway's RMS [rad] (VAF ≥ 0.75), or look like noise while the model accounts for at least
    a quarter of the sway's mean square (the notes of the constants above)."""
    r = residual.reshape(-1, n_links)
    rms = float(np.sqrt(np.mean(r**2)))
    if rms <= _DESCRIBES_FRACTION * sway:
        return True
    if not rms**2 <= (1.0 - _MIN_VAF_WITH_NOISE) * sway**2:
        return False
    noise = float(np.sqrt(np.mean(np.diff(r, axis=0) ** 2) / 2)) if r.shape[0] > 1 else 0.0
    return rms <= _NOISE_MULTIPLE * noise


def _restart_point(rng: np.random.Generator, names: Sequence[str], x0: np.ndarray,
                   lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """A seeded starting point: the delay and the weight uniform in their box, a gain the
    start scaled by 10^U(−1, 1) (within the box). [units of each parameter]"""
    point = np.empty(x0.size)
    for k, name in enumerate(names):
        if name in ("feedback_delay", "proprioceptive_weight") or x0[k] <= 0:
            point[k] = rng.uniform(lower[k], upper[k])
        else:
            point[k] = x0[k] * 10.0 ** rng.uniform(-1.0, 1.0)
    return np.clip(point, lower + 1e-9, upper)


def _determinacy(jac: np.ndarray, scale: np.ndarray, names: Sequence[str], sway: float,
                 samples: int) -> tuple[np.ndarray, list[str]]:
    """Which parameters the data determine, and why not (the others).

    A column of the Jacobian times the parameter's scale (its value, or its start, or
    10⁻³ of its box: never 0, so a parameter at 0 is judged as any other) that moves the
    angles by less than :data:`_NO_EFFECT` of the sway: "the data do not depend on it".
    Columns scaled to unit norm whose singular values fall below :data:`_DEPENDENT`: the
    parameters with a share above :data:`_NULL_SHARE` of such a direction are "not
    separable from" the others in it.
    """
    p = jac.shape[1]
    reasons = [""] * p
    effect = np.linalg.norm(jac, axis=0) * scale / math.sqrt(max(samples, 1))
    moving = effect > _NO_EFFECT * max(sway, 1e-12)
    for k in np.flatnonzero(~moving):
        reasons[k] = "the data do not depend on it"
    idx = np.flatnonzero(moving)
    if idx.size > 1:
        cols = jac[:, idx] / np.linalg.norm(jac[:, idx], axis=0)
        _, sv, vt = np.linalg.svd(cols, full_matrices=False)
        for row in vt[sv < _DEPENDENT * sv.max()]:
            involved = idx[np.abs(row) > _NULL_SHARE]
            for k in involved:
                others = [names[j] for j in involved if j != k]
                if others and not reasons[k]:
                    reasons[k] = f"not separable from {', '.join(others)}"
    return np.array([not why for why in reasons]), reasons


#: A parameter whose share of a near-null direction of the scaled Jacobian exceeds this
#: is reported as not identifiable (standard error NaN). [-]
_NULL_SHARE = 0.1
#: Singular values below this fraction of the largest count as null directions. [-]
_RANK_TOLERANCE = 1e-7


def _identifiable(jac: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Which parameters the data determine.

    Judged on the Jacobian scaled by the parameter values, so a parameter the angles do
    not depend on (e.g. a pair that never stretches) is found whatever the noise level.
    """
    scale = np.where(np.abs(x) > 0, np.abs(x), 1.0)
    _, sv, vt = np.linalg.svd(jac * scale, full_matrices=False)
    null = sv < _RANK_TOLERANCE * max(sv.max(), 1e-300)
    bad = np.zeros(x.size, dtype=bool)
    if null.any():
        bad = np.any(np.abs(vt[null]) > _NULL_SHARE, axis=0)
    return ~bad


def _covariance(jac: np.ndarray, x: np.ndarray, s2: float, good: np.ndarray | None = None
                ) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Newton covariance s²(JᵀJ)⁻¹ of independent residuals, with the parameters not
    in ``good`` (default: :func:`_identifiable`) set to NaN."""
    p = x.size
    cov = np.full((p, p), np.nan)
    good = _identifiable(jac, x) if good is None else good
    if good.any():
        jg = jac[:, good]
        cov[np.ix_(good, good)] = s2 * np.linalg.pinv(jg.T @ jg)
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    return cov, se


#: Largest |lag-1 correlation| of a residual series the AR(1) model uses. [-]
_MAX_RHO = 0.99


def ar1_filter_sum(values: np.ndarray, rho: float) -> np.ndarray:
    """Σₛ ρ^|t−s| values[s] for every t (axis 0 is time): a forward and a backward
    first-order recursion (scipy's ``lfilter``), O(S) instead of the S × S matrix.
    [same units]"""
    from scipy.signal import lfilter

    forward = lfilter([1.0], [1.0, -rho], values, axis=0)
    backward = lfilter([1.0], [1.0, -rho], values[::-1], axis=0)[::-1]
    return forward + backward - values


def _ar1_covariance(jac: np.ndarray, x: np.ndarray, residuals: np.ndarray, n_links: int,
                    good: np.ndarray | None = None
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """The sandwich covariance of least squares when each link's residuals are a
    stationary AR(1) series (see the module's notes).

    Returns
    -------
    cov, se : the covariance and standard errors (NaN where not identifiable)
    rho : numpy.ndarray, shape (N,)
        Lag-1 correlation of each link's residuals. [-]
    dof : float
        Effective samples minus parameters (at least 1). [-]
    """
    p = x.size
    r = residuals.reshape(-1, n_links)  # (samples, links): the residual vector is sample-major
    j = jac.reshape(r.shape[0], n_links, p)
    samples = r.shape[0]
    # each link's variance with the textbook correction for the fitted parameters
    shrink = residuals.size / max(residuals.size - p, 1)
    rho = np.zeros(n_links)
    variance = np.zeros(n_links)
    for i in range(n_links):
        ri = r[:, i]
        ss = float(ri @ ri)
        variance[i] = ss / samples * shrink
        if ss > 0 and samples > 2:
            lag1 = float(ri[1:] @ ri[:-1] / ss)
            # Kendall's (1954) correction of the estimator's small-sample bias −(1 + 3ρ)/S
            rho[i] = float(np.clip(lag1 + (1 + 3 * lag1) / samples, -_MAX_RHO, _MAX_RHO))
    # (negative correlation would count more samples than there are: capped at the count)
    effective = float(np.sum(np.minimum(samples, samples * (1 - rho) / (1 + rho))))
    dof = max(effective - p, 1.0)
    cov = np.full((p, p), np.nan)
    good = _identifiable(jac, x) if good is None else good
    if good.any():
        jg = jac[:, good]
        bread = np.linalg.pinv(jg.T @ jg)
        meat = np.zeros((int(good.sum()),) * 2)
        for i in range(n_links):
            ji = j[:, i, :][:, good]
            meat += variance[i] * (ji.T @ ar1_filter_sum(ji, rho[i]))
        cov[np.ix_(good, good)] = bread @ meat @ bread
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    return cov, se, rho, dof
