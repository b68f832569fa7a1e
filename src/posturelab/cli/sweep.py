"""``posturelab sweep``: simulations over a grid of pair gains; outcomes to CSV or Parquet."""

from __future__ import annotations

import argparse
import os
import sys
import time

from ..errors import ParameterError
from ..model.muscles import DEFAULT_VISCOSITY_RATIO
from ..parameters import PAPER_JOINTS, PAPER_PAIRS
from ..simulation.tolerances import DEFAULT_ATOL, DEFAULT_RTOL
from ..studies.sweep import (
    MAX_RUNS,
    OUTCOME_COLUMNS,
    SWEEP_PARAMETERS,
    SweepInterrupted,
    max_workers,
    parse_vary,
    run_sweep,
    table_format,
)
from . import UsageError
from ._common import check_writable, naming_given_options
from ._flags import add_flag, add_flags
from .simulate import add_experiment_arguments, experiment_inputs, scenario_from_args

#: Most simulated time of all the experiments of one --experiment prts sweep (experiments
#: × cycles × the cycle): about 8 CPU-hours of the compiled engine, a bound on the work. [s]
MAX_PRTS_SIMULATED = 1e8

DESCRIPTION = f"""\
Simulate the nonlinear model for every combination of the --vary values (the full grid,
the first --vary varying slowest) with the compiled engine, and write one row per run.

--vary NAME=LO:HI:N takes N evenly spaced values from LO to HI inclusive (N >= 1; N = 1
needs LO = HI; at most {MAX_RUNS:,} runs in all; LO and HI within NAME's bounds). NAME
is one of the parameter table's (docs/parameters.md; the same names as fit --free and
fit-frf --free): stiffness:PAIR [N·m/rad] (PAIR {", ".join(PAPER_PAIRS)} on the paper's
body; ankle, or ankle and hip, on one or two links; a one-pair body may leave out :PAIR),
the intrinsic part when the base experiment has active gains, the whole pair feedback
otherwise; viscosity:PAIR [N·m·s/rad]; active_stiffness:PAIR [N·m/rad] and
active_viscosity:PAIR [N·m·s/rad], a pair's active (delayed) gains; viscosity_ratio [s];
disturbance_scale [-], a factor on the base experiment's platform motion (velocity-step
speed, pulse peak, ramp displacement, sine amplitudes, measured accelerations: --vary
disturbance_scale=0.5:3:26 with a 1 m/s step sweeps 0.5-3 m/s); feedback_delay [s];
proprioceptive_weight [-]; visual_weight [-] (W_v, with --visual-tilt; every run's
proprioceptive_weight + visual_weight <= 1); or torque_limit:JOINT [N·m]
({", ".join(PAPER_JOINTS)} on the paper's body), the largest net muscle moment at a joint;
repeat --vary for each parameter. Every other gain comes from the base experiment:
--case/--stiffness/--controller with --disturbance or --tilt (as in posturelab simulate),
--scenario FILE.toml or --builtin NAME. A pair's viscosity is the varied viscosity:PAIR,
else the ratio times its stiffness: the varied viscosity_ratio, else --viscosity-ratio,
else the base experiment's (0.25, the paper's, for --case); viscosity_ratio and
viscosity:PAIR are not varied together.

Columns: the varied parameters (stiffness:ankle, ...), then
{", ".join(OUTCOME_COLUMNS)} (one peak_theta
per link). outcome is recovered (completed, ending within ±0.01 rad of upright and below
0.05 rad/s), not recovered (completed but ending farther or still moving), steady sway
(completed under a sustained stimulus: a sine or PRTS tilt, a sum of sines, motor noise),
fell or failed; fell is true/false; fall_time [s] is empty if the run did not fall;
peak_thetaI [rad] are the largest |θ_i| over the samples; settling_time [s] runs from the
end of the platform motion or tilt (0 for a velocity step) to the last sample time at which
some |θ_i| exceeded 0.01 rad (0 if none did; empty if the run fell, had not settled by
the end, or the stimulus is sustained); final_lean [rad] and final_rate [rad/s] are the
largest |θ_i| and |θ̇_i| at the last sample. Under a sustained stimulus the columns
steady_rms_thetaI, steady_peak_thetaI [rad] follow: RMS about upright and peak |·| after the
first stimulus cycle (or over the second half of a run shorter than two cycles); each run
that completed is then run again alone for its trajectory (the centre of pressure's steady
sway, ten times as costly, is left to posturelab simulate).
The file type follows the suffix of --out: .csv or .parquet (pyarrow); it is
written to a temporary file and renamed, so no half-written file is left behind.

Ctrl-C (or SIGTERM) stops a sweep at once: the runs not started are dropped, the rows that
finished are written and counted (exit 130, 143). Options this kind of sweep does not use
(the PRTS options on a simulation sweep; the step, profile, duration, initial state and
integrator options on --experiment prts, where --sample-rate is the recording's, as
--record-rate) are refused.

Everything of the base experiment carries into every run: --torque-limits, --feedback-delay,
active gains, --tilt and --proprioceptive-weight, --visual-tilt and --visual-weight, --foot
with --centre-of-pressure, the knee model.

--experiment prts runs, for every parameter set, the in-silico PRTS identification
experiment instead of one simulation: the base experiment's --tilt prts:… for
--discard-cycles + --cycles cycles, recorded at --record-rate with --sensor-noise [rad] of
white measurement noise (seeded per run from --seed), --motor-noise in the loop (seeded per
run), the FRF of --output at the sequence's bands, and with --fit NAMES the FRF fit of those
parameters (posturelab fit-frf's names) started from the base experiment's values. Its
columns: the varied parameters, fell, gain_B, phase_deg_B [deg], coherence_B per band, then
fit_NAME and se_NAME per fitted parameter (fit_active_stiffness:ankle, ...) and fit_error.
Before it starts, a PRTS sweep says on standard error how many experiments of how much
simulated time it runs; it refuses more than {MAX_PRTS_SIMULATED:.0e} s simulated in all
(fewer --vary values or --cycles). Any sweep that will take over 10 s says, after its first
chunk, about how long it will take in all.

Parallelism: the runs use every CPU
available (one thread each). --workers N sends chunks of runs to a Dask LocalCluster of N
single-threaded worker processes (N from 1 to 4 × the CPUs), --scheduler ADDRESS
([tcp://]HOST:PORT) to a running Dask cluster (its workers need posturelab installed);
the results are identical. Tolerances default to the
compiled engine's (rtol 1e-6, atol 1e-9: angles within 1e-6 rad of a tight DOP853
reference for undelayed runs); --rtol/--atol override them.
"""


#: Below this many runs a local sweep is faster than starting a Dask cluster. [-]
SMALL_FOR_DASK = 20_000


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab sweep``."""
    g = p.add_argument_group("sweep")
    g.add_argument("--vary", action="append", metavar="NAME=LO:HI:N", default=[],
                   help="N evenly spaced values of NAME from LO to HI inclusive; names: "
                   + ", ".join(SWEEP_PARAMETERS) + " (repeat for several).")
    g.add_argument("--out", required=True, metavar="FILE.csv|FILE.parquet",
                   help="output table (.csv or .parquet).")
    g.add_argument("--workers", type=int, default=None, metavar="N",
                   help="run on a Dask LocalCluster with N worker processes (1 … 4 × the "
                   "CPUs).")
    g.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on the Dask cluster whose scheduler is at ADDRESS "
                   "([tcp://]HOST:PORT; refused if it does not answer within 10 s).")
    g.add_argument("--chunk-size", type=int, default=None, metavar="RUNS",
                   help="runs per chunk (progress step / Dask task).")
    g.add_argument("--strategy", action="store_true",
                   help="also a hip_fraction column: each run's share of the hip (anti-phase) "
                        "mode, after Creath et al. 2005 (every run again alone).")
    add_flags(g, "--progress")
    e = p.add_argument_group("PRTS experiments (--experiment prts)")
    e.add_argument("--experiment", choices=["simulation", "prts"], default="simulation",
                   help="what each run is: one simulation (default) or a PRTS "
                   "identification experiment.")
    add_flags(e, "--cycles")
    add_flag(e, "--discard-cycles", "1", default=None)
    add_flags(e, "--sensor-noise")
    e.add_argument("--record-rate", type=float, default=None, metavar="HZ",
                   help="samples per second of the recording [Hz] (default 100); "
                   "--sample-rate says the same with --experiment prts.")
    add_flag(e, "--output", " or thetaN", default=None)
    e.add_argument("--fit", metavar="NAMES",
                   help="fit these parameters to each experiment's FRF (comma-separated, "
                   "as for posturelab fit-frf --free).")
    add_experiment_arguments(p)
    # None means "not given": a scenario then keeps its own ratio
    p.set_defaults(viscosity_ratio=None)


def run(args: argparse.Namespace) -> int:
    from .._files import refuse_input_as_output

    if not args.vary:
        raise UsageError("sweep: give at least one --vary NAME=LO:HI:N (see "
                         "'posturelab sweep --help')")
    varies = [parse_vary(v) for v in args.vary]
    refuse_input_as_output(experiment_inputs(args), {"--out": args.out})
    table_format(args.out)
    check_writable([args.out])
    if not (args.scenario or args.builtin or args.case is not None
            or args.stiffness is not None or args.controller is not None):
        raise UsageError("sweep: give the base experiment: --case, --stiffness or --controller "
                         "(with --disturbance), or --scenario FILE.toml / --builtin NAME")
    if args.workers is not None and not 1 <= args.workers <= max_workers():
        raise ParameterError(f"--workers must be in 1 … {max_workers()} (4 × the "
                             f"{os.cpu_count() or 1} CPUs), got {args.workers}")
    if args.scheduler is not None:
        from ..studies._sweep_dask import check_scheduler_address

        check_scheduler_address(args.scheduler)
    if args.chunk_size is not None and args.chunk_size < 1:
        raise ParameterError(f"--chunk-size must be >= 1, got {args.chunk_size}")
    ratio = args.viscosity_ratio
    if ratio is None and not (args.scenario or args.builtin or args.controller):
        args.viscosity_ratio = DEFAULT_VISCOSITY_RATIO  # what --case / --stiffness build with
    if args.experiment == "prts" and args.sample_rate is not None:
        # (the recording's samples per second: --sample-rate, as everywhere, or --record-rate)
        if args.record_rate is not None and args.record_rate != args.sample_rate:
            raise UsageError(f"sweep: --sample-rate {args.sample_rate:g} and --record-rate "
                             f"{args.record_rate:g} are the same setting with --experiment "
                             "prts; give one")
        args.record_rate, args.sample_rate = args.sample_rate, None
    _refuse_unused(args)
    scenario = scenario_from_args(args, "sweep")
    try:
        if args.experiment == "prts":
            return _run_experiments(args, scenario, varies, ratio)
        return _run_simulations(args, scenario, varies, ratio)
    except SweepInterrupted as exc:
        return _keep_finished(args, exc)


#: The message prefix of a PRTS protocol's check -> the option that sets it.
PROTOCOL_FIELD_OPTIONS = {"cycles": "--cycles", "discard": "--discard-cycles",
                          "sensor_noise [rad]": "--sensor-noise",
                          "sample_rate [Hz]": "--record-rate",
                          "output": "--output"}
#: Options of one kind of sweep that the other does not use (attribute names).
PRTS_ONLY = ("cycles", "discard_cycles", "sensor_noise", "record_rate", "output", "fit")
#: The base experiment's options a PRTS experiment has no use for: its stimulus is the tilt,
#: its length the cycles, its recording --record-rate, its integrator its own.
SIMULATION_ONLY = ("disturbance", "speed", "platform_profile", "duration",
                   "initial_posture", "initial_rates", "rtol", "atol", "max_steps",
                   "time_limit", "tilt_axis_depth")


def _refuse_unused(args: argparse.Namespace) -> None:
    """One line naming the options given that this kind of sweep does not use."""
    prts = args.experiment == "prts"
    unused = [f for f in (SIMULATION_ONLY if prts else PRTS_ONLY)
              if getattr(args, f, None) is not None]
    if prts and args.rates_from is not None:
        unused.append("rates_from")
    if unused:
        names = ", ".join(f"--{f.replace('_', '-')}" for f in unused)
        raise UsageError(f"sweep: {names} {'is' if len(unused) == 1 else 'are'} not used by "
                         + ("--experiment prts (the stimulus is the PRTS tilt, the length "
                            "--discard-cycles + --cycles, the recording --record-rate)" if prts
                            else "a simulation sweep (they are for --experiment prts)"))


def _keep_finished(args: argparse.Namespace, exc: SweepInterrupted) -> int:
    """Ctrl-C or SIGTERM: write the rows that finished, say how many; 130 or 143."""
    word = "terminated" if exc.terminated else "interrupted"
    if exc.result is None:
        print(f"posturelab: {word} before any run finished; nothing written",
              file=sys.stderr)
    else:
        exc.result.write(args.out)
        print(f"posturelab: {word}: wrote the {exc.rows:,} of {exc.total:,} runs that "
              f"finished to {args.out}", file=sys.stderr)
    return 143 if exc.terminated else 130


def _run_simulations(args: argparse.Namespace, scenario, varies, ratio) -> int:
    """The ordinary sweep: one simulation per parameter set."""
    # (a sweep's own tolerances unless --rtol / --atol, which the scenario now holds)
    rtol = DEFAULT_RTOL if args.rtol is None else scenario.options.rtol
    atol = DEFAULT_ATOL if args.atol is None else scenario.options.atol
    total = _runs(varies)
    with naming_given_options(args):
        result, elapsed = _with_progress(args, total, lambda progress: run_sweep(
            scenario, varies, viscosity_ratio=ratio, workers=args.workers,
            scheduler=args.scheduler, chunk_size=args.chunk_size, progress=progress,
            rtol=rtol, atol=atol, strategy=args.strategy))
    result.write(args.out)
    o = result.outcomes
    shape = " × ".join(str(v.count) for v in varies)
    failed = int((o.status_code >= 2).sum())
    kinds = o.outcome
    counts = ", ".join(f"{int((kinds == k).sum())} {k}" for k in
                       ("recovered", "not recovered", "steady sway", "fell", "failed")
                       if (kinds == k).any())
    print(f"wrote {args.out}: {o.n_runs} runs ({shape}: {', '.join(result.grid.names)}): "
          f"{counts}, in {elapsed:.2f} s")
    if args.workers is not None and total < SMALL_FOR_DASK:
        print(f"posturelab: note: {total} runs take well under a second without Dask; "
              f"starting a cluster of {args.workers} workers took most of the "
              f"{elapsed:.1f} s (leave out --workers for small sweeps)", file=sys.stderr)
    if failed:
        print(f"posturelab: warning: {failed} runs failed to integrate (fell = false, "
              "outcomes up to the failure)", file=sys.stderr)
    return 0


def _runs(varies) -> int:
    """Runs in the grid of ``varies``. [-]"""
    total = 1
    for v in varies:
        total *= v.count
    return total


def _with_progress(args: argparse.Namespace, total: int, work):
    """``work(progress)`` with a progress bar on standard error (a terminal, or
    --progress); returns its result and the seconds it took."""
    from .._progress import Progress, shown
    from ._common import ExpectedTime

    bar = Progress(total, label="sweep", unit="runs") if shown(args.progress) else None
    t0 = time.perf_counter()
    try:
        result = work(bar or ExpectedTime("sweep", "runs"))
    finally:
        if bar is not None:
            bar.close()
    return result, time.perf_counter() - t0


def _check_experiment_length(args: argparse.Namespace, protocol, scenario, varies) -> None:
    """Refuse, naming --cycles and --discard-cycles, an experiment longer than the longest
    run, or experiments longer than :data:`MAX_PRTS_SIMULATED` in all; else say how many
    and how long (standard error)."""
    from ..simulation.setup import MAX_DURATION

    tilt = scenario.options.tilt
    if tilt is None or not hasattr(tilt, "cycle"):
        return  # (prts_sweep says the tilt must be a PRTS)
    cycles = protocol.cycles + protocol.discard
    total = tilt.cycle * cycles
    given = f"--cycles {protocol.cycles}" if protocol.discard == 0 else (
        f"(--cycles {protocol.cycles} + --discard-cycles {protocol.discard})")
    if total > MAX_DURATION:
        raise ParameterError(f"{given} × the {tilt.cycle:g} s cycle = {total:.3g} s exceeds "
                             f"the longest run, {MAX_DURATION:,.0f} s")
    runs = _runs(varies)
    if runs * total > MAX_PRTS_SIMULATED:
        raise ParameterError(f"{runs:,} PRTS experiments × {total:.4g} s ({given} × the "
                             f"{tilt.cycle:g} s cycle) = {runs * total:.3g} s simulated; a "
                             f"sweep runs at most {MAX_PRTS_SIMULATED:.0e} s (fewer --vary "
                             "values or --cycles)")
    if runs * total > 1e5:  # (over about half a minute)
        print(f"posturelab: sweep: {runs:,} PRTS experiments of {total:.4g} s simulated each "
              f"({runs * total:.3g} s in all)", file=sys.stderr)


def _run_experiments(args: argparse.Namespace, scenario, varies, ratio) -> int:
    """``--experiment prts``: a PRTS identification experiment per parameter set."""
    from ..frequency.population import PRTSProtocol, prts_sweep

    fit = tuple(s.strip() for s in (args.fit or "").split(",") if s.strip())
    given = {key: getattr(args, flag) for key, flag in (
        ("cycles", "cycles"), ("discard", "discard_cycles"), ("sensor_noise", "sensor_noise"),
        ("sample_rate", "record_rate"), ("output", "output")) if getattr(args, flag) is not None}
    with naming_given_options(args, PROTOCOL_FIELD_OPTIONS):
        protocol = PRTSProtocol(seed=args.seed or 0, fit=fit, **given)
    _check_experiment_length(args, protocol, scenario, varies)
    with naming_given_options(args, PROTOCOL_FIELD_OPTIONS):
        result, elapsed = _with_progress(args, _runs(varies), lambda progress: prts_sweep(
            scenario, varies, protocol, viscosity_ratio=ratio, workers=args.workers,
            scheduler=args.scheduler, chunk_size=args.chunk_size, progress=progress))
    result.write(args.out)
    fitted = f", fitted {', '.join(fit)}" if fit else ""
    print(f"wrote {args.out}: {result.fell.size} PRTS experiments ({', '.join(result.grid.names)}"
          f"), {int(result.fell.sum())} fell{fitted}, in {elapsed:.2f} s")
    return 0
