"""The compiled engine: the model of :mod:`posturelab.model` in C.

:func:`integrate_compiled` runs a :class:`~posturelab.simulation.setup.RunSetup` and
returns the same :class:`~posturelab.simulation.results.SimulationResult` as the
reference engine (``posturelab.simulate(..., engine="compiled")``);
:func:`simulate_batch` runs many parameter sets (gains, torque limits, feedback
delays, perturbation sizes) and keeps only their outcomes (:class:`BatchResult`),
spread over the CPU cores. Everything the reference engine does, this one does:
one-sided pairs, the knee free, locked or against its stop, joint torque
saturation, falls by link angle, centre of gravity and centre of pressure, and
neural feedback delay as a delay differential equation (``docs/simulators.md``).

The C sources (``csrc/``, built by ``setup.py`` when the package is installed):
``pl_rhs.c`` (the equation of motion, general N) and ``pl_rhs_small.c`` (generated for
N = 1, 2, 3 by :mod:`._codegen`); ``pl_explicit.c`` (one step routine for every explicit
pair, whose tableau comes from :mod:`._tableaux` as data); ``pl_radau.c`` (Radau IIA of
order 5, the default: the model is stiff); ``pl_history.c`` (the past of a delayed run);
``pl_events.c`` (event functions and roots); ``pl_driver.c`` (the integration loop,
written once); ``pl_module.c`` (the entry points). In Python: :mod:`._encode` (set-up →
arrays), :mod:`._binding` (the structs and the library), :mod:`._layout` (shared codes).

Nothing is compiled at run time: the extension is built at install (a C compiler, a few
seconds). A batch runs in chunks on Python threads; each C call releases the GIL.
"""

from __future__ import annotations

import ctypes
import math
from typing import Any

import numpy as np

from ...model.body import Body
from ...model.muscles import MuscleSet, muscle_set_gains
from ...model.platform import Disturbance
from ..options import RunOptions
from ..results import SimulationResult
from ..setup import prepare_run
from ..tolerances import DEFAULT_ATOL, DEFAULT_RTOL
from . import _encode as enc
from ._batch import BatchResult, batch_threads, simulate_batch
from ._binding import library, pointer
from ._run import METHODS, check_method, default_method, integrate_compiled

__all__ = [
    "DEFAULT_RTOL",
    "DEFAULT_ATOL",
    "METHODS",
    "BatchResult",
    "integrate_compiled",
    "simulate_fast",
    "simulate_batch",
    "batch_threads",
    "default_method",
    "warm_up",
]


def simulate_fast(body: Body, muscles: MuscleSet, disturbance: Disturbance | None = None,
                  duration: float | None = None, **keywords: Any) -> SimulationResult:
    """``posturelab.simulate(..., engine="compiled")``, under its former name.

    The options (fields of :class:`~posturelab.simulation.options.RunOptions` by name, but
    not ``engine``) and the result as :func:`posturelab.simulate`; the tolerances default to
    the compiled engine's (rtol 1e-6, atol 1e-9 [rad, rad/s]) and the method to
    :func:`default_method`.
    """
    from ...errors import ParameterError

    if "engine" in keywords:
        raise ParameterError("simulate_fast always runs the compiled engine; use "
                             "posturelab.simulate(..., engine=...) to choose")
    if duration is not None:
        keywords["duration"] = duration
    options = RunOptions.from_keywords("simulate_fast()", **keywords)
    return integrate_compiled(prepare_run(body, muscles, disturbance, options),
                              options.integrator())


def state_derivative(body: Body, muscles: MuscleSet, state, *, active=None, locked=False,
                     platform_acceleration=(0.0, 0.0), delayed_moments=None,
                     saturation=None, torque_limits=None, general=False) -> np.ndarray:
    """[Θ̇, Θ̈] of the C right-hand side at one state (for tests and checks).

    Parameters
    ----------
    state : array_like, shape (2N,)
        [rad], [rad/s]
    active : array_like, shape (P,), optional
        Which pairs act (1) or are slack (0); all by default. [-]
    locked : bool
        The knee constraint holds.
    platform_acceleration : (float, float)
        (ẍ_d, ÿ_d). [m/s²]
    delayed_moments : array_like, shape (N,), optional
        τ_delayed added to the joint moments. [N·m]
    saturation, torque_limits : array_like, shape (N,), optional
        ±1 where a joint saturates at its limit [N·m].
    general : bool
        Use the general-N code even where generated straight-line code exists.

    Returns
    -------
    numpy.ndarray, shape (2N,)
        [rad/s], [rad/s²]
    """
    n = body.n_links
    P = len(muscles.pairs)
    x = np.ascontiguousarray(state, dtype=float)
    act = np.ones(P) if active is None else np.ascontiguousarray(active, dtype=float)
    g = np.ascontiguousarray(muscle_set_gains(muscles, 0.0))
    lim = np.ascontiguousarray(enc.limits(torque_limits, n))
    sat = np.zeros(n) if saturation is None else np.ascontiguousarray(saturation, dtype=float)
    inp = np.zeros(2 + n)
    inp[:2] = platform_acceleration
    if delayed_moments is not None:
        inp[2:] = delayed_moments
    out = np.empty(2 * n)
    tau = np.empty(n)
    bp = enc.body_array(body)
    E = np.ascontiguousarray(muscles.selection_matrix)
    C = np.ascontiguousarray(muscles.crossing_matrix)
    library().pl_state_derivative(n, P, pointer(bp), pointer(E), pointer(C), pointer(g),
                                  pointer(act), pointer(lim), pointer(sat), pointer(x),
                                  pointer(inp), int(bool(locked)), int(bool(general)),
                                  pointer(out), pointer(tau))
    return out


def rotated_sine_cosine(theta: float, theta_b: float) -> tuple[float, float]:
    """(sin θ, cos θ) as the C right-hand side computes them from those of θ_b (tests)."""
    s, c = ctypes.c_double(), ctypes.c_double()
    library().pl_rotate_value(theta, theta_b, math.sin(theta_b), math.cos(theta_b),
                              ctypes.byref(s), ctypes.byref(c))
    return s.value, c.value


def warm_up(methods: tuple[str, ...] = ("Radau",),
            entries: tuple[str, ...] = ("one", "parallel", "serial")) -> None:
    """Load the engine and check that it runs (nothing is compiled at run time; the
    arguments, which once chose what numba compiled, are kept for compatibility)."""
    for method in methods:
        check_method(method)
    library()

from ..._lazy import submodule_getattr  # noqa: E402

__getattr__ = submodule_getattr(__name__, __path__)
