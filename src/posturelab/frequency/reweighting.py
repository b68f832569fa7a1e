"""Sensory reweighting across conditions: one parameter (by default the proprioceptive weight
W, ``proprioceptive_weight``) per condition, against the stimulus amplitude and vision, and a
test of whether it differs between the conditions.

Peterka (2002, J Neurophysiol 88:1097–1118, "Sensorimotor integration in human postural
control") fitted an independent-channel model to surface-tilt FRFs at several stimulus
amplitudes and found the proprioceptive weight W falling as the amplitude grew (the subject
relies less on the surface as it moves more, and more on graviception), with eyes open and
closed. :func:`compare_conditions` fits the same data twice with
:func:`posturelab.frequency.fit.fit_frf`:

* the **general** fit: the parameter takes one value per condition (``NAME#k``), the other
  free parameters shared, ``per_condition`` ones per condition;
* the **restricted** fit: the parameter shared by every condition (the null hypothesis
  W_1 = … = W_C), everything else as before,

and compares them by a **likelihood-ratio test**. fit.py's error model is (generalised)
weighted least squares: the band residuals e = H(f; p) − Ĥ are complex normal with a known
covariance (the estimate's, from the cycles' scatter, or a table's standard errors), so the
log-likelihood is −S/2 + const with S = Σ u² the whitened residuals' sum of squares
(:attr:`FRFFit.objective`) and −2 ln Λ = S_restricted − S_general exactly. The restriction
removes r = C − 1 parameters; by Wilks' theorem (nested models, the null an interior point,
the estimates asymptotically normal: Seber and Wild 2003, *Nonlinear Regression*, §5.9)

    ΔS = S_restricted − S_general ~ χ²(r)          (known variances, ν = ∞),

exact for a model linear in its parameters. When the variances are estimated with ν degrees
of freedom (trial estimates: ν = 2(C − 1) × the bins pooled, at least 20; a table's ``dof``)
the statistic is referred to F(r, ν_min): ΔS/r ~ F(r, ν) exactly if every band's variance
were off by one common χ²_ν/ν factor, which makes F(r, ν_min) conservative for independent
per-band estimates, and the same fewest-dof rule fit.py's intervals use. Without per-band
precision (``"relative"`` weighting) the noise level is itself estimated from the general
fit's residuals and the test is the extra-sum-of-squares F test (Bates and Watts 1988,
*Nonlinear Regression Analysis*, §3.5.1): (ΔS/r)/(S_general/(2B − K)) ~ F(r, 2B − K).
When the general fit shows a model mismatch (``model_error`` δ > 0), both fits allow the
same δ (the restricted one is fitted with ``model_error=δ``), so that S compares like with
like. The restricted fit is never better than the general one at their optima; if the
optimiser leaves it so, ΔS is taken as 0 and a warning says so. An estimate on its bound
(W = 0 or 1) breaks the interior-point condition: the χ² reference is then approximate
(Self and Liang 1987, J Am Stat Assoc 82:605–610) and a warning says so.

**Eyes open against eyes closed** (``by="vision"``): every condition carries its vision
label, and the general fit gives the parameter one value per label (the conditions of one
label share it, :func:`~posturelab.frequency.fit.fit_frf`'s ``condition_groups``; other
``per_condition`` parameters then also take one value per label), the restricted one a
single value: r = 1, the same likelihood-ratio test. Peterka (2002) reported W for eyes
open and closed at each amplitude; this test asks whether vision moves it, with the
amplitudes pooled within each label.

The stimulus amplitude of a condition is its peak-to-peak stimulus [rad for a tilt, m for a
translation]: given, or, for an :class:`~posturelab.frequency.FRFEstimate`, measured from its
cycle-averaged stimulus; a table without it has none (NaN).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from .fit import FRFFit, check_fit_request, fit_frf

__all__ = ["ConditionComparison", "compare_conditions", "stimulus_amplitude", "VISION",
           "SIGNIFICANCE", "GROUPINGS"]

#: The vision labels a condition may carry.
VISION = ("open", "closed")
#: The level below which a difference is called significant in words. [-]
SIGNIFICANCE = 0.05
#: What :func:`compare_conditions` gives one value each: every condition, or every vision
#: label.
GROUPINGS = ("condition", "vision")


def stimulus_amplitude(condition) -> float:
    """The peak-to-peak stimulus of a condition: an estimate's cycle-averaged stimulus's range,
    NaN for a table (which does not carry it). [rad for a tilt, m for a translation]"""
    x = getattr(condition, "cycle_stimulus", None)
    if x is None or np.size(x) == 0:
        return math.nan
    return float(np.max(x) - np.min(x))


@dataclass(frozen=True)
class ConditionComparison:
    """The result of :func:`compare_conditions` (module notes).

    Attributes
    ----------
    parameter : str
        The compared parameter (the parameter table's spelling).
    unit : str
        Its unit.
    labels : tuple of str
        Per condition, its name (a file name on the command line).
    amplitudes : numpy.ndarray, shape (C,)
        Peak-to-peak stimulus per condition (NaN unknown). [rad or m]
    vision : tuple of {"open", "closed", None}
    estimates, standard_errors : numpy.ndarray, shape (C,)
        The parameter per condition (general fit). [its unit]
    confidence_intervals : numpy.ndarray, shape (C, 2)
        95 %. [its unit]
    determined : numpy.ndarray of bool, shape (C,)
    shared_estimate : float
        The restricted fit's one value. [its unit]
    shared_interval : numpy.ndarray, shape (2,)
        Its 95 % interval. [its unit]
    likelihood_ratio : float
        ΔS = S_restricted − S_general = −2 ln Λ. [-]
    statistic : float
        The value referred to ``distribution``: ΔS (χ²), ΔS/r or (ΔS/r)/s² (F). [-]
    df : int
        r = C − 1 (by vision: the labels − 1), the parameters the restriction removes. [-]
    denominator_dof : float
        ν of the F reference (∞ for the χ² one). [-]
    distribution : str
        ``"chi2(r)"`` or ``"F(r, ν)"``.
    p_value : float
        The probability of a statistic this large if the parameter does not differ. [-]
    general, restricted : FRFFit
        The two fits.
    warnings : tuple of str
    amplitude_unit : str
        ``"rad"`` (a tilt) or ``"m"`` (a translation).
    grouping : {"condition", "vision"}
        What took one value each in the general fit (with ``"vision"`` each condition's
        ``estimates`` row is its label's value).
    groups : tuple of str
        The general fit's values in order: the labels, or the vision labels (``"open"``,
        ``"closed"``).
    """

    parameter: str
    unit: str
    labels: tuple
    amplitudes: np.ndarray
    vision: tuple
    estimates: np.ndarray
    standard_errors: np.ndarray
    confidence_intervals: np.ndarray
    determined: np.ndarray
    shared_estimate: float
    shared_interval: np.ndarray
    likelihood_ratio: float
    statistic: float
    df: int
    denominator_dof: float
    distribution: str
    p_value: float
    general: FRFFit
    restricted: FRFFit
    warnings: tuple = ()
    amplitude_unit: str = "rad"
    grouping: str = "condition"
    groups: tuple = ()

    @property
    def significant(self) -> bool:
        """p < :data:`SIGNIFICANCE`."""
        return bool(self.p_value < SIGNIFICANCE)

    def columns(self) -> list[tuple[str, np.ndarray]]:
        """The table, one row per condition: ``condition`` (1 …), ``label``,
        ``amplitude`` [rad or m], ``vision``, ``estimate``, ``standard_error``,
        ``ci95_low``, ``ci95_high`` [its unit], ``determined``."""
        return [("condition", np.arange(1, len(self.labels) + 1, dtype=float)),
                ("label", np.array(self.labels, dtype=str)),
                ("amplitude", np.asarray(self.amplitudes, float)),
                ("vision", np.array([v or "" for v in self.vision], dtype=str)),
                ("estimate", self.estimates), ("standard_error", self.standard_errors),
                ("ci95_low", self.confidence_intervals[:, 0]),
                ("ci95_high", self.confidence_intervals[:, 1]),
                ("determined", np.asarray(self.determined, bool))]

    def to_dict(self) -> dict:
        """Plain-Python summary (JSON-safe: a non-finite number is null)."""
        def num(v):
            return float(v) if math.isfinite(v) else None

        return {
            "parameter": self.parameter, "unit": self.unit,
            "amplitude_unit": self.amplitude_unit,
            "test": ("likelihood ratio, shared against per-condition"
                     if self.grouping == "condition" else
                     "likelihood ratio, shared against per vision label"),
            "grouping": self.grouping,
            **({"vision_groups": [
                {"vision": g, "conditions": [k + 1 for k, v in enumerate(self.vision)
                                             if v == g],
                 "estimate": num(self.general.estimates[i]),
                 "standard_error": num(self.general.standard_errors[i]),
                 "ci95": [num(v) for v in self.general.confidence_intervals[i]]}
                for i, g in ((self.general.names.index(f"{self.parameter}#{j + 1}"), g)
                             for j, g in enumerate(self.groups))]}
               if self.grouping == "vision" else {}),
            "conditions": [
                {"condition": k + 1, "label": lab, "amplitude": num(a), "vision": v,
                 "estimate": num(e), "standard_error": num(s), "ci95": [num(lo), num(hi)],
                 "determined": bool(d)}
                for k, (lab, a, v, e, s, (lo, hi), d) in enumerate(zip(
                    self.labels, self.amplitudes, self.vision, self.estimates,
                    self.standard_errors, self.confidence_intervals, self.determined,
                    strict=True))],
            "shared": {"estimate": num(self.shared_estimate),
                       "ci95": [num(v) for v in self.shared_interval]},
            "likelihood_ratio": num(self.likelihood_ratio), "statistic": num(self.statistic),
            "df": int(self.df), "denominator_dof": num(self.denominator_dof),
            "distribution": self.distribution, "p_value": num(self.p_value),
            "significant": self.significant, "significance_level": SIGNIFICANCE,
            "model_error": num(self.general.model_error), "warnings": list(self.warnings)}

    def write(self, path) -> None:
        """Write the table to ``path`` atomically: ``.json`` (:meth:`to_dict`) or ``.csv``
        (:meth:`columns`, quoted where a cell needs it)."""
        from pathlib import Path

        from .._files import atomic_write_text

        suffix = Path(path).suffix.lower()
        if suffix == ".json":
            import json

            atomic_write_text(path, json.dumps(self.to_dict(), indent=2, ensure_ascii=False)
                              + "\n")
        elif suffix == ".csv":
            from .cohort import csv_text

            atomic_write_text(path, csv_text(self.columns()))
        else:
            raise ParameterError(f"the comparison table must end in .json or .csv, got "
                                 f"{str(path)!r}")


def _amplitudes(amplitudes, conditions) -> np.ndarray:
    if amplitudes is None:
        return np.array([stimulus_amplitude(c) for c in conditions])
    if isinstance(amplitudes, str) or len(amplitudes) != len(conditions):
        raise ParameterError(f"amplitudes must give one value per condition ({len(conditions)}"
                             f"), got {amplitudes!r}"[:200])
    out = []
    for k, a in enumerate(amplitudes):
        if a is None:
            out.append(stimulus_amplitude(conditions[k]))
            continue
        if isinstance(a, bool) or not isinstance(a, int | float | np.number) \
                or not math.isfinite(a) or a < 0:
            raise ParameterError(f"amplitude of condition {k + 1} must be a number >= 0 "
                                 f"[rad or m], got {a!r}"[:200])
        out.append(float(a))
    return np.array(out)


def _vision(vision, count: int) -> tuple:
    if vision is None:
        return (None,) * count
    if isinstance(vision, str) or len(vision) != count:
        raise ParameterError(f"vision must give one of {', '.join(VISION)} (or None) per "
                             f"condition ({count}), got {vision!r}"[:200])
    for k, v in enumerate(vision):
        if v is not None and v not in VISION:
            raise ParameterError(f"vision of condition {k + 1} must be one of "
                                 f"{', '.join(VISION)}, got {v!r}"[:200])
    return tuple(vision)


def compare_conditions(body, muscles, data, free, *, parameter: str = "proprioceptive_weight",
                       per_condition=(), amplitudes=None, vision=None, labels=None,
                       by: str = "condition", **fit_options) -> ConditionComparison:
    """Fit ``parameter`` per condition and shared, and test whether it differs (module notes).

    Parameters
    ----------
    body, muscles
        As for :func:`posturelab.frequency.fit.fit_frf`.
    data : sequence of FRFEstimate or FRFTable
        At least two conditions.
    free : sequence of str
        Parameters shared by the conditions (``parameter`` may be among them: it is moved).
    parameter : str
        The parameter compared across conditions (default W, ``proprioceptive_weight``).
    per_condition : sequence of str
        Other parameters with one value per condition.
    amplitudes : sequence of float or None, optional
        Peak-to-peak stimulus per condition (None: measured from an estimate, else
        unknown). [rad for a tilt, m for a translation]
    vision : sequence of {"open", "closed", None}, optional
    labels : sequence of str, optional
        Names of the conditions (default ``condition k``).
    by : {"condition", "vision"}
        One value per condition, or per vision label (every condition labelled, both
        labels present; module notes).
    **fit_options
        ``input``, ``output``, ``feedback_delay``, ``proprioceptive_weight``, ``bounds`` of
        :func:`~posturelab.frequency.fit.fit_frf`.

    Returns
    -------
    ConditionComparison

    Raises
    ------
    ParameterError
        Fewer than two conditions, a bad amplitude or vision label, or what
        :func:`~posturelab.frequency.fit.fit_frf` refuses.
    """
    from scipy.stats import chi2
    from scipy.stats import f as fisher

    from ..parameters import unit as parameter_unit

    if "model_error" in fit_options:
        raise ParameterError("compare_conditions chooses the model error itself")
    conditions = list(data) if isinstance(data, list | tuple) else [data]
    C = len(conditions)
    if C < 2:
        raise ParameterError(f"comparing {parameter!r} across conditions needs at least two "
                             f"conditions, got {C}")
    for label, names in (("free", free), ("per_condition", per_condition)):
        if isinstance(names, str) or not isinstance(names, list | tuple):
            raise ParameterError(f"{label} must be a list of parameter names, got {names!r}"
                                 [:200])

    def canonical(n: str) -> str:
        return check_fit_request(muscles, [n])[0][0]

    name = canonical(parameter)
    free_c, per_c, *_ = check_fit_request(
        muscles, [n for n in free if canonical(n) != name],
        [n for n in per_condition if canonical(n) != name] + [name])
    per_c = per_c[:-1]
    amps = _amplitudes(amplitudes, conditions)
    seen = _vision(vision, C)
    labels = tuple(str(v) for v in labels) if labels is not None else tuple(
        f"condition {k + 1}" for k in range(C))
    if len(labels) != C:
        raise ParameterError(f"labels must name each of the {C} conditions")
    group_of, groups = _grouping(by, seen, labels)
    general = fit_frf(body, muscles, conditions, free_c, per_condition=per_c + [name],
                      condition_groups=group_of, **fit_options)
    restricted = fit_frf(body, muscles, conditions, free_c + [name], per_condition=per_c,
                         condition_groups=group_of,
                         model_error=general.model_error, **fit_options)
    warnings = []
    delta_s = restricted.objective - general.objective
    if delta_s < -1e-6 * max(1.0, general.objective):
        warnings.append(f"the per-condition fit ended above the shared one (S "
                        f"{general.objective:.6g} > {restricted.objective:.6g}): the optimiser "
                        "did not reach its optimum; ΔS taken as 0")
    delta_s = max(delta_s, 0.0)
    r = len(groups) - 1
    if general.weighting == "relative":
        nu = general.residual_dof
        statistic = (delta_s / r) / max(general.objective / nu, 1e-300)
    else:
        nu = general.noise_dof
        statistic = delta_s if math.isinf(nu) else delta_s / r
    if math.isinf(nu):
        p_value, distribution = float(chi2.sf(statistic, r)), f"chi2({r})"
    else:
        p_value, distribution = float(fisher.sf(statistic, r, nu)), f"F({r}, {nu:g})"
    idx = [general.names.index(f"{name}#{group_of[k] + 1}") for k in range(C)]
    j = restricted.names.index(name)
    sides = [general.at_bound[i] for i in idx] + [restricted.at_bound[j]]
    if any(side is not None for side in sides):
        warnings.append(f"an estimate of {name} is on its search bound: the test's reference "
                        "distribution is then approximate (Self and Liang 1987)")
    if not (general.success and restricted.success):
        warnings.append("an optimiser did not converge: "
                        f"{general.message if not general.success else restricted.message}")
    return ConditionComparison(
        name, parameter_unit(name), labels, amps, seen, general.estimates[idx],
        general.standard_errors[idx], general.confidence_intervals[idx],
        general.determined[idx], float(restricted.estimates[j]),
        restricted.confidence_intervals[j].copy(), float(delta_s), float(statistic), r,
        float(nu), distribution, p_value, general, restricted,
        tuple(warnings) + general.warnings,
        "m" if fit_options.get("input", "tilt") == "translation" else "rad", by, groups)


def _grouping(by: str, vision: tuple, labels: tuple) -> tuple[list[int], tuple]:
    """Each condition's group and the groups' names: every condition its own, or the
    vision labels (each condition labelled, both labels present)."""
    if by not in GROUPINGS:
        raise ParameterError(f"by must be one of {', '.join(GROUPINGS)}, got {by!r}"[:200])
    if by == "condition":
        return list(range(len(labels))), labels
    missing = [k + 1 for k, v in enumerate(vision) if v is None]
    if missing:
        raise ParameterError(f"grouping by vision needs every condition's vision label "
                             f"(open or closed); condition(s) {missing} have none")
    groups = tuple(v for v in VISION if v in vision)
    if len(groups) < 2:
        raise ParameterError(f"grouping by vision needs conditions with eyes open and with "
                             f"eyes closed; all are {vision[0]}")
    return [groups.index(v) for v in vision], groups
