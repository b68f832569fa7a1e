"""The explorer's web application (Flask) and its local server (Werkzeug).

Why Flask: a WSGI micro-framework kept by the Pallets project since 2010, pure Python,
with five small dependencies of its own (Werkzeug, Jinja2 — which posturelab already
uses for its report —, MarkupSafe, itsdangerous, click, blinker), no build step and
no JavaScript toolchain. The page draws its charts in the browser with Chart.js (MIT,
kept since 2014, one file with no dependencies, shipped in ``static/`` with its
licence), so a control change costs one JSON request: the server computes numbers
with the public API and never renders an image.

The server binds to 127.0.0.1 only: nothing outside this machine can reach it.
"""

from __future__ import annotations

import errno
import sys
import threading
from collections.abc import Callable
from typing import TextIO

from ..errors import ParameterError, PostureLabError

__all__ = ["create_app", "serve", "HOST"]

#: The only address the explorer listens on (loopback).
HOST = "127.0.0.1"
#: Largest request body the API reads. [bytes]
MAX_REQUEST_BYTES = 64 * 1024


def create_app():
    """The Flask application: the page at ``/``, the views at ``POST /api/views``.

    ``POST /api/views`` takes a JSON object of control values
    (:data:`posturelab.explore.views.CONTROLS`; missing ones take their defaults) and
    answers 200 with :func:`posturelab.explore.views.compute_views`, or 422 with
    ``{"error": one line, "field": the control}`` for a bad value or a body that is not a
    JSON object (nested deeper than :data:`MAX_JSON_DEPTH` included); a bad request is a
    4xx with ``{"error": …}``; only a bug is 500, never an HTML error page.
    """
    from flask import Flask, jsonify, render_template, request

    from .views import CONTROLS, compute_views, controller_presets, parse_parameters

    app = Flask(__name__, static_folder="static", template_folder="templates")
    app.config["MAX_CONTENT_LENGTH"] = MAX_REQUEST_BYTES
    app.json.sort_keys = False

    @app.get("/")
    def page():
        groups: dict[str, list] = {}
        for c in CONTROLS:
            groups.setdefault(c.group, []).append(c)
        return render_template("explore.html", groups=groups, controls=CONTROLS,
                               presets=controller_presets())

    @app.post("/api/views")
    def views():
        fields = _json_object(request.get_data(cache=False)) if request.is_json else None
        if fields is None:
            return jsonify(error="the request must be a JSON object of control values",
                           field=None), 422
        try:
            return jsonify(compute_views(parse_parameters(fields)))
        except PostureLabError as exc:
            return jsonify(error=str(exc).splitlines()[0],
                           field=getattr(exc, "field", None)), 422

    @app.errorhandler(404)
    @app.errorhandler(405)
    @app.errorhandler(413)
    def client_error(exc):
        return jsonify(error=exc.description, field=None), exc.code

    @app.errorhandler(Exception)
    def server_error(exc):  # a bug: still an answer the page can show
        from werkzeug.exceptions import HTTPException

        if isinstance(exc, HTTPException):
            return jsonify(error=exc.description, field=None), exc.code
        return jsonify(error=f"posturelab could not compute this: {type(exc).__name__}: "
                       f"{exc}", field=None), 500

    return app


#: Deepest nesting of brackets a request body may have (a control value is a number, a
#: string or a short list). [-]
MAX_JSON_DEPTH = 8


def _json_object(body: bytes) -> dict | None:
    """The JSON object ``body`` holds, or None (not UTF-8, not JSON, not an object, or
    nested deeper than :data:`MAX_JSON_DEPTH`: checked before parsing, so a hostile
    nesting never reaches the parser's recursion)."""
    import json

    try:
        text = body.decode("utf-8")
    except UnicodeDecodeError:
        return None
    depth = deepest = 0
    in_string = escaped = False
    for ch in text:
        if in_string:
            if escaped:
                escaped = False
            elif ch == "\\":
                escaped = True
            elif ch == '"':
                in_string = False
        elif ch == '"':
            in_string = True
        elif ch in "[{":
            depth += 1
            deepest = max(deepest, depth)
            if deepest > MAX_JSON_DEPTH:
                return None
        elif ch in "]}":
            depth -= 1
    try:
        value = json.loads(text)
    except (ValueError, RecursionError):
        return None
    return value if isinstance(value, dict) else None


def _json_error_handler(base):
    """``base`` (Werkzeug's request handler) with errors found before the application
    runs (a malformed request line, an unsupported HTTP version, a request line or header
    over 64 KiB) answered as JSON ``{"error": …, "field": null}`` with a 4xx, not an HTML
    page, and no line logged per request."""
    import json

    class JSONErrorHandler(base):
        def log_request(self, code="-", size="-") -> None:  # no line per request
            pass

        def log_error(self, format, *args) -> None:  # nor a line per bad request
            pass

        def send_error(self, code, message=None, explain=None) -> None:
            code = int(code)
            if code >= 500:  # the request's fault (e.g. HTTP/9.9): a client error
                code = 400
            reason = self.responses.get(code, ("error",))[0]
            if self.request_version == "HTTP/0.9":  # a line too malformed to say its
                self.request_version = "HTTP/1.0"   # version still gets a status line
            body = json.dumps({"error": f"{code} {reason}: {message or reason}",
                               "field": None}).encode("utf-8")
            self.send_response(code, reason)
            self.send_header("Content-Type", "application/json")
            self.send_header("Connection", "close")
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.close_connection = True
            if self.command != "HEAD" and code >= 200 and code not in (204, 304):
                self.wfile.write(body)

    return JSONErrorHandler


def serve(port: int = 8050, *, open_browser: bool = True, stream: TextIO | None = None,
          on_ready: Callable[[object], None] | None = None) -> None:
    """Serve the explorer on http://127.0.0.1:PORT/ until interrupted.

    Parameters
    ----------
    port : int
        TCP port, 0 … 65535; 0 picks a free one. [-]
    open_browser : bool
        Open the page in the user's web browser once the server listens.
    stream : text stream, optional
        Where the address is printed (standard output by default).
    on_ready : callable, optional
        Called with the server once it listens (``server.server_port``, ``shutdown()``:
        for tests that run it in a thread).

    Raises
    ------
    ParameterError
        A port outside 0 … 65535, or one already in use.
    """
    import socket

    from werkzeug.serving import WSGIRequestHandler, make_server

    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise ParameterError(f"port must be an integer in [0, 65535], got {port!r}")
    # Listen here, not in Werkzeug (which prints two lines and exits 1 on a busy port).
    listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        listener.bind((HOST, port))
        listener.listen(128)
    except OSError as exc:
        listener.close()
        hint = " (give another --port, or 0 for a free one)" if exc.errno == errno.EADDRINUSE \
            else ""
        raise ParameterError(f"cannot listen on {HOST}:{port}: {exc.strerror or exc}{hint}"
                             ) from None
    try:
        server = make_server(HOST, port, create_app(), threaded=True,
                             request_handler=_json_error_handler(WSGIRequestHandler),
                             fd=listener.fileno())
    finally:
        listener.close()  # (the server holds its own duplicate)
    server.server_name, server.server_port = HOST, server.port
    url = f"http://{HOST}:{server.server_port}/"
    print(f"posturelab explore: serving {url} (Ctrl-C to stop)", file=stream or sys.stdout,
          flush=True)
    if open_browser:
        import webbrowser

        threading.Thread(target=webbrowser.open, args=(url,), daemon=True).start()
    if on_ready is not None:
        on_ready(server)
    try:
        server.serve_forever()
    finally:
        server.server_close()
