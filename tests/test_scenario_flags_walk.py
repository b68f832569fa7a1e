"""With --scenario (or --builtin) every simulate/sweep flag is honoured (it overrides the
scenario, as --knee does) or refused in one line: never silently ignored (the trial found
--foot none and --gastrocnemius ignored over a scenario file)."""

import argparse

import pytest

from posturelab.cli import simulate, sweep
from posturelab.errors import PostureLabError

SCENARIO = """\
name = "lab-ramp"
duration = 4.0
[body]
preset = "paper"
[muscles]
case = "1"
gastrocnemius = "one-sided"
[disturbance]
type = "ramp-and-hold"
displacement = -0.10
duration = 0.4
[knee]
mode = "stop"
[fall]
base_of_support = "literature"
"""

PROFILE = "time,x_acceleration\n0,0\n0.1,-2\n0.2,0\n1,0\n"

#: A value for every experiment flag, each unlike the scenario's ("" for a switch).
VALUES = {
    "--body": "paper-1link", "--height": "1.8", "--mass": "80", "--case": "2",
    "--stiffness": "900,300,200,100,100", "--controller": "peterka-2002",
    "--viscosity": "1,1,1,1,1", "--active-stiffness": "1,1,1,1,1",
    "--active-viscosity": "1,1,1,1,1", "--gastrocnemius": "two-sided",
    "--viscosity-ratio": "0.3", "--active-viscosity-ratio": "0.3",
    "--feedback-delay": "0.05", "--proprioceptive-weight": "0.5", "--visual-weight": "0.1",
    "--torque-feedback-gain": "0.5", "--torque-feedback-time-constant": "10",
    "--disturbance": "none", "--speed": "2", "--platform-profile": "PROFILE",
    "--initial-posture": "0.01,0,0", "--initial-rates": "0.1,0,0", "--rates-from": "posture",
    "--knee": "free", "--foot": "none", "--centre-of-pressure": "",
    "--tilt": "sine:0.01:0.5", "--visual-tilt": "sine:0.01:0.5", "--tilt-axis-depth": "0.05",
    "--motor-noise": "1", "--motor-noise-cutoff": "5", "--seed": "3",
    "--torque-limits": "100,inf,inf", "--ankle-limit-from-foot": "",
    "--max-link-angle": "0.5", "--duration": "2", "--rtol": "1e-7", "--atol": "1e-9",
    "--sample-rate": "200", "--max-steps": "1000", "--time-limit": "5",
}
#: Where paper-forward-case1 already has VALUES' value: another one.
BUILTIN_VALUES = {"--gastrocnemius": "one-sided", "--knee": "stop", "--foot": "literature"}
#: Flags that are not about the experiment, and where each command honours them.
NOT_EXPERIMENT = {
    "simulate": {"--scenario", "--builtin", "--out", "--plot", "--animate", "--json",
                 "--engine"},
    "sweep": {"--scenario", "--builtin", "--vary", "--out", "--workers", "--scheduler",
              "--chunk-size", "--strategy", "--progress", "--experiment", "--cycles",
              "--discard-cycles", "--sensor-noise", "--record-rate", "--output", "--fit"},
}


def _flags(module) -> list[str]:
    p = argparse.ArgumentParser()
    module.add_arguments(p)
    return [a.option_strings[0] for a in p._actions if a.option_strings
            and a.option_strings[0] != "-h"]


def _args(module, argv):
    p = argparse.ArgumentParser()
    module.add_arguments(p)
    extra = ["--out", "x.csv"] if module is sweep else []
    return p.parse_args([*argv, *extra])


@pytest.mark.parametrize("module", [simulate, sweep], ids=["simulate", "sweep"])
@pytest.mark.parametrize("source", ["scenario", "builtin"])
def test_every_flag_over_a_scenario_is_honoured_or_refused(tmp_path, module, source):
    command = module.__name__.rsplit(".", 1)[1]
    path = tmp_path / "s1.toml"
    path.write_text(SCENARIO, encoding="utf-8")
    (tmp_path / "profile.csv").write_text(PROFILE, encoding="utf-8")
    base_argv = (["--scenario", str(path)] if source == "scenario"
                 else ["--builtin", "paper-forward-case1"])
    flags = _flags(module)
    missing = [f for f in flags if f not in VALUES and f not in NOT_EXPERIMENT[command]]
    assert not missing, f"give these flags a value in VALUES: {missing}"
    base = simulate.scenario_from_args(_args(module, base_argv), command)
    verdicts = {}
    for flag in flags:
        if flag in NOT_EXPERIMENT[command]:
            continue
        value = (BUILTIN_VALUES.get(flag, VALUES[flag]) if source == "builtin"
                 else VALUES[flag]).replace("PROFILE", str(tmp_path / "profile.csv"))
        argv = [*base_argv, flag] + ([value] if value else [])
        args = _args(module, argv)
        try:
            got = simulate.scenario_from_args(args, command)
        except PostureLabError as exc:
            assert "\n" not in str(exc)
            verdicts[flag] = "refused"
            continue
        if command == "sweep" and flag == "--viscosity-ratio":
            verdicts[flag] = "honoured"  # (sweep passes it to run_sweep: viscosity = R k)
            assert args.viscosity_ratio == 0.3
            continue
        assert repr(got) != repr(base), f"{command} {flag} {value} is silently ignored"
        verdicts[flag] = "honoured"
    # the trial's cases, by name
    assert verdicts["--foot"] == verdicts["--knee"] == "honoured"
    if source == "scenario":
        assert verdicts["--gastrocnemius"] == "honoured"
    assert verdicts["--stiffness"] == verdicts["--body"] == "refused"
    if command == "simulate":
        assert verdicts["--viscosity-ratio"] == "refused"


def test_foot_none_over_a_scenario_removes_its_foot(tmp_path):
    path = tmp_path / "s1.toml"
    path.write_text(SCENARIO, encoding="utf-8")
    sc = simulate.scenario_from_args(_args(simulate, ["--scenario", str(path)]))
    assert sc.options.fall.base_of_support is not None
    sc = simulate.scenario_from_args(_args(simulate, ["--scenario", str(path), "--foot",
                                                      "none"]))
    assert sc.options.fall.base_of_support is None
    sc = simulate.scenario_from_args(_args(simulate, ["--scenario", str(path),
                                                      "--gastrocnemius", "two-sided"]))
    assert not any(p.one_sided for p in sc.muscles.pairs)
    sc = simulate.scenario_from_args(_args(simulate, ["--builtin", "paper-forward-case1",
                                                      "--gastrocnemius", "pull-only"]))
    gastrocnemius = sc.muscles.pairs[sc.muscles.names.index("gastrocnemius")]
    assert gastrocnemius.one_sided and gastrocnemius.pull_only
