"""``posturelab sweep``: simulations over a grid of pair gains; outcomes to CSV or Parquet."""

from __future__ import annotations

import argparse
import sys
import time

from ..errors import ParameterError
from ..model.muscles import DEFAULT_VISCOSITY_RATIO, PAPER_PAIR_NAMES
from ..studies.sweep import (
    MAX_RUNS,
    OUTCOME_COLUMNS,
    SWEEP_PARAMETERS,
    TORQUE_LIMIT_PARAMETERS,
    ProgressBar,
    parse_vary,
    run_sweep,
    table_format,
)
from . import UsageError
from ._common import check_writable
from .simulate import add_experiment_arguments, scenario_from_args

DESCRIPTION = f"""\
Simulate the nonlinear model for every combination of the --vary values (the full grid,
the first --vary varying slowest) with the compiled engine, and write one row per run.

--vary NAME=LO:HI:N takes N evenly spaced values from LO to HI inclusive (N >= 1; N = 1
needs LO = HI; at most {MAX_RUNS:,} runs in all). NAME is a pair stiffness [N·m/rad]
({", ".join(PAPER_PAIR_NAMES)} on the paper's body; ankle, or ankle and hip, on one or
two links): the intrinsic part when the base experiment has active gains, the whole pair
feedback otherwise; active_PAIR [N·m/rad] and active_viscosity_PAIR [N·m·s/rad], a pair's
active (delayed) gains; viscosity_ratio [s]; disturbance_scale [-], a factor on the base
experiment's platform motion (velocity-step speed, pulse peak, ramp displacement, sine
amplitudes, measured accelerations: --vary disturbance_scale=0.5:3:26 with a 1 m/s step
sweeps 0.5-3 m/s); feedback_delay [s]; proprioceptive_weight [-]; or JOINT_torque_limit
[N·m] ({", ".join(TORQUE_LIMIT_PARAMETERS)} on the paper's body), the largest net muscle
moment at a joint; repeat --vary for each parameter. Every other gain comes from the
base experiment: --case/--stiffness/--controller with --disturbance or --tilt (as in
posturelab simulate), --scenario FILE.toml or --builtin NAME. A pair's viscosity is the
ratio times its stiffness: the varied viscosity_ratio, else --viscosity-ratio, else the
base experiment's (0.25, the paper's, for --case).

Columns: the varied parameters, then {", ".join(OUTCOME_COLUMNS)} (one peak_theta
per link). outcome is recovered (completed, ending within ±0.01 rad of upright and below
0.05 rad/s), not recovered (completed but ending farther or still moving), fell or failed;
fell is true/false; fall_time [s] is empty if the run did not fall; peak_thetaI [rad]
are the largest |θ_i| over the samples; settling_time [s] is the last sample time at which
some |θ_i| exceeded 0.01 rad (0 if none did; empty if the run fell or had not settled by
the end); final_lean [rad] and final_rate [rad/s] are the largest |θ_i| and |θ̇_i| at the
last sample. The file type follows the suffix of --out: .csv or .parquet (pyarrow); it is
written to a temporary file and renamed, so no half-written file is left behind.

Everything of the base experiment carries into every run: --torque-limits, --feedback-delay,
active gains, --tilt and --proprioceptive-weight, --foot with --centre-of-pressure, the
knee model.

--experiment prts runs, for every parameter set, the in-silico PRTS identification
experiment instead of one simulation: the base experiment's --tilt prts:… for
--discard-cycles + --cycles cycles, recorded at --record-rate with --sensor-noise [rad] of
white measurement noise (seeded per run from --seed), --motor-noise in the loop (seeded per
run), the FRF of --output at Peterka's bands, and with --fit NAMES the FRF fit of those
parameters (posturelab fit-frf's names) started from the base experiment's values. Its
columns: the varied parameters, fell, gain_B, phase_deg_B [deg], coherence_B per band, then
fit_NAME and se_NAME per fitted parameter and fit_error.

Parallelism: the runs use every CPU
available (one thread each). --workers N sends chunks of runs to a Dask LocalCluster of N
single-threaded worker processes, --scheduler ADDRESS to a running Dask cluster (its
workers need posturelab installed); the results are identical. Tolerances default to the
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
                   help="run on a Dask LocalCluster with N worker processes.")
    g.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on the Dask cluster whose scheduler is at ADDRESS.")
    g.add_argument("--chunk-size", type=int, default=None, metavar="RUNS",
                   help="runs per chunk (progress step / Dask task).")
    g.add_argument("--progress", action="store_true",
                   help="draw a progress bar on standard error even when it is not a terminal.")
    e = p.add_argument_group("PRTS experiments (--experiment prts)")
    e.add_argument("--experiment", choices=["simulation", "prts"], default="simulation",
                   help="what each run is: one simulation (default) or a PRTS "
                   "identification experiment.")
    e.add_argument("--cycles", type=int, default=5, metavar="N",
                   help="cycles analysed per experiment (default 5).")
    e.add_argument("--discard-cycles", type=int, default=1, metavar="N",
                   help="cycles run first and dropped (default 1).")
    e.add_argument("--sensor-noise", type=float, default=0.0, metavar="RAD",
                   help="standard deviation of the measurement noise on the recorded angle "
                   "[rad] (default 0).")
    e.add_argument("--record-rate", type=float, default=100.0, metavar="HZ",
                   help="samples per second of the recording [Hz] (default 100).")
    e.add_argument("--output", default="com_angle", metavar="ANGLE",
                   help="the angle recorded: com_angle (default) or thetaI.")
    e.add_argument("--fit", metavar="NAMES",
                   help="fit these parameters to each experiment's FRF (comma-separated, "
                   "as for posturelab fit-frf --free).")
    add_experiment_arguments(p)
    # None means "not given": a scenario then keeps its own ratio
    p.set_defaults(viscosity_ratio=None)


def run(args: argparse.Namespace) -> int:
    if not args.vary:
        raise UsageError("sweep: give at least one --vary NAME=LO:HI:N (see "
                         "'posturelab sweep --help')")
    varies = [parse_vary(v) for v in args.vary]
    table_format(args.out)
    check_writable([args.out])
    if not (args.scenario or args.builtin or args.case is not None
            or args.stiffness is not None or args.controller is not None):
        raise UsageError("sweep: give the base experiment: --case, --stiffness or --controller "
                         "(with --disturbance), or --scenario FILE.toml / --builtin NAME")
    if args.workers is not None and args.workers < 1:
        raise ParameterError(f"--workers must be >= 1, got {args.workers}")
    if args.chunk_size is not None and args.chunk_size < 1:
        raise ParameterError(f"--chunk-size must be >= 1, got {args.chunk_size}")
    ratio = args.viscosity_ratio
    if ratio is None and not (args.scenario or args.builtin or args.controller):
        args.viscosity_ratio = DEFAULT_VISCOSITY_RATIO  # what --case / --stiffness build with
    scenario = scenario_from_args(args, "sweep")
    if args.experiment == "prts":
        return _run_experiments(args, scenario, varies, ratio)
    tolerances = {}
    if args.rtol is not None:
        tolerances["rtol"] = scenario.rtol
    if args.atol is not None:
        tolerances["atol"] = scenario.atol
    total = _runs(varies)
    result, elapsed = _with_progress(args, total, lambda progress: run_sweep(
        scenario, varies, viscosity_ratio=ratio, workers=args.workers,
        scheduler=args.scheduler, chunk_size=args.chunk_size, progress=progress,
        **tolerances))
    result.write(args.out)
    o = result.outcomes
    shape = " × ".join(str(v.count) for v in varies)
    failed = int((o.status_code >= 2).sum())
    kinds = o.outcome
    counts = ", ".join(f"{int((kinds == k).sum())} {k}" for k in
                       ("recovered", "not recovered", "fell", "failed") if (kinds == k).any())
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
    bar = ProgressBar(total) if args.progress or sys.stderr.isatty() else None
    t0 = time.perf_counter()
    try:
        result = work(None if bar is None else (lambda done, _: bar.update(done)))
    finally:
        if bar is not None:
            bar.close()
    return result, time.perf_counter() - t0


def _run_experiments(args: argparse.Namespace, scenario, varies, ratio) -> int:
    """``--experiment prts``: a PRTS identification experiment per parameter set."""
    from ..frequency.population import PRTSProtocol, prts_sweep

    fit = tuple(s.strip() for s in (args.fit or "").split(",") if s.strip())
    protocol = PRTSProtocol(cycles=args.cycles, discard=args.discard_cycles,
                            sensor_noise=args.sensor_noise, seed=args.seed or 0,
                            sample_rate=args.record_rate, output=args.output, fit=fit)
    result, elapsed = _with_progress(args, _runs(varies), lambda progress: prts_sweep(
        scenario, varies, protocol, viscosity_ratio=ratio, workers=args.workers,
        scheduler=args.scheduler, chunk_size=args.chunk_size, progress=progress))
    result.write(args.out)
    fitted = f", fitted {', '.join(fit)}" if fit else ""
    print(f"wrote {args.out}: {result.fell.size} PRTS experiments ({', '.join(result.grid.names)}"
          f"), {int(result.fell.sum())} fell{fitted}, in {elapsed:.2f} s")
    return 0
