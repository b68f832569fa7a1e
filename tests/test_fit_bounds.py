"""Estimates stuck on a search bound are flagged, and intervals stay in the accepted range."""

from __future__ import annotations

import json

import numpy as np
import pytest

from _cli import cli
from posturelab._bounds import at_bound, clip_intervals

BANDS = [0.05, 0.1, 0.2, 0.4, 0.8, 1.6]


def test_at_bound_within_a_millionth_of_the_range():
    sides = at_bound([0.0, 1e-7, 0.5, 1 - 1e-7, 1.0, 2e-6], [0] * 6, [1] * 6)
    assert sides == ("low", "low", None, "high", "high", None)


def test_intervals_clipped_to_the_table_and_the_search_box():
    ci, clipped = clip_intervals(
        ["feedback_delay", "active_stiffness:ankle", "proprioceptive_weight#2"],
        [[-0.8, 0.8], [-1.4e4, 2.1e5], [0.2, 0.4]], [0.0, 0.0, 0.0], [1.0, 1e5, 1.0])
    assert ci.tolist() == [[0.0, 0.8], [0.0, 1e5], [0.2, 0.4]]
    assert clipped.tolist() == [True, True, False]


def _table(tmp_path, phase):
    path = tmp_path / "table.json"
    path.write_text(json.dumps({"frequency": BANDS, "gain": [1.0] * len(BANDS),
                                "phase_deg": phase}))
    return str(path)


def _fit(path, free, *extra):
    return cli("fit-frf", "--data", path, "--controller", "peterka-2002", "--free", free,
               *extra)


def test_a_gain_on_its_search_bound_is_flagged_not_determined(tmp_path):
    # gain 1, phase 0 at every band: the stiffness runs to the default search bound 1e5
    path = _table(tmp_path, [0.0] * len(BANDS))
    free = "active_stiffness:ankle,active_viscosity:ankle"
    p = _fit(path, free, "--json")
    assert p.returncode == 0, p.stderr
    par = json.loads(p.stdout)["parameters"][0]
    assert par["estimate"] == pytest.approx(1e5) and par["at_bound"] == "high"
    assert par["determined"] is False
    assert 0.0 <= par["ci95"][0] <= par["ci95"][1] <= 1e5
    text = _fit(path, free)
    assert text.returncode == 0, text.stderr
    line = next(x for x in text.stdout.splitlines() if "active_stiffness:ankle" in x)
    assert "at its search bound HI = 1e+05" in line and "not determined" in line
    assert "clipped" in line


def test_a_delay_on_zero_has_no_negative_interval(tmp_path):
    # phases given in radians by mistake: the delay runs to 0
    path = _table(tmp_path, [-0.1, -0.2, -0.3, -0.5, -0.8, -1.2])
    p = _fit(path, "feedback_delay", "--json")
    assert p.returncode == 0, p.stderr
    (par,) = json.loads(p.stdout)["parameters"]
    assert par["at_bound"] == "low" and par["determined"] is False
    assert par["ci95"][0] >= 0.0 and par["ci95_clipped"] is True
    text = _fit(path, "feedback_delay")
    line = next(x for x in text.stdout.splitlines() if "feedback_delay" in x)
    assert "at its search bound LO = 0 s" in line


def test_an_interior_estimate_is_not_flagged():
    import posturelab as pl
    from posturelab.frequency import model_frf
    from posturelab.frequency.fit import fit_frf
    from posturelab.frequency.table import FRFTable
    from posturelab.model.controllers import get_controller

    c = get_controller("peterka-2002")
    body = pl.get_body("paper-1link")
    muscles = c.muscles(body)
    f = np.array(BANDS)
    H = model_frf(body, muscles, f, feedback_delay=c.feedback_delay,
                  proprioceptive_weight=c.proprioceptive_weight)
    table = FRFTable(f, H, frf_se=0.01 * np.abs(H))
    fit = fit_frf(body, muscles, table, ["feedback_delay"], feedback_delay=0.1,
                  proprioceptive_weight=c.proprioceptive_weight)
    assert fit.at_bound == (None,) and fit.determined.all() and not fit.clipped.any()
    assert abs(fit.estimates[0] - c.feedback_delay) < 1e-3
