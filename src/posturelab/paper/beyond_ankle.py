"""Beyond the ankle, in the report: the hip strategy under a designed multi-joint controller
and the step threshold by age, each beside the human figures it is compared with.

Computed by :func:`beyond_ankle_finding` from the public studies
(:func:`posturelab.studies.strategy.translation_map`, :func:`~posturelab.studies.strategy.
oscillation_map`, :func:`posturelab.studies.stepping.step_threshold`); the words say what the
model cannot do.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.body import Body

__all__ = ["BeyondAnkleFinding", "beyond_ankle_finding", "STRATEGY_SPEEDS",
           "STRATEGY_FREQUENCIES", "OSCILLATION_AMPLITUDE"]

#: Peak speeds of the backward translations of the strategy map. [m/s]
STRATEGY_SPEEDS = (0.05, 0.1, 0.3, 0.5, 0.75, 1.0)
#: Frequencies of the sinusoidal translations. [Hz]
STRATEGY_FREQUENCIES = (0.1, 0.5, 0.75, 1.0, 1.25)
#: Their amplitude (issue 22's 5 cm; Buchanan & Horak 1999 used sinusoids of this order). [m]
OSCILLATION_AMPLITUDE = 0.05


@dataclass(frozen=True)
class BeyondAnkleFinding:
    """The hip strategy and the step threshold, with their numbers.

    Attributes
    ----------
    controller : str
        The multi-joint preset's name.
    ankle_torque_limit : float
        The ankle's limit both ways in the strategy maps. [N·m]
    speeds, translation_hip_fractions : tuple of float
        Backward translations: peak speed [m/s] and hip fraction [-] (NaN: fell).
    frequencies, oscillation_hip_fractions : tuple of float
        Sinusoids of :data:`OSCILLATION_AMPLITUDE`: frequency [Hz], steady hip fraction [-].
    transition_frequency : float or None
        First frequency at which the hip mode dominates. [Hz]
    thresholds : tuple of (str, float, float, float)
        (population, model's largest translation, published mean, published SD). [m]
    move_duration : float
        Of the step-threshold moves. [s]
    """

    controller: str
    ankle_torque_limit: float
    speeds: tuple
    translation_hip_fractions: tuple
    frequencies: tuple
    oscillation_hip_fractions: tuple
    transition_frequency: float | None
    thresholds: tuple
    move_duration: float

    @property
    def text(self) -> str:
        """The finding in words, with its numbers."""
        def fractions(values, keys, unit):
            return ", ".join(f"{v:.2f} at {k:g} {unit}" if np.isfinite(v) else
                             f"a fall at {k:g} {unit}" for k, v in zip(keys, values, strict=True))

        transition = ("no frequency up to the last" if self.transition_frequency is None
                      else f"{self.transition_frequency:g} Hz")
        thresholds = "; ".join(
            f"{name} {model * 100:.1f} cm against {mean * 100:.1f} ± {sd * 100:.1f} cm ("
            + ("within" if abs(model - mean) <= 2 * sd else "outside") + " two SD)"
            for name, model, mean, sd in self.thresholds)
        return (
            "Beyond the ankle (posturelab strategy and step-threshold; the paper's abstract "
            "leaves the hip strategy and stepping for later). On the paper's body with the "
            f"designed multi-joint controller {self.controller} (delayed full-state feedback "
            "from an LQR design, knee locked) and the ankle limited to "
            f"{self.ankle_torque_limit:.0f} N·m both ways, the hip fraction of backward 6 cm "
            "ramp-and-holds rises with their peak speed: "
            + fractions(self.translation_hip_fractions, self.speeds, "m/s")
            + " (people bring in the hip at fast backward translations: Horak & Nashner "
            "1986, Runge et al. 1999); under 5 cm sinusoidal translations it is "
            + fractions(self.oscillation_hip_fractions, self.frequencies, "Hz")
            + f", the hip mode dominating from {transition} (Buchanan & Horak 1999 saw the "
            "change from riding the platform to a head-stable multi-segment pattern as the "
            "frequency rose). The limit lets the centre of pressure pass the heel; with the "
            "heel's own limit the body falls between the slow and fast ends. Largest backward "
            "translation without a step (a one-link body of 1.75 m and 75 kg, the "
            "population's functional base of support, the platform's remaining path counted, "
            f"moves over {self.move_duration:g} s, posturelab's assumption): {thresholds} "
            "(Koushyar et al. 2019, PMC6338353). The step-threshold body has no hip and no "
            "torque that builds up at a limited rate; docs/guide/stepping.rst gives how much "
            "the numbers hang on the assumptions."
        )


def beyond_ankle_finding(body: Body) -> BeyondAnkleFinding:
    """The strategy maps of ``multijoint-default`` on ``body`` and the step thresholds of the
    young and older presets (1.75 m, 75 kg)."""
    from ..linear.lqr import multijoint_controller
    from ..studies.stepping import PROTOCOL, PUBLISHED, step_threshold
    from ..studies.strategy import oscillation_map, translation_map

    controller = multijoint_controller(body)
    limit = float(controller.effort_limits[0])
    options = controller.run_options()
    moves = translation_map(body, controller.muscles, STRATEGY_SPEEDS, direction="backward",
                            ankle_torque_limit=limit, **options)
    waves = oscillation_map(body, controller.muscles, OSCILLATION_AMPLITUDE,
                            STRATEGY_FREQUENCIES, ankle_torque_limit=limit, **options)
    thresholds = []
    for name in ("young", "older"):
        published = PUBLISHED[(name, "backward")]
        result = step_threshold(1.75, 75.0, name, "backward")
        thresholds.append((name, result.largest_translation, published.mean, published.sd))
    return BeyondAnkleFinding(
        controller.name, limit, STRATEGY_SPEEDS,
        tuple(r.hip_fraction for r in moves.runs), STRATEGY_FREQUENCIES,
        tuple(r.hip_fraction for r in waves.runs), waves.transition_frequency,
        tuple(thresholds), PROTOCOL.move_duration)
