"""Fitting a controller to frequency response functions (``fit_frf``).

The parameters (``PARAMETERS``; their names, units and bounds are the parameter table's,
:mod:`posturelab.parameters`; ``:PAIR`` names the pair, and may be left out on a body with
one pair):

    stiffness:PAIR, viscosity:PAIR                 intrinsic gains [N·m/rad], [N·m·s/rad]
    active_stiffness:PAIR, active_viscosity:PAIR   active (delayed) gains [N·m/rad], [N·m·s/rad]
    feedback_delay                                 τ [s]
    proprioceptive_weight                          W [-]

Every other parameter keeps the value of the starting ``muscles`` and options. With several
conditions (for example tilts of different amplitudes) the ``free`` parameters are shared
and the ``per_condition`` ones take a value per condition (Peterka 2002 let W vary with the
stimulus amplitude).

The model's band FRF is averaged over each band's harmonics with the stimulus's power, as
the estimate is (:meth:`FRFEstimate.band_average`), so that band averaging adds no bias.

Objective: the complex error of the model against each band's estimate, weighted by that
band's 95 % bound radius ρ_k = r_k |Ĥ_k| (:mod:`.estimate`), so that every band counts by its
precision:  Σ_k |H(f_k; p) − Ĥ_k|² / ρ_k²  (real and imaginary parts as residuals; a band
whose bound is undefined weighs as 1/|Ĥ_k|²). Since ρ ≈ 2.45 σ for the 95 % circle of a
complex normal error, the weighted residuals have unit variance by construction, and the
covariance is max(1, s²)(JᵀJ)⁻¹: s², the fit's own residual variance, only inflates it when
the model does not explain the data (s² computed from the data's own weights runs below 1,
about 0.5, because bands that happen to scatter more also get wider bounds; taking it at
face value made the intervals 1.4× too narrow in the tests). The 95 % intervals are t-based.
A parameter the residuals do not depend on, whose relative standard error exceeds 1, or
that the Jacobian cannot separate (condition number above 1e10), is reported as not
determined. Bands with coherence below 0.5 raise a
warning in ``warnings``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from ..model.body import Body
from ..model.muscles import MuscleSet
from ..parameters import QUANTITIES, check_value, resolve
from ..parameters import unit as parameter_unit
from .estimate import FRFEstimate
from .model import model_frf_batch

__all__ = ["FRFFit", "fit_frf", "PARAMETERS"]

PARAMETERS = ("stiffness", "viscosity", "active_stiffness", "active_viscosity",
              "feedback_delay", "proprioceptive_weight")
#: The default search interval of each parameter: the table's lower bound to its fit_high.
_DEFAULT_BOUNDS = {name: (QUANTITIES[name].low, QUANTITIES[name].fit_high)
                   for name in PARAMETERS}


@dataclass(frozen=True)
class FRFFit:
    """The result of :func:`fit_frf`.

    Attributes
    ----------
    names : tuple of str
        Fitted parameters; per-condition ones as ``name#k`` (k from 1).
    estimates, standard_errors : numpy.ndarray
        In the parameters' units (:func:`unit`).
    confidence_intervals : numpy.ndarray, shape (K, 2)
        95 %.
    determined : numpy.ndarray of bool
        False for a parameter the data cannot determine.
    fit_error : float
        RMS of the weighted residuals (≈ 1 when the model explains the data within its noise).
    success : bool
    message : str
    warnings : tuple of str
    curves : tuple of (numpy.ndarray, numpy.ndarray)
        Per condition, the fitted model's FRF (complex) on 200 log-spaced frequencies [Hz]
        from a third below the lowest band to a half above the highest (for plots).
    """

    names: tuple[str, ...]
    estimates: np.ndarray
    standard_errors: np.ndarray
    confidence_intervals: np.ndarray
    determined: np.ndarray
    fit_error: float
    success: bool
    message: str
    warnings: tuple[str, ...] = ()
    curves: tuple = field(default=(), repr=False)

    def unit(self, name: str) -> str:
        """Unit of a fitted parameter."""
        return parameter_unit(name)

    def to_dict(self) -> dict:
        """Plain-Python summary."""
        return {"parameters": [
            {"name": n, "unit": self.unit(n), "estimate": float(e), "standard_error": float(s),
             "ci95": [float(lo), float(hi)], "determined": bool(d)}
            for n, e, s, (lo, hi), d in zip(self.names, self.estimates, self.standard_errors,
                                             self.confidence_intervals, self.determined,
                                             strict=True)],
            "fit_error": float(self.fit_error), "success": bool(self.success),
            "message": self.message, "warnings": list(self.warnings)}


def _name(name: str, muscles: MuscleSet) -> str:
    """The one spelling of an FRF fit parameter (the parameter table's)."""
    return resolve(name, muscles.names, (), accepts=PARAMETERS, what="FRF fit parameter")


def _parse(name: str, muscles: MuscleSet) -> tuple[str, int | None]:
    base, _, pair = _name(name, muscles).partition(":")
    return base, muscles.names.index(pair) if pair else None


def _checked_bounds(bounds, muscles: MuscleSet) -> dict:
    """``bounds`` keyed by each name's one spelling, every end within the table's bounds."""
    out = {}
    for key, (low, high) in dict(bounds or {}).items():
        name = _name(key, muscles)
        out[name] = (check_value(name, low, f"bound {name} LO"),
                     check_value(name, high, f"bound {name} HI"))
    return out


def fit_frf(body: Body, muscles: MuscleSet, data, free, *, input: str = "tilt",
            output: str = "com_angle", feedback_delay: float = 0.0,
            proprioceptive_weight: float = 1.0, per_condition=(), bounds=None) -> FRFFit:
    """Fit controller parameters to one or several FRF estimates (module notes).

    Parameters
    ----------
    body : Body
    muscles : MuscleSet
        The starting gains (intrinsic and active).
    data : FRFEstimate or sequence of FRFEstimate
        One per condition.
    free : sequence of str
        Parameters shared by all conditions.
    input, output : str
        As for :func:`posturelab.frequency.model_frf`.
    feedback_delay, proprioceptive_weight : float
        Starting values. [s], [-]
    per_condition : sequence of str
        Parameters fitted separately for each condition.
    bounds : dict of name -> (low, high), optional
        Within the parameter table's bounds; defaults: the table's search intervals (gains
        [0, 1e5], delay [0, 1] s, W [0, 1]).
    """
    from scipy.optimize import least_squares
    from scipy.stats import t as student

    free = [_name(n, muscles) for n in ([free] if isinstance(free, str) else free)]
    per = [_name(n, muscles) for n in ([per_condition] if isinstance(per_condition, str)
                                       else per_condition)]
    if not free and not per:
        raise ParameterError("give at least one parameter to fit")
    if set(free) & set(per):
        raise ParameterError(f"{sorted(set(free) & set(per))[0]!r} is both shared and "
                             "per condition")
    for names in (free, per):  # by their one spelling: stiffness and stiffness:ankle alike
        if len(set(names)) != len(names):
            twice = sorted({n for n in names if names.count(n) > 1})[0]
            raise ParameterError(f"{twice!r} is named more than once")
    specs = [_parse(n, muscles) for n in free + per]
    bounds = _checked_bounds(bounds, muscles)
    conditions = [data] if isinstance(data, FRFEstimate) else list(data)
    if not conditions or not all(isinstance(c, FRFEstimate) for c in conditions):
        raise ParameterError("data must be one FRFEstimate or a list of them")
    base = np.stack([muscles.stiffnesses, muscles.viscosities, muscles.active_stiffnesses,
                     muscles.active_viscosities])
    C = len(conditions)
    slots = [(i, None) for i in range(len(free))] + [
        (len(free) + j, k) for j in range(len(per)) for k in range(C)]
    labels = free + [f"{per[j]}#{k + 1}" for j in range(len(per)) for k in range(C)]

    def start(name: str, spec) -> float:
        b, j = spec
        row = {"stiffness": 0, "viscosity": 1, "active_stiffness": 2, "active_viscosity": 3}
        if b == "feedback_delay":
            return feedback_delay
        if b == "proprioceptive_weight":
            return proprioceptive_weight
        return float(base[row[b], j])

    names_all = free + per
    x0 = np.array([start(names_all[i], specs[i]) for i, _ in slots])
    lo = np.array([bounds.get(names_all[i], _DEFAULT_BOUNDS[specs[i][0]])[0] for i, _ in slots])
    hi = np.array([bounds.get(names_all[i], _DEFAULT_BOUNDS[specs[i][0]])[1] for i, _ in slots])
    if np.any(lo >= hi):
        raise ParameterError("every bound needs low < high")
    x0 = np.clip(x0, lo + 1e-9 * (hi - lo), hi - 1e-9 * (hi - lo))
    scale = np.maximum(np.abs(x0), 1e-3 * np.maximum(hi - lo, 1e-12))
    weights, targets = [], []
    for c in conditions:
        radius = (c.gain_ci95[:, 1] - c.gain) if np.all(np.isfinite(c.gain_ci95)) \
            else np.full(c.gain.shape, np.nan)
        rho = np.where(np.isfinite(radius) & (radius > 0), radius / 2.4477, np.abs(c.frf))
        weights.append(1.0 / np.maximum(rho, 1e-300))
        targets.append(c.frf)
    warnings = tuple(f"condition {k + 1}: coherence below 0.5 at {int(np.sum(c.coherence < 0.5))}"
                     " band(s)" for k, c in enumerate(conditions) if np.any(c.coherence < 0.5))

    def model(p: np.ndarray, dense: bool = False) -> list:
        out = []
        for k, c in enumerate(conditions):
            gains = base.copy()
            tau, w = feedback_delay, proprioceptive_weight
            for (i, cond), value in zip(slots, p, strict=True):
                if cond is not None and cond != k:
                    continue
                b, j = specs[i]
                if b == "feedback_delay":
                    tau = value
                elif b == "proprioceptive_weight":
                    w = value
                else:
                    gains[("stiffness", "viscosity", "active_stiffness",
                           "active_viscosity").index(b), j] = value
            active = muscles.has_active_feedback or any(
                specs[i][0].startswith("active") for i, _ in slots)
            def frf_at(f, gains=gains, tau=tau, w=w, active=active):
                return model_frf_batch(body, muscles, f, gains[0][None], gains[1][None],
                                       gains[2][None] if active else None,
                                       gains[3][None] if active else None, tau, w,
                                       input=input, output=output)[0]

            if dense:
                f = np.geomspace(c.frequency.min() / 1.5, c.frequency.max() * 1.5, 200)
                out.append((f, frf_at(f)))
            else:
                out.append(c.band_average(frf_at) if c.harmonic_weight
                           else frf_at(c.frequency))
        return out

    def residuals(z: np.ndarray) -> np.ndarray:
        H = model(z * scale)
        parts = [w * (h - t) for w, h, t in zip(weights, H, targets, strict=True)]
        r = np.concatenate(parts)
        return np.concatenate([r.real, r.imag])

    sol = least_squares(residuals, x0 / scale, bounds=(lo / scale, hi / scale), x_scale=1.0,
                        method="trf")
    p = sol.x * scale
    m, k = sol.fun.size, p.size
    dof = max(m - k, 1)
    s2 = float(sol.fun @ sol.fun) / dof
    J = sol.jac / scale[None, :]  # d residual / d parameter, in the parameters' units
    # a parameter the residuals do not depend on cannot be determined; the rest are
    # judged by the conditioning of their own columns
    norms = np.linalg.norm(J, axis=0)
    seen = norms > 1e-10 * max(float(norms.max()), 1e-300)
    se = np.full(k, np.inf)
    cond = np.inf
    if seen.any():
        Js = J[:, seen]
        sv = np.linalg.svd(Js, compute_uv=False)
        cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else np.inf
        if np.isfinite(cond):
            cov = max(s2, 1.0) * np.linalg.inv(Js.T @ Js)
            se[seen] = np.sqrt(np.maximum(np.diag(cov), 0.0))
    q = float(student.ppf(0.975, dof))
    ci = np.stack([p - q * se, p + q * se], axis=1)
    determined = seen & np.isfinite(se) & (se <= np.abs(p)) & (cond < 1e10)
    return FRFFit(tuple(labels), p, se, ci, determined, float(np.sqrt(s2)), bool(sol.success),
                  str(sol.message), warnings, tuple(model(p, dense=True)))
