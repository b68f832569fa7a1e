"""Searching a PRTS experiment's design for the smallest predicted errors.

:func:`optimise_design` compares, over a grid of state durations (the register's states
fixed, so the cycle T = states × Δ) and amplitudes, each with as many cycles as fit, the
designs whose total time (discarded + analysed cycles) × T is within a budget, by
Σ_k (se_k/|θ_k|)² over the chosen parameters, se from the Fisher information of
:mod:`posturelab.frequency.design`. 𝓘 ∝ C A² at a fixed state duration, so it is computed
once per state duration and scaled; the work is bounded by :data:`MAX_GRID` state
durations. Under the linear model the largest amplitude always wins; a real subject
reweights with the amplitude (Peterka 2002), which the prediction does not know.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validation import float_in_range
from ..errors import ParameterError
from ..model.body import Body
from ..model.muscles import MuscleSet
from .design import (
    MAX_CYCLES,
    DesignPrediction,
    _check_design,
    _specs,
    _values,
    predict_errors,
)

__all__ = ["DesignOptimum", "optimise_design", "AMPLITUDE_RANGE", "STATE_DURATION_RANGE",
           "MAX_GRID"]

#: Amplitudes :func:`optimise_design` searches by default (peak to peak). [rad]
AMPLITUDE_RANGE = (0.005, 0.07)
#: State durations it searches by default. [s]
STATE_DURATION_RANGE = (0.1, 0.5)
#: Most state durations (and amplitudes) in its grid. [-]
MAX_GRID = 41


@dataclass(frozen=True)
class DesignOptimum:
    """What :func:`optimise_design` found.

    Attributes
    ----------
    best : DesignPrediction
        The design with the smallest objective.
    objective : float
        Σ_k (se_k/|θ_k|)² over the targets. [-]
    targets : tuple of str
    budget : float
        [s]
    searched : dict
        The ranges searched: ``amplitude`` (LO, HI) [rad], ``state_duration`` (LO, HI) [s],
        ``cycles`` (LO, HI), and ``designs`` (how many were compared).
    table : tuple of dict
        Per state duration, its best design (amplitude, cycles, objective).
    """

    best: DesignPrediction
    objective: float
    targets: tuple[str, ...]
    budget: float
    searched: dict
    table: tuple = ()

    def to_dict(self) -> dict:
        """Plain-Python summary (JSON-safe)."""
        def num(v):
            return float(v) if math.isfinite(v) else None

        return {**self.best.to_dict(), "optimised": {
            "objective": num(self.objective), "targets": list(self.targets),
            "budget": self.budget, "searched": self.searched,
            "by_state_duration": [{k: (num(v) if isinstance(v, float) else v)
                                   for k, v in row.items()} for row in self.table]}}


def optimise_design(body: Body, muscles: MuscleSet, free, *, budget: float, targets=None,
                    tilt=None, discard: int = 1, sensor_noise: float = 0.0, motor_noise=None,
                    sample_rate: float = 100.0, output: str = "com_angle",
                    feedback_delay: float = 0.0, proprioceptive_weight: float = 1.0,
                    amplitude_range=AMPLITUDE_RANGE,
                    state_duration_range=STATE_DURATION_RANGE, grid: int = 9,
                    input: str = "tilt", visual_weight: float = 0.0) -> DesignOptimum:
    """The PRTS design (amplitude, state duration, cycles) with the smallest
    Σ (se/|θ|)² over ``targets`` within ``budget`` seconds of recording (module notes).

    Parameters
    ----------
    free : sequence of str
        The parameters the fit will estimate.
    budget : float
        Total time, discarded cycles included, in (0, 86400]. [s]
    targets : sequence of str, optional
        The parameters whose errors count (default: all of ``free``); each among ``free``.
    tilt : PRTSTilt, optional
        Its register (sequence) is kept; default posturelab-80.
    amplitude_range : (float, float)
        Peak-to-peak amplitudes searched, within (0, 0.5]. [rad]
    state_duration_range : (float, float)
        State durations searched (rounded to whole samples), within [0.01, 10]. [s]
    grid : int
        Values per range, 2 … :data:`MAX_GRID`. [-]
    input, visual_weight
        What the PRTS moves ("tilt" or "visual-tilt") and W_v [-], as for
        :func:`~posturelab.frequency.design.predict_errors`.
    """
    from ..model.tilt import PRTSTilt

    tilt = PRTSTilt.named("posturelab-80", 0.035) if tilt is None else tilt
    _check_design(tilt, 2, discard, sample_rate)
    budget = float_in_range("budget [s]", budget, 1e-3, 86_400.0, unit="s")
    if isinstance(grid, bool) or not isinstance(grid, int) or not 2 <= grid <= MAX_GRID:
        raise ParameterError(f"grid must be an integer in [2, {MAX_GRID}], got {grid!r}")
    a_lo, a_hi = _range("amplitude_range [rad]", amplitude_range, 1e-4, 0.5)
    d_lo, d_hi = _range("state_duration_range [s]", state_duration_range, 0.01, 10.0)
    names, specs = _specs(muscles, free)
    chosen = names if targets is None else _specs(muscles, targets)[0]
    missing = [n for n in chosen if n not in names]
    if missing:
        raise ParameterError(f"targets must be among the free parameters ({', '.join(names)}), "
                             f"got {', '.join(missing)}")
    index = [names.index(n) for n in chosen]
    values = _values(muscles, specs, feedback_delay, proprioceptive_weight, visual_weight)
    stimulus = {"input": input, "visual_weight": visual_weight}
    scale = np.array([abs(values[i]) if values[i] else 1.0 for i in index])
    amplitudes = np.geomspace(a_lo, a_hi, grid)
    durations = np.unique(np.round(np.linspace(d_lo, d_hi, grid) * sample_rate) / sample_rate)
    durations = durations[durations > 0]
    states = tilt.velocity_sequence.size
    best = (np.inf, None)
    table, compared = [], 0
    for d in durations:
        cycle = states * d
        most = int(budget // cycle) - discard
        if most < 2:
            continue
        cycles = min(most, MAX_CYCLES)
        unit_tilt = PRTSTilt(a_hi, float(d), tilt.registers, tilt.taps, tilt.seed)
        try:
            one = predict_errors(body, muscles, names, tilt=unit_tilt, cycles=2, discard=discard,
                                 sensor_noise=sensor_noise, motor_noise=motor_noise,
                                 sample_rate=sample_rate, output=output,
                                 feedback_delay=feedback_delay,
                                 proprioceptive_weight=proprioceptive_weight, **stimulus)
        except ParameterError:  # (this state duration's bands do not fit below Nyquist)
            continue
        # 𝓘 ∝ C A² (module notes): the most cycles and the largest amplitude win at each Δ
        row_best = (np.inf, None, None)
        for amplitude in amplitudes:
            compared += 1
            factor = cycles / 2 * (amplitude / a_hi) ** 2
            se = one.standard_errors / math.sqrt(factor)
            objective = float(np.sum((se[index] / scale) ** 2))
            if objective < row_best[0]:
                row_best = (objective, float(amplitude), cycles)
        table.append({"state_duration": float(d), "cycle_length": float(cycle),
                      "cycles": row_best[2], "amplitude": row_best[1],
                      "objective": row_best[0]})
        if row_best[0] < best[0]:
            best = (row_best[0], (float(d), row_best[1], row_best[2]))
    if best[1] is None:
        least = (2 + discard) * states * d_lo
        raise ParameterError(f"no design fits the budget of {budget:g} s: a cycle of "
                             f"{states} states at {d_lo:g} s needs {least:g} s for 2 cycles "
                             f"and {discard} discarded")
    d, amplitude, cycles = best[1]
    design = PRTSTilt(amplitude, d, tilt.registers, tilt.taps, tilt.seed)
    prediction = predict_errors(body, muscles, names, tilt=design, cycles=cycles,
                                discard=discard, sensor_noise=sensor_noise,
                                motor_noise=motor_noise, sample_rate=sample_rate, output=output,
                                feedback_delay=feedback_delay,
                                proprioceptive_weight=proprioceptive_weight, **stimulus)
    searched = {"amplitude": [a_lo, a_hi], "state_duration": [float(durations[0]),
                                                              float(durations[-1])],
                "grid": grid, "designs": compared}
    return DesignOptimum(prediction, float(best[0]), tuple(chosen), budget, searched,
                         tuple(table))


def _range(label: str, value, low: float, high: float) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError):
        raise ParameterError(f"{label} must be (low, high), got {value!r}"[:200]) from None
    if not (low <= lo < hi <= high):
        raise ParameterError(f"{label} must satisfy {low:g} <= low < high <= {high:g}, got "
                             f"{lo:g}, {hi:g}")
    return lo, hi
