"""``posturelab explore``: an interactive explorer of the model in the web browser.

Move a control (body, pair stiffnesses, viscosity ratio, active gains, feedback delay,
proprioceptive weight, perturbation) and the page shows at once the poles and the
rightmost characteristic roots with the delay, the stability verdict, the delay
margin, the tilt-to-CoM frequency response, a simulated response on the compiled
engine (link angles and the centre-of-gravity phase plane) and a moving stick figure.

* :mod:`posturelab.explore.views`: the controls, stated once, and the views as pure
  functions of them (the public API only).
* :mod:`posturelab.explore.app`: the Flask application and the loopback server.

Needs Flask (``pip install 'posturelab[explore]'``).
"""

from .app import HOST, create_app, serve
from .views import CONTROLS, compute_views, parse_parameters

__all__ = ["HOST", "create_app", "serve", "CONTROLS", "compute_views", "parse_parameters"]

from .._lazy import submodule_getattr  # noqa: E402

__getattr__ = submodule_getattr(__name__, __path__)
