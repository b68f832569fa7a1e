"""The ``posturelab`` command line: one module per subcommand, each a thin call of the API.

Errors a user can cause (bad input, unknown names, unreadable files) are
printed as one line on standard error with exit code 2, never a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from ..errors import PostureLabError

#: Subcommand name -> module in this package: each defines ``DESCRIPTION``,
#: ``add_arguments(parser)`` and ``run(args)``; its one line of help is in
#: :data:`SUBCOMMAND_HELP`.
SUBCOMMANDS: dict[str, str] = {
    "poles": "poles",
    "sensitivity": "sensitivity",
    "simulate": "simulate",
    "reproduce": "reproduce",
    "stability-map": "stability_map",
    "sweep": "sweep",
    "fit": "fit",
    "delay-margin": "delay_margin",
    "frf": "frf",
    "convert": "convert",
    "frf-model": "frf_model",
    "fit-frf": "fit_frf",
    "compare-frf": "compare_frf",
    "likeness": "likeness",
    "likeness-reference": "likeness_reference",
    "cohort": "cohort",
    "design": "design",
    "compare": "compare",
    "explore": "explore",
    "step-threshold": "step_threshold",
    "strategy": "strategy",
}

#: Subcommand name -> its line in ``posturelab --help`` (here, so that ``posturelab --help``
#: imports no subcommand's module).
SUBCOMMAND_HELP: dict[str, str] = {
    "poles": "poles and stability of the linearised model (Table II)",
    "sensitivity": "disturbance severity J⁻¹H at a posture",
    "simulate": "simulate a platform disturbance (nonlinear model)",
    "reproduce": "regenerate the paper's tables and figures (HTML report)",
    "stability-map": "stability map of the linearised model over two parameters",
    "sweep": "simulate a grid of gains, delays, torque limits and perturbation sizes; outcomes "
             "to CSV or Parquet",
    "fit": "fit pair stiffness to measured angles (with confidence intervals)",
    "delay-margin": "delay margin of the linearised model: the feedback delay at which it loses "
                    "stability",
    "frf": "frequency response function of a periodic-stimulus (PRTS) trial, from a CSV",
    "convert": "a lab recording (C3D or CSV) to a posturelab table: uniform time, SI units, "
               "com_angle from markers or force plates",
    "frf-model": "frequency response of the linearised model to tilt or translation (exact "
                 "delay)",
    "fit-frf": "fit controller gains, delay and sensory weight to FRFs (one or several "
               "conditions)",
    "compare-frf": "compare two groups of FRFs band by band, with a permutation test over all "
                   "bands",
    "likeness": "human-likeness score of an FRF: its distance to a human reference (COMTEST)",
    "likeness-reference": "build a human-likeness reference from one's own cohort of FRFs",
    "cohort": "fit the same model to every subject's FRF in parallel; a table per subject "
              "and parameter, a summary",
    "design": "predict the standard errors of a PRTS experiment's fit before running it "
              "(Fisher information), and optimise its design",
    "compare": "overlay saved runs (posturelab simulate --out) in one figure, and tabulate them",
    "explore": "explore the model interactively in the web browser (a local page)",
    "step-threshold": "the largest platform translation withstood without a step (XCoM, Hof "
                      "2005), young or older",
    "strategy": "strategy maps: the hip fraction across translation speeds or frequencies "
                "(multi-joint LQR controller)",
}


class UsageError(PostureLabError):
    """Bad command-line usage."""


class OneLineParser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line and exit code 2, and which takes options
    only as spelled in full (``--cas 1`` is refused, not read as ``--case 1``)."""

    def __init__(self, *args, **kwargs) -> None:
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> None:  # type: ignore[override]
        where = "" if self.prog == "posturelab" else f"{self.prog.removeprefix('posturelab ')}: "
        raise UsageError(f"{where}{message} (see '{self.prog} --help')")


CONVENTIONS_EPILOG = (
    "Conventions: SI units; link angles θ are absolute from the vertical, positive "
    "leaning forward (+x); link 1 is the leg (lowest), 3 the torso; state order "
    "[θ1 θ2 θ3 θ̇1 θ̇2 θ̇3]; y is up; a backward platform motion (ẋ_d < 0) makes the "
    "body sway forward."
)


def build_parser(command: str | None = None, *, summary: bool = False) -> OneLineParser:
    """The top-level parser with every available subcommand, or with ``command`` alone.

    ``command``: build that subcommand only, importing no other subcommand's module (what
    ``posturelab COMMAND ...`` needs). ``summary``: every subcommand's name and help line
    only, importing none of them (what ``posturelab --help`` shows; it runs nothing).
    """
    from .. import __version__

    parser = OneLineParser(
        prog="posturelab",
        description="Human standing balance on a moving platform: the ankle-strategy paper "
        "and beyond.",
        epilog=CONVENTIONS_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"posturelab {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=OneLineParser)
    for name, module_name in SUBCOMMANDS.items():
        if command is not None and name != command:
            continue
        if summary:  # (names and help lines only: nothing to run)
            sub.add_parser(name, help=SUBCOMMAND_HELP[name])
            continue
        try:
            module = importlib.import_module(f"{__name__}.{module_name}")
        except ModuleNotFoundError as exc:  # a subcommand not built yet
            if exc.name == f"{__name__}.{module_name}":
                continue
            raise
        from ._flags import HelpFormatter

        p = sub.add_parser(name, help=SUBCOMMAND_HELP[name], description=module.DESCRIPTION,
                           epilog=CONVENTIONS_EPILOG, formatter_class=HelpFormatter)
        module.add_arguments(p)
        p.set_defaults(_run=module.run)
    return parser


#: Options whose value is a comma-separated list that may start with a minus sign.
LIST_OPTIONS = ("--posture", "--stiffness", "--initial-posture", "--initial-rates", "--foot",
                "--viscosity", "--torque-limits")


def _join_negative_lists(argv: list[str]) -> list[str]:
    """Turn ``--posture -0.1,0.2,0`` into ``--posture=-0.1,0.2,0`` (argparse would take the
    value for an option because it starts with '-')."""
    out: list[str] = []
    i = 0
    while i < len(argv):
        tok = argv[i]
        nxt = argv[i + 1] if i + 1 < len(argv) else None
        if tok in LIST_OPTIONS and nxt is not None and nxt.startswith("-") and len(nxt) > 1 \
                and (nxt[1].isdigit() or nxt[1] == "."):
            out.append(f"{tok}={nxt}")
            i += 2
            continue
        out.append(tok)
        i += 1
    return out


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the program is, so that every clean-up that runs on Ctrl-C
    (temporary files and folders removed) runs on it too."""


def _on_sigterm(signum, frame) -> None:
    raise Terminated()


def _unraisable(hook):
    """``sys.unraisablehook`` that re-delivers a :class:`Terminated` Python had to ignore
    (raised while a weakref callback ran, e.g. inside an import's module lock): SIGTERM is
    sent again to this process a moment later, from a timer thread, so that its handler
    raises it where the program then is, outside the callback; anything else goes to
    ``hook``."""
    import os
    import signal
    import threading

    def handle(info) -> None:
        if isinstance(info.exc_value, Terminated):
            again = threading.Timer(0.01, os.kill, (os.getpid(), signal.SIGTERM))
            again.daemon = True
            again.start()
            return
        hook(info)

    return handle


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``posturelab`` console script; returns the exit code (2 for bad
    input, 130 when interrupted, 143 when terminated).

    Without ``argv`` (the program itself: the console script or ``python -m posturelab``,
    which exit right after) the objects left are frozen out of the garbage collector
    (:func:`gc.freeze`) on return: the interpreter's final collections would otherwise walk
    every object numba and matplotlib created (about 0.2 s at exit). Exit handlers still
    run, and every output has been written and closed by then."""
    import signal
    import threading

    hook = sys.unraisablehook
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _on_sigterm)
        sys.unraisablehook = _unraisable(hook)
    else:  # (signals can only be handled on the main thread)
        previous = None
    try:
        return _main(argv)
    except Terminated:
        print("posturelab: terminated", file=sys.stderr)
        return 143
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
            sys.unraisablehook = hook
        if argv is None:
            import gc

            gc.freeze()


def _main(argv: Sequence[str] | None) -> int:
    try:
        argv = _join_negative_lists(list(sys.argv[1:] if argv is None else argv))
        # only the named subcommand's module is imported; without one, only the help lines
        command = next((arg for arg in argv if not arg.startswith("-")), None)
        parser = (build_parser(command) if command in SUBCOMMANDS
                  else build_parser(summary=True))
        args, extra = parser.parse_known_args(argv)
        if extra:  # named with the subcommand's own help, not the top-level one
            where = f"posturelab {command}" if command in SUBCOMMANDS else "posturelab"
            prefix = f"{command}: " if command in SUBCOMMANDS else ""
            raise UsageError(f"{prefix}unrecognized arguments: {' '.join(extra)} "
                             f"(see '{where} --help')")
        if getattr(args, "_run", None) is None:
            parser.print_help()
            return 2
        code = int(args._run(args) or 0)
        sys.stdout.flush()  # (a reader gone: BrokenPipeError here, not at exit)
        return code
    except PostureLabError as exc:
        print(f"posturelab: error: {exc}", file=sys.stderr)
        return 2
    except Terminated:
        raise
    except KeyboardInterrupt:
        print("posturelab: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return _quiet_broken_pipe()


def _quiet_broken_pipe() -> int:
    """The reader of standard output went away (``posturelab poles --all | head -1``): exit
    141, the shell's code for SIGPIPE, without a word; standard output is pointed at the null
    device so that flushing it at exit raises no second error."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):  # (no real file descriptor behind sys.stdout)
        pass
    return 141


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
