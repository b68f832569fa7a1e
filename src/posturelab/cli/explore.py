"""``posturelab explore``: the interactive explorer in the web browser."""

from __future__ import annotations

import argparse

DESCRIPTION = """\
Serve a page on http://127.0.0.1:PORT/ (this machine only) and open it in the web
browser: move the body, the five pair stiffnesses, the viscosity ratio, the active
gains, the feedback delay, the proprioceptive weight or the perturbation, and the
poles with the delay's rightmost roots, the stability verdict, the delay margin, the
tilt-to-CoM frequency response, a simulated response (angles and the CoG phase plane,
compiled engine) and a stick figure update at once. Ctrl-C stops the server.
Needs Flask: pip install 'posturelab[explore]'.
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab explore``."""
    p.add_argument("--port", type=int, default=8050,
                   help="TCP port on 127.0.0.1 (default 8050; 0 picks a free one).")
    p.add_argument("--no-browser", action="store_true",
                   help="do not open the page in the web browser; just serve it.")


def run(args: argparse.Namespace) -> int:
    from ..errors import PostureLabError

    try:
        import flask  # noqa: F401
    except ModuleNotFoundError:
        raise PostureLabError("explore needs Flask: pip install 'posturelab[explore]'") from None
    from ..explore.app import serve

    try:
        serve(args.port, open_browser=not args.no_browser)
    except KeyboardInterrupt:  # (Werkzeug's loop returns on Ctrl-C; a signal elsewhere)
        pass
    print("posturelab explore: stopped")
    return 0
