"""The command line of the field's experiments: bodies, intrinsic and active gains, the
delay, the proprioceptive weight, tilt, controller presets and ``delay-margin``.

Each command's numbers are compared with the public API's for the same inputs; bad input
gets one line naming the field and exit code 2.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import posturelab as pl
from posturelab.cli import main
from posturelab.model.controllers import CONTROLLERS, get_controller
from posturelab.model.muscles import MusclePair, MuscleSet
from posturelab.model.tilt import MeasuredTilt, PRTSTilt, SineTilt


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_delay_margin_json_is_the_api_s_for_a_one_link_body(capsys):
    code, out, err = run(capsys, "delay-margin", "--body", "paper-1link", "--stiffness", "1000",
                         "--viscosity", "100", "--json")
    assert code == 0 and err == ""
    obj = json.loads(out)
    assert set(obj) == {"delay_margin", "crossing_frequency", "stable_without_delay",
                        "stable_at_every_delay", "units"}
    muscles = MuscleSet((MusclePair("ankle", 0, 1, 1000.0, 100.0),), 1)
    api = pl.delay_margin(pl.get_body("paper-1link"), muscles)
    assert obj["delay_margin"] == api.delay_margin
    assert obj["crossing_frequency"] == api.crossing_frequency
    assert obj["stable_without_delay"] is True


@pytest.mark.parametrize("argv,expected", [
    (["--body", "paper-1link", "--stiffness", "300"],
     {"delay_margin": None, "crossing_frequency": None, "stable_without_delay": False,
      "stable_at_every_delay": False}),
    (["--case", "1", "--active-stiffness", "0,0,0,0,0"],  # (null, not "infinite")
     {"delay_margin": None, "crossing_frequency": None, "stable_without_delay": True,
      "stable_at_every_delay": True}),
])
def test_delay_margin_verdicts(capsys, argv, expected):
    code, out, _ = run(capsys, "delay-margin", *argv, "--json")
    units = {"units": {"delay_margin": "s", "crossing_frequency": "rad/s"}}
    assert code == 0 and json.loads(out) == expected | units


def test_delay_margin_text_names_the_margin_and_the_frequency(capsys):
    code, out, _ = run(capsys, "delay-margin", "--case", "1", "--feedback-delay", "0.002")
    api = pl.delay_margin(pl.paper_body(), pl.paper_muscles("1"))
    assert code == 0
    assert f"{api.delay_margin * 1000:.4g} ms" in out
    assert f"{api.crossing_frequency / (2 * math.pi):.4g} Hz" in out
    assert "at τ = 0.002 s: stable" in out


def test_controller_presets_carry_citations_and_scale_with_the_body():
    body = pl.get_body("paper-1link")
    for preset in CONTROLLERS.values():
        assert preset.citation and preset.name in CONTROLLERS
        m = preset.muscles(body)
        assert m.active_stiffnesses[0] == pytest.approx(preset.active_stiffness
                                                        * body.load_stiffness)
        assert pl.delay_margin(body, m).delay_margin > preset.feedback_delay  # stable at τ
    with pytest.raises(pl.UnknownNameError, match="known controllers: peterka-2002"):
        get_controller("nobody-1999")
    with pytest.raises(pl.ParameterError, match="one-link body"):
        get_controller("peterka-2002").muscles(pl.paper_body())


def test_simulate_with_controller_and_tilt_is_the_api_run(capsys):
    code, out, err = run(capsys, "simulate", "--controller", "peterka-2002", "--tilt",
                         "prts:0.035", "--duration", "3", "--engine", "compiled", "--json")
    assert code == 0 and err == ""
    obj = json.loads(out)
    preset = get_controller("peterka-2002")
    body = pl.get_body("paper-1link")
    api = pl.simulate(body, preset.muscles(body), None, 3.0,
                      tilt=PRTSTilt.named("posturelab-80", 0.035),
                      engine="compiled", rtol=1e-8, atol=1e-10, **preset.run_options())
    assert obj["final_state"] == [float(v) for v in api.final_state]


def test_simulate_reads_a_tilt_column_from_the_platform_profile(capsys, tmp_path):
    t = np.arange(0.0, 2.0005, 0.001)
    path = tmp_path / "tilt.csv"
    path.write_text("time [s],tilt [rad]\n"
                    + "".join(f"{a:.6f},{0.02 * math.sin(2 * math.pi * a):.12g}\n" for a in t))
    code, out, err = run(capsys, "simulate", "--body", "paper-1link", "--stiffness", "900",
                         "--platform-profile", str(path), "--duration", "2", "--json")
    assert code == 0, err
    body = pl.get_body("paper-1link")
    muscles = pl.model.muscles.muscles_for(1, [900.0])
    sampled = MeasuredTilt(np.round(t, 6), [float(f"{0.02 * math.sin(2 * math.pi * a):.12g}")
                                            for a in t])
    api = pl.simulate(body, muscles, None, 2.0, tilt=sampled)
    np.testing.assert_allclose(json.loads(out)["final_state"], api.final_state, atol=1e-12)
    analytic = pl.simulate(body, muscles, None, 2.0, tilt=SineTilt(0.02, 1.0))
    np.testing.assert_allclose(json.loads(out)["final_state"][:1], analytic.final_state[:1],
                               atol=1e-6)


def test_poles_of_a_subject_scaled_body_with_active_gains(capsys):
    code, out, _ = run(capsys, "poles", "--height", "1.8", "--mass", "82", "--case", "1",
                       "--active-stiffness", "400,0,0,0,0", "--json")
    assert code == 0
    body = pl.body_from_anthropometry(1.8, 82)
    muscles = pl.paper_muscles("1", active_stiffness=[400, 0, 0, 0, 0])
    poles = [complex(p["re"], p["im"]) for p in json.loads(out)["poles"]]
    np.testing.assert_allclose(poles, pl.analyse(body, muscles).poles, rtol=1e-12)


@pytest.mark.parametrize("argv,needle", [
    (["delay-margin", "--case", "1", "--proprioceptive-weight", "1.5"],
     "--proprioceptive-weight [-] must be in [0, 1], got 1.5"),
    (["delay-margin", "--case", "1", "--feedback-delay", "-0.1"],
     "--feedback-delay [s] must be in [0, 1], got -0.1"),
    (["delay-margin", "--case", "1", "--active-stiffness", "1,2"],
     "--active-stiffness [N·m/rad] must have 5 comma-separated values, got 2"),
    (["delay-margin", "--body", "paper-1link", "--stiffness", "1,2"],
     "--stiffness [N·m/rad] must have 1 comma-separated values, got 2"),
    (["simulate", "--case", "1", "--tilt", "sine:0.1"], "--tilt must be sine:AMPLITUDE_RAD"),
    (["simulate", "--case", "1", "--tilt", "sine:9:1"], "tilt amplitude [rad] must be in"),
    (["simulate", "--case", "1", "--tilt", "spin:1:1"], "--tilt must be"),
    (["delay-margin", "--controller", "peterka-2002", "--viscosity-ratio", "0.3"],
     "--controller sets every gain"),
    (["delay-margin", "--controller", "nobody"], "known controllers"),
    (["poles", "--height", "1.8", "--case", "1"], "--height [m] and --mass [kg] go together"),
])
def test_bad_input_is_one_line_and_exit_2(capsys, argv, needle):
    code, out, err = run(capsys, *argv)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and needle in err, err


def test_stability_map_with_a_delay_is_the_d_subdivision_map(capsys, tmp_path):
    """The CLI's delayed map writes what delay_stability_map computes, CSV row by row."""
    import csv

    from posturelab.linear.delay_batch import delay_stability_map

    out = tmp_path / "d.png"
    code, stdout, err = run(capsys, "stability-map", "--body", "paper-1link", "--stiffness",
                            "28", "--viscosity", "11", "--x", "active_stiffness:0:1700",
                            "--y", "active_viscosity:0:680", "--feedback-delay", "0.15",
                            "--resolution", "12", "--out", str(out))
    assert code == 0, err
    assert out.stat().st_size > 5_000 and "12 × 12 sets of the ankle pair" in stdout
    rows = list(csv.DictReader((tmp_path / "d.csv").open()))
    body = pl.get_body("paper-1link")
    api = delay_stability_map(body, pl.model.muscles.muscles_for(1, [28.0], [11.0]), 0.15,
                              (0, 1700), (0, 680), 12)
    assert len(rows) == 144
    assert [int(r["stable"]) for r in rows] == api.stable.ravel().astype(int).tolist()
    assert [float(r["max_real_part"]) for r in rows] == api.max_real_part.ravel().tolist()


@pytest.mark.parametrize("argv,needle", [
    (["--x", "active_stiffness:ankle:0:1", "--y", "active_viscosity:ankle:0:1"],
     "needs --feedback-delay"),
    (["--x", "stiffness:ankle:0:1", "--y", "stiffness:hip:0:1", "--feedback-delay", "0.1"],
     "--feedback-delay is for the delayed map"),
    (["--x", "active_stiffness:ankle:0:1", "--y", "stiffness:hip:0:1", "--feedback-delay",
      "0.1"], "both axes are active_stiffness:PAIR and active_viscosity:PAIR"),
    # the paper's body has five pairs: the axis names one
    (["--x", "active_stiffness:0:1", "--y", "active_viscosity:0:1", "--feedback-delay", "0.1"],
     "'active_stiffness' needs its pair: active_stiffness:ankle, active_stiffness:knee"),
    (["--x", "active_stiffness:ankle:0:1", "--y", "active_viscosity:hip:0:1",
      "--feedback-delay", "0.1"], "must name the same pair, got 'ankle' and 'hip'"),
    (["--x", "active_stiffness:0:1", "--y", "active_viscosity:0:1", "--feedback-delay", "0.1",
      "--pair", "hip"], "--pair is now part of the axis names: --x active_stiffness:hip:LO:HI"),
])
def test_bad_delayed_maps(capsys, tmp_path, argv, needle):
    code, out, err = run(capsys, "stability-map", *argv, "--out", str(tmp_path / "e.png"))
    assert code == 2 and needle in err and err.count("\n") == 1


def test_poles_with_a_delay_give_the_rightmost_roots(capsys):
    code, out, _ = run(capsys, "poles", "--case", "1", "--feedback-delay", "0.01", "--json")
    obj = json.loads(out)
    # one verdict, with the delay: unstable at 10 ms although stable without it
    assert code == 0 and obj["stable"] is False and obj["stable_without_delay"] is True
    assert obj["linear_stability"]["status"] == "unstable"
    assert obj["linear_stability"]["feedback_delay"] == 0.01
    roots = [complex(r["re"], r["im"]) for r in obj["rightmost_roots"]]
    np.testing.assert_allclose(roots, pl.rightmost_roots(pl.paper_body(), pl.paper_muscles("1"),
                                                         0.01, 6), rtol=1e-12)
    code, out, _ = run(capsys, "poles", "--controller", "peterka-2002", "--json")
    obj = json.loads(out)
    mgh = pl.get_body("paper-1link").load_stiffness
    assert obj["active_stiffness"] == [pytest.approx(1.35 * mgh)]
    assert obj["viscosity_ratio"] is None
