"""Argument helpers shared by the subcommands (parsing only; no physics here)."""

from __future__ import annotations

import argparse
import json
import math
import sys

from ..errors import ParameterError
from ..model.muscles import PAPER_PAIR_NAMES, STIFFNESS_CASES

GASTROCNEMIUS_HELP = (
    "two-sided (default) adds the paper's artificial antagonist so the gastrocnemius pair "
    "acts for either sign of θ2; one-sided lets it act only while θ2 >= 0."
)


def parse_float_list(text: str, field: str, n: int | None = None) -> list[float]:
    """Parse ``"a,b,c"`` into floats, checking count and finiteness; errors name ``field``."""
    parts = [p.strip() for p in str(text).split(",")]
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise ParameterError(
            f"{field} must be comma-separated numbers, got {text!r}"
        ) from None
    if n is not None and len(values) != n:
        raise ParameterError(f"{field} must have {n} comma-separated values, got {len(values)}")
    for v in values:
        if not math.isfinite(v):
            raise ParameterError(f"{field} must contain finite numbers, got {v}")
    return values


def parse_limit_list(text: str, field: str, n: int) -> list[float]:
    """Parse ``"120,inf,80"``: n positive numbers, ``inf``/``none`` meaning no limit."""
    parts = [p.strip().lower() for p in str(text).split(",")]
    if len(parts) != n:
        raise ParameterError(f"{field} must have {n} comma-separated values, got {len(parts)}")
    out = []
    for p in parts:
        if p in ("inf", "none"):
            out.append(math.inf)
            continue
        try:
            v = float(p)
        except ValueError:
            raise ParameterError(f"{field} must be numbers or 'inf', got {p!r}") from None
        if not (math.isfinite(v) and v > 0):
            raise ParameterError(f"{field} must be > 0 (or 'inf'), got {p!r}")
        out.append(v)
    return out


def add_muscle_arguments(p: argparse.ArgumentParser, *, require: bool = False) -> None:
    """--case / --stiffness / --viscosity-ratio / --gastrocnemius."""
    g = p.add_mutually_exclusive_group(required=require)
    g.add_argument(
        "--case", metavar="CASE",
        help=f"Table I stiffness set: {', '.join(STIFFNESS_CASES)}.",
    )
    g.add_argument(
        "--stiffness", metavar="K1,K2,K3,K4,K5",
        help="five pair stiffnesses [N·m/rad] in the order "
        + ", ".join(PAPER_PAIR_NAMES) + ".",
    )
    p.add_argument(
        "--viscosity-ratio", type=float, default=0.25, metavar="R",
        help="pair viscosity = R × pair stiffness [s] (default 0.25, as in the paper).",
    )
    p.add_argument(
        "--gastrocnemius", choices=["two-sided", "one-sided"], default="two-sided",
        help=GASTROCNEMIUS_HELP,
    )


def muscles_from_args(args: argparse.Namespace):
    """Build the paper's MuscleSet from --case / --stiffness arguments."""
    from ..model.muscles import paper_muscles

    if args.case is None and args.stiffness is None:
        raise ParameterError("give --case (Table I) or --stiffness K1,K2,K3,K4,K5")
    stiffness = None
    if args.stiffness is not None:
        stiffness = parse_float_list(args.stiffness, "--stiffness [N·m/rad]", 5)
    return paper_muscles(
        args.case, stiffness=stiffness, viscosity_ratio=args.viscosity_ratio,
        gastrocnemius=args.gastrocnemius,
    )


def print_json(obj) -> None:
    """Print exactly one JSON object on standard output."""
    json.dump(obj, sys.stdout, allow_nan=False)
    sys.stdout.write("\n")


def check_writable(paths: list[str]) -> None:
    """Fail early, before any work, when an output's directory is missing or read-only."""
    import os
    from pathlib import Path

    for p in paths:
        d = Path(p).parent if str(Path(p).parent) else Path(".")
        if not d.is_dir():
            raise ParameterError(f"cannot write {p!r}: directory {str(d)!r} does not exist")
        if not os.access(d, os.W_OK):
            raise ParameterError(f"cannot write {p!r}: directory {str(d)!r} is not writable")
        if Path(p).is_dir():
            raise ParameterError(f"cannot write {p!r}: it is a directory")


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

    t0 = time.perf_counter()
    try:
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
