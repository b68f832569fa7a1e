"""``posturelab fit``: estimate pair stiffness from measured link angles."""

from __future__ import annotations

import argparse

from ..parameters import PAPER_PAIRS, resolve
from ..parameters import unit as parameter_unit
from ..studies.identification import ENGINES, FIT_QUANTITIES, RESIDUAL_MODELS
from . import UsageError
from ._common import check_writable, print_json
from ._flags import add_flag, add_flags
from .simulate import add_experiment_arguments, experiment_inputs, scenario_from_args

DESCRIPTION = """\
Fit muscle-pair stiffness [N·m/rad] (and optionally the viscosity ratio [s]) to
measured link angles, by running the nonlinear simulation inside a least-squares
fit. The experiment (body, disturbance, initial state) is described exactly as for
'posturelab simulate' (--case/--stiffness give the starting guess and the fixed
pairs; or --scenario / --builtin). --data is a CSV with columns t [s] and
theta1..theta3 [rad] (what 'posturelab simulate --out' writes), or a .c3d with those
columns; --resample HZ puts an uneven time column on a uniform grid, --angle-unit deg
reads angles in degrees, --time-unit ms a time column in ms (what was resampled or cut:
stderr, or "resampling"/"trimming" in --json). Reports each
estimate with its standard error and 95 % confidence interval; by default these
allow for residuals correlated from sample to sample (a first-order autoregression
per link, estimated from the residuals), which measured sway always has.
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab fit``."""
    add_experiment_arguments(p)
    g = p.add_argument_group("fit")
    g.add_argument("--data", required=True, metavar="ANGLES.csv",
                   help="measured angles: columns t [s], theta1..theta3 [rad].")
    g.add_argument("--free", required=True, metavar="NAME[,NAME…]",
                   help="parameters to fit, named as in the parameter table (the same "
                   "as sweep --vary and fit-frf --free): stiffness:PAIR, viscosity:PAIR, "
                   "active_stiffness:PAIR, active_viscosity:PAIR (PAIR " + ", ".join(PAPER_PAIRS)
                   + " on the paper's body), viscosity_ratio, feedback_delay, "
                   "proprioceptive_weight, visual_weight (with --visual-tilt; one of the two "
                   "weights at a time), torque_feedback_gain, torque_feedback_time_constant "
                   "(the torque feedback with --engine reference; its starting values from the "
                   "scenario's [muscles]).")
    add_flag(g, "--engine", ", run inside the fit at the scenario's tolerances and "
             "solver.method (fast: a former name of compiled)", choices=ENGINES)
    g.add_argument("--residual-model", choices=RESIDUAL_MODELS, default="ar1",
                   help="residuals of the standard errors: ar1 (default: correlated from "
                   "sample to sample, estimated per link) or independent (the textbook "
                   "s²(JᵀJ)⁻¹, too narrow when the residuals are correlated).")
    g.add_argument("--report", metavar="FIT.json", help="also write the JSON summary to a file.")
    add_flags(g, "--json")
    from ._recording import add_recording_arguments

    add_recording_arguments(p, sway=False)


def run(args: argparse.Namespace) -> int:
    import json

    from .._files import refuse_input_as_output
    from ..simulation.results import atomic_write_text
    from ..studies.identification import fit_stiffness, read_trajectory_csv

    refuse_input_as_output({"--data": args.data, **experiment_inputs(args)},
                           {"--report": args.report})
    if args.report:
        check_writable([args.report], {args.report: (".json",)})
    if args.duration is not None:
        raise UsageError("fit: --duration is set by --data (its last time); leave it out")
    sc = scenario_from_args(args, "fit")
    free = [s.strip() for s in args.free.split(",") if s.strip()]
    for name in free:  # the names first, before the data are read
        resolve(name, sc.muscles.names, (), accepts=FIT_QUANTITIES)
    reading = None
    if (args.resample is not None or args.angle_unit != "rad" or args.start is not None
            or args.time_unit != "s" or str(args.data).lower().endswith(".c3d")):
        import numpy as np

        from ..recordings.table import read_recording, read_table
        from ._recording import print_reading, recording_options

        names = [f"theta{i + 1}" for i in range(sc.body.n_links)]
        rec = read_recording(args.data, names, {n: ("rad",) for n in names},
                             kinds=dict.fromkeys(names, "angle"), **recording_options(args))
        fs, cols, reading = rec.rate, rec.columns, rec
        if not args.json:
            print_reading(rec)
        times = read_table(args.data, names[:1], time_unit=args.time_unit)[0]
        start = float(times[times >= (args.start if args.start is not None else -np.inf)
                            - 1e-9][0])
        time = start + np.arange(cols[names[0]].size) / fs
        theta = np.stack([cols[n] for n in names], axis=1)
    else:
        time, theta = read_trajectory_csv(args.data, sc.body.n_links)
    sc = sc.replace(duration=max(float(time[-1]), 1e-3))
    ratio = 0.25 if args.viscosity_ratio is None else args.viscosity_ratio
    fit = fit_stiffness(sc, time, theta, free, viscosity_ratio=ratio,
                        engine=args.engine, residual_model=args.residual_model)
    summary = {**fit.to_dict(), **({} if reading is None else reading.report_dict())}
    if args.report:
        atomic_write_text(args.report, json.dumps(summary, indent=2) + "\n")
    if args.json:
        print_json(summary)
        return 0
    print(f"fitted {len(free)} parameter(s) to {fit.n_samples} angle samples with "
          f"{fit.n_simulations} simulations; residual RMS {fit.residual_rms:.3g} rad")
    if fit.residual_model == "ar1":
        rho = ", ".join(f"{v:.2f}" for v in fit.residual_autocorrelation)
        print(f"residuals: lag-1 correlation per link {rho} (allowed for in the intervals; "
              f"{fit.degrees_of_freedom:.0f} effective degrees of freedom)")
    clipped = [False] * len(free) if fit.clipped is None else fit.clipped
    for name, e, se, (lo, hi), why, cut in zip(fit.parameter_names, fit.estimates,
                                               fit.standard_errors, fit.confidence_intervals,
                                               fit.undetermined_reasons, clipped, strict=True):
        unit = parameter_unit(name)
        if why:
            print(f"  {name:<22} cannot be determined from these data: {why} "
                  f"(stopped at {e:.4g} {unit})")
        elif fit.success:
            print(f"  {name:<22} {e:10.4g} ± {se:.3g} {unit}   (95 % CI {lo:.4g} … {hi:.4g})"
                  + ("   (interval clipped to the accepted range and search bounds)" if cut
                     else ""))
        else:
            print(f"  {name:<22} {e:10.4g} {unit}   (no interval: see the warning)")
    if fit.warning:
        print(f"warning: {fit.warning}")
    return 0
