"""The one vocabulary of parameters (posturelab.parameters): its names are accepted by every
command, a former spelling gets one line naming the new one (exit 2), the table's bounds are
enforced where a value enters (sweep --vary included), and the feedback delay has one bound,
the same at every entry point. CLI cases run as real subprocesses."""

from __future__ import annotations

import csv
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

import posturelab as pl
from _cli import cli, one_line_exit_2
from posturelab import parameters
from posturelab.errors import ParameterError, UnknownNameError, UnknownParameterError
from posturelab.parameters import (
    MAX_FEEDBACK_DELAY,
    QUANTITIES,
    check_value,
    parse_name,
    renamed,
    resolve,
)

ROOT = Path(__file__).resolve().parents[1]
#: Just past the delay bound. [s]
TOO_LONG = 1.0001



# ---- the table -----------------------------------------------------------------------


def test_docs_page_holds_the_table():
    """docs/parameters.md ends with the table the module writes (names, units, bounds)."""
    page = (ROOT / "docs" / "parameters.md").read_text(encoding="utf-8")
    assert page.endswith(parameters.markdown_table())


def test_the_table_states_each_quantity_once_with_unit_bounds_and_meaning():
    assert list(QUANTITIES) == ["stiffness", "viscosity", "active_stiffness",
                                "active_viscosity", "viscosity_ratio",
                                "active_viscosity_ratio", "feedback_delay",
                                "proprioceptive_weight", "visual_weight",
                                "torque_feedback_gain",
                                "torque_feedback_time_constant", "joint_feedback_scale",
                                "torque_limit",
                                "disturbance_scale",
                                "height", "mass", "step_speed", "tilt_amplitude"]
    for q in QUANTITIES.values():
        assert q.unit and q.meaning and q.low <= q.high
        assert math.isnan(q.fit_high) or q.low < q.fit_high <= q.high
    assert QUANTITIES["feedback_delay"].high == MAX_FEEDBACK_DELAY == 1.0
    assert {q.per for q in QUANTITIES.values()} == {"pair", "joint", ""}


@pytest.mark.parametrize("text, parsed", [
    ("active_stiffness:ankle", ("active_stiffness", "ankle")),
    ("stiffness:hip", ("stiffness", "hip")),
    ("torque_limit:knee", ("torque_limit", "knee")),
    ("feedback_delay", ("feedback_delay", None)),
    (" Viscosity:Gastrocnemius ", ("viscosity", "gastrocnemius")),
])
def test_parse_name(text, parsed):
    assert parse_name(text) == parsed


@pytest.mark.parametrize("text, error, words", [
    ("feedback_delay:ankle", ParameterError, "feedback_delay takes no :PAIR"),
    ("elbow", UnknownNameError, "unknown parameter 'elbow'; known: stiffness:PAIR"),
    ("stiffness:ankle:hip", ParameterError, "QUANTITY or QUANTITY:PAIR"),
])
def test_parse_name_refuses(text, error, words):
    with pytest.raises(error, match=re.escape(words)):
        parse_name(text)


def test_resolve_gives_one_spelling():
    assert resolve("stiffness:hip") == "stiffness:hip"
    assert resolve("torque_limit:ankle") == "torque_limit:ankle"
    # a one-pair body: the pair may be left out, and is then named
    assert resolve("active_stiffness", ("ankle",), ("ankle",)) == "active_stiffness:ankle"
    with pytest.raises(ParameterError, match="needs its pair: stiffness:ankle, stiffness:knee"):
        resolve("stiffness")
    with pytest.raises(UnknownParameterError, match="unknown pair 'knee'.*pairs: ankle, hip"):
        resolve("stiffness:knee", ("ankle", "hip"), ("ankle", "hip"))
    with pytest.raises(ParameterError, match="cannot be 'torque_limit:ankle'; it takes"):
        resolve("torque_limit:ankle", accepts=("stiffness",))


@pytest.mark.parametrize("old, new", [
    ("ankle", "stiffness:ankle"),
    ("gastrocnemius", "stiffness:gastrocnemius"),
    ("active_ankle", "active_stiffness:ankle"),
    ("active_viscosity_hip", "active_viscosity:hip"),
    ("knee_torque_limit", "torque_limit:knee"),
    ("stiffness_quadriceps", "stiffness:quadriceps"),
])
def test_former_spellings_name_the_new(old, new):
    assert renamed(old) == new
    with pytest.raises(ParameterError, match=f"'{old}' is now called '{new}'$"):
        resolve(old)


def test_names_that_are_no_former_spelling():
    for name in ("viscosity_ratio", "active_viscosity_ratio", "feedback_delay", "elbow"):
        assert renamed(name) is None


@pytest.mark.parametrize("name, value, words", [
    ("feedback_delay", TOO_LONG, "feedback_delay [s] must be in [0, 1], got 1.0001"),
    ("active_stiffness:ankle", 1e9, "active_stiffness:ankle [N·m/rad] must be in [0, 1e+08]"),
    ("torque_limit:hip", 0.0, "torque_limit:hip [N·m] must be in (0, inf], got 0.0"),
    ("proprioceptive_weight", float("nan"), "must be in [0, 1], got nan"),
    ("viscosity_ratio", "abc", "viscosity_ratio [s] must be a number in [0, 10], got 'abc'"),
    ("disturbance_scale", True, "must be a number in [0, 100], got True (bool)"),
])
def test_check_value_is_one_line_naming_field_value_and_range(name, value, words):
    with pytest.raises(ParameterError) as info:
        check_value(name, value)
    assert words in str(info.value) and "\n" not in str(info.value)


def test_check_value_accepts_the_ends():
    assert check_value("feedback_delay", 1.0) == 1.0
    assert check_value("torque_limit:ankle", math.inf) == math.inf
    assert check_value("stiffness:ankle", 0) == 0.0


# ---- every command takes the table's names -------------------------------------------


@pytest.mark.parametrize("leave_out", ["viscosity_ratio", "viscosity:"])
def test_sweep_takes_every_name_it_can_vary(tmp_path, leave_out):
    """One run (N = 1 each) varying every sweep name of the paper's body (but the viscosity
    ratio and the pair viscosities together, which a sweep refuses: one or the other); the
    columns are the names, in the order given."""
    from posturelab.studies.sweep import SWEEP_PARAMETERS

    value = {"feedback_delay": 0.0, "proprioceptive_weight": 1.0, "viscosity_ratio": 0.25,
             "disturbance_scale": 1.0}
    # (joint_feedback_scale needs a joint controller, which case 1 has not:
    # tests/test_multijoint.py sweeps it)
    names = [n for n in SWEEP_PARAMETERS
             if not n.startswith(leave_out) and n != "joint_feedback_scale"]
    varies = []
    for name in names:
        v = value.get(name, 500.0 if name.startswith(("stiffness", "torque")) else 0.0)
        varies += ["--vary", f"{name}={v}:{v}:1"]
    out = tmp_path / "all.csv"
    p = cli("sweep", "--case", "1", "--disturbance", "backward", "--duration", "0.2",
            "--visual-tilt", "sine:0.01:0.5",  # (visual_weight weighs a scene tilt)
            *varies, "--out", str(out))
    assert p.returncode == 0, p.stderr
    header = next(csv.reader(out.open()))
    assert header[:len(names)] == names
    assert "stiffness:ankle" in header and "torque_limit:hip" in header


def test_fit_takes_the_table_names(tmp_path):
    data = tmp_path / "run.csv"
    sc = pl.builtin_scenario("paper-backward-case1").replace(duration=0.4, sample_rate=50)
    run = sc.run()
    with data.open("w") as f:
        f.write("t,theta1,theta2,theta3\n")
        for t, th in zip(run.time, run.theta, strict=True):
            f.write(",".join(repr(float(v)) for v in (t, *th)) + "\n")
    p = cli("fit", "--data", str(data), "--case", "1", "--disturbance", "backward", "--free",
            "stiffness:ankle,viscosity:hip,active_stiffness:knee,active_viscosity:ankle,"
            "viscosity_ratio,feedback_delay,proprioceptive_weight", "--json")
    assert p.returncode == 0, p.stderr
    names = list(json.loads(p.stdout)["parameters"])
    assert names == ["stiffness:ankle", "viscosity:hip", "active_stiffness:knee",
                     "active_viscosity:ankle", "viscosity_ratio", "feedback_delay",
                     "proprioceptive_weight"]
    one_line_exit_2(cli("fit", "--data", str(data), "--case", "1", "--free", "active_ankle"),
                    "'active_ankle' is now called 'active_stiffness:ankle'")
    one_line_exit_2(cli("fit", "--data", str(data), "--case", "1", "--free",
                        "torque_limit:ankle"), "cannot be 'torque_limit:ankle'")


@pytest.fixture(scope="module")
def frf_json(tmp_path_factory):
    """The peterka-2002 preset's model FRF at six frequencies, as posturelab frf --json
    writes an estimate (no bounds)."""
    from posturelab.frequency.model import model_frf
    from posturelab.model.controllers import get_controller

    preset = get_controller("peterka-2002")
    body = pl.get_body("paper-1link")
    f = np.array([0.05, 0.1, 0.2, 0.4, 0.8, 1.6])
    h = model_frf(body, preset.muscles(body), f, **preset.run_options())
    path = tmp_path_factory.mktemp("frf") / "frf.json"
    path.write_text(json.dumps({"frequency": f.tolist(),
                                "frf": [{"re": z.real, "im": z.imag} for z in h],
                                "coherence": [1.0] * f.size,
                                "gain_ci95": [[None, None]] * f.size}))
    return path


def test_fit_frf_takes_the_table_names(frf_json):
    p = cli("fit-frf", "--data", str(frf_json), "--controller", "peterka-2002", "--free",
            "stiffness:ankle,viscosity:ankle,active_stiffness,active_viscosity:ankle",
            "--per-condition", "feedback_delay,proprioceptive_weight",
            "--bounds", "feedback_delay=0:0.5,stiffness:ankle=0:5000", "--json")
    assert p.returncode == 0, p.stderr
    names = [q["name"] for q in json.loads(p.stdout)["parameters"]]
    assert names == ["stiffness:ankle", "viscosity:ankle", "active_stiffness:ankle",
                     "active_viscosity:ankle", "feedback_delay#1", "proprioceptive_weight#1"]


@pytest.mark.parametrize("args, words", [
    (["--free", "active_ankle"], "'active_ankle' is now called 'active_stiffness:ankle'"),
    (["--free", "feedback_delay", "--per-condition", "ankle"],
     "'ankle' is now called 'stiffness:ankle'"),
    (["--free", "feedback_delay", "--bounds", "feedback_delay=0:1.0001"],
     "bound feedback_delay HI [s] must be in [0, 1], got 1.0001"),
    (["--free", "feedback_delay", "--bounds", "feedback_dely=0:0.5"],
     "unknown FRF fit parameter 'feedback_dely'"),
    (["--free", "torque_limit:ankle"], "cannot be 'torque_limit:ankle'"),
    (["--free", "active_stiffness,active_stiffness:ankle"],
     "'active_stiffness:ankle' is named twice"),
])
def test_fit_frf_refuses_in_one_line(frf_json, args, words):
    one_line_exit_2(cli("fit-frf", "--data", str(frf_json), "--controller", "peterka-2002",
                        *args), words)


def test_stability_map_takes_the_table_names(tmp_path):
    p = cli("stability-map", "--x", "stiffness:knee:0:800", "--y", "viscosity_ratio:0.1:1",
            "--resolution", "2", "--out", str(tmp_path / "m.png"))
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "m.csv").read_text().startswith("stiffness:knee,viscosity_ratio,")
    p = cli("stability-map", "--x", "active_stiffness:hip:0:800",
            "--y", "active_viscosity:hip:0:300", "--feedback-delay", "0.1", "--resolution", "2",
            "--out", str(tmp_path / "d.png"))
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "d.csv").read_text().startswith("active_stiffness:hip,"
                                                       "active_viscosity:hip,")
    one_line_exit_2(cli("stability-map", "--x", "ankle:0:1", "--y", "stiffness:hip:0:1",
                        "--out", str(tmp_path / "x.png")),
                    "'ankle' is now called 'stiffness:ankle'")


@pytest.mark.parametrize("vary, words", [
    ("active_ankle=0:1:2", "sweep parameter 'active_ankle' is now called "
                           "'active_stiffness:ankle'"),
    ("ankle=0:1:2", "sweep parameter 'ankle' is now called 'stiffness:ankle'"),
    ("hip_torque_limit=10:20:2", "'hip_torque_limit' is now called 'torque_limit:hip'"),
    ("active_viscosity_knee=0:1:2", "is now called 'active_viscosity:knee'"),
    # the table's bounds: a row beyond them is never simulated
    ("active_stiffness:ankle=0:1e9:3", "active_stiffness:ankle HI [N·m/rad] must be in "
                                       "[0, 1e+08], got 1000000000.0"),
    ("feedback_delay=0:1.0001:2", "feedback_delay HI [s] must be in [0, 1], got 1.0001"),
    ("proprioceptive_weight=0:1.5:2", "proprioceptive_weight HI [-] must be in [0, 1]"),
    ("torque_limit:ankle=0:50:2", "torque_limit:ankle LO [N·m] must be in (0, inf]"),
    ("disturbance_scale=0:1000:2", "disturbance_scale HI [-] must be in [0, 100]"),
    ("viscosity:hip=0:2e7:2", "viscosity:hip HI [N·m·s/rad] must be in [0, 1e+07]"),
    ("stiffness=0:10:2", "'stiffness' needs its pair: stiffness:ankle"),
    ("active_viscosity_ratio=0:1:2", "a sweep cannot vary 'active_viscosity_ratio'"),
])
def test_sweep_vary_refuses_in_one_line_and_writes_nothing(tmp_path, vary, words):
    out = tmp_path / "x.csv"
    one_line_exit_2(cli("sweep", "--case", "1", "--disturbance", "backward", "--vary", vary,
                        "--out", str(out)), words)
    assert not out.exists()


def test_prts_sweep_fit_names_are_the_table_s(tmp_path):
    """sweep --experiment prts --fit: the table's names, columns fit_NAME; a former spelling
    is refused before any experiment runs."""
    base = ["sweep", "--experiment", "prts", "--controller", "peterka-2002", "--tilt",
            "prts:0.035", "--vary", "feedback_delay=0.15:0.15:1", "--out",
            str(tmp_path / "p.csv")]
    one_line_exit_2(cli(*base, "--fit", "active_ankle"),
                    "'active_ankle' is now called 'active_stiffness:ankle'")
    assert not (tmp_path / "p.csv").exists()


def test_explorer_names_and_bounds_are_the_table_s():
    from posturelab.explore.views import CONTROLS, parse_parameters

    by_name = {c.name: c for c in CONTROLS}
    for name, c in by_name.items():
        if ":" in name or name in QUANTITIES:
            q = QUANTITIES[name.partition(":")[0]]
            # the explorer's step starts at 0.01 m/s (a step of 0 is no experiment)
            low = 0.01 if name == "step_speed" else q.low
            assert (c.unit, c.low, c.high) == (q.unit, low, q.high), name
    assert {"stiffness:ankle", "active_stiffness:hip", "active_viscosity:knee",
            "feedback_delay"} <= set(by_name)
    with pytest.raises(ParameterError, match="control 'active_ankle' is now called "
                                             "'active_stiffness:ankle'"):
        parse_parameters({"active_ankle": 100})


def test_scenario_muscle_keys_are_table_quantities():
    """A scenario file's [muscles] keys that carry values are the table's quantities (the
    names of a case, the pairs, the gastrocnemius' form and a controller preset aside)."""
    import msgspec

    from posturelab.scenarios.schema import MusclesTable

    keys = {f.name for f in msgspec.structs.fields(MusclesTable)} - {
        "case", "pairs", "gastrocnemius", "controller"}
    assert keys <= set(QUANTITIES), keys - set(QUANTITIES)


# ---- the delay bound: one, everywhere ------------------------------------------------


def _entry_points(tmp_path):
    """Every way a feedback delay enters, each given ``TOO_LONG``."""
    from posturelab.explore.views import parse_parameters
    from posturelab.frequency.fit import fit_frf
    from posturelab.frequency.model import model_frf, model_frf_batch
    from posturelab.linear.delay import rightmost_roots
    from posturelab.linear.delay_batch import delay_stability_map
    from posturelab.linear.verdict import upright_verdict
    from posturelab.simulation.compiled import simulate_batch
    from posturelab.studies.sweep import VaryRange

    body, m = pl.paper_body(), pl.paper_muscles("1")
    one, m1 = pl.get_body("paper-1link"), pl.model.muscles.muscles_for(1, [900.0], [300.0])
    toml = tmp_path / "s.toml"
    toml.write_text(f'duration = 1.0\n[muscles]\ncase = "1"\nfeedback_delay = {TOO_LONG}\n')
    return {
        "simulate": lambda: pl.simulate(body, m, None, 0.1, feedback_delay=TOO_LONG),
        "simulate_batch": lambda: simulate_batch(body, [m.stiffnesses], [m.viscosities], None,
                                                 0.1, feedback_delay=TOO_LONG),
        "model_frf": lambda: model_frf(one, m1, [0.1], feedback_delay=TOO_LONG),
        "model_frf_batch": lambda: model_frf_batch(one, m1, [0.1], m1.stiffnesses[None],
                                                   m1.viscosities[None],
                                                   feedback_delay=TOO_LONG),
        "rightmost_roots": lambda: rightmost_roots(body, m, TOO_LONG),
        "upright_verdict": lambda: upright_verdict(body, m, TOO_LONG),
        "delay_stability_map": lambda: delay_stability_map(one, m1, TOO_LONG, (0, 1), (0, 1),
                                                           2),
        "scenario": lambda: pl.load_scenario(toml),
        "sweep --vary": lambda: VaryRange("feedback_delay", 0.0, TOO_LONG, 2),
        "fit-frf bounds": lambda: fit_frf(one, m1, [], ["feedback_delay"],
                                          bounds={"feedback_delay": (0.0, TOO_LONG)}),
        "explorer": lambda: parse_parameters({"feedback_delay": TOO_LONG}),
    }


def test_every_entry_point_refuses_a_delay_past_the_one_bound(tmp_path):
    for where, call in _entry_points(tmp_path).items():
        with pytest.raises(pl.PostureLabError) as info:
            call()
        text = str(info.value)
        assert "[0, 1]" in text and "1.0001" in text, (where, text)


def test_the_command_line_refuses_a_delay_past_the_bound():
    one_line_exit_2(cli("poles", "--case", "1", "--feedback-delay", str(TOO_LONG)),
                    "--feedback-delay [s] must be in [0, 1], got 1.0001")


def test_no_other_module_states_a_delay_bound():
    """The bound is written once: every module's constant is the table's, and no source
    line compares a delay with a number of its own (these patterns find the eight places
    that stated it before the table: 1 s in six, 10 s in two)."""
    from posturelab.linear import delay
    from posturelab.simulation import setup

    assert setup.MAX_FEEDBACK_DELAY is parameters.MAX_FEEDBACK_DELAY
    assert delay.MAX_DELAY_FOR_ROOTS is parameters.MAX_FEEDBACK_DELAY
    literal = re.compile(r"(delay\w*\s*(<=?|>=?)\s*(0*[1-9]|0\.0*[1-9]))"
                         r"|(delay.*\b0(\.0)?, (1|10)(\.0)?\b[,)])|(delay.*, (1|10)(\.0)?\))"
                         r"|(MAX_\w*?DELAY(_FOR_ROOTS)?\s*=\s*\d)|(delay\w*=\s*(1|10)(\.0)?\b)")
    found = []
    for path in (ROOT / "src" / "posturelab").rglob("*.py"):
        if path.name == "parameters.py":
            continue
        text = path.read_text(encoding="utf-8")
        prose = _multiline_string_lines(text)  # docstrings and help texts say the bound
        for k, line in enumerate(text.splitlines(), 1):
            if k not in prose and literal.search(line.split("#")[0]):
                found.append(f"{path.relative_to(ROOT)}:{k}: {line.strip()}")
    assert not found, found


def _multiline_string_lines(text: str) -> set[int]:
    """Line numbers covered by string tokens that span several lines."""
    import io
    import tokenize

    lines: set[int] = set()
    for tok in tokenize.generate_tokens(io.StringIO(text).readline):
        if tok.type == tokenize.STRING and tok.end[0] > tok.start[0]:
            lines.update(range(tok.start[0], tok.end[0] + 1))
    return lines
