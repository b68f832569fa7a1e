"""The explorer under hostile requests, over real sockets: every error is JSON with a 4xx
(never an HTML page, never a 500), and a busy port is one line and exit 2."""

from __future__ import annotations

import json
import socket
import subprocess
import sys
from urllib.parse import urlparse

import pytest

pytest.importorskip("flask")

from _browser import explorer_page, needs_browser  # noqa: E402
from posturelab.explore.app import MAX_JSON_DEPTH  # noqa: E402
from posturelab.explore.browser import running_server  # noqa: E402


def _exchange(port: int, request: bytes) -> tuple[int, dict[str, str], bytes]:
    """Send raw bytes, read the whole answer: (status, headers, body)."""
    with socket.create_connection(("127.0.0.1", port), timeout=30) as s:
        s.sendall(request)
        data = b""
        while chunk := s.recv(65536):
            data += chunk
    head, _, body = data.partition(b"\r\n\r\n")
    lines = head.decode("latin-1").split("\r\n")
    status = int(lines[0].split()[1])
    headers = {k.strip().lower(): v.strip() for k, _, v in (h.partition(":") for h in lines[1:])}
    return status, headers, body


def _post(port: int, body: bytes) -> bytes:
    return (b"POST /api/views HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
            b"Content-Length: %d\r\nConnection: close\r\n\r\n" % len(body) + body)


@pytest.fixture(scope="module")
def port():
    with running_server() as url:
        yield urlparse(url).port


@pytest.mark.parametrize("request_bytes, code", [
    (b"GARBAGE\r\n\r\n", 400),
    (b'GET "/x" HTTP/1.1 junk\r\n\r\n', 400),
    (b"GET / HTTP/9.9\r\nHost: x\r\n\r\n", 400),
    (b"GET /" + b"a" * 70_000 + b" HTTP/1.1\r\nHost: x\r\n\r\n", 414),
    (b"GET / HTTP/1.1\r\nHost: x\r\nX-Long: " + b"b" * 70_000 + b"\r\n\r\n", 431),
    (b"GET /nothing HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n", 404),
])
def test_a_malformed_request_gets_json_with_a_4xx(port, request_bytes, code):
    status, headers, body = _exchange(port, request_bytes)
    assert status == code
    assert headers["content-type"] == "application/json"
    answer = json.loads(body)
    assert answer["field"] is None and answer["error"] and "<" not in answer["error"]


@pytest.mark.parametrize("body", [
    b"[" * 3000 + b"]" * 3000,
    b'{"a":' * 3000 + b"1" + b"}" * 3000,
    b"[" * (MAX_JSON_DEPTH + 1) + b"]" * (MAX_JSON_DEPTH + 1),
    b"\xff\xfe{}",
    b"[1, 2]",
])
def test_a_deeply_nested_or_malformed_body_is_422_json(port, body):
    status, headers, answer = _exchange(port, _post(port, body))
    assert status == 422 and headers["content-type"] == "application/json"
    assert "JSON object" in json.loads(answer)["error"]


def test_brackets_inside_strings_are_not_nesting(port):
    status, _, answer = _exchange(port, _post(port, b'{"x": "' + b"[" * 50 + b'"}'))
    assert status == 422 and json.loads(answer) == {"error": "unknown control 'x'",
                                                    "field": "x"}
    status, _, answer = _exchange(port, _post(port, b'{"stiffness:hip": 350}'))
    assert status == 200 and "stable" in json.loads(answer)


def test_a_busy_port_is_one_line_and_exit_2():
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen(1)
        taken = busy.getsockname()[1]
        p = subprocess.run([sys.executable, "-m", "posturelab", "explore", "--port",
                            str(taken), "--no-browser"], capture_output=True, text=True,
                           timeout=60)
    assert p.returncode == 2, p.stderr
    assert p.stderr.strip().splitlines() == [
        f"posturelab: error: cannot listen on 127.0.0.1:{taken}: Address already in use "
        "(give another --port, or 0 for a free one)"]
    assert p.stdout == ""


def test_an_unstable_loop_gets_a_notice_instead_of_an_frf():
    from posturelab.explore import compute_views, parse_parameters

    stable = compute_views(parse_parameters({}))
    assert stable["stable"] and stable["frf"]["note"] is None
    assert len(stable["frf"]["gain"]) == len(stable["frf"]["frequency"]) > 100
    unstable = compute_views(parse_parameters({"stiffness:ankle": 100}))
    assert not unstable["stable"]
    assert unstable["frf"]["gain"] == unstable["frf"]["frequency"] == []
    assert unstable["frf"]["note"].startswith(
        "the loop is unstable at this delay: an FRF cannot be measured")
    delayed = compute_views(parse_parameters({"feedback_delay": 0.2}))  # past the margin
    assert not delayed["stable"] and "unstable at this delay" in delayed["frf"]["note"]


@needs_browser
def test_the_page_shows_the_notice_and_gives_the_frf_room(tmp_path):
    with explorer_page() as (page, errors):
        assert page.is_hidden("#frf-note")
        gain = page.locator("#frf-gain").bounding_box()
        poles = page.locator("#poles-chart").bounding_box()
        assert gain["width"] >= poles["width"] and gain["height"] >= 200
        page.fill('[id="stiffness:ankle"]', "100")
        page.wait_for_function("Number(document.body.dataset.updates) >= 2", timeout=60_000)
        assert page.is_visible("#frf-note")
        assert "an FRF cannot be measured" in page.inner_text("#frf-note")
        page.screenshot(path=str(tmp_path / "unstable.png"), full_page=True)
    assert errors == []


def test_a_body_not_declared_json_is_refused(port):
    request = (b"POST /api/views HTTP/1.1\r\nHost: x\r\nContent-Type: text/plain\r\n"
               b"Content-Length: 2\r\nConnection: close\r\n\r\n{}")
    status, headers, body = _exchange(port, request)
    assert status == 422 and "JSON object" in json.loads(body)["error"]
