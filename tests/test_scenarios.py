"""Scenario files: schema, unknown keys, built-ins."""

import numpy as np
import pytest

from posturelab.errors import ScenarioError, UnknownNameError
from posturelab.model.platform import MeasuredProfile, VelocityStep
from posturelab.scenarios import builtin_scenario, builtin_scenario_names, load_scenario

MINIMAL = """
duration = 2.0
[muscles]
case = "1"
[disturbance]
type = "velocity-step"
direction = "backward"
speed = 0.5
"""


def write(tmp_path, text, name="s.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_builtin_scenarios_cover_the_papers_figures():
    names = builtin_scenario_names()
    for n in ("paper-backward-case1", "paper-forward-case1", "paper-forward-case2",
              "paper-forward-case3"):
        assert n in names
    sc = builtin_scenario("paper-backward-case1")
    assert sc.case == "1" and sc.duration == 5.0
    assert isinstance(sc.disturbance, VelocityStep) and sc.disturbance.velocity == -1.0
    np.testing.assert_allclose(sc.initial_state, [0.1, -0.1, 0.1, 0, 0, 0])
    fwd = builtin_scenario("paper-forward-case1")
    assert fwd.disturbance.velocity == 1.0


def test_unknown_builtin_lists_known():
    with pytest.raises(UnknownNameError, match="paper-backward-case1"):
        builtin_scenario("nope")


def test_minimal_scenario_runs(tmp_path):
    sc = load_scenario(write(tmp_path, MINIMAL))
    r = sc.run(sample_rate=100)
    assert r.status == "completed"
    assert r.theta[5, 0] > 0  # backward platform: forward sway


def test_full_scenario(tmp_path):
    (tmp_path / "prof.csv").write_text("time,x_acceleration\n0,0\n0.1,-2\n0.2,0\n")
    text = """
name = "custom"
duration = 1.0
[body]
segments = [
  {name = "leg", mass = 5, length = 0.4, com_distance = 0.2, inertia = 0.2},
  {name = "trunk", mass = 50, length = 0.8, com_distance = 0.4, inertia = 3.0},
]
[muscles]
pairs = [
  {name = "ankle", lo = 0, hi = 1, stiffness = 900},
  {name = "hip", lo = 1, hi = 2, stiffness = 300, viscosity = 40},
]
[[disturbance]]
type = "profile"
file = "prof.csv"
[[disturbance]]
type = "half-sine"
peak_acceleration = 0.5
duration = 0.2
axis = "y"
[knee]
mode = "free"
[fall]
base_of_support = {heel = -0.05, toe = 0.2}
[solver]
rtol = 1e-7
sample_rate = 200
"""
    sc = load_scenario(write(tmp_path, text))
    assert sc.body.n_links == 2
    assert sc.muscles.viscosities[0] == pytest.approx(225.0)  # default ratio 0.25
    assert sc.fall.base_of_support.toe == 0.2
    assert any(isinstance(p, MeasuredProfile) for p in sc.disturbance.parts)
    assert sc.run().time.size > 1


@pytest.mark.parametrize("text,needle", [
    (MINIMAL + "colour = 'red'\n", "unknown key 'colour'"),
    (MINIMAL.replace("speed = 0.5", "speed = 0.5\nspeeed = 1"), "unknown key 'speeed'"),
    (MINIMAL + "[fall]\nmax_angle = 1\n", "unknown key 'max_angle'"),
    ("duration = 1\n[muscles]\ncase = '1'\n[body]\npreset = 'paper'\nheight = 2\n",
     "unknown key 'height'"),
    ("[muscles]\ncase = '1'\n", "duration"),
    ("duration = -1\n[muscles]\ncase = '1'\n", "duration"),
    ("duration = 1\n[muscles]\ncase = '12'\n", "known cases"),
    ("duration = 1\n[muscles]\ncase = '1'\n[body]\npreset = 'giant'\n", "known presets"),
    ("duration = 1\n[muscles]\ncase = '1'\n[disturbance]\ntype = 'earthquake'\n",
     "disturbance.type"),
    ("duration = 1 [\n", "not valid TOML"),
    ("duration = 1\n[muscles]\ncase = '1'\nstiffness = [1,2,3,4,5]\n", "exactly one"),
])
def test_bad_scenarios(tmp_path, text, needle):
    with pytest.raises(ScenarioError, match=needle):
        load_scenario(write(tmp_path, text))


def test_unknown_replace_field():
    from posturelab.errors import ParameterError

    with pytest.raises(ParameterError, match="durration"):
        builtin_scenario("paper-forward-case1").replace(durration=2)


def test_scenario_run_on_either_engine():
    """Scenario.run() is the compiled simulator (by default; "fast" is its former name) at the
    scenario's tolerances; it agrees with the reference run to 1e-6 rad; an unknown engine is
    refused."""
    import numpy as np

    from posturelab.errors import ParameterError
    from posturelab.scenarios import builtin_scenario

    sc = builtin_scenario("paper-forward-case2")
    ref, fast = sc.run(engine="reference"), sc.run()
    np.testing.assert_array_equal(sc.run(engine="fast").theta, fast.theta)
    assert fast.fell == ref.fell and abs(fast.fall_time - ref.fall_time) < 1e-6
    np.testing.assert_allclose(fast.theta, ref.theta, rtol=0, atol=1e-6)
    with pytest.raises(ParameterError, match="engine"):
        sc.run(engine="turbo")


def test_scenario_method_is_honoured_or_refused_on_the_compiled_engine():
    """solver.method reaches the compiled engine (RK45 runs RK45, not the default Radau); a
    method it does not have is refused in one line naming it; none means the engine's own."""
    import posturelab as pl
    from posturelab.errors import ParameterError

    sc = builtin_scenario("paper-forward-case1").replace(duration=1.0)
    assert sc.method is None
    args = (sc.body, sc.muscles, sc.disturbance, 1.0)
    options = {"initial_state": sc.initial_state, "rtol": sc.rtol, "atol": sc.atol}
    for method in ("RK45", "Radau"):
        api = pl.simulate(*args, engine="compiled", method=method, **options)
        np.testing.assert_array_equal(sc.replace(method=method).run().theta, api.theta)
    assert not np.array_equal(sc.replace(method="RK45").run().theta, sc.run().theta)
    np.testing.assert_array_equal(
        sc.replace(method="RK45").run(engine="reference").theta,
        pl.simulate(*args, engine="reference", method="RK45", **options).theta)
    with pytest.raises(ParameterError, match="solver.method 'DOP853'") as err:
        sc.replace(method="DOP853").run()
    assert "\n" not in str(err.value)


def test_a_sweep_honours_or_refuses_the_scenarios_method():
    """A sweep runs on the compiled engine: with the scenario's method (a row equals its single
    run with that method), or refused in one line before any run."""
    import posturelab as pl
    from posturelab.errors import ParameterError
    from posturelab.studies.sweep import parse_vary, run_sweep

    sc = builtin_scenario("paper-forward-case1").replace(duration=0.5, method="RK45")
    ankle = sc.muscles.stiffnesses[0]  # varied over its own value: the row is the scenario
    vary = [parse_vary(f"stiffness:ankle={ankle}:{ankle}:1")]
    result = run_sweep(sc, vary)
    options = {"initial_state": sc.initial_state, "rtol": 1e-6, "atol": 1e-9}  # a sweep's
    for method in ("RK45", "Radau"):
        single = pl.simulate(sc.body, sc.muscles, sc.disturbance, 0.5, method=method, **options)
        same = np.array_equal(result.outcomes.final_state[0], single.final_state)
        assert same == (method == "RK45")
    with pytest.raises(ParameterError, match="solver.method 'BDF'"):
        run_sweep(sc.replace(method="BDF"), vary)


TILTED = """
duration = 1.0
[muscles]
case = "1"
active_stiffness = [100.0, 0.0, 0.0, 0.0, 50.0]
active_viscosity_ratio = 0.3
feedback_delay = 0.02
proprioceptive_weight = 0.7
[tilt]
type = "sine"
amplitude = 0.01
frequency = 0.5
"""


def test_scenario_with_active_gains_and_tilt_runs_as_the_api_does(tmp_path):
    import posturelab as pl
    from posturelab.model.tilt import PRTSTilt, SineTilt

    sc = load_scenario(write(tmp_path, TILTED))
    assert sc.tilt == SineTilt(0.01, 0.5) and sc.proprioceptive_weight == 0.7
    np.testing.assert_array_equal(sc.muscles.active_stiffnesses, [100, 0, 0, 0, 50])
    np.testing.assert_array_equal(sc.muscles.active_viscosities, [30, 0, 0, 0, 15])
    muscles = pl.paper_muscles("1", active_stiffness=[100, 0, 0, 0, 50],
                               active_viscosity_ratio=0.3)
    api = pl.simulate(pl.paper_body(), muscles, None, 1.0, feedback_delay=0.02,
                      proprioceptive_weight=0.7, tilt=SineTilt(0.01, 0.5), engine="compiled",
                      rtol=sc.rtol, atol=sc.atol)
    np.testing.assert_array_equal(sc.run(engine="compiled").theta, api.theta)
    prts = load_scenario(write(tmp_path, MINIMAL + '[tilt]\ntype = "prts"\namplitude = 0.02\n',
                               "p.toml"))
    assert prts.tilt == PRTSTilt.named("posturelab-80", 0.02)
    csv = tmp_path / "tilt.csv"
    t = np.linspace(0, 2, 201)
    csv.write_text("time [s],tilt [rad]\n" + "".join(f"{a},{0.01 * np.sin(a)}\n" for a in t))
    measured = load_scenario(write(tmp_path, MINIMAL + '[tilt]\ntype = "profile"\n'
                                   'file = "tilt.csv"\n', "m.toml"))
    np.testing.assert_allclose(measured.tilt.angle(1.0), 0.01 * np.sin(1.0), atol=1e-9)


@pytest.mark.parametrize("extra,needle", [
    ('[tilt]\ntype = "wobble"\n', "tilt.type must be one of"),
    ('[tilt]\ntype = "sine"\namplitude = 0.01\nfrequency = 1.0\nperiod = 2\n',
     r"unknown key 'period' in \[tilt\]"),
    ('[tilt]\ntype = "sine"\namplitude = 3.0\nfrequency = 1.0\n', "tilt amplitude"),
])
def test_bad_tilt_tables(tmp_path, extra, needle):
    with pytest.raises((ScenarioError, Exception), match=needle):
        load_scenario(write(tmp_path, MINIMAL + extra))


def test_bad_weight_in_a_scenario(tmp_path):
    text = MINIMAL.replace('case = "1"', 'case = "1"\nproprioceptive_weight = 1.5')
    with pytest.raises(ScenarioError, match=r"proprioceptive_weight \[-\] must be in \[0, 1\]"):
        load_scenario(write(tmp_path, text))


def test_a_scenario_names_its_prts_sequence(tmp_path):
    from posturelab.model.tilt import PRTSTilt

    named = load_scenario(write(tmp_path, MINIMAL + '[tilt]\ntype = "prts"\namplitude = 0.02\n'
                                'sequence = "peterka-2002-242"\n', "n.toml"))
    assert named.tilt == PRTSTilt.named("peterka-2002-242", 0.02)
    assert named.tilt.cycle == 60.5
    with pytest.raises(ScenarioError, match=r"n2.toml: tilt.sequence: unknown PRTS sequence "
                       r"'peterka'; known sequences: posturelab-80, comtest-80, "
                       r"peterka-2002-242"):
        load_scenario(write(tmp_path, MINIMAL + '[tilt]\ntype = "prts"\namplitude = 0.02\n'
                            'sequence = "peterka"\n', "n2.toml"))
    with pytest.raises(ScenarioError, match="takes sequence or a register"):
        load_scenario(write(tmp_path, MINIMAL + '[tilt]\ntype = "prts"\namplitude = 0.02\n'
                            'sequence = "comtest-80"\nregisters = 4\n', "n3.toml"))


def test_a_one_link_scenario_takes_stiffness_per_pair_as_the_command_line_does(tmp_path):
    """[muscles] stiffness / active gains, one value per pair of a body of other than three
    links (the command line's --stiffness), equal the API's muscles_for; a wrong count or a
    Table I case on such a body is one line naming the pairs."""
    import subprocess
    import sys

    import posturelab as pl
    from posturelab.model.muscles import muscles_for

    text = ('duration = 1.0\n[body]\npreset = "paper-1link"\n[muscles]\nstiffness = [0.0]\n'
            'active_stiffness = [761.4]\nactive_viscosity = [265.0]\nfeedback_delay = 0.15\n')
    path = tmp_path / "one.toml"
    path.write_text(text)
    sc = pl.load_scenario(path)
    want = muscles_for(1, [0.0], active_stiffness=[761.4], active_viscosity=[265.0])
    assert sc.muscles == want and sc.feedback_delay == 0.15
    for bad, words in (("stiffness = [0.0, 1.0]", "one value per pair of this 1-link body "
                        "(ankle)"), ('case = "1"', "muscles.case is one of the paper's")):
        path.write_text(text.replace("stiffness = [0.0]", bad))
        p = subprocess.run([sys.executable, "-m", "posturelab", "simulate", "--scenario",
                            str(path)], capture_output=True, text=True, timeout=120)
        assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1, p.stderr
        assert words in p.stderr


def test_a_scenario_names_a_controller_preset(tmp_path):
    """[muscles] controller = NAME gives the preset's gains on the one-link body and its
    delay and weight (unless the table gives them); gains beside it, a three-link body or an
    unknown name are one line each."""
    import posturelab as pl
    from posturelab.errors import ScenarioError
    from posturelab.model.controllers import CONTROLLERS, get_controller

    text = ('duration = 1.0\n[body]\npreset = "paper-1link"\n[muscles]\n'
            'controller = "peterka-2002"\n')
    path = tmp_path / "c.toml"
    path.write_text(text)
    sc = pl.load_scenario(path)
    preset = get_controller("peterka-2002")
    body = pl.get_body("paper-1link")
    assert sc.muscles == preset.muscles(body)
    assert (sc.feedback_delay, sc.proprioceptive_weight) == (preset.feedback_delay,
                                                             preset.proprioceptive_weight)
    path.write_text(text + "feedback_delay = 0.1\n")
    assert pl.load_scenario(path).feedback_delay == 0.1
    for extra, words in (("stiffness = [500.0]\n", "cannot be given with muscles.controller"),
                         ("", "is a one-link controller")):
        body_text = text if extra else text.replace('"paper-1link"', '"paper"')
        path.write_text(body_text + extra)
        with pytest.raises(ScenarioError, match=words):
            pl.load_scenario(path)
    path.write_text(text.replace("peterka-2002", "peterka"))
    with pytest.raises(ScenarioError, match=", ".join(CONTROLLERS)):
        pl.load_scenario(path)
