"""What the explorer shows, as pure functions of its parameters.

:data:`CONTROLS` states every control once: its name (the model's parameters by the
parameter table's names, ``stiffness:ankle``, ``feedback_delay``, …), words, unit, default,
the range the package accepts (the table's bounds) and the range of its slider. The page is
built from it and :func:`parse_parameters` checks a request against it, so the page and the server
cannot disagree. :func:`compute_views` turns checked parameters into the numbers and
figures of the page with the public API only: :func:`posturelab.analyse`,
:func:`posturelab.rightmost_roots`, :func:`posturelab.delay_margin`,
:func:`posturelab.frequency.model.model_frf` and :func:`posturelab.simulate` on the
compiled engine.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..model.anthropometry import HEIGHT_RANGE, MASS_RANGE
from ..model.controllers import CONTROLLERS
from ..model.muscles import PAPER_PAIR_NAMES, STIFFNESS_CASES
from ..model.platform import MAX_PLATFORM_SPEED
from ..model.tilt import MAX_TILT
from ..parameters import (
    MAX_FEEDBACK_DELAY,
    MAX_PAIR_VISCOSITY,
    QUANTITIES,
    TORQUE_FEEDBACK_TIME_CONSTANT,
    renamed,
)

__all__ = ["Control", "CONTROLS", "PAIRS", "BODIES", "OWN_GAINS", "parse_parameters",
           "build_body", "build_model", "compute_views", "controller_presets"]

#: The paper's five pairs, in the order of their stiffness arrays.
PAIRS = PAPER_PAIR_NAMES


@dataclass(frozen=True)
class Control:
    """One control of the page.

    Attributes
    ----------
    name : str
        The request field.
    label : str
        Words on the page.
    unit : str
        Unit of the value ("" for none, or for a choice).
    default : float or str
        The starting value.
    low, high : float
        The values the package accepts, inclusive. [unit]
    slider_low, slider_high, step : float
        The slider's range and step (a typed value may go beyond the slider). [unit]
    group : str
        Where on the page it sits.
    choices : tuple of str
        For a choice, its options (then ``low`` … ``step`` are unused).
    """

    name: str
    label: str
    unit: str
    default: float | str
    low: float = 0.0
    high: float = 0.0
    slider_low: float = 0.0
    slider_high: float = 0.0
    step: float = 1.0
    group: str = ""
    choices: tuple[str, ...] = ()


def _table(name: str, label: str, default: float, slider_high: float, step: float,
           group: str) -> Control:
    """A control of a model parameter: its name, unit and range the parameter table's."""
    q = QUANTITIES[name.partition(":")[0]]
    return Control(name, label, q.unit, default, q.low, q.high, q.low, slider_high, step, group)


def _pair_controls() -> tuple[Control, ...]:
    out = []
    # the defaults: Table I, case 1, the paper's stable reference gains
    for name, k in zip(PAIRS, STIFFNESS_CASES["1"], strict=True):
        out.append(_table(f"stiffness:{name}", f"{name} stiffness", float(k), 3000.0, 10.0,
                          "pairs"))
    for name in PAIRS:
        out.append(_table(f"active_stiffness:{name}", f"{name} active stiffness", 0.0, 3000.0,
                          10.0, "active"))
    for name in PAIRS:
        out.append(_table(f"active_viscosity:{name}", f"{name} active viscosity", 0.0, 1000.0,
                          5.0, "active"))
    return tuple(out)


#: The bodies of the page: the paper's (three links) or one from height and mass, each also
#: as one rigid link (knee and hip locked: the inverted pendulum of a one-link controller).
BODIES = ("paper", "height and mass", "paper, one link", "height and mass, one link")
#: "own gains" (the pair controls) or a published one-link controller
#: (:data:`posturelab.model.controllers.CONTROLLERS`), whose gains scale with the body's mgh.
OWN_GAINS = "own gains"

#: Every control of the explorer, in page order.
CONTROLS: tuple[Control, ...] = (
    Control("body", "body", "", "paper", group="body", choices=BODIES),
    Control("controller", "controller", "", OWN_GAINS, group="body",
            choices=(OWN_GAINS, *CONTROLLERS)),
    Control("height", "height", "m", 1.75, *HEIGHT_RANGE, 1.0, 2.2, 0.01, "body"),
    Control("mass", "mass", "kg", 75.0, *MASS_RANGE, 30.0, 150.0, 0.5, "body"),
    *_pair_controls(),
    _table("viscosity_ratio", "viscosity ratio L/K", 0.25, 1.0, 0.01, "pairs"),
    _table("feedback_delay", "feedback delay τ", 0.0, 0.3, 0.005, "neural"),
    _table("proprioceptive_weight", "proprioceptive weight W", 1.0, 1.0, 0.05, "neural"),
    _table("visual_weight", "visual weight W_v", 0.0, 1.0, 0.05, "neural"),
    _table("torque_feedback_gain", "torque feedback gain K_t", 0.0, 3.0, 0.05, "neural"),
    Control("torque_feedback_time_constant", "torque feedback time constant τ_t", "s",
            TORQUE_FEEDBACK_TIME_CONSTANT, QUANTITIES["torque_feedback_time_constant"].low,
            QUANTITIES["torque_feedback_time_constant"].high, 0.5, 100.0, 0.5, "neural"),
    Control("perturbation", "perturbation", "", "backward step", group="perturbation",
            choices=("backward step", "forward step", "tilt", "visual tilt")),
    Control("step_speed", "step speed", "m/s", 0.3, 0.01, MAX_PLATFORM_SPEED, 0.01, 2.0, 0.01,
            "perturbation"),
    Control("tilt_amplitude", "tilt amplitude", "rad", 0.02, 0.0, MAX_TILT, 0.0, 0.1, 0.002,
            "perturbation"),
    Control("tilt_frequency", "tilt frequency", "Hz", 0.2, 0.01, 10.0, 0.05, 2.0, 0.05,
            "perturbation"),
    Control("duration", "duration", "s", 5.0, 0.5, 30.0, 0.5, 20.0, 0.5, "perturbation"),
)
_BY_NAME = {c.name: c for c in CONTROLS}


def _number(value: float) -> str:
    return f"{value:g}"


def _shown(raw) -> str:
    """A request value as a message quotes it, cut at 40 characters: a string or a number
    by its repr, JSON's true, false, null, lists and objects as JSON wrote them."""
    if isinstance(raw, bool) or raw is None or isinstance(raw, list | dict):
        import json

        text = json.dumps(raw, ensure_ascii=False, default=str)
    else:
        text = repr(raw if isinstance(raw, str) else str(raw))
    return text if len(text) <= 40 else text[:39] + "…"


#: The controls a controller sets (every pair gain, and the viscosity ratio): refused with
#: one (:func:`parse_parameters`).
_SET_BY_CONTROLLER = tuple(c.name for c in CONTROLS if c.group in ("pairs", "active"))


def parse_parameters(fields: dict) -> dict:
    """Check a request's fields against :data:`CONTROLS`; missing ones take their default.

    With a controller (not :data:`OWN_GAINS`) the feedback delay and the proprioceptive
    weight not given are the controller's (as ``posturelab simulate --controller``; the
    page sends its own), and a pair gain or the viscosity ratio given is refused: the
    controller sets them.

    Returns
    -------
    dict
        Control name -> float (or str for a choice).

    Raises
    ------
    ParameterError
        An unknown field, a value that is not a finite number, a number outside the
        control's range, an unknown choice, or a gain given with a controller; the message
        names the control, the value (as the JSON gave it) and the range, and
        ``error.field`` the control's name.
    """
    if not isinstance(fields, dict):
        raise ParameterError("the request must be a JSON object of control values")
    unknown = sorted(set(fields) - set(_BY_NAME))
    if unknown:
        new = renamed(unknown[0], PAIRS)
        if new in _BY_NAME:
            raise _field_error(unknown[0], f"control {_shown(unknown[0])} is now called "
                               f"{new!r}")
        raise _field_error(unknown[0], f"unknown control {_shown(unknown[0])}")
    out: dict = {}
    for c in CONTROLS:
        raw = fields.get(c.name, c.default)
        if c.choices:
            if raw not in c.choices:
                raise _field_error(c.name, f"{c.label} must be one of "
                                   f"{', '.join(c.choices)}; got {_shown(raw)}")
            out[c.name] = raw
            continue
        try:
            if isinstance(raw, bool) or (isinstance(raw, str) and "_" in raw):
                raise ValueError
            value = float(raw.strip() if isinstance(raw, str) else raw)
        except (TypeError, ValueError, OverflowError):
            got = ("an empty box (or one the browser could not read as a number)"
                   if isinstance(raw, str) and not raw.strip() else _shown(raw))
            raise _field_error(c.name, f"{c.label} [{c.unit}] must be a number, got "
                               f"{got}") from None
        if not math.isfinite(value) or not c.low <= value <= c.high:
            raise _field_error(c.name, f"{c.label} [{c.unit}] must be in "
                               f"[{_number(c.low)}, {_number(c.high)}], got {_number(value)}")
        out[c.name] = value
    if out["controller"] != OWN_GAINS:  # its gains, and its τ and W unless given
        preset = CONTROLLERS[out["controller"]]
        given = [name for name in _SET_BY_CONTROLLER if name in fields]
        if given:
            raise _field_error(given[0], f"{_BY_NAME[given[0]].label} ({given[0]}) is set "
                               f"by the controller {out['controller']}: leave it out, or "
                               f"choose {OWN_GAINS!r}")
        for name in ("feedback_delay", "proprioceptive_weight"):
            if name not in fields:
                out[name] = float(getattr(preset, name))
    if out["proprioceptive_weight"] + out["visual_weight"] > 1.0 + 1e-12:
        raise _field_error("visual_weight", (
            f"proprioceptive weight W + visual weight W_v must be at most 1 (the rest is "
            f"graviceptive), got {_number(out['proprioceptive_weight'])} + "
            f"{_number(out['visual_weight'])}"))
    if out["torque_feedback_time_constant"] <= 0:  # the table's range is open at 0
        raise _field_error("torque_feedback_time_constant", "torque feedback time constant "
                           "τ_t [s] must be > 0, got 0")
    if out["torque_feedback_gain"] > 0 and out["feedback_delay"] <= 0:
        raise _field_error("torque_feedback_gain", "torque feedback filters the delayed "
                           "active torque: give a feedback delay τ > 0 with K_t > 0")
    for name in PAIRS:  # a pair's viscosity is ratio × stiffness: its bound, on the stiffness
        viscosity = out["viscosity_ratio"] * out[f"stiffness:{name}"]
        if viscosity > MAX_PAIR_VISCOSITY:
            raise _field_error(f"stiffness:{name}", (
                f"{name} viscosity = viscosity ratio × stiffness = {_number(viscosity)} "
                f"N·m·s/rad must be at most {_number(MAX_PAIR_VISCOSITY)} (lower the "
                f"{name} stiffness or the viscosity ratio)"))
    return out


def _field_error(field: str, message: str) -> ParameterError:
    error = ParameterError(message)
    error.field = field
    return error


def controller_presets() -> dict:
    """What the page fills in when a controller is chosen: its feedback delay τ [s] and
    proprioceptive weight W [-], by name, and its citation."""
    return {name: {"feedback_delay": c.feedback_delay,
                   "proprioceptive_weight": c.proprioceptive_weight,
                   "citation": c.citation}
            for name, c in CONTROLLERS.items()}


def build_body(p: dict):
    """The body of the checked parameters ``p``: a one-link body for a one-link choice or a
    controller (the three-link body lumped, as ``posturelab simulate --controller`` does)."""
    import posturelab as pl

    if p["body"].startswith("paper"):
        body = pl.paper_body()
    else:
        body = pl.body_from_anthropometry(p["height"], p["mass"])
    if p["body"].endswith("one link") or p["controller"] != OWN_GAINS:
        from ..model.anthropometry import one_link

        body = (pl.get_body("paper-1link") if p["body"].startswith("paper")
                else one_link(body))
    return body


def build_model(p: dict):
    """The body, muscle set, disturbance and tilt the checked parameters ``p`` describe.

    A controller gives every gain (scaled by the body's mgh); the feedback delay and the
    proprioceptive weight are ``p``'s (:func:`parse_parameters` fills in the controller's
    when a request leaves them out; the page sets them to the controller's when it is
    chosen). On a one-link body with own gains only the ankle pair acts.
    """
    import posturelab as pl

    from ..model.muscles import muscles_for
    from ..model.tilt import SineTilt

    body = build_body(p)
    if p["controller"] != OWN_GAINS:
        muscles = CONTROLLERS[p["controller"]].muscles(body)
    else:
        names = PAIRS if body.n_links == 3 else ("ankle",)
        active_k = [p[f"active_stiffness:{n}"] for n in names]
        active_l = [p[f"active_viscosity:{n}"] for n in names]
        active = any(v > 0 for v in active_k + active_l)
        muscles = muscles_for(body.n_links, [p[f"stiffness:{n}"] for n in names],
                              viscosity_ratio=p["viscosity_ratio"],
                              active_stiffness=active_k if active else None,
                              active_viscosity=active_l if active else None)
    disturbance, tilt = None, None
    if p["perturbation"] == "backward step":
        disturbance = pl.VelocityStep.backward(p["step_speed"])
    elif p["perturbation"] == "forward step":
        disturbance = pl.VelocityStep.forward(p["step_speed"])
    else:
        tilt = SineTilt(p["tilt_amplitude"], p["tilt_frequency"])
    return body, muscles, disturbance, tilt


def _complex_list(values) -> list[dict]:
    return [{"re": float(z.real), "im": float(z.imag)} for z in values]


def _rounded(values, digits: int = 6) -> list:
    return np.round(np.asarray(values, dtype=float), digits).tolist()


#: Frequencies of the FRF view. [Hz]
FRF_FREQUENCIES = np.logspace(-2, 1, 140)


@functools.lru_cache(maxsize=64)
def _linear(body, muscles):
    """The poles and the delay margin, which depend on the body and gains only: kept for
    the changes of delay, weight or perturbation that follow."""
    import posturelab as pl

    return pl.analyse(body, muscles), pl.delay_margin(body, muscles,
                                                        max_delay=MAX_FEEDBACK_DELAY)
#: Output samples per second of the simulated response. [Hz]
SAMPLE_RATE = 100.0
#: Stick-figure frames per second. [Hz]
FRAME_RATE = 25.0
#: The wall-clock budget of one simulated response. [s]
TIME_LIMIT = 5.0


def compute_views(p: dict) -> dict:
    """Everything the page shows for the checked parameters ``p``
    (:func:`parse_parameters`).

    Returns
    -------
    dict (JSON-ready)
        ``stable``, ``verdict`` (words) and ``linear_stability``
        (:func:`posturelab.upright_verdict`); ``body`` (its name) and ``n_links``;
        ``poles`` at τ = 0 and ``roots`` (the 2N rightmost characteristic roots at τ) as
        {"re", "im"} [1/s]; ``delay_margin`` [s] (None when unstable without delay, inf
        as None with ``no_margin``);
        ``frf`` (frequencies [Hz], gain [-], phase [deg] of the surface tilt's FRF, or of the
        visual scene's with the perturbation "visual tilt"; empty with a ``note`` saying why
        when the loop is not stable at τ, else ``note`` None); ``run`` (outcome words,
        time [s], link angles [rad], CoG position [m] and velocity [m/s], joint positions
        [m] of the stick figure and the surface tilt [rad] at :data:`FRAME_RATE`).
        With torque feedback (``torque_feedback_gain`` > 0) the verdict, ``poles`` and
        ``roots`` are the linear system's with its filter states, ``delay_margin_note``
        says the margin is not computed; the run is on the compiled engine as always.
    """
    import posturelab as pl

    from ..frequency.model import model_frf
    from ..viz.animation import joint_positions

    body, muscles, disturbance, tilt = build_model(p)
    delay, weight = p["feedback_delay"], p["proprioceptive_weight"]
    visual = p["perturbation"] == "visual tilt"  # the sine tilts the scene, not the surface
    stimulus = {"visual_tilt" if visual else "tilt": tilt, "visual_weight": p["visual_weight"]}
    torque_feedback = {"torque_feedback_gain": p["torque_feedback_gain"],
                       "torque_feedback_time_constant": p["torque_feedback_time_constant"]}
    lin, margin = _linear(body, muscles)
    # the one verdict about upright (posturelab poles, simulate and the report give it too)
    verdict = pl.upright_verdict(body, muscles, delay, **torque_feedback)
    engaged = verdict.side(engaged=True)  # the side the model FRF linearises
    roots = engaged.roots
    status = engaged.status
    poles = lin.poles
    margin_note = None
    if p["torque_feedback_gain"] > 0:  # the poles with the filter states
        from ..linear.system import linear_system

        poles = linear_system(body, muscles, delay=0.0, inputs=False,
                              **torque_feedback).poles()[0]
        margin_note = "not computed with torque feedback"
    if status == "stable":
        frf = model_frf(body, muscles, FRF_FREQUENCIES, input="visual-tilt" if visual else "tilt",
                        output="com_angle", feedback_delay=delay, proprioceptive_weight=weight,
                        visual_weight=p["visual_weight"], **torque_feedback)
        frf_view = {"frequency": _rounded(FRF_FREQUENCIES, 9), "gain": _rounded(np.abs(frf), 9),
                    "phase": _rounded(np.degrees(np.unwrap(np.angle(frf))), 4), "note": None}
    else:  # no steady response to measure: say so rather than draw a formula's curve
        word = "marginal (undamped)" if status == "marginal" else "unstable"
        frf_view = {"frequency": [], "gain": [], "phase": [],
                    "note": f"the loop is {word} at this delay: an FRF cannot be measured "
                    "(the sway grows or never settles), so none is drawn"}
    rate = SAMPLE_RATE if tilt is None else max(SAMPLE_RATE, 40.0 * tilt.frequency)
    run = pl.simulate(body, muscles, disturbance, p["duration"],
                      feedback_delay=delay, proprioceptive_weight=weight, **stimulus,
                      sample_rate=rate, time_limit=TIME_LIMIT, **torque_feedback)
    every = max(1, int(round(rate / FRAME_RATE)))
    frames = joint_positions(body, run.theta[::every])
    surface = (np.zeros(len(frames)) if tilt is None or visual
               else np.asarray(tilt.angle_and_rate(run.time[::every])[0], dtype=float))

    outcome = run.outcome
    return {
        "stable": verdict.stable,
        "verdict": verdict.describe(),
        "linear_stability": verdict.to_dict(),
        "body": body.name,
        "n_links": body.n_links,
        "poles": _complex_list(poles),
        "roots": _complex_list(roots),
        "delay_margin": (None if margin.delay_margin is None
                         or math.isinf(margin.delay_margin) else float(margin.delay_margin)),
        "stable_without_delay": bool(margin.stable_without_delay),
        "delay_margin_note": margin_note,
        "delayed_part": "active" if muscles.has_active_feedback else "all",
        "frf": frf_view,
        "run": {"outcome": outcome.kind, "message": outcome.message,
                "time": _rounded(run.time, 6),
                "theta": [_rounded(run.theta[:, i]) for i in range(body.n_links)],
                "link_names": [seg.name for seg in body.segments],
                "cog_x": _rounded(run.cog_position[:, 0]),
                "cog_v": _rounded(run.cog_velocity[:, 0]),
                "frame_rate": FRAME_RATE, "frames": _rounded(frames, 5),
                "surface_tilt": _rounded(surface, 6),
                "height": float(body.lengths.sum())},
    }
