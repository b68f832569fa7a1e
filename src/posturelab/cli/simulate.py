"""``posturelab simulate``: one nonlinear simulation, to CSV / JSON / PNG / GIF."""

from __future__ import annotations

import argparse
import math
import sys
from typing import TypeVar

from ..errors import DataFileError, ParameterError
from ..model.options import KneeModel
from ..model.platform import MAX_PLATFORM_SPEED, VelocityStep
from ..parameters import RUN_SETTINGS, check_value
from ..scenarios import (
    SCENARIO_DEFAULTS,
    Scenario,
    builtin_scenario,
    builtin_scenario_names,
    load_scenario,
)
from ..simulation.options import RunOptions
from . import UsageError
from ._common import (
    FIGURE_SUFFIXES,
    FLAG_NAMES,
    add_muscle_arguments,
    add_torque_feedback_arguments,
    check_writable,
    model_from_args,
    naming_given_options,
    naming_option,
    parse_tilt,
    print_json,
)
from ._flags import add_flag, add_flags

DESCRIPTION = """\
Simulate the paper's three-link biped (or a scenario file) under muscle-pair feedback
and platform motion, on the compiled C engine (Radau, or RK45 with a feedback delay;
--engine reference integrates the numpy model with scipy's DOP853 instead).

Disturbances: --disturbance backward|forward is the paper's "unit impulse", a sudden
platform velocity change of --speed m/s (default 1); the link rates jump by
−J⁻¹H·Δẋ_d (J⁻¹H at upright as the paper does; --rates-from posture for the exact
value). These start from the paper's slightly flexed posture [0.1, −0.1, 0.1] rad
unless --initial-posture is given. --platform-profile FILE.csv reads a measured
acceleration (columns time [s], x_acceleration [m/s²], optional y_acceleration
[m/s²]; 0 after the last sample) and starts upright at rest unless told otherwise.

A fall is any |θ_i| beyond --max-link-angle (default 1.047 rad = 60°) or, with
--foot, the centre of gravity leaving the base of support; the run stops there.
Output CSV columns: t [s], theta1..3 [rad], omega1..3 [rad/s], M_<pair> [N·m],
U1..3 [N·m], joint_moment1..3 [N·m], cog_x, cog_y [m], cog_vx, cog_vy [m/s],
platform_ax, platform_ay [m/s²], platform_vx, platform_vy [m/s], platform_x,
platform_y [m], cop_x [m] (centre of pressure from the ankle), ground_fx, ground_fy [N]
(force of the platform on the foot), and with a tilt, tilt and com_angle [rad] (with a
visual-scene tilt, visual_tilt [rad] before com_angle). The first line printed (outcome
in --json) is recovered, not recovered, steady sway, fell or failed.
Settling is counted from the end of the platform motion or tilt (0 for a velocity step). A
sustained stimulus (a sine or PRTS tilt, a sum of sines, motor noise) has no settling time:
its outcome is a steady sway, the RMS (about upright) and peak |·| of each θ_i [rad] and of
the centre of pressure [m] after the first stimulus cycle (or over the second half of a
run shorter than two cycles).
"""


T = TypeVar("T")

#: The wall-clock budget of one `simulate` run when neither --time-limit nor the scenario
#: gives one: nothing legitimate takes this long on either engine. [s]
DEFAULT_TIME_LIMIT = 600.0


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab simulate``."""
    add_experiment_arguments(p)
    out = p.add_argument_group("output")
    out.add_argument("--out", metavar="RUN.csv|RUN.parquet",
                     help="write the time series as CSV, or Parquet (units in each field's "
                     "metadata).")
    add_flag(out, "--plot", "a 2×2 summary figure", metavar="RUN.png")
    out.add_argument("--animate", metavar="RUN.gif", help="write a stick-figure animation (GIF).")
    out.add_argument("--json", action="store_true",
                     help='print one JSON summary: {"outcome" (recovered, not recovered, '
                     'steady sway, fell, failed), "settling_time", "fall_time", "fall_reason", '
                     '"final_lean", "final_rate", "outcome_message", "perturbation_end", '
                     '"steady_from", "steady_rms_theta", "steady_peak_theta" [rad], '
                     '"steady_rms_cop", "steady_peak_cop" [m] (null unless a steady sway), '
                     '"fell", "status", "message", '
                     '"max_abs_theta", "final_state", "hip_fraction", "engine" (compiled or '
                     'reference), "linear_stability" '
                     '(the verdict about upright, as posturelab poles: {"status": stable, '
                     'unstable, marginal or "depends on the side" of a one-sided pair\'s '
                     'switch, "stable", "rightmost_root" [1/s], "feedback_delay" [s], '
                     '"sides", ...})}; hip_fraction [-] is the share of the anti-phase (hip) '
                     'mode of leg and trunk, null for one link.')
    add_flag(p, "--engine", ". Either runs at the tolerances of --rtol/--atol (default: "
             "the scenario's, 1e-8 and 1e-10) and with the scenario's solver.method if it "
             "names one")


def add_experiment_arguments(p: argparse.ArgumentParser) -> None:
    """The options that describe one experiment (shared with ``posturelab fit``)."""
    src = p.add_argument_group("what to simulate")
    src.add_argument("--scenario", metavar="FILE.toml",
                     help="a scenario file (see the README); replaces the model options below.")
    src.add_argument("--builtin", metavar="NAME",
                     help="a built-in scenario: " + ", ".join(builtin_scenario_names()) + ".")
    add_muscle_arguments(p)
    # None: not given (then the scenario's form, else two-sided), so that a given value
    # overrides a scenario's
    p.set_defaults(gastrocnemius=None)
    add_torque_feedback_arguments(p)
    src.add_argument("--disturbance", choices=["backward", "forward", "none"],
                     help="platform velocity step of --speed m/s at t = 0 (backward: the "
                     "platform moves back, the body sways forward).")
    src.add_argument("--speed", type=float, default=None,
                     help="size of the velocity step [m/s] (default 1).")
    src.add_argument("--platform-profile", metavar="FILE.csv|FILE.parquet",
                     help="measured platform acceleration (time [s], x_acceleration [m/s²], "
                     "optional y_acceleration [m/s²]; each within ±1000 m/s²), linearly "
                     "interpolated and 0 after the last sample (the platform goes on at the "
                     "velocity it has reached).")
    src.add_argument("--initial-posture", metavar="T1,T2,T3",
                     help="initial link angles [rad] (forward positive).")
    src.add_argument("--initial-rates", metavar="W1,W2,W3",
                     help="initial link rates before any velocity step [rad/s].")
    src.add_argument("--rates-from", choices=["upright", "posture"], default=None,
                     help="evaluate J⁻¹H for the velocity step at upright (the paper; the "
                     "default unless a scenario says otherwise) or at the initial posture "
                     "(exact).")
    src.add_argument("--knee", choices=["free", "locked", "stop"], default=None,
                     help="free (the paper's default), locked (θ2 − θ1 constant), or a "
                     "hyper-extension stop at θ2 − θ1 = 0; default: the scenario's, or the "
                     "multi-joint controller's design (locked), else free.")
    src.add_argument("--foot", metavar="none|literature|HEEL,TOE", default=None,
                     help="base of support for the fall test: none (the paper, and the "
                     "default unless a scenario has a foot; the foot never "
                     "tips), literature (heel −0.063 m, toe 0.188 m: a 1.65 m person) or "
                     "HEEL,TOE [m] relative to the ankle.")
    src.add_argument("--centre-of-pressure", action="store_true",
                     help="with --foot, also fall when the centre of pressure leaves the foot "
                     "(the foot tips), not only the centre of gravity.")
    add_flag(src, "--tilt",
             "sine:AMPLITUDE_RAD:FREQUENCY_HZ[:PHASE_RAD], "
             "raised-cosine:AMPLITUDE_RAD:DURATION_S[:START_S] (a smooth ramp, then "
             "held), prts:AMPLITUDE_RAD[:STATE_DURATION_S][:SEQUENCE] (peak to peak; "
             "SEQUENCE posturelab-80 (default: posturelab's own 80-state, 20 s "
             "sequence), comtest-80 (the Eurobench COMTEST protocol's 80-state one) "
             "or peterka-2002-242 (Peterka 2002's 242-state, 60.5 s one)). A tilt "
             "column [rad] in --platform-profile does the same from data.")
    add_flag(src, "--visual-tilt", ". With --tilt too, a dual-stimulus trial (CSV columns "
             "tilt and visual_tilt)")
    src.add_argument("--tilt-axis-depth", type=float, default=None, metavar="M",
                     help="the tilt axis this far below the ankle [m], in "
                     f"{RUN_SETTINGS['tilt_axis_depth'].interval()} (default 0: "
                     "about the ankle; then the ankle moves with the surface). Needs a tilt "
                     "without rate jumps (not prts).")
    add_flags(src, "--motor-noise", "--motor-noise-cutoff")
    add_flag(src, "--seed", "the motor noise (and with sweep --experiment prts, of the "
             "measurement noise)", default=None)
    src.add_argument("--torque-limits", metavar="ANKLE,KNEE,HIP",
                     help="largest net muscle moment at each joint [N·m], each > 0 ('inf' for "
                     "none); or LO:HI, the moment kept in [LO, HI], LO < 0 < HI (at the ankle "
                     "HI is plantarflexion, pressing toward the toes, LO dorsiflexion, toward "
                     "the heel); or 'foot' for the ankle: LO = m g x_heel, HI = m g x_toe "
                     "from the body's weight and --foot.")
    add_flag(src, "--ankle-limit-from-foot", "of --foot, which it needs (the same as 'foot' "
             "as the first --torque-limits entry)")
    src.add_argument("--max-link-angle", type=float, default=None, metavar="RAD",
                     help="fall when any |θ_i| exceeds this [rad] (default π/3).")
    run = p.add_argument_group("integration")
    run.add_argument("--duration", type=float, default=None,
                     help=f"simulated time [s] (default {SCENARIO_DEFAULTS.duration:g}).")
    run.add_argument("--rtol", type=float, default=None,
                     help="relative tolerance (default: the scenario's, 1e-8 unless it says "
                     "otherwise, on either engine; sweep: 1e-6).")
    run.add_argument("--atol", type=float, default=None,
                     help="absolute tolerance [rad, rad/s] (default: the scenario's, 1e-10 "
                     "unless it says otherwise; sweep: 1e-9).")
    add_flag(run, "--sample-rate", f"{SCENARIO_DEFAULTS.sample_rate:g}")
    run.add_argument("--max-steps", type=int, default=None, metavar="N",
                     help="step budget of each run: after N accepted integrator steps it "
                     "stops as failed (default 1e6 + 1e4 per simulated second).")
    run.add_argument("--time-limit", type=float, default=None, metavar="SECONDS",
                     help="wall-clock budget of each run: past it the run stops as failed "
                     "(default: 600 for simulate, none for sweep).")


MODEL_OPTIONS = ("case", "stiffness", "disturbance", "speed", "platform_profile",
                 "initial_posture", "initial_rates", "controller", "body", "height", "mass",
                 "viscosity", "active_stiffness", "active_viscosity", "active_viscosity_ratio")


def scenario_from_args(args: argparse.Namespace, command: str = "simulate") -> Scenario:
    """The scenario the arguments describe: a file, a built-in, or the model options, with
    the run's options (:class:`~posturelab.simulation.options.RunOptions`) the command line
    changes (:func:`run_options_from_args`).

    ``command`` names the subcommand in usage errors.
    """
    if args.scenario and args.builtin:
        raise UsageError(f"{command}: give --scenario or --builtin, not both")
    if args.scenario or args.builtin:
        clash = [o for o in MODEL_OPTIONS if getattr(args, o) is not None]
        if clash:
            raise UsageError(f"{command}: --{clash[0].replace('_', '-')} cannot be "
                             "combined with a scenario; edit the scenario instead")
        if command == "simulate" and args.viscosity_ratio is not None:
            raise UsageError(f"{command}: --viscosity-ratio cannot be combined with a scenario "
                             "(its [muscles] viscosity_ratio or viscosity); edit the scenario "
                             "instead")
        sc = load_scenario(args.scenario) if args.scenario else builtin_scenario(args.builtin)
        if args.gastrocnemius is not None:
            sc = sc.replace(muscles=with_gastrocnemius(sc.muscles, args.gastrocnemius))
    else:
        sc = _scenario_from_options(args, command)
    return sc.replace(options=run_options_from_args(args, sc, command))


def with_gastrocnemius(muscles, form: str):
    """``muscles`` with the gastrocnemius pair of ``form`` ("two-sided", "one-sided",
    "pull-only"; :data:`posturelab.model.muscles.GASTROCNEMIUS_FORMS`): --gastrocnemius over
    a scenario's own. Refused in one line when there is no such pair."""
    from dataclasses import replace

    from ..model.muscles import GASTROCNEMIUS_FORMS, MuscleSet

    if "gastrocnemius" not in muscles.names:
        raise UsageError(f"--gastrocnemius {form}: this experiment's body has no gastrocnemius "
                         f"pair (pairs: {', '.join(muscles.names)})")
    one_sided, pull_only, _ = GASTROCNEMIUS_FORMS[form]
    pairs = tuple(replace(p, one_sided=one_sided, pull_only=pull_only)
                  if p.name == "gastrocnemius" else p for p in muscles.pairs)
    return MuscleSet(pairs, muscles.n_links)


def run_options_from_args(args: argparse.Namespace, sc: Scenario,
                          command: str = "simulate") -> RunOptions:
    """The scenario's run options with those the command line gives: each option's flag read
    here once, then checked by :class:`~posturelab.simulation.options.RunOptions` (a bad
    value names the flag)."""
    from ..scenarios._parse import fall_from_table, torque_limits_from_table

    base = sc.options
    n = sc.body.n_links
    fall = base.fall
    fall_table = {"max_link_angle": args.max_link_angle,
                  "base_of_support": args.foot,  # ("none" given: no foot, whatever the scenario)
                  "centre_of_pressure": args.centre_of_pressure or None}
    fall_table = {k: v for k, v in fall_table.items() if v is not None}
    if fall_table:
        with naming_option("--max-link-angle" if args.max_link_angle is not None
                           else "--foot"):
            fall = fall_from_table(fall_table, "", FLAG_NAMES, base=fall)
    feedback = {attribute: check_value(attribute, getattr(args, attribute),
                                       FLAG_NAMES[f"muscles.{attribute}"])
                for attribute in ("feedback_delay", "proprioceptive_weight", "visual_weight",
                                  "torque_feedback_gain", "torque_feedback_time_constant")
                if getattr(args, attribute, None) is not None}
    description = base.description
    tilt, description = _tilt_from_flag(args, "tilt", base.tilt, description, command)
    visual_tilt, description = _tilt_from_flag(args, "visual_tilt", base.visual_tilt,
                                               description, command)
    torque_limits = base.torque_limits
    if args.torque_limits:
        torque_limits = torque_limits_from_table(args.torque_limits, n, "", FLAG_NAMES)
    if getattr(args, "ankle_limit_from_foot", False):
        torque_limits = ("foot",) + tuple(torque_limits[1:] if torque_limits is not None
                                          else (math.inf,) * (n - 1))
    if torque_limits is not None and "foot" in torque_limits and fall.base_of_support is None:
        raise UsageError(f"{command}: the ankle's limits from the foot (--ankle-limit-from-foot "
                         "or 'foot' in --torque-limits / [limits] torque) need a foot: give "
                         "--foot literature (or HEEL,TOE)")
    with naming_option("--motor-noise"):
        motor_noise = motor_noise_from_args(args, n)
    if motor_noise is not None:
        if base.motor_noise is not None:
            raise UsageError(f"{command}: the experiment already has motor noise; give "
                             "--motor-noise or [motor_noise], not both")
        description = f"{description}, {motor_noise.describe()}"
    else:
        motor_noise = base.motor_noise
    with naming_given_options(args):
        return base.replace(
            duration=_given(args.duration, base.duration),
            rtol=_given(args.rtol, base.rtol), atol=_given(args.atol, base.atol),
            sample_rate=_given(args.sample_rate, base.sample_rate),
            max_steps=_given(args.max_steps, base.max_steps),
            time_limit=_given(args.time_limit, base.time_limit),
            fall=fall, **feedback, tilt=tilt, visual_tilt=visual_tilt,
            tilt_axis_depth=_given(args.tilt_axis_depth, base.tilt_axis_depth),
            torque_limits=torque_limits,
            motor_noise=motor_noise, description=description,
            knee=KneeModel(args.knee) if args.knee is not None else base.knee,
            rates_from=_given(args.rates_from, base.rates_from))


#: What --tilt and --visual-tilt set: the ``args`` attribute (and scenario table) -> the
#: experiment's other source of it, and the words before its description.
TILT_FLAGS = {"tilt": ("a tilt column", ""),
              "visual_tilt": ("[visual_tilt]", "visual scene: ")}


def _tilt_from_flag(args: argparse.Namespace, attribute: str, given, description: str,
                    command: str):
    """(the Tilt, the description with it) of the flag of ``attribute`` (--tilt or
    --visual-tilt), or (``given``, ``description``) when the flag is not given; refused when
    the experiment has that tilt already (``given``)."""
    spec = getattr(args, attribute, None)
    if spec is None:
        return given, description
    option, (other, words) = "--" + attribute.replace("_", "-"), TILT_FLAGS[attribute]
    if given is not None:
        raise UsageError(f"{command}: the experiment already has a {attribute.replace('_', ' ')}"
                         f"; give {option} or {other}, not both")
    with naming_option(option):
        tilt = parse_tilt(spec, attribute)
    return tilt, f"{description}, {words}{tilt.describe()}"


def _given(value: T | None, default: T) -> T:
    """A flag's value, or ``default`` when the flag was not given (None)."""
    return default if value is None else value


def motor_noise_from_args(args: argparse.Namespace, n_joints: int):
    """The MotorNoise of --motor-noise, --motor-noise-cutoff and --seed (None without
    --motor-noise; the other two need it)."""
    from ..scenarios._parse import motor_noise_from_table

    if args.motor_noise is None:
        # (sweep --experiment prts seeds its measurement noise with --seed too)
        flags = ("motor_noise_cutoff",) if getattr(args, "experiment", "") == "prts" else (
            "motor_noise_cutoff", "seed")
        for flag in flags:
            if getattr(args, flag) is not None:
                raise UsageError(f"--{flag.replace('_', '-')} needs --motor-noise")
        return None
    table = {"standard_deviation": args.motor_noise, "cutoff": args.motor_noise_cutoff,
             "seed": args.seed or 0}
    return motor_noise_from_table(table, n_joints, "", FLAG_NAMES)


def _scenario_from_options(args: argparse.Namespace, command: str) -> Scenario:
    """The scenario of the model and experiment flags: their scenario tables
    (:func:`experiment_tables`, :func:`~posturelab.cli._common.model_tables`), built by the
    scenario parser as a file's are."""
    if args.case is None and args.stiffness is None and args.controller is None:
        raise UsageError(f"{command}: give --case, --stiffness or --controller (or "
                         "--scenario / --builtin)")
    from ..paper.printed import BACKWARD_INITIAL_STATE

    tables = experiment_tables(args, command)
    try:
        sc = model_from_args(args, tables, joint_feedback=True)
    except DataFileError as exc:
        if "tilt" in tables or "lacks column" not in str(exc):  # (a bad value: it is there)
            raise
        raise DataFileError(f"{exc} (or a tilt [rad] column)") from None
    n = sc.body.n_links
    initial = sc.options.initial_state
    if isinstance(sc.disturbance, VelocityStep) and args.initial_posture is None and n == 3:
        # the paper's flexed posture before a step, unless told otherwise
        rates = [0.0] * n if initial is None else list(initial[n:])
        initial = tuple(BACKWARD_INITIAL_STATE[:n]) + tuple(rates)
    label = (f"case {args.case}" if args.case else f"controller {args.controller}"
             if args.controller else "custom stiffness")
    if args.gastrocnemius not in (None, "two-sided"):
        label += f", {args.gastrocnemius} gastrocnemius"
    if args.body is not None or args.height is not None:
        label += f", body {sc.body.name}"
    tilt = sc.options.tilt
    what = sc.disturbance.describe() + (f", {tilt.describe()}" if tilt is not None else "")
    return sc.replace(name="cli", source="command line", options=sc.options.replace(
        initial_state=initial, description=f"{label}, {what}"))


def experiment_tables(args: argparse.Namespace, command: str) -> dict[str, dict]:
    """The scenario tables of the experiment flags: [disturbance] (--disturbance and
    --speed, or a --platform-profile's translation), [tilt] (a --platform-profile's tilt
    column) and [initial] (--initial-posture, --initial-rates)."""
    if args.disturbance not in (None, "none") and args.platform_profile:
        raise UsageError(f"{command}: give --disturbance or --platform-profile, not both")
    tables: dict[str, dict] = {}
    if args.platform_profile:
        tables.update(_platform_tables(args.platform_profile))
    elif args.disturbance in ("backward", "forward"):
        speed = 1.0 if args.speed is None else args.speed
        if not (math.isfinite(speed) and 0 < speed <= MAX_PLATFORM_SPEED):
            raise ParameterError(f"--speed [m/s] must be in (0, {MAX_PLATFORM_SPEED:g}] (the "
                                 f"step's size; --disturbance gives its direction), got "
                                 f"{speed:g}")
        tables["disturbance"] = {"type": "velocity-step", "direction": args.disturbance,
                                 "speed": speed}
    if args.speed is not None and "speed" not in tables.get("disturbance", {}):
        raise UsageError(f"{command}: --speed is the size of a velocity step; it needs "
                         "--disturbance backward or forward")
    initial = {"posture": args.initial_posture, "rates": args.initial_rates}
    tables["initial"] = {k: v for k, v in initial.items() if v is not None}
    return tables


def _platform_tables(path: str) -> dict[str, dict]:
    """A measured profile as the scenario tables of the columns it has: [disturbance] of
    type profile (x_acceleration, y_acceleration) and [tilt] of type profile (tilt [rad]);
    a file with neither is read as a translation profile (whose error says so)."""
    from .._files import csv_rows, read_text
    from .._parquet import is_parquet, parquet_rows

    first = next(parquet_rows(path, repr(path)) if is_parquet(path)
                 else csv_rows(read_text(path, "platform profile"), repr(path)), None)
    header = first[1] if first is not None else []
    names = {h.split("[")[0].strip().lower() for h in header}
    tables: dict[str, dict] = {}
    if names & {"x_acceleration", "ax", "xdd"} or "tilt" not in names:
        tables["disturbance"] = {"type": "profile", "file": path}
    if "tilt" in names:
        tables["tilt"] = {"type": "profile", "file": path}
    return tables


def experiment_inputs(args: argparse.Namespace) -> dict[str, str | None]:
    """The files an experiment's options read, by option (for
    :func:`posturelab._files.refuse_input_as_output`)."""
    return {"--scenario": args.scenario, "--platform-profile": args.platform_profile}


def _write_run(result, path: str) -> None:
    """--out: the run's time series as CSV, or Parquet with each unit in its field's
    metadata (as sweep and convert write)."""
    if not str(path).lower().endswith(".parquet"):
        result.to_csv(path)
        return
    from .._files import atomic_write_bytes
    from ..studies._sweep_grid import table_parquet_bytes

    names, table = result.columns()
    atomic_write_bytes(path, table_parquet_bytes(list(zip(names, table.T, strict=True)),
                                                 result.column_units()))


#: Bytes a value of a perturbed run's CSV takes on average ("%.10g" and a comma: most
#: values are 11 to 17 characters, a few columns zeros; 12.6 measured for a velocity step,
#: 11.4 for a sine tilt), for the estimate made before a run. An unperturbed run from
#: upright is zeros (2 to 3 bytes a value): not estimated. [B]
CSV_BYTES_PER_VALUE = 12


def check_csv_size(sc: Scenario, out: str) -> None:
    """Refuse, before the run, a CSV whose rows (floor(duration × sample rate) + 1) times
    its columns (those every run has, at least) at :data:`CSV_BYTES_PER_VALUE` would pass
    what posturelab reads back (the write refuses what gets past this estimate)."""
    from .._files import MAX_INPUT_BYTES
    from ..simulation.outcome import stimulus_timing

    o, n = sc.options, sc.body.n_links
    still = not stimulus_timing(sc.disturbance, o.tilt, o.motor_noise, o.visual_tilt).perturbed
    if still and not any(o.initial_state or ()):
        return  # (zeros: the write's own check suffices)
    rows = math.floor(o.duration * o.sample_rate) + 1
    columns = 1 + 2 * n + len(sc.muscles.names) + 2 * n + 10  # t, θ, ω, M, U, joint, cog…
    columns += (o.tilt is not None) + (o.visual_tilt is not None)
    estimate = rows * columns * CSV_BYTES_PER_VALUE
    if estimate > MAX_INPUT_BYTES:
        raise ParameterError(
            f"--out {out!r} would be about {estimate / 2**20:,.0f} MiB ({rows:,} rows of "
            f"--duration {o.duration:.10g} s at --sample-rate {o.sample_rate:.10g} Hz × {columns} "
            f"columns); at most {MAX_INPUT_BYTES // 2**20} MiB, the most posturelab reads "
            "back: write .parquet, or lower --sample-rate or --duration")


def run(args: argparse.Namespace) -> int:
    from .._files import refuse_input_as_output

    refuse_input_as_output(experiment_inputs(args),
                           {"--out": args.out, "--plot": args.plot, "--animate": args.animate})
    sc = scenario_from_args(args)
    outputs = [p for p in (args.out, args.plot, args.animate) if p]
    check_writable(outputs, {args.out: (".csv", ".parquet"), args.plot: FIGURE_SUFFIXES,
                             args.animate: (".gif",)})
    if args.out and args.out.lower().endswith(".csv"):
        check_csv_size(sc, args.out)
    if sc.options.time_limit is None:
        sc = sc.replace(time_limit=DEFAULT_TIME_LIMIT)
    with naming_given_options(args):
        result = sc.run(engine=args.engine)
    if args.out:
        _write_run(result, args.out)
    if args.plot:
        from ..viz.plots import plot_run_overview, save_figure

        fig = plot_run_overview(result, link_names=[s.name for s in sc.body.segments],
                                base_of_support=sc.options.fall.base_of_support)
        save_figure(fig, args.plot)
    if args.animate:
        from ..viz.animation import animate

        animate(result, sc.body, args.animate)
    from ..linear.verdict import upright_verdict

    verdict = upright_verdict(
        sc.body, sc.muscles, sc.options.feedback_delay,
        torque_feedback_gain=sc.options.torque_feedback_gain,
        torque_feedback_time_constant=sc.options.torque_feedback_time_constant,
        joint_feedback=sc.options.joint_feedback, knee=sc.options.knee.mode)
    outcome = result.outcome
    knee_note = None
    if sc.options.joint_feedback is not None and sc.options.knee.mode != "locked":
        knee_note = (f"the multi-joint controller was designed with the knee locked; this "
                     f"run's knee is {sc.options.knee.mode} (the linear verdict takes the "
                     f"{sc.options.knee.mode} knee)")
    if args.json:
        stability = verdict.to_dict()
        if knee_note is not None:
            stability["note"] = knee_note
        print_json({**result.summary(), "engine": args.engine,
                    "linear_stability": stability})
    else:
        peaks = ", ".join(f"{x:.4f}" for x in result.max_abs_theta)
        print(f"outcome: {outcome.message}")  # first, as the help and README say
        if sc.options.description.strip():
            print(sc.options.description.strip())
        print(f"status: {result.status} ({result.message})")
        print(f"engine: {args.engine}")
        print(f"linear model: {verdict.describe()}")
        print(f"peak |θ| [rad]: {peaks}")
        if sc.body.n_links >= 2:
            share = result.hip_fraction
            print("hip fraction (anti-phase leg–trunk mode): "
                  + (f"{share:.3f}" if share == share else "none (no sway)"))
        print("final state [rad, rad/s]: " + ", ".join(f"{x:.4g}" for x in result.final_state))
        for path in outputs:
            print(f"wrote {path}")
    if knee_note is not None:
        print(f"posturelab: note: {knee_note}", file=sys.stderr)
    if verdict.status == "depends on the side":
        print("posturelab: warning: upright's linear stability depends on the side of a "
              f"one-sided pair's switch for these gains and this body ({verdict.describe()})",
              file=sys.stderr)
    elif not verdict.stable:
        print(f"posturelab: warning: these gains are {verdict.describe()} for this body",
              file=sys.stderr)
    if result.status == "failed":
        print(f"posturelab: warning: {result.message}", file=sys.stderr)
        return 1
    return 0
