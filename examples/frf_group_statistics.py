"""Two groups of FRFs compared, with bootstrap bands and a likeness score
=========================================================================

A synthetic experiment of the kind :mod:`posturelab.frequency.statistics` is for: two
groups of 12 virtual subjects on the one-link body (``paper-1link``), each subject its own
independent-channel controller around the ``peterka-2002`` preset (active stiffness 1.35 mgh
and viscosity 0.47 mgh·s, each times a log-normal factor of spread 0.15; delay 0.15 s with
a standard deviation of 0.015 s: spreads chosen here for illustration, not published
ones). Group A has a proprioceptive weight W drawn about 0.8, group B about 0.6 (standard
deviation 0.08 each): a difference of 0.2 built in, as sensory reweighting between two
stimulus amplitudes would give. Each subject stands through a seeded PRTS tilt experiment
(:func:`posturelab.frequency.experiment.prts_experiment`: the 80-state sequence, 0.035 rad
peak to peak, 5 cycles after one discarded, 2 mrad of white sensor noise), its FRF
estimated at the 11 bands.

The left panel draws each group's mean gain, the right one the difference of the group
means in the complex plane per band with its bootstrap 95 % intervals of the real and
imaginary parts (:func:`posturelab.frequency.statistics.compare_frf_groups`); the title
gives the permutation test's p over all bands (10⁴ permutations, seeded). That p is one
seeded draw of 24 subjects, not a rate: another seed gives another p (the tests measure
the test's level and power over hundreds of seeded cohorts). The script also prints the
bootstrap bands of one subject's FRF over its cycles and each group's human-likeness
distances to a reference built from group A itself
(:func:`posturelab.frequency.likeness.build_likeness_reference`, shrunk: 12 subjects are
fewer than the 23 an unshrunk covariance of 11 bands needs).

Usage: python examples/frf_group_statistics.py [OUTPUT_DIR]   (default: current directory)
"""

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

import posturelab as pl
from posturelab.frequency.experiment import prts_experiment
from posturelab.frequency.likeness import build_likeness_reference, likeness_score
from posturelab.frequency.statistics import bootstrap_frf_bands, compare_frf_groups
from posturelab.model.controllers import get_controller
from posturelab.viz.plots import new_figure, save_figure

SUBJECTS = 12  # per group [-]
WEIGHTS = {"A": 0.8, "B": 0.6}  # mean proprioceptive weight per group [-]
SEED = 20261202


def group(name: str, rng: np.random.Generator) -> list:
    """The FRF estimates of one group's virtual subjects."""
    body = pl.get_body("paper-1link")
    preset = get_controller("peterka-2002")
    out = []
    for _ in range(SUBJECTS):
        subject = replace(
            preset, active_stiffness=preset.active_stiffness * rng.lognormal(0, 0.15),
            active_viscosity=preset.active_viscosity * rng.lognormal(0, 0.15),
            feedback_delay=float(np.clip(rng.normal(0.15, 0.015), 0.1, 0.2)),
            proprioceptive_weight=float(np.clip(rng.normal(WEIGHTS[name], 0.08), 0.1, 1.0)))
        exp = prts_experiment(body, subject.muscles(body), cycles=5, discard=1,
                              sensor_noise=0.002, seed=int(rng.integers(2**31)),
                              **subject.run_options())
        if exp.estimate is not None:  # (a subject who fell has no FRF)
            out.append(exp.estimate)
    return out


def make_figure():
    """The figure (a pyplot-free matplotlib Figure)."""
    rng = np.random.default_rng(SEED)
    a, b = group("A", rng), group("B", rng)
    result = compare_frf_groups(a, b, permutations=10_000, seed=1)
    f = result.frequency
    fig, (left, right) = new_figure(1, 2, figsize=(9.0, 4.0))
    for mean, label in ((result.mean_a, f"A (W ≈ {WEIGHTS['A']})"),
                        (result.mean_b, f"B (W ≈ {WEIGHTS['B']})")):
        left.plot(f, np.abs(mean), "o-", label=label)
    left.set_xscale("log")
    left.set_xlabel("frequency [Hz]")
    left.set_ylabel("mean gain [-]")
    left.legend(fontsize=8)
    d = result.difference
    right.errorbar(d.real, d.imag, xerr=np.abs(result.re_ci.T - d.real),
                   yerr=np.abs(result.im_ci.T - d.imag), fmt="o", ms=3, lw=0.8)
    for k in (0, 4, 10):
        right.annotate(f"{f[k]:.2f} Hz", (d.real[k], d.imag[k]), fontsize=7)
    right.axhline(0, color="0.6", lw=0.5)
    right.axvline(0, color="0.6", lw=0.5)
    right.set_xlabel("Re(mean A − mean B) [-]")
    right.set_ylabel("Im(mean A − mean B) [-]")
    fig.suptitle(f"{len(a)} against {len(b)} subjects: permutation test over 11 bands, "
                 f"p = {result.p_value:.4f}", fontsize=10)
    print(f"p = {result.p_value:.4g} (T = {result.statistic:.3g}, "
          f"{result.permutations:,} permutations)")
    # one subject's bootstrap bands over its cycles
    body = pl.get_body("paper-1link")
    preset = get_controller("peterka-2002")
    exp = prts_experiment(body, preset.muscles(body), cycles=12, discard=1,
                          sensor_noise=0.002, seed=3, **preset.run_options())
    bands = bootstrap_frf_bands(exp.stimulus, exp.response, 100.0, 20.0, discard_cycles=1,
                                response_sign=-1, resamples=2000, seed=1)
    for k in (0, 5, 10):
        lo, hi = bands.gain_ci[k]
        print(f"one subject, 12 cycles, {bands.frequency[k]:.2f} Hz: gain "
              f"{abs(bands.frf[k]):.3f}, bootstrap 95 % {lo:.3f} … {hi:.3f}")
    reference = build_likeness_reference(a, shrinkage=0.3, name="group A")
    for name, frfs in (("A", a), ("B", b)):
        scores = [likeness_score(e.frf, reference) for e in frfs]
        print(f"likeness distance to group A's reference, group {name}: median "
              f"{np.median(scores):.2f} (quartiles {np.quantile(scores, 0.25):.2f} … "
              f"{np.quantile(scores, 0.75):.2f})")
    return fig


if __name__ == "__main__":
    out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
    fig = make_figure()
    print(save_figure(fig, out_dir / "frf_group_statistics.png"))
