"""Fitting a controller to frequency response functions (``fit_frf``).

The parameters (``PARAMETERS``; their names, units and bounds are the parameter table's,
:mod:`posturelab.parameters`; ``:PAIR`` names the pair, and may be left out on a body with
one pair):

    stiffness:PAIR, viscosity:PAIR                 intrinsic gains [N·m/rad], [N·m·s/rad]
    active_stiffness:PAIR, active_viscosity:PAIR   active (delayed) gains [N·m/rad], [N·m·s/rad]
    feedback_delay                                 τ [s]
    proprioceptive_weight                          W [-]
    visual_weight                                  W_v [-] (Peterka 2002's visual channel)
    torque_feedback_gain                           K_t [-] (Peterka 2002's torque feedback)
    torque_feedback_time_constant                  τ_t [s]

Every other parameter keeps the value of the starting ``muscles`` and options. With several
conditions (for example tilts of different amplitudes) the ``free`` parameters are shared
and the ``per_condition`` ones take a value per condition (Peterka 2002 let W vary with the
stimulus amplitude). Names and bounds are the parameter table's
(:mod:`posturelab.parameters`): a bound must lie within its parameter's range there; a name
given twice (in any spelling), or a bound for a parameter not fitted, is refused.

The model's band FRF is averaged over each band's harmonics with the stimulus's power, as
the estimate is (:meth:`FRFEstimate.band_average`), so that band averaging adds no bias
(taken at the band frequencies instead, the noise-free README trial's fit is off by 2 %
with a 4 % RMS misfit); a table (:class:`~posturelab.frequency.table.FRFTable`) is averaged
the same way when it gives its bands' harmonics (``posturelab frf --json`` writes them),
else the model is taken at its frequencies.

Weighting (``FRFFit.weighting`` says which was used), every band by its own precision:

* ``"variance"`` (an :class:`FRFEstimate`, or a table with ``frf_se``): the complex error
  e = H(f; p) − Ĥ over the bands, whitened by the estimate's band covariance V
  (:mod:`.estimate`: the noise about each harmonic from the scatter of the cycles, pooled
  over neighbouring DFT bins to at least 20 degrees of freedom; COMTEST's bands share
  harmonics, so they are correlated): the real and imaginary parts each have covariance
  V/2, and the fit is generalised least squares (Aitken 1935, Proc R Soc Edinb 55:42–48),
  Σ = eᵀ(V/2)⁻¹e over both parts, with the covariance (JᵀJ)⁻¹ of the whitened Jacobian. A
  table's ``frf_se`` gives V = diag(se²), or its ``frf_covariance`` when it has one
  (``posturelab frf --json``).
* ``"gain-phase"`` (a table with ``gain_se`` and ``phase_se_deg``, as published group means
  come): the residuals (|H| − g)/se_g and wrap(arg H − φ)/se_φ, least squares (ν = ∞ unless
  the table gives ``dof``).
* ``"relative"`` (a table without standard errors): every band weighted by 1/|Ĥ_k| (its
  relative error), the noise level then estimated from the residuals themselves
  (covariance s²(JᵀJ)⁻¹ with s² the residual variance): no test of the model is possible.

Fit error (with precision): each band's statistic is mapped through its own distribution
(F(2, ν_k) for q_k/2) to the χ²₂ value of the same probability, and the fit error is
√(Σ χ² / (2B − K)) (B bands over all conditions, K parameters): about 1 when the model
explains the data within their noise, whatever ν_k. When it is too large for chance
(the χ² exceeds its 0.999 quantile) the model does not describe the data: the result says
so (``mismatch``), and the fit is repeated with a relative model error δ added to every
band's variance (var_k + δ²|Ĥ_k|², and so for gain and phase) with δ chosen so that the
fit error is 1, and ``model_error`` is δ. That fit's intervals treat the model error as
random across bands; a systematic one (the nonlinear plant against the linearised model:
0.1 % at a 0.035 rad PRTS) biases the estimates coherently, so the intervals are widened
on each side by β_k = δ Σ_b |∂p_k/∂e_b| |Ĥ_b| (``systematic``), the most a model error of
δ|Ĥ_b| at every band, in any direction, moves parameter k (linearised). The 95 % intervals
are estimate ± q standard errors (± β_k), q Student's t quantile with the residual dof for
``"relative"``, else with the fewest degrees of freedom of any band's variance (∞ for known
standard errors: q = 1.96), a conservative stand-in for the Satterthwaite dof of each
estimate's variance. A parameter the residuals do not depend on, whose relative standard
error exceeds 1, that the Jacobian cannot separate (condition number above 1e10), or whose
estimate stopped on its search bound (within 1e-6 of the bounds' range: ``at_bound``,
:mod:`posturelab._bounds`) is reported as not determined; every interval is clipped to the
parameter's accepted range (the parameter table) and its search bounds (``clipped``).
Bands with coherence below 0.5 raise a warning in ``warnings``.

Success: a fit with no residual degrees of freedom (2B ≤ K) is refused. A fit is a
success (``success``) only when the optimiser converged, the fitted loop is stable about
upright, and the model describes the data: its variance accounted for, VAF = 1 −
Σ|H − Ĥ|²/Σ|Ĥ|² over every band, is at least 0.5 (the fit error alone cannot tell: a
noise-only response is fitted "within its noise" by almost any loop). Otherwise
``reason`` says which failed and the estimates stay, flagged.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .._bounds import at_bound, clip_intervals
from ..errors import ParameterError, PostureLabError
from ..model.body import Body
from ..model.muscles import MuscleSet
from ..parameters import (
    MAX_FEEDBACK_DELAY,
    QUANTITIES,
    TORQUE_FEEDBACK_TIME_CONSTANT,
    check_value,
    resolve,
)
from ..parameters import unit as parameter_unit
from ._fit_checks import (
    MIN_VARIANCE_ACCOUNTED,
    check_bounds,
    group_conditions,
    loop_verdict,
    systematic_bound,
    variance_accounted_for,
)
from ._fit_targets import chi2 as _chi2
from ._fit_targets import target as _target
from .estimate import FRFEstimate
from .model import model_frf_batch

__all__ = ["FRFFit", "fit_frf", "check_fit_request", "PARAMETERS", "WEIGHTINGS",
           "MISMATCH_P"]

PARAMETERS = ("stiffness", "viscosity", "active_stiffness", "active_viscosity",
              "feedback_delay", "proprioceptive_weight", "torque_feedback_gain",
              "torque_feedback_time_constant", "visual_weight")
#: The lowest τ_t a fit searches by default (the table's range excludes 0). [s]
_MIN_FIT_TIME_CONSTANT = 0.5
#: The default search interval of each parameter: the table's lower bound to its fit_high
#: (for a range open at its lower bound, from a positive value).
_DEFAULT_BOUNDS = {name: (_MIN_FIT_TIME_CONSTANT if QUANTITIES[name].low_open
                          else QUANTITIES[name].low, QUANTITIES[name].fit_high)
                   for name in PARAMETERS}
#: The weightings (module notes).
WEIGHTINGS = {
    "variance": "each band by its own variance (generalised least squares with the "
                "estimate's band covariance, from the cycles' scatter)",
    "gain-phase": "each band's gain and phase by their given standard errors",
    "relative": "no per-band precision given: each band by 1/|H| (relative error); the noise "
                "level estimated from the residuals, so the fit error cannot test the model",
}
#: The probability of a fit error this large by chance below which the model is said not to
#: describe the data. [-]
MISMATCH_P = 1e-3


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
        √(χ²/dof) of the band residuals (module notes; ≈ 1 when the model explains the data
        within their noise), before any model error was allowed. [-]
    success : bool
        The optimiser converged, the fitted loop is stable and the model describes the data
        (``reason`` says which failed; the estimates stay visible, flagged).
    message : str
        The optimiser's message.
    warnings : tuple of str
    curves : tuple of (numpy.ndarray, numpy.ndarray)
        Per condition, the fitted model's FRF (complex) on 200 log-spaced frequencies [Hz]
        from a third below the lowest band to a half above the highest (for plots).
    weighting : str
        ``"variance"``, ``"gain-phase"`` or ``"relative"`` (module notes); with several
        conditions weighted differently, their names joined by ``+``.
    mismatch : bool
        The fit error is too large for the data's noise: the model does not describe them.
    model_error : float
        δ, the relative model error the intervals allow (0 without a mismatch). [-]
    systematic : numpy.ndarray, shape (K,)
        β, the most a systematic model error of δ|Ĥ| per band moves each parameter; the
        intervals are widened by it (0 without a mismatch). [its unit]
    at_bound : tuple of {"low", "high", None}
        Per parameter, the search bound its estimate stopped on (within 1e-6 of the
        bounds' range, :data:`posturelab._bounds.AT_BOUND_TOLERANCE`; then not determined).
    search_bounds : numpy.ndarray, shape (K, 2)
        Each parameter's search interval (LO, HI). [its unit]
    clipped : numpy.ndarray of bool, shape (K,)
        Whether the interval was clipped to the parameter's accepted range (the parameter
        table) or its search interval.
    objective : float
        S = Σ u², the squared whitened residuals at the estimates with the model error δ:
        what the fit minimised (nested fits' S compare in a likelihood-ratio test). [-]
    residual_dof, noise_dof : float
        2B − K, and ν, the degrees of freedom of the noise the intervals use (module notes;
        the residual dof for ``"relative"``, ∞ for known standard errors). [-]
    stable : bool or None
        Whether the fitted loop of every condition is stable about upright at its delay
        (:func:`posturelab.linear.verdict.upright_verdict`, the engaged side); False adds a
        warning: an unstable loop's FRF is not measurable, so the estimates describe no
        experiment, and the fit is not a success. None when not checked.
    converged : bool
        The optimiser met its own criterion.
    variance_accounted_for : float
        VAF = 1 − Σ|H − Ĥ|²/Σ|Ĥ|² over all bands (module notes). [-]
    describes_data : bool
        VAF ≥ :data:`MIN_VARIANCE_ACCOUNTED` (0.5): the model accounts for at least half of
        the measured FRF's variation; otherwise not a success.
    reason : str
        Why the fit is not a success, "; "-joined ("" when it is).
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
    weighting: str = "variance"
    mismatch: bool = False
    model_error: float = 0.0
    systematic: np.ndarray = field(default_factory=lambda: np.zeros(0))
    at_bound: tuple = ()
    search_bounds: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    clipped: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    objective: float = math.nan
    residual_dof: float = math.nan
    noise_dof: float = math.inf
    stable: bool | None = None
    converged: bool = True
    variance_accounted_for: float = math.nan
    describes_data: bool = True
    reason: str = ""

    def unit(self, name: str) -> str:
        """Unit of a fitted parameter."""
        return parameter_unit(name)

    def weighting_text(self) -> str:
        """One sentence on the weighting used."""
        return "; ".join(f"{w}: {WEIGHTINGS[w]}" for w in self.weighting.split("+"))

    def to_dict(self) -> dict:
        """Plain-Python summary (JSON-safe: a non-finite number is null)."""
        def num(v):
            return float(v) if math.isfinite(v) else None

        sides = self.at_bound or (None,) * len(self.names)
        clipped = self.clipped if self.clipped.size else np.zeros(len(self.names), bool)
        return {"parameters": [
            {"name": n, "unit": self.unit(n), "estimate": num(e), "standard_error": num(s),
             "ci95": [num(lo), num(hi)], "determined": bool(d), "at_bound": side,
             "ci95_clipped": bool(c)}
            for n, e, s, (lo, hi), d, side, c in zip(
                self.names, self.estimates, self.standard_errors, self.confidence_intervals,
                self.determined, sides, clipped, strict=True)],
            "fit_error": num(self.fit_error), "weighting": self.weighting,
            "weighting_description": self.weighting_text(), "mismatch": bool(self.mismatch),
            "model_error": num(self.model_error),
            "systematic": [num(v) for v in self.systematic],
            "success": bool(self.success), "stable": self.stable,
            "converged": bool(self.converged), "describes_data": bool(self.describes_data),
            "variance_accounted_for": num(self.variance_accounted_for),
            "reason": self.reason, "message": self.message, "warnings": list(self.warnings)}


def _name(name: str, muscles: MuscleSet) -> str:
    """The one spelling of an FRF fit parameter (the parameter table's)."""
    return resolve(name, muscles.names, (), accepts=PARAMETERS, what="FRF fit parameter")


def _parse(name: str, muscles: MuscleSet) -> tuple[str, int | None]:
    base, _, pair = _name(name, muscles).partition(":")
    return base, muscles.names.index(pair) if pair else None


def _canonical(name: str, spec, muscles: MuscleSet) -> str:
    """The parameter table's one spelling of a parsed name."""
    base, j = spec
    return base if j is None else f"{base}:{muscles.names[j]}"


def check_fit_request(muscles: MuscleSet, free, per_condition=(), bounds=None) -> tuple:
    """The names to fit and their bounds, checked (each known, none named twice, each bound
    for a fitted parameter and within its range), before any data are read.

    Returns
    -------
    (list, list, list, list, dict)
        ``free``, ``per_condition``, each name's (base name, pair index), each name's one
        spelling, and the bounds by that spelling.
    """
    for label, names in (("free", free), ("per_condition", per_condition)):
        if isinstance(names, str) or not isinstance(names, list | tuple):
            raise ParameterError(f"{label} must be a list of parameter names, got {names!r}"
                                 [:200])
    free, per = list(free), list(per_condition)
    if not free and not per:
        raise ParameterError("give at least one parameter to fit")
    specs = [_parse(n, muscles) for n in free + per]
    canon = [_canonical(n, s, muscles) for n, s in zip(free + per, specs, strict=True)]
    seen: dict[str, tuple[str, bool]] = {}
    for i, (given, name) in enumerate(zip(free + per, canon, strict=True)):
        if name in seen:
            first, shared = seen[name]
            raise ParameterError(f"{name!r} is named twice ({first!r} and {given!r})"
                                 if shared == (i < len(free))
                                 else f"{name!r} is both shared and per condition")
        seen[name] = (given, i < len(free))
    bounds = check_bounds(bounds, lambda g: _canonical(g, _parse(g, muscles), muscles),
                          dict(zip(canon, (s[0] for s in specs), strict=True)))
    return canon[:len(free)], canon[len(free):], specs, canon, bounds


def fit_frf(body: Body, muscles: MuscleSet, data, free, *, input: str | Sequence[str] = "tilt",
            output: str = "com_angle", feedback_delay: float = 0.0,
            proprioceptive_weight: float = 1.0, per_condition=(), bounds=None,
            model_error: float | None = None, torque_feedback_gain: float = 0.0,
            torque_feedback_time_constant: float | None = None,
            visual_weight: float = 0.0,
            condition_groups=None) -> FRFFit:
    """Fit controller parameters to one or several FRFs (module notes).

    Parameters
    ----------
    body : Body
    muscles : MuscleSet
        The starting gains (intrinsic and active).
    data : FRFEstimate or FRFTable, or a sequence of them
        One per condition (:func:`posturelab.frequency.estimate_frf`, or a table of gain and
        phase, :class:`posturelab.frequency.table.FRFTable`).
    free : sequence of str
        Parameters shared by all conditions.
    input : str or sequence of str
        As for :func:`posturelab.frequency.model_frf`, or one per condition: the two FRFs
        of a dual-stimulus trial (:mod:`posturelab.frequency.dual`) are two conditions,
        ``["tilt", "visual-tilt"]``, fitted jointly for the shared W and W_v.
    output : str
        As for :func:`posturelab.frequency.model_frf`.
    feedback_delay, proprioceptive_weight : float
        Starting values. [s], [-]
    per_condition : sequence of str
        Parameters fitted separately for each condition.
    bounds : dict of name -> (low, high), optional
        Each within the parameter table's bounds (docs/parameters.md); defaults: the
        table's search intervals (gains [0, 1e5], delay [0, 1] s, W [0, 1], K_t [0, 3],
        τ_t [0.5, 200] s).
    model_error : float, optional
        A relative model error δ to allow from the start instead of the one a mismatch
        would choose (module notes; nested fits compared under one error model). [-]
    torque_feedback_gain, torque_feedback_time_constant : float
        Starting values of the torque feedback (K_t 0: none; τ_t by default the table's
        17.4 s). [-], [s]
    visual_weight : float
        Starting W_v. [-]
    condition_groups : sequence of int, optional
        Per condition its group 0 … G − 1 (each used): the ``per_condition`` parameters
        then take one value per group (``NAME#g``, g = 1 … G), as for conditions grouped
        by vision; by default each condition is its own group.

    Raises
    ------
    ParameterError
        Unknown, repeated or not-fitted names, bounds outside a parameter's range, data
        that are not FRFs.
    """
    from scipy.optimize import least_squares
    from scipy.stats import chi2
    from scipy.stats import t as student

    from .._validation import float_in_range
    from .table import FRFTable

    if not isinstance(body, Body) or not isinstance(muscles, MuscleSet):
        raise ParameterError("fit_frf needs a Body and a MuscleSet")
    free, per, specs, canon, bounds = check_fit_request(muscles, free, per_condition, bounds)
    kinds = (FRFEstimate, FRFTable)
    conditions = [data] if isinstance(data, kinds) else (
        list(data) if isinstance(data, list | tuple) else None)
    if not conditions:
        raise ParameterError("data must be one FRFEstimate or FRFTable, or a list of them")
    feedback_delay = float_in_range("feedback_delay [s]", feedback_delay, 0.0,
                                    MAX_FEEDBACK_DELAY, unit="s")
    proprioceptive_weight = float_in_range("proprioceptive_weight [-]", proprioceptive_weight,
                                           0.0, 1.0)
    torque_feedback_gain = check_value("torque_feedback_gain", torque_feedback_gain)
    torque_feedback_time_constant = check_value(
        "torque_feedback_time_constant", TORQUE_FEEDBACK_TIME_CONSTANT
        if torque_feedback_time_constant is None else torque_feedback_time_constant)
    inputs = [input] * len(conditions) if isinstance(input, str) else list(input)
    if len(inputs) != len(conditions):
        raise ParameterError(f"input gives {len(inputs)} input(s) for {len(conditions)} "
                             "condition(s)")
    scalars = {"feedback_delay": feedback_delay, "proprioceptive_weight": proprioceptive_weight,
               "visual_weight": check_value("visual_weight", visual_weight),
               "torque_feedback_gain": torque_feedback_gain,
               "torque_feedback_time_constant": torque_feedback_time_constant}
    targets = [_target(c, k) for k, c in enumerate(conditions)]
    base = np.stack([muscles.stiffnesses, muscles.viscosities, muscles.active_stiffnesses,
                     muscles.active_viscosities])
    group_of = group_conditions(condition_groups, len(conditions))
    C = max(group_of) + 1  # the values of each per-condition parameter
    slots = [(i, None) for i in range(len(free))] + [
        (len(free) + j, k) for j in range(len(per)) for k in range(C)]
    labels = free + [f"{per[j]}#{k + 1}" for j in range(len(per)) for k in range(C)]
    rows = {"stiffness": 0, "viscosity": 1, "active_stiffness": 2, "active_viscosity": 3}

    def start(spec) -> float:
        b, j = spec
        if b in scalars:
            return scalars[b]
        return float(base[rows[b], j])

    x0 = np.array([start(specs[i]) for i, _ in slots])
    lo = np.array([bounds.get(canon[i], _DEFAULT_BOUNDS[specs[i][0]])[0] for i, _ in slots])
    hi = np.array([bounds.get(canon[i], _DEFAULT_BOUNDS[specs[i][0]])[1] for i, _ in slots])
    x0 = np.clip(x0, lo + 1e-9 * (hi - lo), hi - 1e-9 * (hi - lo))
    scale = np.maximum(np.abs(x0), 1e-3 * np.maximum(hi - lo, 1e-12))
    warnings = [f"condition {k + 1}: coherence below 0.5 at {int(np.sum(c.coherence < 0.5))}"
                " band(s)" for k, c in enumerate(conditions)
                if c.coherence is not None and np.any(c.coherence < 0.5)]
    active = muscles.has_active_feedback or any(
        specs[i][0].startswith("active") for i, _ in slots)

    def condition_values(p: np.ndarray, k: int) -> tuple[np.ndarray, dict]:
        gains = base.copy()
        values = dict(scalars)
        for (i, cond), value in zip(slots, p, strict=True):
            if cond is not None and cond != group_of[k]:
                continue
            b, j = specs[i]
            if b in values:
                values[b] = value
            else:
                gains[rows[b], j] = value
        return gains, values

    def unstable(p: np.ndarray) -> str | None:
        """The first condition's verdict whose loop is not stable at these values (None:
        every one stable; "": not settled, the linear model refusing these values)."""
        for k in range(len(conditions)):
            gains, values = condition_values(p, k)
            try:
                verdict = loop_verdict(body, muscles, gains, active, values)
            except PostureLabError:
                return ""
            if verdict.side(engaged=True).status != "stable":
                return verdict.describe()
        return None

    def model(p: np.ndarray, dense: bool = False) -> list:
        out = []
        for k, c in enumerate(conditions):
            gains, values = condition_values(p, k)

            def frf_at(f, gains=gains, v=values, source=inputs[k]):
                return model_frf_batch(body, muscles, f, gains[0][None], gains[1][None],
                                       gains[2][None] if active else None,
                                       gains[3][None] if active else None,
                                       v["feedback_delay"], v["proprioceptive_weight"],
                                       input=source, output=output,
                                       visual_weight=v["visual_weight"],
                                       torque_feedback_gain=v["torque_feedback_gain"],
                                       torque_feedback_time_constant=v[
                                           "torque_feedback_time_constant"])[0]

            if dense:
                f = np.geomspace(c.frequency.min() / 1.5, c.frequency.max() * 1.5, 200)
                out.append((f, frf_at(f)))
            elif c.harmonic_weight:
                out.append(c.band_average(frf_at))
            else:
                out.append(frf_at(c.frequency))
        return out

    def standardised(p: np.ndarray, delta: float) -> list:
        return [t.standardised(m, delta) for t, m in zip(targets, model(p), strict=True)]

    def residuals(z: np.ndarray, delta: float) -> np.ndarray:
        return np.concatenate([np.concatenate(u) for u in standardised(z * scale, delta)])

    def solve(z0: np.ndarray, delta: float):
        return least_squares(residuals, z0, bounds=(lo / scale, hi / scale), x_scale=1.0,
                             method="trf", args=(delta,), xtol=1e-12, ftol=1e-12, gtol=1e-12)

    def chi2_sum(p: np.ndarray, delta: float, values: list | None = None) -> float:
        values = model(p) if values is None else values
        return float(sum(np.sum(_chi2(t.standardised(v, delta), t.dof))
                         for t, v in zip(targets, values, strict=True)))

    K = x0.size
    m = 2 * sum(t.frf.size for t in targets)
    if m - K <= 0:
        raise ParameterError(f"{K} free parameter(s) cannot be fitted to {m} numbers ({m // 2} "
                             "band(s), real and imaginary parts): no degrees of freedom left; "
                             "free fewer parameters or give more bands")
    dof = m - K
    weighting = "+".join(dict.fromkeys(t.kind for t in targets))
    relative = weighting == "relative"
    delta = 0.0 if model_error is None else float_in_range("model_error [-]", model_error,
                                                           0.0, 1e3)
    if start_verdict := unstable(x0):
        warnings.append(f"the starting loop is {start_verdict}: its FRF is not measurable; "
                        "start from stable values (the fit may end on an unstable loop)")
    sol = solve(x0 / scale, delta)
    p = sol.x * scale
    total = chi2_sum(p, 0.0)
    fit_error = math.sqrt(total / dof)
    mismatch = not relative and total > float(chi2.ppf(1.0 - MISMATCH_P, dof))
    if mismatch and model_error is None:
        for _ in range(2):  # the model error that makes the fit error 1, then refit
            a, b = -14.0, 2.0
            values = model(p)
            for _ in range(50):
                mid = 0.5 * (a + b)
                a, b = (mid, b) if chi2_sum(p, 10.0 ** mid, values) > dof else (a, mid)
            delta = 10.0 ** b
            sol = solve(p / scale, delta)
            p = sol.x * scale
        warnings.insert(0, (
            f"the model does not describe the data within their noise (fit error "
            f"{fit_error:.3g}, chance p < {MISMATCH_P:g}): the estimates and intervals allow a "
            f"model error of {100 * delta:.3g} % of |H| per band"))
    # the Jacobian of the standardised residuals (central differences)
    J = np.empty((m, K))
    for k in range(K):
        h = 1e-6 * scale[k]
        up, dn = p.copy(), p.copy()
        up[k] = min(p[k] + h, hi[k])
        dn[k] = max(p[k] - h, lo[k])
        J[:, k] = (np.concatenate([np.concatenate(u) for u in standardised(up, delta)])
                   - np.concatenate([np.concatenate(u) for u in standardised(dn, delta)])
                   ) / (up[k] - dn[k])
    u_all = np.concatenate([np.concatenate(u) for u in standardised(p, delta)])
    s2 = float(u_all @ u_all) / dof if relative else 1.0
    norms = np.linalg.norm(J, axis=0)
    seen_col = norms > 1e-10 * max(float(norms.max()), 1e-300)
    se = np.full(K, np.inf)
    cond = np.inf
    if seen_col.any():
        Js = J[:, seen_col]
        sv = np.linalg.svd(Js, compute_uv=False)
        cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else np.inf
        if np.isfinite(cond):
            cov = s2 * np.linalg.inv(Js.T @ Js)
            se[seen_col] = np.sqrt(np.maximum(np.diag(cov), 0.0))
    if relative:
        fit_error = math.sqrt(s2)
    finite = [d for t in targets for d in np.asarray(t.dof, float) if np.isfinite(d)]
    nu = dof if relative else (min(finite) if finite else np.inf)
    q = float(student.ppf(0.975, nu))
    systematic = np.zeros(K)
    if mismatch and np.isfinite(cond) and seen_col.all():
        systematic = systematic_bound(J, targets, delta, seen_col)
    ci = np.stack([p - q * se - systematic, p + q * se + systematic], axis=1)
    sides = at_bound(p, lo, hi)  # an estimate on its search bound is not determined
    determined = (seen_col & np.isfinite(se) & (se <= np.abs(p)) & (cond < 1e10)
                  & np.array([side is None for side in sides]))
    ci, clipped = clip_intervals(labels, ci, lo, hi)
    pair = ("proprioceptive_weight", "visual_weight")
    fitted = {specs[i][0]: v for (i, c), v in zip(slots, p, strict=True)
              if c is None and specs[i][0] in pair}
    total = sum(fitted.get(name, scalars[name]) for name in pair)
    if fitted and total > 1.0 + 1e-9:
        warnings.append(f"proprioceptive_weight + visual_weight = {total:.4g} > 1: the "
                        "graviceptive weight 1 − W − W_v would be negative")
    end_verdict = unstable(p)
    if end_verdict:
        warnings.insert(0, f"the fitted loop is unstable ({end_verdict}): its FRF is not "
                        "measurable, so these estimates describe no experiment")
    vaf = variance_accounted_for(targets, model(p))
    reasons = [why for bad, why in (
        (not sol.success, f"the optimiser did not converge ({sol.message})"),
        (bool(end_verdict), "the fitted loop is unstable"),
        (vaf < MIN_VARIANCE_ACCOUNTED, f"the model does not describe the data: it accounts "
         f"for {100 * vaf:.3g} % of the FRF's variation (VAF; at least "
         f"{100 * MIN_VARIANCE_ACCOUNTED:g} % needed)")) if bad]
    return FRFFit(tuple(labels), p, se, ci, determined, float(fit_error), not reasons,
                  str(sol.message), tuple(warnings), tuple(model(p, dense=True)), weighting,
                  bool(mismatch), float(delta), systematic, sides,
                  np.stack([lo, hi], axis=1), clipped, float(u_all @ u_all), float(dof),
                  float(nu), None if end_verdict == "" else end_verdict is None,
                  bool(sol.success), float(vaf), vaf >= MIN_VARIANCE_ACCOUNTED,
                  "; ".join(reasons))

