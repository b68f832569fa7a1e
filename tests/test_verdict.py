"""One verdict about upright (posturelab.upright_verdict): both sides of a one-sided pair's
switch against linearisations built here by hand, the delay, the same verdict from
``poles`` and ``simulate`` (real subprocesses), the gastrocnemius forms on the command line,
and a published one-link controller on a body from height and mass on every command."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

import posturelab as pl
from posturelab.frequency.model import model_frf
from posturelab.model.controllers import get_controller
from posturelab.model.dynamics import mass_matrix

#: The paper's five pairs by hand (Appendix C, eq. 4): the rows of E over (θ1, θ2, θ3).
E_BY_HAND = {"ankle": [1, 0, 0], "knee": [-1, 1, 0], "hip": [0, -1, 1],
             "quadriceps": [-1, 0, 1], "gastrocnemius": [0, 1, 0]}


def _poles_by_hand(stiffness: dict[str, float], ratio: float = 0.25) -> np.ndarray:
    """numpy eigenvalues of the state matrix of the paper's body with these pairs acting
    (viscosity = ratio × stiffness) [1/s]."""
    body = pl.paper_body()
    E = np.array([E_BY_HAND[n] for n in stiffness], dtype=float)
    k = np.array(list(stiffness.values()))
    K = E.T @ np.diag(k) @ E
    J0 = mass_matrix(body, np.zeros(3))
    G = body.gravity * np.diag(body.gravity_coefficients)
    A = np.block([[np.zeros((3, 3)), np.eye(3)],
                  [np.linalg.solve(J0, G - K), -np.linalg.solve(J0, ratio * K)]])
    return np.linalg.eigvals(A)


def _rightmost(poles: np.ndarray) -> complex:
    return complex(max(poles, key=lambda z: (z.real, z.imag)))


CASE1 = dict(zip(E_BY_HAND, (500.0, 300.0, 300.0, 300.0, 300.0), strict=True))


def test_case_1_with_the_one_sided_gastrocnemius_depends_on_the_side():
    """Upright is the gastrocnemius's switching point: engaged, the poles of case 1 (stable);
    slack, those without it (case 2, unstable): the verdict says it depends on the side."""
    v = pl.upright_verdict(pl.paper_body(), pl.paper_muscles("1", gastrocnemius="one-sided"))
    engaged = _poles_by_hand(CASE1)
    slack = _poles_by_hand({n: k for n, k in CASE1.items() if n != "gastrocnemius"})
    assert v.switching_pairs == ("gastrocnemius",) and v.switching_conditions == ("θ2 ≥ 0",)
    assert v.side(engaged=True).engaged == ("gastrocnemius",)
    assert v.side(engaged=False).slack == ("gastrocnemius",)
    np.testing.assert_allclose(v.side(engaged=True).rightmost_root, _rightmost(engaged),
                               rtol=1e-9)
    np.testing.assert_allclose(v.side(engaged=False).rightmost_root, _rightmost(slack),
                               rtol=1e-9)
    np.testing.assert_allclose(sorted(v.side(engaged=False).roots, key=lambda z: z.real),
                               sorted(slack, key=lambda z: z.real), rtol=1e-9)
    assert _rightmost(engaged).real < 0 < _rightmost(slack).real
    assert v.status == "depends on the side" and not v.stable
    assert [s.status for s in v.sides] == ["stable", "unstable"]
    assert v.rightmost_root == v.side(engaged=False).rightmost_root
    words = v.describe()
    assert "stable while gastrocnemius engaged" in words
    assert "unstable while gastrocnemius slack" in words and "not settled" in words
    d = v.to_dict()
    assert d["status"] == "depends on the side" and d["stable"] is False
    assert d["units"]["rightmost_root"] == "1/s" and d["units"]["feedback_delay"] == "s"
    json.dumps(d, allow_nan=False)


@pytest.mark.parametrize("ankle,status", [(1000.0, "stable"), (100.0, "unstable")])
def test_both_sides_agreeing_give_their_verdict(ankle, status):
    """Ankle 1000: slack is case 3, stable, as is the engaged side; ankle 100: both unstable."""
    gains = {**CASE1, "ankle": ankle}
    sides = [_poles_by_hand(gains),
             _poles_by_hand({n: k for n, k in gains.items() if n != "gastrocnemius"})]
    assert {("stable" if _rightmost(p).real < 0 else "unstable") for p in sides} == {status}
    v = pl.upright_verdict(pl.paper_body(), pl.paper_muscles(
        stiffness=list(gains.values()), gastrocnemius="one-sided"))
    assert v.status == status and v.stable == (status == "stable")
    assert v.describe().startswith(f"{status} about upright on every side of the switch")


def test_without_a_switch_one_linearisation_and_the_delay_s_roots():
    body, muscles = pl.paper_body(), pl.paper_muscles("1")
    v = pl.upright_verdict(body, muscles)
    assert len(v.sides) == 1 and not v.at_switching_point and v.delayed_part == "none"
    np.testing.assert_allclose(v.rightmost_root, _rightmost(_poles_by_hand(CASE1)), rtol=1e-9)
    # the paper's gains wholly delayed by 10 ms: past the 2.81 ms delay margin, unstable
    delayed = pl.upright_verdict(body, muscles, 0.01)
    assert delayed.status == "unstable" and delayed.delayed_part == "all"
    np.testing.assert_allclose(delayed.side(engaged=True).roots,
                               pl.rightmost_roots(body, muscles, 0.01, 6), rtol=1e-12)
    # with a delay both sides of the switch are the delay equation's
    both = pl.upright_verdict(body, pl.paper_muscles("1", gastrocnemius="one-sided"), 0.002)
    np.testing.assert_allclose(both.side(engaged=False).roots,
                               pl.rightmost_roots(body, pl.paper_muscles("2"), 0.002, 6),
                               rtol=1e-12)
    assert both.status == "depends on the side" and "τ = 0.002 s" in both.describe()


def test_two_one_sided_pairs_give_four_sides():
    """Each one-sided pair engaged or slack: four linearisations, each numpy's by hand."""
    from dataclasses import replace

    m = pl.paper_muscles("1")
    muscles = pl.MuscleSet(tuple(replace(p, one_sided=p.name in ("quadriceps", "gastrocnemius"))
                                 for p in m.pairs), 3)
    v = pl.upright_verdict(pl.paper_body(), muscles)
    assert v.switching_pairs == ("quadriceps", "gastrocnemius")
    assert v.switching_conditions == ("θ3 − θ1 ≥ 0", "θ2 ≥ 0")
    assert [s.engaged for s in v.sides] == [("quadriceps", "gastrocnemius"), ("quadriceps",),
                                            ("gastrocnemius",), ()]
    for side in v.sides:
        by_hand = _poles_by_hand({n: k for n, k in CASE1.items() if n not in side.slack})
        np.testing.assert_allclose(side.rightmost_root, _rightmost(by_hand), rtol=1e-9)
    statuses = {s.status for s in v.sides}
    assert v.status == (statuses.pop() if len(statuses) == 1 else "depends on the side")


def test_an_undamped_pendulum_is_marginal():
    body = pl.get_body("paper-1link")
    muscles = pl.model.muscles.muscles_for(1, [3 * body.load_stiffness], [0.0])
    v = pl.upright_verdict(body, muscles)
    assert v.status == "marginal" and not v.stable
    assert v.describe().startswith("marginal about upright")


def test_the_gastrocnemius_forms():
    """one-sided: the paper's pair, switching on its stretch only; pull-only: also slack
    while it would push; two-sided: always acting."""
    def gastrocnemius(form):
        return pl.paper_muscles("1", gastrocnemius=form).pairs[-1]

    assert (gastrocnemius("one-sided").one_sided, gastrocnemius("one-sided").pull_only) == (
        True, False)
    assert (gastrocnemius("pull-only").one_sided, gastrocnemius("pull-only").pull_only) == (
        True, True)
    assert not gastrocnemius("two-sided").one_sided
    with pytest.raises(pl.ParameterError, match="'pull-only'"):
        pl.paper_muscles("1", gastrocnemius="both")


def posturelab(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "posturelab", *args], capture_output=True,
                          text=True, timeout=600)


def test_help_says_what_each_gastrocnemius_does():
    out = " ".join(posturelab("simulate", "--help").stdout.split())
    assert "one-sided: the paper's real gastrocnemius, acting only while its stretch θ2 >= 0" \
        in out
    assert "pull-only: one-sided and also slack while its torque" in out
    assert "two-sided (default): the paper's artificial antagonist" in out


@pytest.mark.parametrize("form", ["one-sided", "pull-only"])
def test_simulate_and_poles_give_one_verdict(form):
    """The issue's case: the forward case 1 run with the real gastrocnemius falls, and
    simulate and poles say the same thing about upright (it depends on the side)."""
    case = ("--case", "1", "--gastrocnemius", form)
    sim = posturelab("simulate", *case, "--disturbance", "forward", "--engine", "compiled",
                     "--json")
    poles = posturelab("poles", *case, "--json")
    assert sim.returncode == 0 and poles.returncode == 0, sim.stderr + poles.stderr
    run, lin = json.loads(sim.stdout), json.loads(poles.stdout)
    assert run["outcome"] == "fell"
    assert run["linear_stability"] == lin["linear_stability"]
    assert lin["linear_stability"]["status"] == "depends on the side" and lin["stable"] is False
    assert "depends on the side" in sim.stderr  # the warning beside the run
    text_sim = posturelab("simulate", *case, "--disturbance", "forward", "--engine",
                          "compiled").stdout
    text_poles = posturelab("poles", *case).stdout
    verdict = next(line for line in text_poles.splitlines() if line.startswith("verdict: "))
    line = next(line for line in text_sim.splitlines() if line.startswith("linear model: "))
    assert line.removeprefix("linear model: ") == verdict.removeprefix("verdict: ")
    assert "stable: depends on the side" in text_poles
    assert f"{form} gastrocnemius" in text_sim.splitlines()[1]


def test_a_published_controller_on_a_body_from_height_and_mass_on_every_command(tmp_path):
    """--controller peterka-2002 --height 1.8 --mass 82: the body is Winter's 1.8 m, 82 kg
    lumped to one link, the gains the preset's times its mgh, on every command."""
    body = pl.lump(pl.body_from_anthropometry(1.8, 82.0), [[1, 2, 3]])
    preset = get_controller("peterka-2002")
    muscles = preset.muscles(body)
    delay = preset.feedback_delay
    c = ("--controller", "peterka-2002", "--height", "1.8", "--mass", "82")

    p = posturelab("poles", *c, "--json")
    assert p.returncode == 0, p.stderr
    obj = json.loads(p.stdout)
    assert obj["linear_stability"] == pl.upright_verdict(body, muscles, delay).to_dict()
    assert "one link" in obj["body"]
    assert p.stderr == ("posturelab: note: --controller peterka-2002 is a one-link controller: "
                        "the body is winter H=1.8 m M=82 kg, one link (knee and hip locked)\n")
    np.testing.assert_allclose([z["re"] + 1j * z["im"] for z in obj["poles"]],
                               pl.analyse(body, muscles).poles, rtol=1e-12)

    run = tmp_path / "run.csv"
    p = posturelab("simulate", *c, "--disturbance", "backward", "--speed", "0.1",
                   "--duration", "3", "--sample-rate", "50", "--engine", "compiled",
                   "--out", str(run), "--json")
    assert p.returncode == 0, p.stderr
    want = pl.simulate(body, muscles, pl.VelocityStep.backward(0.1), 3.0, engine="compiled",
                       feedback_delay=delay, proprioceptive_weight=1.0, sample_rate=50.0)
    assert json.loads(p.stdout)["max_abs_theta"] == pytest.approx(
        [float(x) for x in want.max_abs_theta], rel=1e-4)  # (the CLI's tolerances)

    p = posturelab("delay-margin", *c, "--json")
    assert p.returncode == 0, p.stderr
    margin = json.loads(p.stdout)
    assert margin.pop("units") == {"delay_margin": "s", "crossing_frequency": "rad/s"}
    api = pl.delay_margin(body, muscles)
    assert margin.pop("stable_at_every_delay") == (api.stable_without_delay
                                                   and math.isinf(api.delay_margin))
    assert margin == api.to_dict()

    p = posturelab("frf-model", *c, "--bands", "peterka", "--json")
    assert p.returncode == 0, p.stderr
    frf = json.loads(p.stdout)
    model = model_frf(body, muscles, frf["frequency"], input="tilt",
                      output="com_angle", feedback_delay=delay)
    np.testing.assert_allclose([z["re"] + 1j * z["im"] for z in frf["frf"]], model,
                               rtol=1e-9)

    gains = np.abs(model)  # the model's own FRF as data: the fit comes back to the preset
    (tmp_path / "frf.json").write_text(json.dumps({
        "frequency": frf["frequency"], "frf": frf["frf"],
        "coherence": [0.9] * len(gains), "gain_ci95": [[0.9 * g, 1.1 * g] for g in gains],
        "phase_ci95_deg": [[-5.0, 5.0]] * len(gains)}))
    p = posturelab("fit-frf", *c, "--data", str(tmp_path / "frf.json"), "--free",
                   "active_stiffness", "--json")
    assert p.returncode == 0, p.stderr
    fitted = {q["name"]: q["estimate"] for q in json.loads(p.stdout)["parameters"]}
    assert fitted["active_stiffness:ankle"] == pytest.approx(1.35 * body.load_stiffness, rel=1e-3)

    p = posturelab("fit", *c, "--data", str(run), "--disturbance", "backward", "--speed",
                   "0.1", "--free", "feedback_delay", "--json")
    assert p.returncode == 0, p.stderr
    got = json.loads(p.stdout)["parameters"]["feedback_delay"]["estimate"]
    assert got == pytest.approx(delay, rel=1e-4)

    p = posturelab("sweep", *c, "--disturbance", "backward", "--speed", "0.1", "--duration",
                   "3", "--vary", "feedback_delay=0.1:0.15:2", "--out", str(tmp_path / "s.csv"))
    assert p.returncode == 0, p.stderr
    rows = (tmp_path / "s.csv").read_text().splitlines()
    assert len(rows) == 3 and rows[2].startswith("0.15,recovered")

    p = posturelab("stability-map", *c, "--x", "active_stiffness:0:2000", "--y",
                   "active_viscosity:0:800", "--resolution", "4", "--out",
                   str(tmp_path / "d.png"))
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "d.csv").exists()


def test_a_one_link_controller_on_a_three_link_body_is_one_line():
    p = posturelab("simulate", "--controller", "peterka-2002", "--body", "paper",
                   "--disturbance", "backward")
    assert p.returncode == 2 and p.stdout == "" and p.stderr.count("\n") == 1
    assert "--body paper has 3 links" in p.stderr and "get_body" not in p.stderr
