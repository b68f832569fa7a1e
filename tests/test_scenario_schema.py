"""The declared types of a scenario file (posturelab.scenarios.schema): type confusion is
refused with the key named, and the published JSON Schema is the one the code declares."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from posturelab.errors import ScenarioError
from posturelab.scenarios import parse_scenario
from posturelab.scenarios.schema import json_schema

SCHEMA = Path(__file__).resolve().parents[1] / "docs" / "scenario.schema.json"


@pytest.mark.parametrize("data, words", [
    ({"duration": True}, "duration must be a number, got a boolean"),
    ({"duration": 1.0, "muscles": {"stiffness": [True, 1, 1, 1, 1]}},
     "muscles.stiffness[0] must be a number, got a boolean"),
    ({"duration": 1.0, "fall": {"centre_of_pressure": "no"}},
     "fall.centre_of_pressure must be true or false, got a string"),
    ({"duration": 1.0, "muscles": {"stiffness": 5}},
     "muscles.stiffness must be an array, got an integer"),
    ({"duration": 1.0, "initial": {"posture": 0.1}},
     "initial.posture must be an array, got a number"),
    ({"duration": 1.0, "muscles": {"pairs": [{"lo": 0, "hi": 1.5, "stiffness": 1.0}]}},
     "muscles.pairs[0].hi must be an integer, got a number"),
    ({"duration": 1.0, "knee": {"mode": "bent"}},
     "knee.mode must be one of free, locked, stop; got 'bent'"),
    ({"duration": 1.0, "bogus": 1}, "unknown key 'bogus' in the top level"),
    ({"duration": 1.0, "body": {"segments": [{"mass": 1.0}]}},
     "[body.segments[0]] lacks the required key 'length'"),
])
def test_type_confusion_is_refused_naming_the_key(data, words):
    with pytest.raises(ScenarioError) as info:
        parse_scenario(data, origin="s.toml")
    assert str(info.value) == f"s.toml: {words}"


def test_a_boolean_duration_on_the_command_line_is_one_line(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text("duration = true\n[muscles]\ncase = '1'\n")
    p = subprocess.run([sys.executable, "-m", "posturelab", "simulate", "--scenario", str(path)],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and p.stderr.strip().count("\n") == 0
    assert "duration must be a number, got a boolean" in p.stderr


def test_the_published_schema_is_the_declared_one():
    assert json.loads(SCHEMA.read_text(encoding="utf-8")) == json_schema(), (
        "regenerate docs/scenario.schema.json from posturelab.scenarios.schema.json_schema()")


def test_every_builtin_scenario_fits_the_schema():
    import tomllib
    from importlib import resources

    files = [f for f in resources.files("posturelab.scenarios.builtin").iterdir()
             if f.name.endswith(".toml")]
    assert files
    for f in files:
        parse_scenario(tomllib.loads(f.read_text(encoding="utf-8")), origin=f.name)
