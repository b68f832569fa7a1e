"""The example scripts that compute something beyond the paper, checked independently."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np

from posturelab.model.body import paper_body
from posturelab.model.muscles import paper_muscles
from posturelab.model.platform import VelocityStep
from posturelab.simulation import FOOT_FROM_LITERATURE, FallCriteria, simulate
from posturelab.studies.recovery import largest_recoverable

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_largest_step_grid_brackets_the_reference_bisection(tmp_path):
    """The batch grid's boundary (largest speed recovered, smallest that fell) must bracket
    the boundary that bisection finds with the reference simulator (scipy DOP853), run by
    run; the example also writes its figure."""
    example = _load("largest_step_vs_ankle")
    ankle = np.array([400.0, 900.0])
    speed = np.linspace(0.1, 3.0, 30)
    recovered, first_fall = example.largest_recovered(ankle, speed, duration=3.0)
    assert np.all(np.isfinite(recovered)) and np.all(np.isfinite(first_fall))
    assert recovered[1] > recovered[0]  # a stiffer ankle absorbs a larger step
    fall = FallCriteria(base_of_support=FOOT_FROM_LITERATURE)
    base = np.asarray(paper_muscles("1").stiffnesses, dtype=float)
    for a, lo, hi in zip(ankle, recovered, first_fall, strict=True):
        k = base.copy()
        k[0] = a
        muscles = paper_muscles(stiffness=k, viscosity=0.25 * k)

        def run(v, muscles=muscles):
            return simulate(paper_body(), muscles, VelocityStep.backward(v), 3.0, fall=fall,
                            engine="reference")

        # raises if the reference disagrees at either end of the grid's bracket
        boundary = largest_recoverable(run, lo, hi, tolerance=0.02)
        assert lo <= boundary.estimate <= hi
    figure = example.main(tmp_path)
    assert figure.exists() and figure.stat().st_size > 10_000


def test_delay_stability_map_example_marks_a_stable_published_controller(tmp_path):
    """The D-subdivision example: Peterka's round K_P, K_D lie inside the stable region at
    τ = 0.15 s (the exact delay margin of that set is longer), and the figure is written."""
    import posturelab as pl
    from posturelab.model.muscles import MusclePair, MuscleSet

    example = _load("delay_stability_map")
    dmap = example.compute(resolution=41)
    mgh = dmap.load_stiffness
    ix = int(np.argmin(np.abs(dmap.active_stiffness - 1.35 * mgh)))
    iy = int(np.argmin(np.abs(dmap.active_viscosity - 0.47 * mgh)))
    assert dmap.stable[iy, ix]
    body = pl.get_body("paper-1link")
    muscles = MuscleSet((MusclePair("ankle", 0, 1, 0.05 * mgh, 0.02 * mgh,
                                    active_stiffness=dmap.active_stiffness[ix],
                                    active_viscosity=dmap.active_viscosity[iy]),), 1)
    assert pl.delay_margin(body, muscles).delay_margin > example.DELAY
    assert example.main(tmp_path).stat().st_size > 10_000


def test_experiment_design_example_predicts_the_spread_of_simulated_fits(tmp_path):
    """The design example's predicted error of the delay against the spread of its simulated
    fits (20 seeds: the spread's own sampling error is 16 %), and its figure written."""
    from posturelab.frequency.design import predict_errors
    from posturelab.model.tilt import PRTSTilt

    example = _load("plot_experiment_design")
    body, muscles, options = example._model()
    predicted = predict_errors(
        body, muscles, example.FREE, tilt=PRTSTilt.named("posturelab-80", example.AMPLITUDE),
        cycles=4, sensor_noise=example.SENSOR_NOISE,
        motor_noise=example.MotorNoise(example.MOTOR_NOISE), **options).standard_errors
    spread = np.std(example.spread_of_fits(4), axis=0, ddof=1)
    assert np.all(np.abs(spread / predicted - 1) < 0.4), spread / predicted
    assert example.main(tmp_path, seeds=3).stat().st_size > 10_000


def test_synthetic_cohort_example_recovers_the_fall_of_w(tmp_path):
    """The synthetic-cohort page on 8 seeded subjects: the paired interval of W(1°) − W(4°)
    is the one scipy's paired t-test gives, it holds the true mean fall (0.2 built in) and
    excludes 0, every fitted W lies within 0.1 of its subject's true W, every subject's
    compare_conditions finds the difference, and the figure is written."""
    from scipy.stats import ttest_rel

    example = _load("synthetic_cohort")
    study = example.run_study(0, count=8)
    assert study.fell == 0 and np.all(np.isfinite(study.fitted))
    mean, lo, hi = example.paired_interval(study)
    test = ttest_rel(study.fitted[:, 0, 3], study.fitted[:, 1, 3])
    ci = test.confidence_interval(0.95)
    assert np.allclose([lo, hi], [ci.low, ci.high])
    true_fall = np.mean(study.true[:, 0, 3] - study.true[:, 1, 3])
    assert 0 < lo <= true_fall <= hi
    assert np.all(np.abs(study.fitted[..., 3] - study.true[..., 3]) < 0.1)
    assert np.all(study.p_values < 0.05)
    assert np.all(np.isfinite(study.likeness)) and np.all(study.likeness > 0)
    assert example.main(tmp_path, seeds=2, count=6).stat().st_size > 10_000
