"""The findings beyond the paper, computed (their data types are in :mod:`.findings`): the
largest recoverable ramp-and-hold, the largest feedback delay and the delay margin, a
literature controller, the hip strategy under an ankle torque limit, and a simulated PRTS
experiment fitted back.

The two searches, :func:`recovery_finding` and :func:`delay_finding`, take their simulation
runner as one parameter (:func:`ramp_and_hold_run`, :func:`delayed_run`), so that the engine
they run on is changed in one place. :mod:`posturelab.paper.checks` gathers these with the
figure verdicts.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..model.body import Body
from ..model.muscles import MuscleSet, paper_muscles
from ..model.options import BaseOfSupport, FallCriteria
from ..simulation.results import SimulationResult
from .findings import (
    DelayFinding,
    FRFFinding,
    LiteratureControllerFinding,
    RecoveryFinding,
    StrategyFinding,
)

if TYPE_CHECKING:
    from ..scenarios import Scenario

__all__ = [
    "RECOVERY_RAMP_DURATION", "DELAY_BRACKET", "FIT_BACK_SEEDS", "FRF_CYCLES", "FRF_NOISE",
    "ramp_and_hold_run", "recovery_finding", "delayed_run", "delay_finding",
    "with_delay_margin", "literature_controller_finding", "strategy_finding",
    "FRFExperiment", "frf_experiment", "fit_back_errors", "frf_finding",
]

#: Ramp-and-hold duration for the recovery finding. [s]
RECOVERY_RAMP_DURATION = 0.5
#: Bracket of neural delays searched for case 1. [s]
DELAY_BRACKET = (0.002, 0.03)


def ramp_and_hold_run(body: Body, muscles: MuscleSet, distance: float,
                      fall: FallCriteria) -> SimulationResult:
    """The runner of :func:`recovery_finding`: the compiled engine on a backward
    ramp-and-hold (its default tolerances, rtol 1e-6).

    Parameters
    ----------
    body : Body
    muscles : MuscleSet
    distance : float
        How far the platform moves backward, over :data:`RECOVERY_RAMP_DURATION`. [m]
    fall : FallCriteria
    """
    from ..model.platform import RampAndHold
    from ..simulation import simulate

    return simulate(body, muscles, RampAndHold(-distance, RECOVERY_RAMP_DURATION), 4.0,
                    fall=fall, sample_rate=50.0, engine="compiled")


def recovery_finding(
    body: Body, foot: BaseOfSupport,
    run: Callable[[Body, MuscleSet, float, FallCriteria], SimulationResult]
    = ramp_and_hold_run,
) -> RecoveryFinding:
    """Largest backward ramp-and-hold case 1 recovers from, by the CoP and the CoG criteria
    (bisection to 1 mm between 1 cm and 1 m).

    Parameters
    ----------
    body : Body
    foot : BaseOfSupport
        Heel and toe, from the ankle. [m]
    run : callable(body, muscles, distance, fall) -> SimulationResult
        The simulation of one move of ``distance`` [m]; :func:`ramp_and_hold_run` by default.
    """
    from ..studies.recovery import largest_recoverable

    muscles = paper_muscles("1")

    def search(cop: bool) -> float:
        fall = FallCriteria(base_of_support=foot, centre_of_pressure=cop)
        return largest_recoverable(lambda d: run(body, muscles, d, fall), 0.01, 1.0,
                                   tolerance=1e-3).estimate

    by_cop = search(True)
    by_cog = search(False)
    return RecoveryFinding(RECOVERY_RAMP_DURATION, by_cop, by_cog)


def delayed_run(scenario: Scenario, delay: float) -> SimulationResult:
    """The runner of :func:`delay_finding`: ``scenario`` on the compiled engine (at the
    scenario's tolerances) with a feedback delay of ``delay`` [s]."""
    return scenario.run(feedback_delay=delay, engine="compiled")


def delay_finding(
    backward: Scenario,
    run: Callable[[Scenario, float], SimulationResult] = delayed_run,
) -> DelayFinding:
    """Largest neural delay of the muscle feedback case 1 survives, by bisection to 1 ms
    within :data:`DELAY_BRACKET` (1.5 s of the backward run, sampled at 100 Hz).

    Parameters
    ----------
    backward : Scenario
        The backward case 1 scenario.
    run : callable(scenario, delay) -> SimulationResult
        The simulation at one delay [s]; :func:`delayed_run` by default.
    """
    lo, hi = DELAY_BRACKET
    sc = backward.replace(duration=1.5, sample_rate=100.0)
    if run(sc, lo).fell or not run(sc, hi).fell:
        return DelayFinding(None, None)
    while hi - lo > 1e-3:
        mid = 0.5 * (lo + hi)
        if run(sc, mid).fell:
            hi = mid
        else:
            lo = mid
    return DelayFinding(lo, hi)


def with_delay_margin(finding: DelayFinding, backward: Scenario) -> DelayFinding:
    """``finding`` with the linearised delay margin of ``backward``'s body and gains, and the
    oscillation its nonlinear run keeps at the largest delay it survives (1.5 s on the
    compiled engine, sampled at 2 kHz to resolve the fast mode)."""
    from dataclasses import replace

    from ..linear.delay import delay_margin

    margin = delay_margin(backward.body, backward.muscles)
    oscillation = None
    if finding.survives is not None:
        r = backward.replace(duration=1.5, sample_rate=2000.0).run(
            feedback_delay=finding.survives, engine="compiled")
        knee = (r.theta[:, 1] - r.theta[:, 0])[r.time >= r.time[-1] - 0.5]
        oscillation = float(np.abs(knee - knee.mean()).max())
    return replace(finding, margin=margin.delay_margin,
                   crossing_frequency=margin.crossing_frequency, oscillation=oscillation)


def literature_controller_finding(foot: BaseOfSupport, name: str = "peterka-2002"
                                  ) -> LiteratureControllerFinding:
    """The preset ``name`` on ``paper-1link``: delay margin, and the largest backward
    ramp-and-hold (over :data:`RECOVERY_RAMP_DURATION`, bisection to 1 mm) by the CoP and the
    CoG criteria, on the compiled engine with the preset's delay."""
    from ..linear.delay import delay_margin
    from ..model.body import get_body
    from ..model.controllers import get_controller
    from ..model.platform import RampAndHold
    from ..simulation import simulate
    from ..studies.recovery import largest_recoverable

    body = get_body("paper-1link")
    preset = get_controller(name)
    muscles = preset.muscles(body)

    def search(cop: bool) -> float:
        fall = FallCriteria(base_of_support=foot, centre_of_pressure=cop)

        def run(d: float) -> SimulationResult:
            return simulate(body, muscles, RampAndHold(-d, RECOVERY_RAMP_DURATION), 4.0,
                            fall=fall, sample_rate=50.0, engine="compiled",
                            **preset.run_options())

        return largest_recoverable(run, 0.01, 1.0, tolerance=1e-3).estimate

    return LiteratureControllerFinding(
        ramp_duration=RECOVERY_RAMP_DURATION, by_cop=search(True), by_cog=search(False),
        preset=preset, delay_margin=float(delay_margin(body, muscles).delay_margin))


def strategy_finding(body: Body, foot: BaseOfSupport, ankle_torque_limit: float = 60.0
                     ) -> StrategyFinding:
    """Case 1 with the ankle moment limited: hip fraction over backward ramp-and-holds of
    2–30 cm against the small unlimited runs (:func:`posturelab.studies.strategy.
    hip_fraction_study`)."""
    from ..studies.strategy import hip_fraction_study

    muscles = paper_muscles("1")
    fall = FallCriteria(base_of_support=foot)
    free = hip_fraction_study(body, muscles, np.linspace(0.01, 0.05, 5),
                              ankle_torque_limit=1e6, fall=fall,
                              ramp_duration=RECOVERY_RAMP_DURATION)
    sizes = np.linspace(0.02, 0.30, 29)
    limited = hip_fraction_study(body, muscles, sizes, ankle_torque_limit=ankle_torque_limit,
                                 fall=fall, ramp_duration=RECOVERY_RAMP_DURATION)
    kept = limited.hip_fraction[~limited.fell]
    first_fall = float(sizes[limited.fell][0]) if limited.fell.any() else None
    return StrategyFinding(ankle_torque_limit, float(free.hip_fraction.mean()),
                           float(kept.max()) if kept.size else float("nan"), first_fall,
                           RECOVERY_RAMP_DURATION)


@dataclass(frozen=True)
class FRFExperiment:
    """The report's simulated PRTS experiment (:func:`frf_experiment`).

    Attributes
    ----------
    estimate : FRFEstimate
        The 11-band estimate of the sway (tilt FRF, the literature's sign).
    true, fitted, standard_error : tuple of float
        K_P [N·m/rad], K_D [N·m·s/rad], τ [s]: simulated, fitted, and its standard errors.
    fit_error : float
        RMS weighted residual of the fit. [-]
    cycles : int
        Cycles analysed (one more ran first and was dropped). [-]
    noise : float
        Standard deviation of the white sensor noise on the sway. [rad]
    """

    estimate: Any
    true: tuple
    fitted: tuple
    standard_error: tuple
    fit_error: float
    cycles: int
    noise: float


#: Seeds of the fit-back spread (:func:`fit_back_errors`): the report's own and 19 more. [-]
FIT_BACK_SEEDS: tuple[int, ...] = (20261201, *range(1, 20))


@functools.lru_cache(maxsize=1)
def _frf_run():
    """The ``peterka-2002`` preset on ``paper-1link`` under posturelab's 80-state PRTS
    (0.035 rad peak to peak; compiled engine, 6 cycles at 100 Hz): body, preset, muscles,
    tilt, run (noise-free; the sensor noise is added after, outside the loop)."""
    from ..model.body import get_body
    from ..model.controllers import get_controller
    from ..model.tilt import PRTSTilt
    from ..simulation import simulate

    body = get_body("paper-1link")
    preset = get_controller("peterka-2002")
    muscles = preset.muscles(body)
    tilt = PRTSTilt.named("posturelab-80", 0.035)
    r = simulate(body, muscles, None, 20.0 * (FRF_CYCLES + 1), tilt=tilt, sample_rate=100.0,
                 engine="compiled", **preset.run_options())
    return body, preset, muscles, tilt, r


#: Cycles analysed in the report's PRTS experiment (one more runs first, dropped). [-]
FRF_CYCLES = 5
#: Standard deviation of its white sensor noise. [rad]
FRF_NOISE = 0.001


def _fit_back(seed: int):
    """Estimate and fit of the report's PRTS experiment with the sensor noise of ``seed``:
    (estimate, true (K_P, K_D, τ), fit)."""
    from ..frequency import estimate_frf
    from ..frequency.fit import fit_frf

    body, preset, muscles, tilt, r = _frf_run()
    rng = np.random.default_rng(seed)
    sway = r.theta[:-1, 0] + rng.normal(0.0, FRF_NOISE, r.time.size - 1)
    est = estimate_frf(tilt.angle(r.time[:-1]), sway, 100.0, 20.0, discard_cycles=1,
                       response_sign=-1)
    true = (muscles.active_stiffnesses[0], muscles.active_viscosities[0], preset.feedback_delay)
    start = muscles.with_active_feedback([0.8 * true[0]], [1.2 * true[1]])
    fit = fit_frf(body, start, est, ["active_stiffness", "active_viscosity", "feedback_delay"],
                  feedback_delay=0.8 * true[2])
    return est, tuple(float(v) for v in true), fit


def fit_back_errors(seeds=FIT_BACK_SEEDS) -> np.ndarray:
    """Relative error fitted/true − 1 of K_P, K_D and τ of the report's PRTS experiment for
    each seed of the sensor noise (the same noise-free run), shape (S, 3). [-]"""
    rows = []
    for seed in seeds:
        _, true, fit = _fit_back(int(seed))
        rows.append(np.asarray(fit.estimates, dtype=float) / np.asarray(true) - 1.0)
    return np.array(rows)


@functools.lru_cache(maxsize=2)
def frf_experiment(seed: int = 20261201) -> FRFExperiment:
    """The ``peterka-2002`` preset on ``paper-1link`` under posturelab's 80-state PRTS
    (0.035 rad peak to peak; compiled engine, 6 cycles at 100 Hz, the first discarded,
    seeded sensor noise of 1 mrad), estimated at the 11 bands and fitted for K_P, K_D and τ
    from 20 % off."""
    est, true, fit = _fit_back(seed)
    return FRFExperiment(est, true, tuple(float(v) for v in fit.estimates),
                         tuple(float(v) for v in fit.standard_errors), float(fit.fit_error),
                         FRF_CYCLES, FRF_NOISE)


def frf_finding(seed: int = 20261201) -> FRFFinding:
    """The tilt FRFs of case 1 and of ``peterka-2002`` on ``paper-1link`` at 0.05, 0.55 and
    2.2 Hz, the simulated PRTS experiment of :func:`frf_experiment` fitted, and the fit-back
    errors over the :data:`FIT_BACK_SEEDS` noise realisations (:func:`fit_back_errors`:
    median and largest |error| per parameter)."""
    from ..frequency import model_frf
    from ..model.body import get_body, paper_body
    from ..model.controllers import get_controller

    f = np.array([0.05, 0.55, 2.2])
    paper = model_frf(paper_body(), paper_muscles("1"), f)
    body = get_body("paper-1link")
    preset = get_controller("peterka-2002")
    delayed = model_frf(body, preset.muscles(body), f, **preset.run_options())
    exp = frf_experiment(seed)

    def phase(h):
        return tuple(float(p) for p in np.degrees(np.unwrap(np.angle(h))))

    errors = np.abs(fit_back_errors()) * 100.0
    return FRFFinding(tuple(float(v) for v in f), tuple(float(v) for v in np.abs(paper)),
                      phase(paper), tuple(float(v) for v in np.abs(delayed)), phase(delayed),
                      exp.true, exp.fitted, exp.standard_error, exp.cycles, exp.noise,
                      exp.fit_error, len(FIT_BACK_SEEDS),
                      tuple(float(v) for v in np.median(errors, axis=0)),
                      tuple(float(v) for v in errors.max(axis=0)))
