"""Argument helpers shared by the subcommands (parsing only; no physics here)."""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import sys

from ..errors import ParameterError
from ..model.muscles import PAPER_PAIR_NAMES, STIFFNESS_CASES
from ..parameters import MAX_FEEDBACK_DELAY
from ._flags import add_flag, add_options

GASTROCNEMIUS_HELP = (
    "two-sided (default): the paper's artificial antagonist added, the gastrocnemius pair "
    "acts for either sign of θ2 (the paper's analysis, Figs. 3–8); one-sided: the paper's "
    "real gastrocnemius, acting only while its stretch θ2 >= 0 and slack while θ2 < 0; "
    "pull-only: one-sided and also slack while its torque k·θ2 + l·θ̇2 would push (a muscle "
    "cannot push; beyond the paper)."
)
#: The --gastrocnemius choices (posturelab.model.muscles.GASTROCNEMIUS_FORMS, without
#: importing it).
GASTROCNEMIUS_CHOICES = ("two-sided", "one-sided", "pull-only")


def parse_float_list(text: str, field: str, n: int | None = None) -> list[float]:
    """Parse ``"a,b,c"`` into floats, checking count and finiteness; errors name ``field``
    (:func:`posturelab.scenarios._parse.number_list`, which reads a list given as text)."""
    from ..scenarios._parse import number_list

    return number_list(str(text), field, n)


def add_muscle_arguments(p: argparse.ArgumentParser, *, require: bool = False,
                         own_case: bool = False) -> None:
    """The body and its feedback: --body / --height --mass, --case / --stiffness /
    --controller, --viscosity / --viscosity-ratio, --gastrocnemius, the active gains,
    --feedback-delay and --proprioceptive-weight (``own_case``: the command defines --case
    and --viscosity-ratio itself)."""
    from ..model.body import BODY_PRESETS
    from ..model.controllers import CONTROLLERS, MULTIJOINT_CONTROLLERS

    body = p.add_argument_group("body")
    body.add_argument("--body", metavar="PRESET",
                      help=f"body preset: {', '.join(BODY_PRESETS)} (default paper).")
    body.add_argument("--height", type=str, metavar="M",
                      help="subject height [m], with --mass: leg, thigh and HAT scaled by "
                      "Winter's anthropometric table (three links; with a one-link "
                      "--controller, the same body as one rigid link).")
    body.add_argument("--mass", type=str, metavar="KG", help="subject mass [kg], with --height.")
    fb = p.add_argument_group("feedback (muscle pairs)")
    g = fb.add_mutually_exclusive_group(required=require)
    if not own_case:
        g.add_argument("--case", metavar="CASE", help="Table I stiffness set (three links): "
                       f"{', '.join(STIFFNESS_CASES)}.")
    g.add_argument("--stiffness", metavar="LIST",
                   help="pair stiffnesses [N·m/rad], one per pair: five for three links ("
                   + ", ".join(PAPER_PAIR_NAMES) + "), one per joint otherwise (one for a "
                   "one-link body). With active gains this is the intrinsic (undelayed) part.")
    g.add_argument("--controller", metavar="NAME",
                   help="a controller preset. One-link (after a published model: intrinsic "
                   "and active gains as "
                   f"fractions of mgh, delay, weight): {', '.join(CONTROLLERS)}; its body: "
                   "the paper's as one link (paper-1link) by default, --height/--mass "
                   "lumped to one link, or a one-link --body. Multi-joint (an LQR design on "
                   "the three-link body, knee locked; simulate, sweep, fit and strategy take it): "
                   f"{', '.join(MULTIJOINT_CONTROLLERS)}; its body: the paper's, a --body "
                   "or --height/--mass (three links). Which of the one-link presets' numbers "
                   "come from the source: "
                   + " ".join(f"{c.name}: {c.provenance_text()}" for c in CONTROLLERS.values()))
    add_options(fb, {
        "--viscosity": "pair viscosities [N·m·s/rad], one per pair (instead of a ratio).",
        "--active-stiffness": "active (neural) pair stiffnesses [N·m/rad], delayed by "
                              "--feedback-delay; one per pair.",
        "--active-viscosity": "active pair viscosities [N·m·s/rad], one per pair.",
    }, metavar="LIST")
    fb.add_argument("--gastrocnemius", choices=GASTROCNEMIUS_CHOICES, default="two-sided",
                    help=GASTROCNEMIUS_HELP)
    numbers = {  # (None when not given: a scenario's or a preset's value then stands)
        "--viscosity-ratio": ("R", "pair viscosity = R × pair stiffness [s] (default 0.25, "
                              "the paper's)."),
        "--active-viscosity-ratio": ("R", "active viscosity = R × active stiffness [s] "
                                     "(default 0)."),
        "--feedback-delay": ("SECONDS", f"neural delay τ [s], in [0, {MAX_FEEDBACK_DELAY:g}]. "
                             "With active gains it delays their part only (the intrinsic "
                             "gains act at once); without any, it delays every pair's whole "
                             "feedback (the paper's gains read as neural)."),
        "--proprioceptive-weight": ("W", "W in [0, 1]: the active error of pairs that span "
                                    "the foot is θ + W·α under a tilt α (1, the default: "
                                    "relative to the foot; 0: to the vertical)."),
        "--visual-weight": ("W_V", "W_v in [0, 1], with W + W_v <= 1 (the rest graviceptive; "
                            "Peterka 2002's independent channels): the active error gains "
                            "W_v·v under a visual-scene tilt v (--visual-tilt; default 0)."),
    }
    if own_case:  # (the command defines --viscosity-ratio itself)
        del numbers["--viscosity-ratio"]
    add_options(fb, numbers, type=float, default=None)


def add_trial_arguments(p: argparse.ArgumentParser, *,
                        input_help: str = "what a trial's stimulus is: tilt [rad] (default) "
                        "or translation [m].") -> None:
    """How a trial CSV among the inputs is estimated (``fit-frf``, ``cohort``, ``likeness``,
    ``likeness-reference`` and ``compare-frf``; ``frf`` takes the same shared flags)."""
    add_flag(p, "--stimulus", " CSV (or two of a dual-stimulus trial)")
    add_flag(p, "--response")
    add_flag(p, "--cycle-length", " of a trial CSV")
    add_flag(p, "--discard-cycles", "0")
    add_flag(p, "--response-sign", ", as posturelab frf")
    p.add_argument("--input", choices=["tilt", "translation"], default="tilt",
                   help=input_help)


#: The scenario-file key each model flag sets: the command line states its body, muscles and
#: feedback as a scenario file's [body] and [muscles] tables, which the scenario parser
#: (:func:`posturelab.scenarios._parse.parse_tables`) builds, as it builds a file's.
MODEL_FLAGS: dict[str, str] = {
    "body": "body.preset", "height": "body.height", "mass": "body.mass",
    "case": "muscles.case", "stiffness": "muscles.stiffness",
    "controller": "muscles.controller", "viscosity": "muscles.viscosity",
    "viscosity_ratio": "muscles.viscosity_ratio", "gastrocnemius": "muscles.gastrocnemius",
    "active_stiffness": "muscles.active_stiffness",
    "active_viscosity": "muscles.active_viscosity",
    "active_viscosity_ratio": "muscles.active_viscosity_ratio",
    "feedback_delay": "muscles.feedback_delay",
    "proprioceptive_weight": "muscles.proprioceptive_weight",
    "visual_weight": "muscles.visual_weight",
    "torque_feedback_gain": "muscles.torque_feedback_gain",
    "torque_feedback_time_constant": "muscles.torque_feedback_time_constant",
}
#: The experiment flags read into a scenario table by ``simulate`` and the commands that
#: share its options (their values are parsed first: a --tilt spec, a noise list).
EXPERIMENT_FLAGS: dict[str, str] = {
    "tilt": "tilt", "tilt_axis_depth": "tilt.axis_depth",
    "initial_posture": "initial.posture", "initial_rates": "initial.rates",
    "motor_noise": "motor_noise.standard_deviation",
    "motor_noise_cutoff": "motor_noise.cutoff", "seed": "motor_noise.seed",
    "speed": "disturbance.speed", "platform_profile": "disturbance.file",
    "foot": "fall.base_of_support", "max_link_angle": "fall.max_link_angle",
    "torque_limits": "limits.torque",
}


def flag(attribute: str) -> str:
    """The flag of an ``args`` attribute: ``feedback_delay`` → ``--feedback-delay``."""
    return "--" + attribute.replace("_", "-")


#: How a message names a scenario key the command line set: its flag.
FLAG_NAMES: dict[str, str] = {key: flag(attribute) for attribute, key in
                              (MODEL_FLAGS | EXPERIMENT_FLAGS).items()}


def model_tables(args: argparse.Namespace) -> dict[str, dict]:
    """The [body] and [muscles] tables of the model flags given (:data:`MODEL_FLAGS`)."""
    tables: dict[str, dict] = {"body": {}, "muscles": {}}
    for attribute, key in MODEL_FLAGS.items():
        value = getattr(args, attribute, None)
        if value is None or (attribute == "gastrocnemius" and value == "two-sided"):
            continue
        section, field = key.split(".")
        tables[section][field] = value
    return tables


def model_from_args(args: argparse.Namespace, tables: dict | None = None, *,
                    joint_feedback: bool = False):
    """The :class:`~posturelab.Scenario` of the model flags (body, muscles, feedback delay
    and proprioceptive weight in its options) and of ``tables`` (a scenario file's other
    tables), built by the scenario parser; a bad value names the flag the user typed. A
    multi-joint controller (``--controller multijoint-default``) is refused in one line
    unless the command takes one (``joint_feedback``)."""
    from pathlib import Path

    from ..scenarios import SCENARIO_DEFAULTS
    from ..scenarios._parse import parse_tables

    data = {"duration": SCENARIO_DEFAULTS.duration, **model_tables(args), **(tables or {})}
    with naming_given_options(args, MODEL_FIELD_OPTIONS):
        scenario = parse_tables(data, Path("."), "", FLAG_NAMES)
    if scenario.options.joint_feedback is not None and not joint_feedback:
        from . import UsageError

        raise UsageError(f"--controller {args.controller} is a multi-joint controller: "
                         "simulate, sweep, fit and strategy take it, this command does not")
    _note_one_link(args, scenario.body)
    _note_lag_without_gain(args)
    return scenario


def _note_lag_without_gain(args: argparse.Namespace) -> None:
    """Say that --torque-feedback-time-constant does nothing without a torque feedback gain
    (unless the command varies or fits the gain)."""
    if getattr(args, "torque_feedback_time_constant", None) is None or getattr(
            args, "torque_feedback_gain", None):
        return
    varied = " ".join(str(getattr(args, name, None) or "") for name in ("vary", "free", "per"))
    if "torque_feedback_gain" not in varied:
        print("posturelab: note: --torque-feedback-time-constant has no effect without "
              "--torque-feedback-gain > 0 (no torque feedback)", file=sys.stderr)


def _note_one_link(args: argparse.Namespace, body) -> None:
    """Say that a one-link controller lumps a body from height and mass to one link."""
    if (getattr(args, "controller", None) is not None and getattr(args, "height", None)
            and body.n_links == 1):
        print(f"posturelab: note: --controller {args.controller} is a one-link controller: "
              f"the body is {body.name}", file=sys.stderr)


def body_from_args(args: argparse.Namespace):
    """The body of --body / --height --mass (the paper's by default; with --controller, a
    one-link body), built by the scenario parser from the [body] table of the flags."""
    from ..scenarios._parse import body_from_table

    with naming_given_options(args, MODEL_FIELD_OPTIONS):
        body = body_from_table(model_tables(args)["body"], "", FLAG_NAMES,
                               one_link=getattr(args, "controller", None) is not None)
    _note_one_link(args, body)
    return body


def muscles_from_args(args: argparse.Namespace, body=None):
    """The MuscleSet of --case / --stiffness / --controller and the gain options on ``body``
    (default :func:`body_from_args`), built by the scenario parser from the [muscles] table
    of the flags."""
    return muscles_and_delay_from_args(args, body)[0]


def muscles_and_delay_from_args(args: argparse.Namespace, body=None):
    """(:func:`muscles_from_args`, the feedback delay [s]: --feedback-delay, a
    --controller's, or 0)."""
    from ..scenarios._parse import muscles_from_table

    body = body_from_args(args) if body is None else body
    tables = model_tables(args)
    with naming_given_options(args, MODEL_FIELD_OPTIONS):
        muscles, _, delay, _ = muscles_from_table(tables["muscles"], body, "", FLAG_NAMES,
                                                  tables["body"])
    return muscles, delay


def feedback_given(args: argparse.Namespace) -> bool:
    """Whether the command line gives a feedback delay (--feedback-delay, or a
    --controller's)."""
    return (getattr(args, "feedback_delay", None) is not None
            or getattr(args, "controller", None) is not None)


def add_torque_feedback_arguments(p: argparse.ArgumentParser) -> None:
    """--torque-feedback-gain and --torque-feedback-time-constant (Peterka 2002's torque
    feedback, docs/design.md), for the commands whose model takes it."""
    from ..parameters import QUANTITIES

    gain, lag = QUANTITIES["torque_feedback_gain"], QUANTITIES["torque_feedback_time_constant"]
    fb = p.add_argument_group("torque feedback (Peterka 2002)")
    fb.add_argument("--torque-feedback-gain", type=float, default=None, metavar="K",
                    help=f"K_t in {gain.interval()}: the active torque fed back positively "
                    "through K_t/(τ_t s + 1) (default 0: none; K_t = K_F·K_P of the "
                    "source's K_F [rad/(N·m)]).")
    fb.add_argument("--torque-feedback-time-constant", type=float, default=None,
                    metavar="SECONDS", help=f"τ_t [s] in {lag.interval()} (default 17.4, "
                    "PMC5664365 Table 1).")


def torque_feedback_options_from_args(args: argparse.Namespace) -> dict:
    """``torque_feedback_gain`` [-] and ``torque_feedback_time_constant`` [s] given on the
    command line, checked against the parameter table and named by their flags; absent
    when not given."""
    from ..parameters import check_value

    out = {}
    for name in ("torque_feedback_gain", "torque_feedback_time_constant"):
        value = getattr(args, name, None)
        if value is not None:
            out[name] = check_value(name, value, "--" + name.replace("_", "-"))
    return out


def tilt_table(text: str) -> dict:
    """``--tilt`` as a scenario file's [tilt] table:
    ``sine:AMPLITUDE_RAD:FREQUENCY_HZ[:PHASE_RAD]``,
    ``raised-cosine:AMPLITUDE_RAD:DURATION_S[:START_S]`` or
    ``prts:AMPLITUDE_RAD[:STATE_DURATION_S][:SEQUENCE]`` (peak to peak; SEQUENCE one of
    :data:`posturelab.model.tilt.PRTS_SEQUENCES`, posturelab-80 by default)."""
    from ..model.tilt import DEFAULT_PRTS, get_prts_sequence

    forms = ("sine:AMPLITUDE_RAD:FREQUENCY_HZ[:PHASE_RAD], "
             "raised-cosine:AMPLITUDE_RAD:DURATION_S[:START_S] or "
             "prts:AMPLITUDE_RAD[:STATE_DURATION_S][:SEQUENCE]")
    kind, _, rest = str(text).partition(":")
    kind = kind.strip().lower()
    fields = {"sine": ("amplitude", "frequency", "phase"),
              "raised-cosine": ("amplitude", "duration", "start"),
              "prts": ("amplitude", "state_duration")}
    if kind not in fields or not rest:
        raise ParameterError(f"--tilt must be {forms}, got {text!r}")
    sequence = DEFAULT_PRTS
    if kind == "prts":
        head, _, last = rest.rpartition(":")
        if head and last.strip() and not last.strip()[0].isdigit() \
                and last.strip()[0] not in "+-.":
            get_prts_sequence(last)  # an unknown name lists the known ones
            sequence = last.strip().lower()
            rest = head
    values = parse_float_list(rest.replace(":", ","), f"--tilt {kind}", None)
    if not 2 - (kind == "prts") <= len(values) <= len(fields[kind]):
        raise ParameterError(f"--tilt must be {forms}, got {text!r}")
    table = {"type": kind, **dict(zip(fields[kind], values, strict=False))}
    if kind == "prts":
        table["sequence"] = sequence
    return table


def parse_tilt(text: str, table: str = "tilt"):
    """The Tilt of ``--tilt`` (:func:`tilt_table`), or with ``table="visual_tilt"`` of
    ``--visual-tilt`` (the same specs), built by the scenario parser as a file's [tilt] or
    [visual_tilt] table."""
    from pathlib import Path

    from ..scenarios._parse import tilt_from_table

    return tilt_from_table(tilt_table(text), Path("."), "", FLAG_NAMES, table)


@contextlib.contextmanager
def naming_option(option: str):
    """Put the command-line ``option`` (as the user typed it) before the message of a
    ParameterError raised inside, so that a check deep in the model names what was given:
    ``--duration: duration [s] must be in (0, 86400] s, got 1e+09``."""
    try:
        yield
    except ParameterError as exc:
        text = str(exc)
        if text.startswith(option):
            raise
        raise ParameterError(f"{option}: {text}") from None


#: The message prefix of a run setting's check (simulation/setup.py) -> the option that sets
#: it on the command line.
RUN_SETTING_OPTIONS = {"duration [s]": "--duration", "rtol": "--rtol", "atol": "--atol",
                       "sample_rate [Hz]": "--sample-rate", "max_steps": "--max-steps",
                       "time_limit [s]": "--time-limit",
                       "tilt_axis_depth [m]": "--tilt-axis-depth"}
#: The message prefix of a check of the body or the gains (model/) -> the option.
MODEL_FIELD_OPTIONS = {"height [m]": "--height", "mass [kg]": "--mass",
                       "muscle pair '*' active stiffness": "--active-stiffness",
                       "muscle pair '*' active viscosity": "--active-viscosity",
                       "muscle pair '*' stiffness": "--stiffness",
                       "muscle pair '*' viscosity": "--viscosity",
                       "stiffness [N·m/rad]": "--stiffness",
                       "viscosity [N·m·s/rad]": "--viscosity"}


def _given_option(args: argparse.Namespace, text: str, table: dict[str, str]) -> str | None:
    """The option of ``table`` whose message prefix starts ``text`` (``*`` matching a pair
    name) if the user gave that option, else None."""
    import re

    for field, option in table.items():
        given = getattr(args, option[2:].replace("-", "_"), None) is not None
        pattern = "[^']*".join(re.escape(part) for part in field.split("*")) + " "
        if given and re.match(pattern, text):
            return option
    return None


@contextlib.contextmanager
def naming_given_options(args: argparse.Namespace,
                         table: dict[str, str] | None = None):
    """Like :func:`naming_option` for values checked deeper in (the run settings when a
    run is set up, by default; ``table`` for others such as :data:`MODEL_FIELD_OPTIONS`):
    a ParameterError about a value the user gave (--duration, --rtol, ...) names that
    option."""
    try:
        yield
    except ParameterError as exc:
        text = str(exc)
        option = _given_option(args, text, RUN_SETTING_OPTIONS if table is None else table)
        if option is not None and not text.startswith(option):
            raise ParameterError(f"{option}: {text}") from None
        raise


def print_json(obj) -> None:
    """Print exactly one JSON object on standard output: built whole first (nothing is
    printed if it cannot be), a non-finite number written as null, never as bare NaN."""
    sys.stdout.write(json.dumps(_finite_or_null(obj), allow_nan=False) + "\n")


def _finite_or_null(obj):
    """``obj`` with every non-finite float replaced by None (JSON null)."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: _finite_or_null(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_finite_or_null(v) for v in obj]
    return obj


#: The file types each kind of output may have (suffixes, lower case).
FIGURE_SUFFIXES = (".png", ".svg", ".pdf")


def check_writable(paths: list[str], suffixes: dict[str, tuple[str, ...]] | None = None
                   ) -> None:
    """Fail early, before any work and before anything is written, when an output cannot
    be written: its directory is missing or read-only, it is a directory, it exists and is
    not a regular file (a device, FIFO or socket: never replaced), its suffix is not one of
    ``suffixes[path]``, or two outputs are the same file."""
    import os
    from pathlib import Path

    from .._files import refuse_non_regular

    seen: dict[str, str] = {}
    for p in paths:
        if str(p).endswith(tuple(filter(None, ("/", os.sep, os.altsep)))):
            raise ParameterError(f"cannot write {str(p)!r}: a file name cannot end in "
                                 f"{str(p)[-1]!r} (a directory's separator)")
        d = Path(p).parent if str(Path(p).parent) else Path(".")
        if not d.is_dir():
            raise ParameterError(f"cannot write {p!r}: directory {str(d)!r} does not exist")
        if not os.access(d, os.W_OK):
            raise ParameterError(f"cannot write {p!r}: directory {str(d)!r} is not writable")
        if Path(p).is_dir():
            raise ParameterError(f"cannot write {p!r}: it is a directory")
        refuse_non_regular(p, ParameterError)
        allowed = (suffixes or {}).get(p)
        if allowed and Path(p).suffix.lower() not in allowed:
            choices = (", ".join(allowed[:-1]) + " or " + allowed[-1]) if len(allowed) > 1 \
                else allowed[0]
            raise ParameterError(f"an output must end in {choices}, got {p!r}")
        key = os.path.realpath(p)
        if key in seen:
            raise ParameterError(f"{seen[key]!r} and {p!r} are the same file")
        seen[key] = p


class ExpectedTime:
    """A ``progress(done, total)`` callback for long computations that draw no bar: once
    the first block is done, if the whole would take more than ``notice_after`` seconds,
    one line on ``stream`` (standard error) says how many ``unit`` and about how long
    (never for fewer than ``min_total``, which a slow start should not make noisy)."""

    def __init__(self, what: str, unit: str, stream=None, notice_after: float = 10.0,
                 min_total: int = 0) -> None:
        import time

        self.what, self.unit, self.notice_after = what, unit, notice_after
        self.min_total = min_total
        self.stream = sys.stderr if stream is None else stream
        self.start = time.perf_counter()
        self.said = False

    def __call__(self, done: int, total: int) -> None:
        import time

        if self.said or done <= 0 or done >= total or total < self.min_total:
            return
        self.said = True
        expected = (time.perf_counter() - self.start) * total / done
        if expected > self.notice_after:
            about = f"{expected / 60:.0f} min" if expected >= 120 else f"{expected:.0f} s"
            print(f"posturelab: {self.what}: {total:,} {self.unit}, about {about} in all "
                  "(--progress draws a bar)", file=self.stream, flush=True)


def load_compiled(load, what: str, stream=None, notice_after: float = 2.0) -> float:
    """Run ``load()`` (which compiles or loads numba kernels) and say so if numba compiles.

    numba announces a compilation with a ``"numba:compile"`` event, which a load
    from its on-disk cache does not raise. Once numba has been compiling for
    ``notice_after`` seconds (the first use after installing, or after a kernel
    source changed), one line on ``stream`` (standard error by default) says what
    is happening, and a second line when ``load()`` is done. Loading from the
    cache prints nothing, however long it takes; so does a compilation that is
    over within ``notice_after``. Returns the seconds ``load()`` took. [s]
    """
    import threading
    import time

    from numba.core import event

    stream = sys.stderr if stream is None else stream
    lock = threading.Lock()
    state = {"compiling": False, "said": False, "over": False, "timer": None}

    def notice() -> None:
        with lock:
            if state["over"] or state["said"]:
                return
            state["said"] = True
            print(f"posturelab: compiling {what} (once after installing; cached for later "
                  "runs)…", file=stream, flush=True)

    class CompileStarted(event.Listener):
        def on_start(self, ev) -> None:
            with lock:
                if state["compiling"]:
                    return
                state["compiling"] = True
                if notice_after > 0:
                    state["timer"] = threading.Timer(notice_after, notice)
                    state["timer"].daemon = True
                    state["timer"].start()
            if notice_after <= 0:
                notice()

        def on_end(self, ev) -> None:
            pass

    from .._jit import skip_blas_probe

    t0 = time.perf_counter()
    try:
        skip_blas_probe()  # (scipy.linalg's import: ~0.2 s that the kernels do not need)
        with event.install_listener("numba:compile", CompileStarted()):
            load()
    finally:
        with lock:
            state["over"] = True
            if state["timer"] is not None:
                state["timer"].cancel()
    seconds = time.perf_counter() - t0
    if state["said"]:
        print(f"posturelab: compiled {what} in {seconds:.0f} s", file=stream, flush=True)
    return seconds
