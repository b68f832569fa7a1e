"""``posturelab explore``: the controls and views (against the API), the Flask application,
the loopback server and the command line, and the page itself in a real headless Chromium
(Playwright driving Debian's chromium): a stiffness slider moved, a bad value typed, a
screenshot taken."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

import posturelab as pl
from _browser import explorer_page, needs_browser
from posturelab.errors import ParameterError
from posturelab.explore import CONTROLS, compute_views, create_app, parse_parameters
from posturelab.model.muscles import muscles_for

flask = pytest.importorskip("flask")

CASE1 = [500.0, 300.0, 300.0, 300.0, 300.0]


def _api_poles(stiffness, ratio=0.25):
    return pl.analyse(pl.paper_body(), pl.paper_muscles(stiffness=stiffness,
                                                        viscosity_ratio=ratio))


def test_defaults_and_bounds_come_from_one_table():
    p = parse_parameters({})
    assert p["stiffness:ankle"] == 500.0 and p["perturbation"] == "backward step"
    assert {c.name for c in CONTROLS} == set(p)
    for c in CONTROLS:  # every slider lies inside what the package accepts
        if not c.choices:
            assert c.low <= c.slider_low < c.slider_high <= c.high, c.name
            assert c.low <= c.default <= c.high, c.name
    for fields, words, field in (
            ({"stiffness:ankle": "-5"},
             "ankle stiffness [N·m/rad] must be in [0, 1e+08], got -5", "stiffness:ankle"),
            ({"feedback_delay": "abc"}, "feedback delay τ [s] must be a number, got 'abc'",
             "feedback_delay"),
            ({"mass": True}, "mass [kg] must be a number", "mass"),
            ({"duration": "inf"}, "duration [s] must be in [0.5, 30], got inf", "duration"),
            ({"perturbation": "kick"}, "perturbation must be one of backward step",
             "perturbation"),
            ({"speed": 1}, "unknown control 'speed'", "speed")):
        with pytest.raises(ParameterError) as info:
            parse_parameters(fields)
        assert words in str(info.value) and info.value.field == field


def test_views_are_what_the_api_computes():
    p = parse_parameters({"stiffness:ankle": 800, "feedback_delay": 0.1,
                          "active_stiffness:ankle": 400,
                          "active_viscosity:ankle": 100, "perturbation": "tilt"})
    v = compute_views(p)
    body = pl.paper_body()
    muscles = pl.paper_muscles(stiffness=[800, 300, 300, 300, 300],
                               active_stiffness=[400, 0, 0, 0, 0],
                               active_viscosity=[100, 0, 0, 0, 0])
    lin = pl.analyse(body, muscles)
    np.testing.assert_allclose([z["re"] + 1j * z["im"] for z in v["poles"]], lin.poles)
    roots = pl.rightmost_roots(body, muscles, 0.1, count=6)
    np.testing.assert_allclose([z["re"] + 1j * z["im"] for z in v["roots"]], roots)
    assert v["stable"] == (roots[0].real < 0)
    margin = pl.delay_margin(body, muscles, max_delay=1.0).delay_margin
    assert (v["delay_margin"] is None if math.isinf(margin)
            else v["delay_margin"] == pytest.approx(margin))
    assert compute_views(parse_parameters({}))["delay_margin"] == pytest.approx(
        pl.delay_margin(body, pl.paper_muscles(stiffness=CASE1), max_delay=1.0).delay_margin)
    assert v["delayed_part"] == "active"
    frf = pl.frequency.model.model_frf(body, muscles, v["frf"]["frequency"], input="tilt",
                                       output="com_angle", feedback_delay=0.1)
    np.testing.assert_allclose(v["frf"]["gain"], np.abs(frf), rtol=1e-8)
    run = pl.simulate(body, muscles, None, 5.0, engine="compiled", feedback_delay=0.1,
                      tilt=pl.model.tilt.SineTilt(0.02, 0.2), sample_rate=100.0)
    np.testing.assert_allclose(v["run"]["theta"][0], run.theta[:, 0], atol=1e-6)
    assert v["run"]["outcome"] == run.outcome.kind
    assert len(v["run"]["frames"]) == math.ceil(run.time.size / 4)


def test_the_application_answers_json_and_never_a_server_page():
    client = create_app().test_client()
    page = client.get("/")
    assert page.status_code == 200 and b'id="stiffness:ankle"' in page.data
    assert b"chart.umd.min.js" in page.data and client.get(
        "/static/chart.umd.min.js").status_code == 200
    ok = client.post("/api/views", json={"stiffness:hip": 350})
    assert ok.status_code == 200 and ok.get_json()["stable"] in (True, False)
    bad = client.post("/api/views", json={"stiffness:hip": -1})
    assert bad.status_code == 422
    assert bad.get_json() == {"error": "hip stiffness [N·m/rad] must be in [0, 1e+08], got -1",
                              "field": "stiffness:hip"}
    for response in (client.post("/api/views", data="not json"),
                     client.post("/api/views", json=[1, 2])):
        assert response.status_code == 422 and "JSON object" in response.get_json()["error"]
    assert client.get("/nothing").status_code == 404
    assert client.get("/nothing").is_json
    huge = client.post("/api/views", data="x" * 100_000, content_type="application/json")
    assert huge.status_code == 413 and huge.is_json


def test_the_server_listens_on_loopback_only():
    import urllib.request

    from posturelab.explore.browser import running_server

    with running_server() as url:
        assert url.startswith("http://127.0.0.1:")
        with urllib.request.urlopen(url, timeout=10) as response:
            assert response.status == 200


def test_cli_explore_bad_port_and_help():
    p = subprocess.run([sys.executable, "-m", "posturelab", "explore", "--port", "70000",
                        "--no-browser"], capture_output=True, text=True, timeout=60)
    assert p.returncode == 2 and "Traceback" not in p.stderr
    assert p.stderr.strip() == ("posturelab: error: port must be an integer in [0, 65535], "
                                "got 70000")
    p = subprocess.run([sys.executable, "-m", "posturelab", "explore", "--help"],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 0 and "--no-browser" in p.stdout and "127.0.0.1" in p.stdout


# -- in a real browser ----------------------------------------------------------------------

def _table(page, cls):
    cells = page.locator(f"#poles td.{cls}[data-re]")
    return np.array([float(c.get_attribute("data-re")) + 1j * float(c.get_attribute("data-im"))
                     for c in cells.all()])


@needs_browser
def test_the_page_in_chromium(tmp_path):
    with explorer_page() as (page, errors):
        np.testing.assert_allclose(_table(page, "pole"), _api_poles(CASE1).poles, rtol=1e-9)
        assert page.locator("#verdict").get_attribute("class") == "stable"

        # move the ankle stiffness slider: 100 N·m/rad is far below the load mgh
        page.locator('input[type=range][data-for="stiffness:ankle"]').fill("100")
        page.wait_for_function("Number(document.body.dataset.updates) >= 2", timeout=30_000)
        want = _api_poles([100.0, 300.0, 300.0, 300.0, 300.0])
        np.testing.assert_allclose(_table(page, "pole"), want.poles, rtol=1e-9)
        assert page.input_value('[id="stiffness:ankle"]') == "100"
        verdict = page.locator("#verdict")
        assert verdict.get_attribute("class") == ("stable" if want.stable else "unstable")
        assert ("unstable" in verdict.inner_text()) == (not want.stable)
        assert float(page.evaluate("document.body.dataset.roundTrip")) > 0

        # a bad value: the message names the field, value and range; the views stay
        before = _table(page, "pole")
        page.fill('[id="stiffness:ankle"]', "-5")
        page.wait_for_selector("#message:not([hidden])", timeout=30_000)
        assert page.inner_text("#message") == (
            "ankle stiffness [N·m/rad] must be in [0, 1e+08], got -5")
        assert "invalid" in page.get_attribute('[id="stiffness:ankle"]', "class")
        np.testing.assert_array_equal(_table(page, "pole"), before)

        # a good value again clears the message
        page.fill('[id="stiffness:ankle"]', "700")
        page.wait_for_selector("#message[hidden]", state="attached", timeout=30_000)
        np.testing.assert_allclose(_table(page, "pole"),
                                   _api_poles([700.0, 300.0, 300.0, 300.0, 300.0]).poles,
                                   rtol=1e-9)
        # a bad value in a box that then goes grey no longer blocks the page
        page.select_option("#body", "height and mass")
        page.wait_for_function("Number(document.body.dataset.updates) >= 4", timeout=30_000)
        page.fill("#height", "5")
        page.wait_for_selector("#message:not([hidden])", timeout=30_000)
        assert page.inner_text("#message").startswith("height [m] must be in [0.5, 2.5]")
        page.select_option("#body", "paper")
        page.wait_for_selector("#message[hidden]", state="attached", timeout=30_000)
        assert page.is_disabled("#height")
        assert "invalid" not in (page.get_attribute("#height", "class") or "")
        np.testing.assert_allclose(_table(page, "pole"),
                                   _api_poles([700.0, 300.0, 300.0, 300.0, 300.0]).poles,
                                   rtol=1e-9)
        shot = tmp_path / "explore.png"
        page.screenshot(path=str(shot), full_page=True)
    assert shot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and shot.stat().st_size > 50_000
    assert errors == []


def test_values_the_page_could_send_that_the_package_refuses_are_named():
    """Cross-field bounds land on a field; odd numbers get one line; no 500."""
    for fields, words, field in (
            ({"stiffness:ankle": 1e8}, "ankle viscosity = viscosity ratio × stiffness = "
             "2.5e+07 N·m·s/rad must be at most 1e+07", "stiffness:ankle"),
            ({"stiffness:ankle": 10**400}, "ankle stiffness [N·m/rad] must be a number, "
             "got '1000", "stiffness:ankle"),
            ({"mass": "1_000"}, "mass [kg] must be a number, got '1_000'", "mass"),
            ({"height": ""}, "height [m] must be a number, got an empty box", "height"),
            ({"step_speed": 0}, "step speed [m/s] must be in [0.01, 20], got 0", "step_speed")):
        with pytest.raises(ParameterError) as info:
            parse_parameters(fields)
        assert str(info.value).startswith(words) and info.value.field == field
    client = create_app().test_client()
    huge = client.post("/api/views", data='{"stiffness:ankle": 1' + "0" * 400 + "}",
                       content_type="application/json")
    assert huge.status_code == 422 and huge.get_json()["field"] == "stiffness:ankle"
    undamped = compute_views(parse_parameters({"viscosity_ratio": 0}))
    assert undamped["verdict"].startswith("marginal") and not undamped["stable"]


def test_the_stick_figure_gets_the_surface_tilt():
    v = compute_views(parse_parameters({"perturbation": "tilt", "tilt_amplitude": 0.05,
                                        "tilt_frequency": 0.5}))
    alpha = np.array(v["run"]["surface_tilt"])
    t = np.arange(alpha.size) / v["run"]["frame_rate"]
    np.testing.assert_allclose(alpha, 0.05 * np.sin(2 * np.pi * 0.5 * t), atol=1e-6)
    assert len(v["run"]["frames"]) == alpha.size
    still = compute_views(parse_parameters({}))["run"]["surface_tilt"]
    assert set(still) == {0.0}


def test_the_one_link_body_and_the_controller_presets_are_the_api_s():
    """A one-link body with own gains acts through the ankle pair only; a controller preset
    gives its gains on the body lumped to one link (as `simulate --controller`); the
    verdict is posturelab.upright_verdict's."""
    from posturelab.model.controllers import get_controller

    v = compute_views(parse_parameters({"body": "paper, one link", "stiffness:ankle": 900,
                                        "stiffness:knee": 7}))
    body = pl.get_body("paper-1link")
    lin = pl.analyse(body, muscles_for(1, [900.0]))
    np.testing.assert_allclose([z["re"] + 1j * z["im"] for z in v["poles"]], lin.poles)
    assert v["n_links"] == 1 and len(v["run"]["theta"]) == 1 and v["body"] == "paper-1link"

    p = parse_parameters({"body": "height and mass", "height": 1.8, "mass": 82,
                          "controller": "peterka-2002", "feedback_delay": 0.15})
    v = compute_views(p)
    three = pl.body_from_anthropometry(1.8, 82.0)
    one = pl.lump(three, [[1, 2, 3]])
    assert v["n_links"] == 1 and "one link" in v["body"]
    muscles = get_controller("peterka-2002").muscles(one)
    verdict = pl.upright_verdict(one, muscles, 0.15)
    assert v["linear_stability"] == verdict.to_dict() and v["verdict"] == verdict.describe()
    np.testing.assert_allclose([z["re"] + 1j * z["im"] for z in v["roots"]],
                               pl.rightmost_roots(one, muscles, 0.15, count=2), rtol=1e-10)


@needs_browser
def test_the_page_offers_the_one_link_body_and_the_controller_presets():
    from posturelab.model.controllers import get_controller

    with explorer_page() as (page, errors):
        page.select_option("#body", "paper, one link")
        page.wait_for_function("Number(document.body.dataset.updates) >= 2", timeout=30_000)
        body = pl.get_body("paper-1link")
        want = pl.analyse(body, muscles_for(1, [500.0]))
        np.testing.assert_allclose(_table(page, "pole"), want.poles, rtol=1e-9)
        assert not page.is_disabled('[id="stiffness:ankle"]')
        assert page.is_disabled('[id="stiffness:hip"]')

        page.select_option("#controller", "peterka-2002")
        page.wait_for_function("Number(document.body.dataset.updates) >= 3", timeout=30_000)
        preset = get_controller("peterka-2002")
        assert float(page.input_value("#feedback_delay")) == preset.feedback_delay
        assert page.is_disabled('[id="stiffness:ankle"]') and page.is_disabled("#viscosity_ratio")
        muscles = preset.muscles(body)
        verdict = pl.upright_verdict(body, muscles, preset.feedback_delay)
        np.testing.assert_allclose(_table(page, "pole"), pl.analyse(body, muscles).poles,
                                   rtol=1e-9)
        assert page.inner_text("#verdict") == verdict.describe()
        assert page.locator("#verdict").get_attribute("class") == (
            "stable" if verdict.stable else "unstable")
    assert errors == []


def test_a_controller_through_the_api_is_the_command_line_s():
    """Without τ and W the API takes the controller's (as `simulate --controller`); a gain
    sent with a controller is refused, naming the field; JSON's true is quoted as true."""
    from posturelab.model.controllers import get_controller

    preset = get_controller("peterka-2002")
    client = create_app().test_client()
    ok = client.post("/api/views", json={"body": "paper, one link",
                                         "controller": "peterka-2002"})
    assert ok.status_code == 200
    body = pl.get_body("paper-1link")
    want = pl.upright_verdict(body, preset.muscles(body), 0.15)
    assert preset.feedback_delay == 0.15
    assert ok.get_json()["linear_stability"] == want.to_dict()
    p = parse_parameters({"controller": "peterka-2002", "proprioceptive_weight": 0.5})
    assert (p["feedback_delay"], p["proprioceptive_weight"]) == (0.15, 0.5)
    assert parse_parameters({})["feedback_delay"] == 0.0  # own gains: the control's default
    bad = client.post("/api/views", json={"controller": "peterka-2002",
                                          "active_stiffness:ankle": 3000})
    assert bad.status_code == 422
    assert bad.get_json()["field"] == "active_stiffness:ankle"
    assert "set by the controller peterka-2002" in bad.get_json()["error"]
    true = client.post("/api/views", json={"stiffness:ankle": True})
    assert true.status_code == 422
    assert true.get_json()["error"].endswith("must be a number, got true")
