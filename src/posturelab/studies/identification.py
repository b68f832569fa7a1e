"""Fit muscle-pair stiffness (and the viscosity ratio) to measured trajectories.

The paper's closing paragraph proposes it: combined with measured
trajectories and optimisation, the model estimates the stiffness matrix.
:func:`fit_stiffness` runs the nonlinear simulation of a scenario inside a
least-squares fit (scipy's trust-region reflective ``least_squares``) of the
link angles to measured ones, and reports each estimate with a standard
error, a 95 % confidence interval and the correlation between estimates.

The uncertainty. Measured sway residuals are rarely independent from sample to
sample (low-pass sensor noise, unmodelled slow sway, motor noise), and the textbook
Gauss–Newton covariance s²(JᵀJ)⁻¹ then makes the intervals far too narrow: with
AR(1) noise of lag-1 correlation 0.5 its 95 % intervals covered the truth in 73 % of
seeded trials, at 0.8 in 47 %. By default (``residual_model="ar1"``) each link's
residual series is modelled as a stationary first-order autoregression, with its
own variance σᵢ² and lag-1 correlation ρᵢ estimated from the residuals, and the
covariance is the sandwich (JᵀJ)⁻¹ (Σᵢ Jᵢᵀ Σᵢ Jᵢ) (JᵀJ)⁻¹ with
(Σᵢ)ₛₜ = σᵢ² ρᵢ^|s−t|; the interval uses Student's t with the effective degrees of
freedom Σᵢ Sᵢ(1 − ρᵢ)/(1 + ρᵢ) − P. For independent residuals (ρᵢ ≈ 0) it is the
textbook covariance; ``residual_model="independent"`` forces that one.
``examples/fit_coverage.py`` measures the coverage of both (its table: docs/design.md).

Does the fit describe the data. The fit's variance accounted for, VAF = 1 − r²/σ²
(r the residual RMS, σ the measured angles' RMS about upright, ``sway_rms``), must be at
least 0.75 (r ≤ σ/2), or the residuals must look like noise (r at most twice the noise
level from successive differences) while VAF is still at least 0.25: fitted to white
noise any model leaves residuals as large as the data (VAF ≈ 0), which look like noise
too. Otherwise ``describes_data`` is False, ``success`` False and ``warning`` says so
(after seeded restarts from other starting points).

The model of viscosity: every pair's viscosity is ``viscosity_ratio`` times
its stiffness (the paper's L_d = 0.25 K_d); the ratio is fixed or fitted.

The simulations run on the compiled engine (at the scenario's tolerances) by
default, or on the reference engine with ``engine="reference"``; both do every
feature of a scenario (torque limits, feedback delay, centre-of-pressure falls).
scipy's optimiser and statistics are imported when a fit runs.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .._bounds import at_bound, bound_note, clip_intervals
from .._validation import finite_array
from ..errors import DataFileError, ParameterError, PostureLabError, UnknownNameError
from ..model.muscles import MuscleSet
from ..parameters import FIT_MAX_GAIN, QUANTITIES, resolve
from ..parameters import unit as parameter_unit
from ..scenarios import Scenario
from ._fit_statistics import (
    _NO_MOTION,
    _RESTART_SEED,
    _RESTARTS,
    _ar1_covariance,
    _covariance,
    _describes,
    _determinacy,
    _restart_point,
    ar1_filter_sum,
)

if TYPE_CHECKING:  # (loaded when a fit runs: posturelab fit --help stays light)
    from ..simulation.results import SimulationResult

__all__ = ["FitResult", "FitError", "fit_stiffness", "read_trajectory_csv", "ar1_filter_sum"]


class FitError(PostureLabError):
    """A fit that cannot go on: a simulation inside it failed (a spent step or time
    budget, a non-finite state, …)."""

VISCOSITY_RATIO = "viscosity_ratio"
#: The sensory weights W_p, W_v (their sum at most 1).
WEIGHTS = ("proprioceptive_weight", "visual_weight")
#: The quantities of the parameter table a time-domain fit can free.
FIT_QUANTITIES = ("stiffness", "viscosity", "active_stiffness", "active_viscosity",
                  "viscosity_ratio", "feedback_delay", "proprioceptive_weight",
                  "visual_weight", "torque_feedback_gain", "torque_feedback_time_constant",
                  "joint_feedback_scale")
#: How the uncertainty treats the residuals (:func:`fit_stiffness`).
RESIDUAL_MODELS = ("ar1", "independent")
#: The engines ``fit_stiffness`` can run the model on ("fast" is a former name of "compiled").
ENGINES = ("compiled", "reference", "fast")


@dataclass(frozen=True)
class FitResult:
    """Estimates of pair stiffness [N·m/rad] (and viscosity ratio [s]) with uncertainty.

    Attributes
    ----------
    parameter_names : tuple of str
        Fitted parameters, by their names in the parameter table (``stiffness:ankle``
        [N·m/rad], ``viscosity_ratio`` [s], ...).
    estimates : numpy.ndarray, shape (P,)
        Best-fit values. [N·m/rad] or [s]
    standard_errors : numpy.ndarray, shape (P,)
        From the covariance s²(JᵀJ)⁻¹; NaN when not identifiable. [same units]
    confidence_intervals : numpy.ndarray, shape (P, 2)
        95 % intervals, estimate ± t₀.₉₇₅ · standard error. [same units]
    correlation : numpy.ndarray, shape (P, P)
        Correlation between the estimates. [-]
    residual_rms : float
        Root-mean-square angle residual. [rad]
    n_samples : int
        Number of residuals (samples × links). [-]
    success : bool
        Whether the optimiser converged.
    message : str
        The optimiser's message.
    n_simulations : int
        Simulations run by the fit. [-]
    fitted : SimulationResult
        The simulation at the estimates.
    residual_model : {"ar1", "independent"}
        How the covariance treats the residuals (see the module's notes).
    residual_autocorrelation : numpy.ndarray, shape (N,)
        Lag-1 correlation ρᵢ of each link's residual series (0 for "independent"
        fits: not used). [-]
    degrees_of_freedom : float
        Of the t quantile of the intervals: effective samples minus parameters. [-]
    determined : numpy.ndarray of bool, shape (P,)
        Whether the data determine each parameter (else its standard error and interval
        are NaN and ``undetermined_reasons`` says why).
    undetermined_reasons : tuple of str
        Why each parameter cannot be determined ("" where it can).
    converged : bool
        Whether the optimiser converged (its own criterion, within the simulation budget).
    describes_data : bool
        Whether the fitted model describes the data (module notes, "Does the fit describe
        the data"); ``success`` is ``converged and describes_data``.
    sway_rms : float
        RMS of the measured angles about upright, the residual's yardstick. [rad]
    n_starts : int
        Starting points the optimiser ran from (1, or more after a fit that did not
        describe the data). [-]
    warning : str
        One line on why the fit is not a success ("" when it is).
    at_bound : tuple of {"low", "high", None}
        Per parameter, the search bound its estimate stopped on (within 1e-6 of the box's
        width, :mod:`posturelab._bounds`); such a parameter is not determined.
    clipped : numpy.ndarray of bool, shape (P,), or None
        Whether the interval was clipped to the parameter's accepted range (the parameter
        table) or its search box.
    """

    parameter_names: tuple[str, ...]
    estimates: np.ndarray
    standard_errors: np.ndarray
    confidence_intervals: np.ndarray
    correlation: np.ndarray
    residual_rms: float
    n_samples: int
    success: bool
    message: str
    n_simulations: int
    fitted: SimulationResult
    residual_model: str = "independent"
    residual_autocorrelation: np.ndarray | None = None
    degrees_of_freedom: float = math.nan
    determined: np.ndarray | None = None
    undetermined_reasons: tuple[str, ...] = ()
    converged: bool = True
    describes_data: bool = True
    sway_rms: float = math.nan
    n_starts: int = 1
    warning: str = ""
    at_bound: tuple = ()
    clipped: np.ndarray | None = None

    def to_dict(self) -> dict:
        """Plain-Python summary for JSON: units as in the attribute docs. An undetermined
        parameter has ``"determined": false``, a ``"reason"`` and null error and interval;
        a fit that is not a success has null intervals (they would not be trustworthy)."""
        determined = (np.ones(len(self.parameter_names), dtype=bool)
                      if self.determined is None else self.determined)
        reasons = self.undetermined_reasons or ("",) * len(self.parameter_names)
        sides = self.at_bound or (None,) * len(self.parameter_names)
        clipped = (np.zeros(len(self.parameter_names), dtype=bool) if self.clipped is None
                   else self.clipped)
        parameters = {}
        for name, e, se, (lo, hi), ok, why, side, cut in zip(
                self.parameter_names, self.estimates, self.standard_errors,
                self.confidence_intervals, determined, reasons, sides, clipped, strict=True):
            ok = bool(ok) and math.isfinite(se)
            parameters[name] = {
                "estimate": float(e),
                "determined": ok,
                "standard_error": float(se) if ok else None,
                "ci95": [float(lo), float(hi)] if ok and self.success else None,
                "unit": parameter_unit(name),
                "at_bound": side,
                "ci95_clipped": bool(cut) and ok,
            }
            if not ok:
                parameters[name]["reason"] = why or "its standard error is not finite"
        return {
            "parameters": parameters,
            "residual_rms": float(self.residual_rms),
            "sway_rms": float(self.sway_rms),
            "n_samples": int(self.n_samples),
            "success": bool(self.success),
            "converged": bool(self.converged),
            "describes_data": bool(self.describes_data),
            "warning": self.warning or None,
            "n_starts": int(self.n_starts),
            "message": self.message,
            "n_simulations": int(self.n_simulations),
            "residual_model": self.residual_model,
            "residual_autocorrelation": (
                None if self.residual_autocorrelation is None
                else [float(v) for v in self.residual_autocorrelation]),
            "degrees_of_freedom": float(self.degrees_of_freedom),
        }


def _muscles_with(muscles: MuscleSet, stiffness: dict[str, float], ratio: float,
                  viscosity: dict[str, float] | None = None) -> MuscleSet:
    viscosity = viscosity or {}
    pairs = tuple(
        replace(p, stiffness=stiffness.get(p.name, p.stiffness),
                viscosity=viscosity.get(p.name, ratio * stiffness.get(p.name, p.stiffness)))
        for p in muscles.pairs
    )
    return MuscleSet(pairs, muscles.n_links)


def fit_stiffness(
    scenario: Scenario,
    time: Sequence[float],
    theta: np.ndarray,
    free: Sequence[str],
    *,
    viscosity_ratio: float = 0.25,
    initial_guess: Sequence[float] | None = None,
    upper_bound: float = FIT_MAX_GAIN,
    max_simulations: int = 400,
    engine: str = "compiled",
    residual_model: str = "ar1",
) -> FitResult:
    """Fit pair stiffnesses (and optionally the viscosity ratio) to measured angles.

    Parameters
    ----------
    scenario : Scenario
        Body, disturbance, initial state and the muscle pairs; the pairs
        not named in ``free`` keep their stiffness.
    time : array_like, shape (S,)
        Measurement times, increasing, within [0, scenario.duration]. [s]
    theta : array_like, shape (S, N)
        Measured link angles. [rad]
    free : sequence of str
        Names from the parameter table (:mod:`posturelab.parameters`):
        ``"stiffness:PAIR"`` [N·m/rad] (intrinsic, with active gains),
        ``"viscosity:PAIR"`` [N·m·s/rad] (else ratio × stiffness),
        ``"active_stiffness:PAIR"`` [N·m/rad], ``"active_viscosity:PAIR"`` [N·m·s/rad],
        ``"viscosity_ratio"`` [s], ``"feedback_delay"`` [s], ``"proprioceptive_weight"``
        [-], ``"visual_weight"`` [-] (W_v, under the scenario's visual-scene tilt; searched
        up to 1 − W, the other weight held: one of the two weights at a time; started at
        the scenario's W_v, or (1 − W)/2 when that is 0),
        ``"torque_feedback_gain"`` [-] and ``"torque_feedback_time_constant"`` [s]
        (Peterka 2002's torque feedback, on either engine),
        ``"joint_feedback_scale"`` [-] (the factor on the experiment's joint controller,
        :mod:`posturelab.model.joint_feedback`); a former
        spelling (``"ankle"``, ``"active_ankle"``) is refused naming the new.
    viscosity_ratio : float
        Viscosity / stiffness for every pair when the ratio is not fitted,
        and its starting value when it is. [s]
    initial_guess : sequence of float, optional
        Starting values in the order of ``free``; default: the scenario's
        stiffness (or 500 N·m/rad where that is 0) and ``viscosity_ratio``.
    upper_bound : float
        Largest pair gain searched (at most the table's bound). [N·m/rad], [N·m·s/rad]
    max_simulations : int
        Budget of simulations for the optimiser.
    engine : {"compiled", "reference"}
        Which engine runs the model: the compiled one (default) or the reference
        (scipy); either at the scenario's tolerances and ``solver.method``
        (:meth:`posturelab.Scenario.run`); "fast" is a former name of "compiled".
    residual_model : {"ar1", "independent"}
        The residuals' correlation model of the standard errors and intervals: a
        first-order autoregression per link, estimated from the residuals (default), or
        independent samples (the textbook s²(JᵀJ)⁻¹). The estimates do not depend on it.

    Returns
    -------
    FitResult

    Raises
    ------
    FitError
        A simulation inside the fit failed (its message is given): the fit never uses a
        run that stopped short.
    """
    from scipy import stats
    from scipy.optimize import least_squares

    if engine not in ENGINES:
        raise ParameterError(f"engine must be one of {', '.join(ENGINES)}, got {engine!r}")
    if residual_model not in RESIDUAL_MODELS:
        raise UnknownNameError(f"unknown residual_model {residual_model!r}; known: "
                               f"{', '.join(RESIDUAL_MODELS)}")
    if isinstance(free, str):
        free = [free]
    if not list(free):
        raise ParameterError("free must name at least one parameter (stiffness:PAIR, ...)")
    pairs = scenario.muscles.names
    names = [resolve(nm, pairs, (), accepts=FIT_QUANTITIES)
             for nm in free]
    if len(set(names)) != len(names):
        raise ParameterError(f"free names must be unique, got {names}")
    control = scenario.options.joint_feedback
    _check_weight_names(scenario, names)
    if "joint_feedback_scale" in names and control is None:
        raise ParameterError("joint_feedback_scale scales the experiment's joint controller, "
                             "and it has none: give --controller multijoint-default")
    n = scenario.body.n_links
    t = finite_array("time [s]", time, (None,))
    th = finite_array("theta [rad]", theta, (t.size, n))
    if t.size < len(names) + 1:
        raise ParameterError(f"need more than {len(names)} samples, got {t.size}")
    if np.any(np.diff(t) <= 0):
        raise ParameterError("time [s] must be strictly increasing")
    if t[0] < 0 or t[-1] > scenario.options.duration + 1e-9:
        raise ParameterError(
            f"time [s] must lie within [0, duration={scenario.options.duration:g}], got "
            f"[{t[0]:g}, {t[-1]:g}]"
        )
    m0 = scenario.muscles
    current = {**{f"stiffness:{p}": v for p, v in zip(pairs, m0.stiffnesses, strict=True)},
               **{f"viscosity:{p}": viscosity_ratio * v
                  for p, v in zip(pairs, m0.stiffnesses, strict=True)},
               **{f"active_stiffness:{p}": v
                  for p, v in zip(pairs, m0.active_stiffnesses, strict=True)},
               **{f"active_viscosity:{p}": v
                  for p, v in zip(pairs, m0.active_viscosities, strict=True)}}
    special = {VISCOSITY_RATIO: viscosity_ratio,
               "feedback_delay": scenario.options.feedback_delay or 0.1,
               "proprioceptive_weight": scenario.options.proprioceptive_weight,
               # (from 0 the relative finite-difference step would be lost in the noise)
               "visual_weight": scenario.options.visual_weight
               or 0.5 * (1.0 - scenario.options.proprioceptive_weight),
               "torque_feedback_gain": scenario.options.torque_feedback_gain,
               "torque_feedback_time_constant": scenario.options.torque_feedback_time_constant,
               "joint_feedback_scale": 1.0 if control is None else control.scale}
    if initial_guess is None:
        x0 = [special[nm] if nm in special else (current[nm] or 500.0) for nm in names]
    else:
        x0 = list(finite_array("initial_guess", initial_guess, (len(names),)))
    # (a range open at its lower end, τ_t's, is searched from 0.5 s as fit-frf does)
    lower = np.array([0.5 if QUANTITIES[nm.partition(":")[0]].low_open
                      else QUANTITIES[nm.partition(":")[0]].low for nm in names])
    # the search box: the table's fit interval (pair gains: upper_bound, within the table's)
    upper = np.array([QUANTITIES[nm].fit_high if nm in special
                      else min(upper_bound, QUANTITIES[nm.partition(":")[0]].high)
                      for nm in names])
    for k, nm in enumerate(names):  # W_p + W_v <= 1: a weight's box ends at 1 − the other's
        if nm in WEIGHTS:
            other = WEIGHTS[1 - WEIGHTS.index(nm)]
            upper[k] = min(upper[k], 1.0 - getattr(scenario.options, other))
            if upper[k] <= lower[k]:
                raise ParameterError(f"{nm} cannot be fitted: {other} is "
                                     f"{getattr(scenario.options, other):g}, leaving it no "
                                     "room below 1 (their sum is at most 1)")
    x0 = np.clip(np.asarray(x0, dtype=float), lower + 1e-9, upper)
    sc = scenario.replace(duration=float(t[-1]) if t[-1] > 0 else scenario.options.duration)
    count = [0]

    def run(params: np.ndarray) -> SimulationResult:
        count[0] += 1
        value = dict(zip(names, params, strict=True))
        stiff = {nm.removeprefix("stiffness:"): v for nm, v in value.items()
                 if nm.startswith("stiffness:")}
        visc = {nm.removeprefix("viscosity:"): v for nm, v in value.items()
                if nm.startswith("viscosity:")}
        ratio = value.get(VISCOSITY_RATIO, viscosity_ratio)
        muscles = _muscles_with(scenario.muscles, stiff, ratio, visc)
        if control is not None and not (stiff or visc or VISCOSITY_RATIO in value):
            muscles = scenario.muscles  # (a joint controller's own pairs, none of them free)
        if any(nm.startswith("active_") for nm in names):
            ka = [value.get(f"active_stiffness:{p}", current[f"active_stiffness:{p}"])
                  for p in pairs]
            va = [value.get(f"active_viscosity:{p}", current[f"active_viscosity:{p}"])
                  for p in pairs]
            muscles = muscles.with_active_feedback(ka, va)
        trial = sc.replace(
            muscles=muscles,
            feedback_delay=value.get("feedback_delay", sc.options.feedback_delay),
            proprioceptive_weight=value.get("proprioceptive_weight",
                                            sc.options.proprioceptive_weight),
            visual_weight=value.get("visual_weight", sc.options.visual_weight),
            torque_feedback_gain=value.get("torque_feedback_gain",
                                           sc.options.torque_feedback_gain),
            torque_feedback_time_constant=value.get("torque_feedback_time_constant",
                                                    sc.options.torque_feedback_time_constant),
            joint_feedback=(control if "joint_feedback_scale" not in value
                            else control.scaled(value["joint_feedback_scale"])))
        result = trial.run(engine=engine)
        if result.status == "failed":  # never fit to a run that stopped short
            shown = ", ".join(f"{nm} = {v:.6g}" for nm, v in value.items())
            raise FitError(f"a simulation inside the fit failed at {shown}: {result.message}")
        return result

    def predicted(params: np.ndarray) -> np.ndarray:
        r = run(params)
        # a run that fell stops early: hold its last state (a large, smooth residual)
        return np.column_stack([np.interp(t, r.time, r.theta[:, i]) for i in range(n)])

    def residuals(params: np.ndarray) -> np.ndarray:
        return (predicted(params) - th).ravel()

    if np.max(np.abs(predicted(x0))) <= _NO_MOTION:
        raise FitError("the model predicts no motion for this experiment (upright, no "
                       "disturbance, no tilt): check --disturbance/--tilt")
    sway = float(np.sqrt(np.mean(th**2)))

    # A relative step of 1e-6 keeps finite differences well above the integrator's error
    # (rtol 1e-8), so the Jacobian, and with it the standard errors, are not noise.
    def solve(start: np.ndarray):
        return least_squares(residuals, start, bounds=(lower, upper), x_scale="jac",
                             max_nfev=max_simulations, method="trf", diff_step=1e-6)

    sol = solve(x0)
    starts = 1
    if not _describes(sol.fun, sway, n):
        # a local minimum (or a stall): seeded restarts, the best kept
        rng = np.random.default_rng(_RESTART_SEED)
        for _ in range(_RESTARTS):
            starts += 1
            try:
                other = solve(_restart_point(rng, names, x0, lower, upper))
            except FitError:  # a start whose simulations fail is skipped, not fatal
                continue
            if other.cost < sol.cost:
                sol = other
            if _describes(sol.fun, sway, n):
                break
    converged = bool(sol.status > 0)
    describes = _describes(sol.fun, sway, n)
    rms = float(np.sqrt(np.mean(sol.fun**2)))
    # The Jacobian again, with steps of 1e-6 of each parameter's scale (its value, its start
    # or 1e-3 of its box): the optimiser's steps are relative to the value, and at a value
    # near 0 (an active gain at its bound) they are too small to move the simulation.
    scale = np.maximum.reduce([np.abs(sol.x), np.abs(x0), 1e-3 * (upper - lower)])
    jac = np.empty_like(sol.jac)
    for k in range(len(names)):
        step = np.zeros(len(names))
        step[k] = 1e-6 * scale[k] * (1.0 if sol.x[k] + 1e-6 * scale[k] <= upper[k] else -1.0)
        jac[:, k] = (residuals(sol.x + step) - sol.fun) / step[k]
    good, reasons = _determinacy(jac, scale, names, sway, t.size)
    if residual_model == "ar1":
        cov, se, rho, dof = _ar1_covariance(jac, sol.x, sol.fun, n, good=good)
    else:
        dof = max(sol.fun.size - len(names), 1)
        cov, se = _covariance(jac, sol.x, float(sol.fun @ sol.fun) / dof, good=good)
        rho = np.zeros(n)
    sides = at_bound(sol.x, lower, upper)  # an estimate on its search box's edge
    reasons = [why or ("" if side is None else bound_note(nm, side, a, b))
               or ("" if math.isfinite(e) else "its standard error is not finite")
               for why, e, side, nm, a, b in zip(reasons, se, sides, names, lower, upper,
                                                 strict=True)]
    good = np.array([not why for why in reasons])
    se = np.where(good, se, np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(se, se)
    tq = stats.t.ppf(0.975, dof)
    ci, clipped = clip_intervals(names, np.column_stack([sol.x - tq * se, sol.x + tq * se]),
                                 lower, upper)
    warning = ""
    if not describes:
        warning = (f"the fit does not describe the data: residual RMS {rms:.3g} rad against "
                   f"a sway of {sway:.3g} rad RMS (best of {starts} starts); the estimates "
                   "and intervals are not trustworthy")
    elif not converged:
        warning = (f"the optimiser did not converge ({sol.message}); the intervals are not "
                   "trustworthy")
    return FitResult(
        parameter_names=tuple(names), estimates=sol.x.copy(), standard_errors=se,
        confidence_intervals=ci, correlation=corr,
        residual_rms=rms, n_samples=int(sol.fun.size),
        success=converged and describes, message=str(sol.message),
        n_simulations=count[0] + 1,
        fitted=run(sol.x), residual_model=residual_model, residual_autocorrelation=rho,
        degrees_of_freedom=float(dof), determined=good, undetermined_reasons=tuple(reasons),
        converged=converged, describes_data=describes, sway_rms=sway, n_starts=starts,
        warning=warning, at_bound=sides, clipped=clipped,
    )


def read_trajectory_csv(path: str | Path, n_links: int) -> tuple[np.ndarray, np.ndarray]:
    """Read measured link angles (CSV or Parquet): columns ``t`` (or ``time``) [s] and
    ``theta1`` … ``thetaN`` [rad] (a header's ``[deg]`` is converted to rad).

    ``posturelab simulate --out`` writes this format; other columns are ignored.

    Returns
    -------
    time : numpy.ndarray, shape (S,)
        [s]
    theta : numpy.ndarray, shape (S, N)
        [rad]
    """
    from .._files import check_column_unit, csv_rows, read_text
    from .._parquet import is_parquet, parquet_rows

    path = Path(path)
    rows = [r for _, r in (parquet_rows(path, repr(str(path))) if is_parquet(path) else
                           csv_rows(read_text(path, "trajectory"), repr(str(path))))]
    if len(rows) < 3:
        raise DataFileError(f"{str(path)!r} needs a header row and at least 2 samples")
    header = [h.split("[")[0].strip().lower() for h in rows[0]]
    clock = next((c for c in ("t", "time") if c in header), "t")  # as the recordings read
    need = [clock] + [f"theta{i + 1}" for i in range(n_links)]
    missing = [c for c in need if c not in header]
    if missing:
        raise DataFileError(f"{str(path)!r} lacks column {missing[0]!r}; needs a time "
                            f"column (t or time) and {', '.join(need[1:])}")
    idx = [header.index(c) for c in need]
    scale = np.ones(len(need))
    for k, (c, j) in enumerate(zip(need, idx, strict=True)):
        unit = rows[0][j].partition("[")[2].rstrip("] ").strip().lower()
        if c == clock and unit == "ms":
            raise DataFileError(f"{str(path)!r}: column {rows[0][j].strip()!r} is in ms; "
                                "posturelab reads time in s: give --time-unit ms to read "
                                "milliseconds")
        if c != clock and unit == "deg":  # a declared unit is honoured
            scale[k] = np.pi / 180.0
            continue
        check_column_unit(repr(str(path)), rows[0][j], ("s",) if c == clock else ("rad",),
                          "angles in rad and time in s")
    try:
        data = np.array([[float(r[j]) for j in idx] for r in rows[1:]])
    except (ValueError, IndexError):
        raise DataFileError(f"{str(path)!r} has a non-numeric or missing value") from None
    if not np.all(np.isfinite(data)):
        raise DataFileError(f"{str(path)!r} contains NaN or inf")
    if np.any(np.diff(data[:, 0]) <= 0):
        raise DataFileError(f"{str(path)!r}: t must be strictly increasing")
    data = data * scale
    return data[:, 0], data[:, 1:]


def _check_weight_names(scenario: Scenario, names: Sequence[str]) -> None:
    """One line when both weights are free (their sum <= 1 is a constraint the box search
    cannot keep), or W_v is free with no visual-scene tilt (it would act on nothing)."""
    if all(w in names for w in WEIGHTS):
        raise ParameterError("free proprioceptive_weight or visual_weight, not both: their "
                             "sum <= 1 is a constraint this box search cannot keep (posturelab "
                             "fit-frf fits both from a dual-stimulus trial)")
    if "visual_weight" in names and scenario.options.visual_tilt is None:
        raise ParameterError("visual_weight weighs the experiment's visual-scene tilt, and it "
                             "has none: give --visual-tilt or a scenario with [visual_tilt]")
