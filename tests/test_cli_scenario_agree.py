"""The command line and a scenario file build a model in one place: the flags become the
scenario tables that the scenario parser reads, so an invocation and the equivalent file give
equal Scenarios (body, muscles, platform motion, run options), on ``simulate`` and on every
command that takes the model flags; a bad value is named as the user wrote it (the flag on
the command line, the key in a file)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import posturelab as pl
from posturelab.errors import ParameterError, ScenarioError
from posturelab.paper.printed import BACKWARD_INITIAL_STATE

FLEXED = list(BACKWARD_INITIAL_STATE[:3])


def from_command_line(*argv: str, command: str = "simulate") -> pl.Scenario:
    """The scenario of ``posturelab simulate ARGV`` (before it runs)."""
    from posturelab.cli import build_parser
    from posturelab.cli.simulate import scenario_from_args

    return scenario_from_args(build_parser(command).parse_args([command, *argv]), command)


def from_file(text: str, tmp_path) -> pl.Scenario:
    path = tmp_path / "s.toml"
    path.write_text(text, encoding="utf-8")
    return pl.load_scenario(path)


def segments_table(body) -> str:
    """A file's [body] table of ``body``'s segments (a file has no height and mass)."""
    rows = ", ".join(f'{{name = "{s.name}", mass = {s.mass!r}, length = {s.length!r}, '
                     f'com_distance = {s.com_distance!r}, inertia = {s.inertia!r}}}'
                     for s in body.segments)
    return f"[body]\nsegments = [{rows}]\n"


def lumped(height: float, mass: float) -> str:
    """The [body] table of the one-link body a controller has on --height/--mass."""
    from posturelab.model.anthropometry import body_from_anthropometry, one_link

    return segments_table(one_link(body_from_anthropometry(height, mass)))


def assert_same_experiment(a: pl.Scenario, b: pl.Scenario) -> None:
    assert (a.body.segments, a.body.gravity) == (b.body.segments, b.body.gravity)
    assert a.muscles == b.muscles
    assert a.disturbance == b.disturbance
    assert a.case == b.case
    assert a.options.replace(description="") == b.options.replace(description="")


CASES = {
    "a Table I case, a velocity step, feedback and a sine tilt": (
        ["--case", "1", "--disturbance", "backward", "--speed", "0.5", "--feedback-delay",
         "0.1", "--proprioceptive-weight", "0.7", "--tilt", "sine:0.01:0.5", "--duration",
         "2"],
        f"""duration = 2.0
[muscles]
case = "1"
feedback_delay = 0.1
proprioceptive_weight = 0.7
[disturbance]
type = "velocity-step"
direction = "backward"
speed = 0.5
[tilt]
type = "sine"
amplitude = 0.01
frequency = 0.5
[initial]
posture = {FLEXED}
"""),
    "a controller on a body from height and mass, its delay replaced, a PRTS tilt": (
        ["--controller", "peterka-2002", "--height", "1.8", "--mass", "82",
         "--feedback-delay", "0.15", "--tilt", "prts:0.035"],
        "duration = 5.0\n" + lumped(1.8, 82.0) + """[muscles]
controller = "peterka-2002"
feedback_delay = 0.15
[tilt]
type = "prts"
amplitude = 0.035
"""),
    "a named PRTS sequence at its own state duration": (
        ["--controller", "peterka-2002", "--tilt", "prts:0.03:0.2:comtest-80"],
        """duration = 5.0
[body]
preset = "paper-1link"
[muscles]
controller = "peterka-2002"
[tilt]
type = "prts"
amplitude = 0.03
state_duration = 0.2
sequence = "comtest-80"
"""),
    "one link with active gains, motor noise and a tilt about a deeper axis": (
        ["--body", "paper-1link", "--stiffness", "600", "--active-stiffness", "900",
         "--active-viscosity", "300", "--feedback-delay", "0.12", "--motor-noise", "2",
         "--motor-noise-cutoff", "5", "--seed", "3", "--tilt", "raised-cosine:0.02:1:0.5",
         "--tilt-axis-depth", "0.05"],
        """duration = 5.0
[body]
preset = "paper-1link"
[muscles]
stiffness = [600.0]
active_stiffness = [900.0]
active_viscosity = [300.0]
feedback_delay = 0.12
[motor_noise]
standard_deviation = [2.0]
cutoff = 5.0
seed = 3
[tilt]
type = "raised-cosine"
amplitude = 0.02
duration = 1.0
start = 0.5
axis_depth = 0.05
"""),
    "two links with viscosities, torque limits and a foot": (
        ["--body", "paper-2link", "--stiffness", "800,300", "--viscosity", "200,50",
         "--torque-limits", "150,inf", "--foot", "literature", "--max-link-angle", "0.8"],
        """duration = 5.0
[body]
preset = "paper-2link"
[muscles]
stiffness = [800.0, 300.0]
viscosity = [200.0, 50.0]
[limits]
torque = [150.0, "inf"]
[fall]
max_link_angle = 0.8
base_of_support = "literature"
"""),
    "a one-sided gastrocnemius, a forward step, a given state, a knee stop": (
        ["--case", "2", "--gastrocnemius", "one-sided", "--disturbance", "forward",
         "--initial-posture", "0.02,0,0", "--initial-rates", "0,0.1,0", "--knee", "stop",
         "--rates-from", "posture", "--viscosity-ratio", "0.3"],
        """duration = 5.0
[muscles]
case = "2"
gastrocnemius = "one-sided"
viscosity_ratio = 0.3
[disturbance]
type = "velocity-step"
direction = "forward"
[initial]
posture = [0.02, 0.0, 0.0]
rates = [0.0, 0.1, 0.0]
rates_from = "posture"
[knee]
mode = "stop"
"""),
}


@pytest.mark.parametrize("argv,text", CASES.values(), ids=list(CASES))
def test_an_invocation_and_its_scenario_file_build_equal_scenarios(tmp_path, argv, text):
    assert_same_experiment(from_command_line(*argv), from_file(text, tmp_path))


def test_a_measured_profile_with_a_tilt_column_is_both_tables(tmp_path):
    """--platform-profile FILE is [disturbance] and [tilt] of type profile, each of the
    columns the file has."""
    rows = ["time [s],x_acceleration [m/s²],tilt [rad]"]
    rows += [f"{0.01 * i:.2f},{0.1 * math.sin(0.3 * i):.6f},{0.001 * i:.4f}" for i in range(50)]
    (tmp_path / "p.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    cli = from_command_line("--case", "1", "--platform-profile", str(tmp_path / "p.csv"))
    text = ('duration = 5.0\n[muscles]\ncase = "1"\n[disturbance]\ntype = "profile"\n'
            'file = "p.csv"\n[tilt]\ntype = "profile"\nfile = "p.csv"\n')
    sc = from_file(text, tmp_path)
    assert (cli.body, cli.muscles) == (sc.body, sc.muscles)
    assert same_data(cli.disturbance, sc.disturbance)
    assert cli.options.tilt is not None and same_data(cli.options.tilt, sc.options.tilt)


def same_data(a, b) -> bool:
    """Equal values, dataclasses compared field by field and arrays element by element (a
    measured profile)."""
    if type(a) is not type(b):
        return False
    if isinstance(a, np.ndarray):
        return np.array_equal(a, b)
    if dataclasses.is_dataclass(a):
        return all(same_data(getattr(a, f.name), getattr(b, f.name))
                   for f in dataclasses.fields(a))
    if isinstance(a, tuple | list):
        return len(a) == len(b) and all(same_data(x, y) for x, y in zip(a, b, strict=True))
    return a == b


@pytest.mark.parametrize("command", ["poles", "delay-margin", "frf-model", "fit-frf"])
def test_every_model_command_builds_the_model_a_file_does(tmp_path, command, capsys):
    """The body, the muscles and the feedback of a command that analyses a model are those
    of the scenario file with the same tables."""
    from posturelab.cli import build_parser
    from posturelab.cli._common import model_from_args

    flags = ["--controller", "peterka-2002", "--height", "1.7", "--mass", "70",
             "--proprioceptive-weight", "0.6"]
    extra = ["--data", "x.csv", "--free", "feedback_delay"] if command == "fit-frf" else []
    model = model_from_args(build_parser(command).parse_args([command, *flags, *extra]))
    assert "one-link controller" in capsys.readouterr().err
    sc = from_file("duration = 5.0\n" + lumped(1.7, 70.0) + '[muscles]\n'
                   'controller = "peterka-2002"\nproprioceptive_weight = 0.6\n', tmp_path)
    assert (model.body.segments, model.muscles) == (sc.body.segments, sc.muscles)
    assert (model.options.feedback_delay, model.options.proprioceptive_weight) == (
        sc.options.feedback_delay, sc.options.proprioceptive_weight)


BAD = [
    (["--case", "1", "--feedback-delay", "-0.1"], "[muscles]\ncase = \"1\"\n"
     "feedback_delay = -0.1\n", "--feedback-delay [s] must be in [0, 1]",
     "muscles.feedback_delay [s] must be in [0, 1]"),
    (["--controller", "peterka-2002", "--body", "paper"],
     "[body]\npreset = \"paper\"\n[muscles]\ncontroller = \"peterka-2002\"\n",
     "--body paper has 3 links", "body.preset paper has 3 links"),
    (["--controller", "peterka-2002", "--viscosity-ratio", "0.3"],
     "[muscles]\ncontroller = \"peterka-2002\"\nviscosity_ratio = 0.3\n",
     "--viscosity-ratio cannot be given with --controller",
     "muscles.viscosity_ratio cannot be given with muscles.controller"),
    (["--body", "paper-1link", "--case", "1"],
     "[body]\npreset = \"paper-1link\"\n[muscles]\ncase = \"1\"\n",
     "--case is one of the paper's Table I sets", "muscles.case is one of the paper's"),
    (["--case", "1", "--viscosity", "1,2,3,4,5", "--viscosity-ratio", "0.3"],
     "[muscles]\ncase = \"1\"\nviscosity = [1.0, 2.0, 3.0, 4.0, 5.0]\n"
     "viscosity_ratio = 0.3\n", "give --viscosity or --viscosity-ratio, not both",
     "give muscles.viscosity or muscles.viscosity_ratio, not both"),
]


@pytest.mark.parametrize("argv,text,flag_words,key_words", BAD)
def test_a_bad_value_is_named_as_the_user_wrote_it(tmp_path, argv, text, flag_words,
                                                   key_words):
    with pytest.raises(ParameterError) as flag_error:
        from_command_line(*argv)
    assert flag_words in str(flag_error.value)
    with pytest.raises(ScenarioError) as key_error:
        from_file("duration = 1.0\n" + text, tmp_path)
    assert key_words in str(key_error.value)
    assert str(key_error.value).startswith(str(tmp_path / "s.toml"))
