"""A synthetic cohort: 40 virtual subjects at two tilt amplitudes, W falling, and likeness
=========================================================================================

What a lab does with a PRTS surface-tilt study, run on virtual subjects whose true
parameters are known: 40 subjects, each tested at 1° and 4° peak to peak (two of the
amplitudes of Peterka 2002, J Neurophysiol 88:1097–1118, which used 0.5° … 8°), eyes
closed; each trial simulated on the compiled engine
(:func:`posturelab.frequency.experiment.prts_experiment`: the 80-state sequence, 20 s
cycles, 4 analysed after 1 discarded, 5 N·m of white motor noise at the ankle, 1 mrad of
white sensor noise on the recorded centre-of-mass angle; sensor and motor noise draw
independent streams), its FRF estimated at the 11 bands, the model fitted per subject and
amplitude (:func:`posturelab.frequency.cohort.fit_cohort`: K_P, K_D, τ and W free), W
compared across the amplitudes (per subject with
:func:`posturelab.frequency.reweighting.compare_conditions`, and over the cohort by the
paired differences), and each FRF scored against COMTEST's eyes-closed tilt reference
(:func:`posturelab.frequency.likeness.likeness_score`, preset ``comtest-eyes-closed``).

**The subjects, and where each number comes from.** Body: the paper's body as one link
(``paper-1link``). Means: PMC5664365 Table 1, the default parameters of the
independent-channel stance model (posturelab's preset ``icm-pmc5664365``): K_P = 943.9
N·m/rad and K_D = 313.5 N·m·s/rad, divided by that table's m·g·h = 75 × 9.81 × 0.83 N·m/rad
(1.55 mgh and 0.51 mgh·s, scaled here to the paper body's mgh), τ = 0.097 s, W = 0.8, and
its intrinsic stiffness and damping (40.5 N·m/rad, 68.8 N·m·s/rad, likewise per mgh) for
every subject. **Spreads: assumptions of this page, not a source's**: a coefficient of
variation of 15 % on K_P and K_D (log-normal), 0.015 s on τ and 0.08 on W (normal). The
searches made for this page (Peterka 2002; PMC5664365; van der Kooij and Peterka 2011, J
Comput Neurosci 30:759) found no between-subject standard deviations of these parameters in
a form that could be checked, so none is attributed to a source. **W at the larger
amplitude**: Peterka 2002 reports that the proprioceptive weight falls as the surface-tilt
amplitude grows (eyes closed); the size of the fall here (0.2 on average from 1° to 4°,
standard deviation 0.05 between subjects) is this page's assumption, not a number read from
that paper.

**Torque feedback is omitted.** The issue asks for the slow positive torque feedback among
the spreads (PMC5664365 Table 1 gives K_F = 0.0018 rad/N·m and τ_F = 17.4 s); posturelab
models it (``torque_feedback_gain``, ``torque_feedback_time_constant``) on the reference
engine only: the compiled engine refuses it, and 240 reference-engine trials (80 per seed)
do not fit this page's time. The virtual subjects therefore have none (gain 0), and the
fitted model has none either.

**Spread over seeds.** The whole study (new subjects, new noise) is run for ``SEEDS`` seeds;
every number printed is the mean over the seeds ± their standard deviation. The figure
shows the first seed.

**Likeness scale.** COMTEST's FRF is the sway per unit peak-to-peak tilt in the recording's
unit, H_COMTEST = A · H with A the tilt's peak-to-peak amplitude in the unit of the recorded
sway (:mod:`posturelab.frequency.likeness`); its reference file states neither the unit nor
the amplitude, so **the scale is unknown**. This page scores with A in degrees (1 and 4: the
hypothesis that COMTEST's sway was recorded in degrees, which nothing here confirms), and
prints, as a diagnostic, the factor that would make the cohort's median distance smallest
at each amplitude; where the two differ, the scores at the hypothesised scale say more
about the scale than about the subjects. With S = I, D² of a person drawn from the
reference population would be about χ² with 22 degrees of freedom (median D ≈ 4.6).

Left: each subject's fitted W at 1° and 4° (a line per subject). Middle: fitted against
true K_P, K_D, τ and W, each divided by its population mean. Right: the likeness distances.

Usage: python examples/synthetic_cohort.py [OUTPUT_DIR]   (default: current directory)
"""

import sys
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

import posturelab as pl
from posturelab.frequency.cohort import fit_cohort
from posturelab.frequency.experiment import prts_experiment
from posturelab.frequency.likeness import likeness_reference, likeness_score
from posturelab.frequency.reweighting import compare_conditions
from posturelab.model.controllers import get_controller
from posturelab.model.noise import MotorNoise
from posturelab.model.tilt import PRTSTilt
from posturelab.viz.plots import new_figure, save_figure

SUBJECTS = 40  # [-]
AMPLITUDES_DEG = (1.0, 4.0)  # peak to peak [deg]
SEEDS = 3  # whole studies run [-]
SEED = 20261202
CYCLES, DISCARD = 4, 1  # analysed, discarded [-]
MOTOR_NOISE = 5.0  # ankle, white [N·m]
SENSOR_NOISE = 0.001  # on the recorded angle [rad]
PRESET = "icm-pmc5664365"  # the means (module notes)
#: Between-subject spreads: ASSUMPTIONS of this page (module notes), not a source's.
CV_GAINS = 0.15  # log-normal spread of K_P and K_D [-]
SD_DELAY = 0.015  # [s]
SD_WEIGHT = 0.08  # [-]
W_FALL, SD_W_FALL = 0.2, 0.05  # W(1°) − W(4°): mean and spread [-]
FREE = ["active_stiffness:ankle", "active_viscosity:ankle", "feedback_delay",
        "proprioceptive_weight"]
LABELS = ("K_P", "K_D", "τ", "W")


@dataclass
class Study:
    """One seeded run of the whole study."""

    true: np.ndarray  # (subjects, amplitudes, 4): K_P, K_D [N·m/rad, N·m·s/rad], τ [s], W
    fitted: np.ndarray  # same shape, NaN where a subject fell or a fit failed
    p_values: np.ndarray  # (subjects,) compare_conditions, W differs
    likeness: np.ndarray  # (subjects, amplitudes)
    frfs: np.ndarray  # (subjects, amplitudes, bands) complex, NaN where a subject fell
    coherence: np.ndarray  # (subjects, amplitudes) median over the bands [-]
    fell: int


def subjects(rng: np.random.Generator, count: int = SUBJECTS) -> list:
    """``count`` controllers drawn about the preset, each with its W at each amplitude."""
    preset = get_controller(PRESET)
    out = []
    for _ in range(count):
        base = replace(
            preset, active_stiffness=preset.active_stiffness * rng.lognormal(0, CV_GAINS),
            active_viscosity=preset.active_viscosity * rng.lognormal(0, CV_GAINS),
            feedback_delay=float(np.clip(rng.normal(preset.feedback_delay, SD_DELAY),
                                         0.05, 0.2)))
        w_small = float(np.clip(rng.normal(preset.proprioceptive_weight, SD_WEIGHT), 0.3, 1.0))
        w_large = float(np.clip(w_small - rng.normal(W_FALL, SD_W_FALL), 0.05, 1.0))
        out.append([replace(base, proprioceptive_weight=w) for w in (w_small, w_large)])
    return out


def run_study(seed: int, count: int = SUBJECTS, workers: int = 1) -> Study:
    """Simulate, estimate, fit, compare and score one seeded cohort."""
    rng = np.random.default_rng([SEED, seed])
    body = pl.get_body("paper-1link")
    cohort = subjects(rng, count)
    reference = likeness_reference("comtest-eyes-closed")
    A = len(AMPLITUDES_DEG)
    true = np.full((count, A, 4), np.nan)
    fitted = np.full((count, A, 4), np.nan)
    estimates = [[None] * A for _ in range(count)]
    frfs = np.full((count, A, reference.mean.size), np.nan, dtype=complex)
    coherence = np.full((count, A), np.nan)
    fell = 0
    for s, conditions in enumerate(cohort):
        for a, (controller, deg) in enumerate(zip(conditions, AMPLITUDES_DEG, strict=True)):
            muscles = controller.muscles(body)
            options = controller.run_options()
            pair = muscles.pairs[0]
            true[s, a] = (pair.active_stiffness, pair.active_viscosity,
                          options["feedback_delay"], options["proprioceptive_weight"])
            trial = int(rng.integers(2**31))
            exp = prts_experiment(body, muscles, tilt=PRTSTilt.named("posturelab-80",
                                                                     np.radians(deg)),
                                  cycles=CYCLES, discard=DISCARD, sensor_noise=SENSOR_NOISE,
                                  seed=trial, motor_noise=MotorNoise(MOTOR_NOISE, seed=trial),
                                  **options)
            fell += exp.fell
            estimates[s][a] = exp.estimate
            if exp.estimate is not None:
                frfs[s, a] = exp.estimate.frf
                coherence[s, a] = np.median(exp.estimate.coherence)
    # the experimenter's starting point: the preset, not the subject's own values
    start = get_controller(PRESET)
    start_muscles, start_options = start.muscles(body), start.run_options()
    fit_options = {k: start_options[k] for k in ("feedback_delay", "proprioceptive_weight")}
    for a in range(A):
        have = [s for s in range(count) if estimates[s][a] is not None]
        result = fit_cohort(body, start_muscles, [estimates[s][a] for s in have], FREE,
                            workers=workers, **fit_options)
        for s, fit in zip(have, result.subjects, strict=True):
            if not fit.failed:
                fitted[s, a] = fit.estimates
    p_values = np.full(count, np.nan)
    likeness = np.full((count, A), np.nan)
    for s in range(count):
        if any(e is None for e in estimates[s]):
            continue
        comparison = compare_conditions(body, start_muscles, estimates[s], FREE[:3],
                                        parameter="proprioceptive_weight",
                                        vision=["closed"] * A, **fit_options)
        p_values[s] = comparison.p_value
        for a, deg in enumerate(AMPLITUDES_DEG):
            likeness[s, a] = likeness_score(estimates[s][a], reference, scale=deg)
    return Study(true, fitted, p_values, likeness, frfs, coherence, fell)


def paired_interval(study: Study) -> tuple[float, float, float]:
    """Mean of W(1°) − W(4°) over the subjects and its 95 % t-interval. [-]"""
    from scipy.stats import t as student

    d = study.fitted[:, 0, 3] - study.fitted[:, 1, 3]
    d = d[np.isfinite(d)]
    half = student.ppf(0.975, d.size - 1) * np.std(d, ddof=1) / np.sqrt(d.size)
    return float(np.mean(d)), float(np.mean(d) - half), float(np.mean(d) + half)


def summary(studies: list) -> dict:
    """The page's numbers, one value per seeded study each."""
    out: dict[str, list] = {}

    def add(name, value):
        out.setdefault(name, []).append(float(value))

    for st in studies:
        for a, deg in enumerate(AMPLITUDES_DEG):
            add(f"mean fitted W at {deg:g}°", np.nanmean(st.fitted[:, a, 3]))
            add(f"mean true W at {deg:g}°", np.nanmean(st.true[:, a, 3]))
        mean, lo, hi = paired_interval(st)
        add("mean paired W(1°) − W(4°)", mean)
        add("  its 95 % interval, low", lo)
        add("  its 95 % interval, high", hi)
        add("true mean W(1°) − W(4°)", np.mean(st.true[:, 0, 3] - st.true[:, 1, 3]))
        add("subjects with W differing at p < 0.05 [%]",
            100 * np.mean(st.p_values[np.isfinite(st.p_values)] < 0.05))
        for k, label in enumerate(LABELS):
            rel = st.fitted[..., k] / st.true[..., k] - 1
            add(f"median |fitted/true − 1| of {label} [%]", 100 * np.nanmedian(np.abs(rel)))
        for a, deg in enumerate(AMPLITUDES_DEG):
            add(f"median likeness D at {deg:g}° (scale {deg:g})",
                np.nanmedian(st.likeness[:, a]))
        reference = likeness_reference("comtest-eyes-closed")
        for a, deg in enumerate(AMPLITUDES_DEG):
            add(f"  scale minimising it at {deg:g}° (diagnostic)", best_scale(st, a, reference))
        for a, deg in enumerate(AMPLITUDES_DEG):
            add(f"median coherence over bands and subjects, {deg:g}°",
                np.nanmedian(st.coherence[:, a]))
        add("trials that fell", st.fell)
    return out


def best_scale(study: Study, amplitude: int, reference) -> float:
    """The factor on every FRF at one amplitude that makes the cohort's median distance to
    ``reference`` smallest (over a grid of 0.25 … 16): a diagnostic, not a calibration. [-]"""
    grid = np.geomspace(0.25, 16.0, 49)
    frfs = [h for h in study.frfs[:, amplitude] if np.all(np.isfinite(h))]
    medians = [np.median([likeness_score(h, reference, scale=c) for h in frfs]) for c in grid]
    return float(grid[int(np.argmin(medians))])


def make_figure(seeds: int = SEEDS, count: int = SUBJECTS, workers: int = 1):
    """The figure (a pyplot-free matplotlib Figure); prints the page's numbers."""
    studies = [run_study(k, count, workers) for k in range(seeds)]
    numbers = summary(studies)
    print(f"{count} subjects, {seeds} seeded studies: mean ± standard deviation over seeds")
    for name, values in numbers.items():
        v = np.array(values)
        sd = np.std(v, ddof=1) if v.size > 1 else float("nan")
        print(f"  {name:48s} {np.mean(v):8.3f} ± {sd:.3f}")
    st = studies[0]
    fig, (left, middle, right) = new_figure(1, 3, figsize=(12.0, 4.0))
    x = np.arange(len(AMPLITUDES_DEG))
    for s in range(count):
        left.plot(x, st.fitted[s, :, 3], "-", color="0.6", lw=0.6)
    left.plot(x, np.nanmean(st.fitted[:, :, 3], axis=0), "o-", color="C3", lw=2,
              label="cohort mean (fitted)")
    left.plot(x, np.mean(st.true[:, :, 3], axis=0), "s--", color="C0", label="cohort mean (true)")
    left.set_xticks(x, [f"{d:g}° p-p" for d in AMPLITUDES_DEG])
    left.set_xlim(-0.3, len(x) - 0.7)
    left.set_ylabel("fitted proprioceptive weight W [-]")
    mean, lo, hi = paired_interval(st)
    left.set_title(f"W(1°) − W(4°) = {mean:.3f} (95 %: {lo:.3f} … {hi:.3f})", fontsize=9)
    left.legend(fontsize=7)
    for k, label in enumerate(LABELS):
        scale = np.mean(st.true[..., k])
        middle.plot((st.true[..., k] / scale).ravel(), (st.fitted[..., k] / scale).ravel(),
                    "o", ms=3, alpha=0.7, label=label)
    lims = [0.0, 1.8]
    middle.plot(lims, lims, color="0.5", lw=0.6)
    middle.set_xlim(lims)
    middle.set_ylim(lims)
    middle.set_xlabel("true / population mean [-]")
    middle.set_ylabel("fitted / population mean [-]")
    middle.legend(fontsize=7)
    bins = np.linspace(0, np.nanmax(st.likeness) * 1.05, 20)
    for a, deg in enumerate(AMPLITUDES_DEG):
        right.hist(st.likeness[:, a], bins=bins, alpha=0.6, label=f"{deg:g}° (scale {deg:g})")
    right.set_xlabel("likeness distance D to comtest-eyes-closed [-]")
    right.set_ylabel("subjects")
    right.legend(fontsize=7)
    fig.suptitle(f"Synthetic cohort: {count} subjects at two tilt amplitudes (seed 1 of {seeds})",
                 fontsize=10)
    return fig


def main(out_dir: Path, seeds: int = SEEDS, count: int = SUBJECTS) -> Path:
    return save_figure(make_figure(seeds, count), out_dir / "synthetic_cohort.png")


if __name__ == "__main__":
    out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
    fig = make_figure()
    print(save_figure(fig, out_dir / "synthetic_cohort.png"))
