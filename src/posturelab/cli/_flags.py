"""The command line's one vocabulary: every flag that several subcommands take, declared once.

A concept has one flag, one metavar and one help text in every subcommand that takes it
(:data:`SHARED`, added by :func:`add_flag`); where a subcommand says something of its own
about it (what ``--plot`` draws, what ``--seed`` seeds), the shared help has one ``{}`` that
the subcommand fills. A former spelling stays accepted as an alias listed after the flag;
the flag's help names it, the option list shows the flag alone (:class:`HelpFormatter`). A
run of a subcommand's own flags that differ only in name, metavar and help is declared as a
table (:func:`add_options`). Nothing here imports more than argparse: ``--help`` stays
instant.
"""

from __future__ import annotations

import argparse

#: The flags several subcommands share: flag -> the keywords of ``add_argument``. A help
#: with ``{}`` takes the subcommand's own words (``detail``).
SHARED: dict[str, dict] = {
    "--json": dict(action="store_true", help="print one JSON object instead of text."),
    "--plot": dict(metavar="FIG.png", help="write {} (PNG, SVG or PDF, by the suffix)."),
    "--progress": dict(action="store_true", help="draw a progress bar on standard error "
                       "even when it is not a terminal."),
    "--seed": dict(type=int, default=0, metavar="N", help="seed of {} (default 0)."),
    "--engine": dict(choices=("compiled", "reference"), default="compiled",
                     help="compiled (default): the C engine, hundreds of times faster (Radau, "
                     "or RK45 with a feedback delay); reference: the numpy model integrated "
                     "by scipy (DOP853), the independent check{}."),
    "--translation": dict(choices=("backward", "forward"),
                          help="direction of the platform translation: backward (the platform "
                          "moves back, the body sways forward) or forward{}."),
    "--ankle-limit-from-foot": dict(action="store_true", help="limit the ankle to what the "
                                    "foot can carry: plantarflexion m g x_toe, dorsiflexion "
                                    "m g |x_heel| {}."),
    "--tilt": dict(metavar="SPEC", help="support-surface tilt α, positive toes-up, about the "
                   "ankle: {}"),
    "--visual-tilt": dict(metavar="SPEC", help="visual-scene tilt v about the ankle axis, "
                          "positive toes-up like the surface (the specs of --tilt; e.g. "
                          "prts:0.035::comtest-80): it acts only through the active feedback, "
                          "weighted by --visual-weight{}."),
    "--motor-noise": dict(metavar="SIGMA[,SIGMA...]", help="motor noise: a seeded random "
                          "torque added to each joint's net moment, standard deviation per "
                          "joint [N·m], ankle first (one value: the ankle only)."),
    "--motor-noise-cutoff": dict(type=float, default=None, metavar="HZ", help="low-pass the "
                                 "motor noise at HZ (first order; default: white at 100 Hz "
                                 "samples)."),
    "--sensor-noise": dict(type=float, default=None, metavar="RAD", help="standard deviation "
                           "of the white measurement noise on the recorded angle [rad] "
                           "(default 0)."),
    "--sample-rate": dict(type=float, default=None, metavar="HZ",
                          help="samples per second of the output, the recorded time series "
                          "[Hz] (default {})."),
    "--cycles": dict(type=int, default=None, metavar="N", help="stimulus cycles analysed "
                     "(default 5)."),
    "--discard-cycles": dict(type=int, default=0, metavar="N", help="leading stimulus cycles "
                             "dropped, the transient (default {})."),
    "--cycle-length": dict(type=float, default=None, metavar="SECONDS",
                           help="stimulus cycle [s]{}."),
    "--stimulus": dict(metavar="COLUMN", help="stimulus column of a trial{}."),
    "--response": dict(metavar="COLUMN", help="response column of a trial (default "
                       "com_angle)."),
    "--response-sign": dict(choices=("-1", "+1", "1"), default="-1", help="multiply a "
                            "trial's response by this (default -1: posturelab's tilt "
                            "convention{})."),
    "--output": dict(default="com_angle", metavar="NAME", help="the model output the "
                     "response is: com_angle (default){}."),
}

#: ``--data`` of the commands that read several files: ``--data A B`` and ``--data A
#: --data B`` alike (argparse's extend). The declaration to add with
#: :func:`add_data_files`; it joins :data:`SHARED` once every such command takes it.
DATA_FILES = dict(action="extend", nargs="+", required=True, metavar="FILE",
                  help="{} (several after one --data, or --data repeated).")


def add_data_files(p: Parser, detail: str, **changes) -> argparse.Action:
    """Add ``--data`` (:data:`DATA_FILES`) with the subcommand's words for its files
    (``detail``); ``changes`` replace keywords other than the help."""
    spec = {**DATA_FILES, **changes}
    spec["help"] = DATA_FILES["help"].format(detail)
    return p.add_argument("--data", **spec)


#: The outputs of a model FRF (``--output``'s detail where the linear model is evaluated).
MODEL_OUTPUTS = ", thetaN or a joint angle (ankle_angle, knee_angle, hip_angle)"


#: A parser or an argument group (each has ``add_argument``).
Parser = argparse._ActionsContainer


def add_flag(p: Parser, flag: str, detail: str | None = None, *, former: tuple[str, ...] = (),
             **changes) -> argparse.Action:
    """Add the shared ``flag`` (:data:`SHARED`) to the parser or group ``p``.

    ``detail`` fills the help's ``{}`` (the subcommand's own words); ``former``, spellings
    the flag had before, stay accepted as aliases (the help says "formerly …"); ``changes``
    replace keywords of the declaration (a default, ``required``, a ``dest``) but never
    its help.
    """
    if "help" in changes:
        raise TypeError(f"{flag}: its help is the shared one (give a detail)")
    spec = dict(SHARED[flag])
    template = spec.pop("help")
    if ("{}" in template) != (detail is not None):
        raise TypeError(f"{flag}: detail {'needed' if detail is None else 'not taken'}")
    text = template.format(detail) if detail is not None else template
    if former:
        text = text.removesuffix(".") + f" (formerly {', '.join(former)})."
    action = p.add_argument(flag, *former, **{**spec, **changes, "help": text})
    action.former = former  # (listed by HelpFormatter under the flag's help only)
    return action


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """The subcommands' help: the description as written, and each flag under its one
    name (a former spelling, still accepted, is named in the flag's help only)."""

    def _format_action_invocation(self, action: argparse.Action) -> str:
        former = getattr(action, "former", ())
        if not former:
            return super()._format_action_invocation(action)
        import copy

        shown = copy.copy(action)
        shown.option_strings = [s for s in action.option_strings if s not in former]
        return super()._format_action_invocation(shown)


def add_flags(p: Parser, *flags: str) -> None:
    """Add each shared flag of ``flags`` whose help has nothing of the subcommand's own."""
    for flag in flags:
        add_flag(p, flag)


def add_options(p: Parser, table: dict[str, str | tuple[str, str]], **common) -> None:
    """Add a subcommand's own flags from ``table``, flag -> help or (metavar, help), each
    with the ``add_argument`` keywords ``common`` (``action="store_true"``,
    ``type=float``, …)."""
    for flag, entry in table.items():
        metavar, text = (None, entry) if isinstance(entry, str) else entry
        p.add_argument(flag, **common, **({"metavar": metavar} if metavar else {}), help=text)
