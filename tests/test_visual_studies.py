"""The visual weight W_v swept, fitted and designed like every other quantity (issue 21).

Checked against: a batch's per-run W_v and a sweep's rows against their single runs on the
compiled engine (bit for bit); W_v fitted back from a noise-free simulated visual-tilt run;
the two-FRF JSON of ``frf --json`` read back by ``fit-frf`` against the CSV path; one-line
refusals of runs whose W_p + W_v exceeds 1.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import posturelab as pl
from posturelab.cli import main
from posturelab.errors import ParameterError
from posturelab.model.tilt import SineTilt
from posturelab.scenarios import Scenario
from posturelab.simulation.compiled import simulate_batch
from posturelab.studies.sweep import parse_vary, run_sweep, sweep_grid

SCENE = SineTilt(0.03, 0.4)


def split_case_1(share=0.5):
    """Case 1's gains, half intrinsic and half active (so that a weight acts)."""
    k = np.asarray(pl.paper_muscles("1").stiffnesses)
    return pl.paper_muscles(stiffness=(1 - share) * k, active_stiffness=share * k,
                            active_viscosity_ratio=0.25)


def scene_scenario(**options) -> Scenario:
    """Case 1 split, a 0.4 Hz visual-scene sine, no platform motion, 3 s."""
    sc = Scenario("scene", "test", pl.paper_body(), split_case_1(), pl.NoDisturbance())
    return sc.replace(duration=3.0, feedback_delay=0.05, visual_tilt=SCENE,
                      fall=pl.FallCriteria(math.pi / 2), **options)


# ---- the batch ----------------------------------------------------------------------------


def test_a_batch_takes_a_visual_weight_per_run():
    m = 3
    muscles = split_case_1()
    k = np.tile(np.asarray(muscles.stiffnesses), (m, 1))
    ka = np.tile(np.asarray(muscles.active_stiffnesses), (m, 1))
    wv = np.array([0.0, 0.2, 0.45])
    wp = np.array([0.5, 0.6, 0.55])
    out = simulate_batch(pl.paper_body(), k, 0.25 * k, None, 3.0, feedback_delay=0.05,
                         active_stiffness=ka, active_viscosity=0.25 * ka, visual_tilt=SCENE,
                         proprioceptive_weight=wp, visual_weight=wv)
    finals = []
    for r in range(m):
        one = pl.simulate(pl.paper_body(), muscles, None, 3.0, feedback_delay=0.05,
                          visual_tilt=SCENE, proprioceptive_weight=float(wp[r]),
                          visual_weight=float(wv[r]), engine="compiled")
        np.testing.assert_array_equal(out.final_state[r], np.r_[one.theta[-1], one.omega[-1]])
        finals.append(out.final_state[r])
    assert np.abs(finals[0]).max() < 1e-12 < np.abs(finals[2]).max()  # (W_v = 0: no sway)


def test_a_batch_refuses_a_run_over_one_naming_both():
    k = np.tile(np.asarray(pl.paper_muscles("1").stiffnesses), (2, 1))
    with pytest.raises(ParameterError, match=r"proprioceptive_weight \+ visual_weight .* "
                       r"0\.7 \+ 0\.4"):
        simulate_batch(pl.paper_body(), k, 0.25 * k, None, 1.0, visual_tilt=SCENE,
                       proprioceptive_weight=[0.5, 0.7], visual_weight=[0.4, 0.4])


# ---- the sweep ----------------------------------------------------------------------------


def test_a_sweep_over_the_visual_weight_equals_single_runs():
    sc = scene_scenario(proprioceptive_weight=0.4)
    result = run_sweep(sc, [parse_vary("visual_weight=0:0.6:4")])
    assert result.grid.names == ("visual_weight",)
    o = result.outcomes
    for r, (wv,) in enumerate(result.grid.values):
        one = sc.run(engine="compiled", visual_weight=float(wv), rtol=1e-6, atol=1e-9)
        np.testing.assert_array_equal(one.max_abs_theta, o.peak_theta[r])
    assert o.peak_theta[0].max() < 1e-12 < o.peak_theta[-1].max()


def test_a_sweep_grid_over_one_is_refused_naming_both():
    sc = scene_scenario(proprioceptive_weight=0.5)
    with pytest.raises(ParameterError, match=r"proprioceptive_weight \+ visual_weight .* "
                       r"0\.5 \+ 0\.6 = 1\.1"):
        sweep_grid(sc, [parse_vary("visual_weight=0:0.6:3")])
    with pytest.raises(ParameterError, match=r"the first 0\.8 \+ 0\.3"):
        sweep_grid(sc, [parse_vary("proprioceptive_weight=0:0.8:5"),
                        parse_vary("visual_weight=0.1:0.3:3")])
    with pytest.raises(ParameterError, match="visual-scene tilt, and it has none"):
        sweep_grid(sc.replace(visual_tilt=None), [parse_vary("visual_weight=0:0.3:2")])


def test_the_sweep_command_refuses_a_grid_over_one_in_one_line(tmp_path, capsys):
    code = main(["sweep", "--case", "1", "--visual-tilt", "sine:0.03:0.4",
                 "--proprioceptive-weight", "0.5", "--vary", "visual_weight=0:0.6:3",
                 "--out", str(tmp_path / "s.csv")])
    err = capsys.readouterr().err
    assert code == 2 and "proprioceptive_weight + visual_weight" in err
    assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "s.csv").exists()
    assert "visual_weight" in " ".join(_help_text("sweep").split())


def _help_text(command: str) -> str:
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), contextlib.suppress(SystemExit):
        main([command, "--help"])
    return buf.getvalue()


# ---- fit --free visual_weight ---------------------------------------------------------------


def test_fit_recovers_the_visual_weight_of_a_noise_free_run():
    """A 3 s visual-scene sine with W = 0.4, W_v = 0.35: W_v fitted back from 0.1 within 1e-3
    (noise-free: only the integrator's error, rtol 1e-8, moves it)."""
    from posturelab.studies.identification import fit_stiffness

    sc = scene_scenario(proprioceptive_weight=0.4, visual_weight=0.1)
    truth = sc.run(visual_weight=0.35)
    keep = slice(None, None, 5)
    fit = fit_stiffness(sc, truth.time[keep], truth.theta[keep], ["visual_weight"])
    assert fit.parameter_names == ("visual_weight",)
    assert fit.estimates[0] == pytest.approx(0.35, abs=1e-3)


def test_fit_refuses_both_weights_and_a_weight_without_a_scene(tmp_path, capsys):
    from posturelab.studies.identification import fit_stiffness

    sc = scene_scenario(proprioceptive_weight=0.4)
    t = np.linspace(0, 1, 11)
    with pytest.raises(ParameterError, match="not both"):
        fit_stiffness(sc, t, np.zeros((11, 3)), ["proprioceptive_weight", "visual_weight"])
    with pytest.raises(ParameterError, match="visual-scene tilt, and it has none"):
        fit_stiffness(sc.replace(visual_tilt=None), t, np.zeros((11, 3)), ["visual_weight"])


def test_the_fit_command_frees_the_visual_weight(tmp_path, capsys):
    data = tmp_path / "angles.csv"
    sc = scene_scenario(proprioceptive_weight=0.4)
    truth = sc.run(visual_weight=0.35, rtol=1e-8, atol=1e-10)
    rows = ["t,theta1,theta2,theta3"] + [
        ",".join(f"{v:.17g}" for v in (t, *th)) for t, th in
        zip(truth.time[::5], truth.theta[::5], strict=True)]
    data.write_text("\n".join(rows) + "\n", encoding="utf-8")
    code = main(["fit", "--data", str(data), "--free", "visual_weight",
                 "--stiffness", ",".join(f"{v:.17g}" for v in sc.muscles.stiffnesses),
                 "--active-stiffness",
                 ",".join(f"{v:.17g}" for v in sc.muscles.active_stiffnesses),
                 "--active-viscosity",
                 ",".join(f"{v:.17g}" for v in sc.muscles.active_viscosities),
                 "--feedback-delay", "0.05", "--proprioceptive-weight", "0.4",
                 "--visual-tilt", "sine:0.03:0.4"])
    out, err = capsys.readouterr()
    assert code == 0, err
    line = next(ln for ln in out.splitlines() if ln.strip().startswith("visual_weight"))
    assert float(line.split()[1]) == pytest.approx(0.35, abs=1e-3), (out, err)
    assert "visual_weight" in " ".join(_help_text("fit").split())


# ---- fit-frf on the two-FRF JSON of a dual trial --------------------------------------------

GAINS = ["--body", "paper-1link", "--stiffness", "113", "--viscosity", "28",
         "--active-stiffness", "677", "--active-viscosity", "197", "--feedback-delay", "0.12"]


def test_fit_frf_reads_the_dual_json_of_frf_as_the_trial(tmp_path, capsys):
    """simulate a dual trial; frf --json > d.json; fit-frf --data d.json gives the fit of
    fit-frf --data trial.csv (the same two FRFs, each with its model input)."""
    import json

    trial, frfs = tmp_path / "trial.csv", tmp_path / "d.json"
    assert main(["simulate", *GAINS, "--proprioceptive-weight", "0.55",
                 "--visual-weight", "0.3", "--tilt", "prts:0.035",
                 "--visual-tilt", "prts:0.035:0.125", "--duration", "60",
                 "--sample-rate", "100", "--out", str(trial)]) == 0
    capsys.readouterr()
    cycles = ["--cycle-length", "20", "--discard-cycles", "1"]
    assert main(["frf", "--data", str(trial), *cycles, "--json"]) == 0
    frfs.write_text(capsys.readouterr().out, encoding="utf-8")
    free = ["--free", "proprioceptive_weight,visual_weight", "--json"]
    assert main(["fit-frf", "--data", str(trial), *cycles, *GAINS, *free]) == 0
    by_csv = json.loads(capsys.readouterr().out)
    assert main(["fit-frf", "--data", str(frfs), *GAINS, *free]) == 0
    by_json = json.loads(capsys.readouterr().out)
    assert [c["input"] for c in by_json["conditions"]] == ["tilt", "visual-tilt"]
    assert [c["kind"] for c in by_json["conditions"]] == ["frf --json", "frf --json"]
    for a, b in zip(by_csv["parameters"], by_json["parameters"], strict=True):
        assert a["name"] == b["name"]
        assert b["estimate"] == pytest.approx(a["estimate"], rel=1e-9, abs=1e-12)
        assert b["standard_error"] == pytest.approx(a["standard_error"], rel=1e-6)
    got = {q["name"]: q["estimate"] for q in by_json["parameters"]}
    assert got["visual_weight"] == pytest.approx(0.3, abs=0.01)
    # --stimulus picks one of them; an unknown one is refused in one line
    assert main(["fit-frf", "--data", str(frfs), "--stimulus", "visual_tilt", *GAINS,
                 "--free", "visual_weight", "--json"]) == 0
    one = json.loads(capsys.readouterr().out)
    assert [c["input"] for c in one["conditions"]] == ["visual-tilt"]
    assert main(["fit-frf", "--data", str(frfs), "--stimulus", "sound", *GAINS,
                 "--free", "visual_weight"]) == 2
    err = capsys.readouterr().err
    assert "'sound' is not in" in err and len(err.strip().splitlines()) == 1


def test_a_one_frf_reader_names_a_dual_json(tmp_path):
    import json

    from posturelab.frequency.table import read_frf_json, read_frf_json_stimuli

    one = {"frequency": [0.1, 0.2], "gain": [1.0, 0.8], "phase_deg": [-10.0, -30.0]}
    path = tmp_path / "d.json"
    path.write_text(json.dumps({"tilt": one, "visual_tilt": one}), encoding="utf-8")
    tables = read_frf_json_stimuli(path)
    assert list(tables) == ["tilt", "visual_tilt"]
    np.testing.assert_allclose(abs(tables["visual_tilt"].frf), [1.0, 0.8])
    with pytest.raises(ParameterError, match=r"one FRF per stimulus \(tilt, visual_tilt\)"):
        read_frf_json(path)


# ---- design --visual-tilt -----------------------------------------------------------------


def test_a_scene_design_on_active_gains_is_the_surface_design_with_w_as_w_v():
    """With active gains only, a scene tilt weighted W_v acts as a surface tilt weighted W
    = W_v (the surface's mechanical path needs intrinsic gains: test_visual.py checks the
    engines so); the predicted errors of W_v and the gains then equal those of W."""
    from posturelab.frequency.design import predict_errors
    from posturelab.model.muscles import MusclePair, MuscleSet

    body = pl.get_body("paper-1link")
    mgh = body.load_stiffness
    muscles = MuscleSet((MusclePair("ankle", 0, 1, 0.0, 0.0, active_stiffness=1.3 * mgh,
                                    active_viscosity=0.35 * mgh),), 1)
    common = dict(feedback_delay=0.1, sensor_noise=1e-3, cycles=4)
    scene = predict_errors(body, muscles, ["visual_weight", "active_stiffness"],
                           input="visual-tilt", proprioceptive_weight=0.0, visual_weight=0.4,
                           **common)
    surface = predict_errors(body, muscles, ["proprioceptive_weight", "active_stiffness"],
                             proprioceptive_weight=0.4, **common)
    assert scene.stimulus == "visual-tilt" and scene.to_dict()["design"]["stimulus"] == (
        "visual-tilt")
    np.testing.assert_allclose(scene.values, surface.values, rtol=0, atol=0)
    assert np.all(np.isfinite(scene.standard_errors))
    np.testing.assert_allclose(scene.standard_errors, surface.standard_errors, rtol=1e-9)
    with pytest.raises(ParameterError, match=r"proprioceptive_weight \+ visual_weight"):
        predict_errors(body, muscles, ["visual_weight"], input="visual-tilt",
                       proprioceptive_weight=0.8, visual_weight=0.4, **common)


def test_the_design_command_takes_a_visual_tilt(capsys):
    import json

    base = ["design", "--controller", "peterka-2002", "--sensor-noise", "0.001"]
    assert main([*base, "--visual-tilt", "prts:0.035", "--proprioceptive-weight", "0.5",
                 "--visual-weight", "0.3", "--free", "visual_weight", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["design"]["stimulus"] == "visual-tilt"
    assert out["parameters"]["visual_weight"]["value"] == 0.3
    assert out["parameters"]["visual_weight"]["standard_error"] > 0
    assert main([*base, "--tilt", "prts:0.035", "--visual-tilt", "prts:0.035",
                 "--free", "visual_weight"]) == 2
    err = capsys.readouterr().err
    assert "not both" in err and len(err.strip().splitlines()) == 1


def test_a_prts_experiment_sweep_refuses_the_visual_weight_and_a_scene(tmp_path, capsys):
    base = ["sweep", "--experiment", "prts", "--case", "1", "--tilt", "prts:0.035",
            "--out", str(tmp_path / "p.csv")]
    for extra, words in (
            (["--vary", "visual_weight=0:0.3:2", "--visual-tilt", "sine:0.01:0.5"],
             "visual_weight has no effect"),
            (["--vary", "feedback_delay=0:0.1:2", "--visual-tilt", "sine:0.01:0.5"],
             "leave out the visual-scene tilt")):
        assert main([*base, *extra]) == 2
        err = capsys.readouterr().err
        assert words in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "p.csv").exists()
