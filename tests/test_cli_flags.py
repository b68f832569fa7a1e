"""The command line's one vocabulary (cli/_flags.py): a flag several subcommands take has
the same name, metavar and help text in each, and a renamed flag's former spelling still
works, named in the flag's help ("formerly …") but not listed as an option.

Checked against: the declarations of ``posturelab.cli._flags.SHARED`` (each subcommand's
help is the shared text, filled where it has a ``{}``); the former spellings
``step-threshold --direction``, ``strategy --figure`` and ``design --discard`` parse to
what the new ones do.
"""

from __future__ import annotations

import argparse

import pytest

from _cli import cli
from posturelab.cli import SUBCOMMANDS, build_parser
from posturelab.cli._flags import SHARED, add_flag


def _subparser(command: str) -> argparse.ArgumentParser:
    parser = build_parser(command)
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices[command]


def _options(command: str) -> dict[str, argparse.Action]:
    return {s: a for a in _subparser(command)._actions for s in a.option_strings}


ALL = {command: _options(command) for command in SUBCOMMANDS}


def _matches(template: str, text: str) -> bool:
    head, _, tail = template.partition("{}")
    if "{}" not in template:
        return text == template or text.startswith(template.removesuffix(".") + " (formerly ")
    tail = tail.removesuffix(".")
    return text.startswith(head) and tail in text[len(head):]


@pytest.mark.parametrize("flag", sorted(SHARED))
def test_a_shared_flag_has_one_help_and_metavar_in_every_subcommand(flag):
    spec = SHARED[flag]
    takers = {c: options[flag] for c, options in ALL.items() if flag in options}
    assert takers, f"{flag} is shared but no subcommand takes it"
    for command, action in takers.items():
        if command == "simulate" and flag == "--json":
            continue  # (simulate's --json lists the fields of its summary)
        assert _matches(spec["help"], action.help), (command, action.help)
        if "metavar" in spec and flag not in ("--plot", "--stimulus"):
            assert action.metavar == spec["metavar"], (command, action.metavar)


def test_every_json_and_progress_flag_says_the_same():
    helps = {(flag, options[flag].help) for options in ALL.values()
             for flag in ("--json", "--progress") if flag in options}
    helps.discard(("--json", ALL["simulate"]["--json"].help))
    assert helps == {("--json", SHARED["--json"]["help"]),
                     ("--progress", SHARED["--progress"]["help"])}


def _words(text: str) -> str:
    return " ".join(text.split())


def _parse(command: str, *argv: str) -> argparse.Namespace:
    return build_parser(command).parse_args([command, *argv])


@pytest.mark.parametrize("command, new, old, value, attribute", [
    ("step-threshold", "--translation", "--direction", "forward", "translation"),
    ("strategy", "--plot", "--figure", "map.png", "plot"),
    ("design", "--discard-cycles", "--discard", "3", "discard"),
])
def test_a_former_spelling_parses_as_the_new_one_and_the_help_names_it(command, new, old,
                                                                        value, attribute):
    required = {"step-threshold": ["--height", "1.7", "--mass", "70"],
                "strategy": ["--translation", "backward", "--speeds", "0.1:0.2:2"],
                "design": ["--controller", "peterka-2002", "--free", "feedback_delay"]}
    by_new = _parse(command, *required[command], new, value)
    by_old = _parse(command, *required[command], old, value)
    assert getattr(by_new, attribute) == getattr(by_old, attribute)
    assert str(getattr(by_old, attribute)) == value
    action = ALL[command][new]
    assert action.option_strings[:2] == [new, old]
    assert f"(formerly {old})" in action.help
    shown = _words(cli(command, "--help").stdout)
    assert f"{new} " in shown and f"{old} " not in shown  # (listed under its one name)


def test_add_flag_wants_the_detail_its_help_leaves_open():
    p = argparse.ArgumentParser()
    with pytest.raises(TypeError, match="--plot: detail needed"):
        add_flag(p, "--plot")
    with pytest.raises(TypeError, match="--json: detail not taken"):
        add_flag(p, "--json", "more")


@pytest.mark.parametrize("command", ["cohort", "fit-frf", "likeness-reference"])
def test_data_takes_several_files_either_way(command):
    """--data A B and --data A --data B give the same files, in order (likeness-reference
    once kept only the last --data)."""
    parser = _subparser(command)
    required = {"cohort": ["--out", "o.csv", "--free", "feedback_delay"],
                "likeness-reference": ["--out", "r.json"],
                "fit-frf": ["--free", "feedback_delay"]}[command]
    one, _ = parser.parse_known_args(["--data", "a.json", "b.json", *required])
    two, _ = parser.parse_known_args(["--data", "a.json", "--data", "b.json", *required])
    assert one.data == two.data == ["a.json", "b.json"]
