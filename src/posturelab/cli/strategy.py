"""``posturelab strategy``: the hip fraction across a family of platform translations."""

from __future__ import annotations

import argparse
import functools
import math

from . import UsageError
from ._common import print_json
from ._flags import add_flag, add_flags, add_options

DESCRIPTION = """\
Strategy maps: how much of the sway is the hip (anti-phase) mode of leg and trunk, the hip
fraction Σb²/(Σa² + Σb²) (after Creath et al. 2005), across a family of translations of the
support surface, with a multi-joint controller (an LQR design on the linearised chain,
delayed; posturelab.linear.lqr) and the ankle moment limited to m g x_toe both ways, the
design's τ_max (--ankle-limit-from-foot: m g x_toe toward the toes, m g |x_heel| toward the
heel, what a flat foot carries).

--translation backward|forward --speeds LO:HI:N   transient translations: a ramp-and-hold of
    --displacement D (0.06 m) whose peak speed 2D/T is each speed (after Horak & Nashner
    1986's ramp translations at a range of velocities).
--oscillation A --frequencies LO:HI:N   sinusoidal translations of amplitude A [m]; the hip
    fraction over the steady part (after 2 cycles), and "transition_frequency", the first
    frequency at which the hip mode dominates (hip fraction > 0.5).

--json prints {"runs": [{"speed" or "frequency": …, "hip_fraction": …, "outcome":
"recovered"|"fell"|"failed", "peak_ankle_moment": N·m, "ankle_saturated": bool,
"peak_hip_angle": rad}], "profile", "ankle_torque_limit" (and, with
--ankle-limit-from-foot, "ankle_dorsiflexion_limit", its magnitude), "units", "controller",
"feedback_delay" [s], "delay_margin" [s] and "design_poles" [1/s] of its linear design}.
A run that fell or failed has "hip_fraction": null (so has one that did not move); a single
map's "transition_frequency" is a number or null (none found).
--ankle-torque-limits LO:HI:N  a two-parameter map: the family at each limit [N·m], each
run with its "ankle_torque_limit", and "transition_frequencies": [{"ankle_torque_limit",
"frequency"}] per limit (oscillations) (the sweep does the same with --vary
torque_limit:ankle=… and --strategy, on Dask with --workers).

Example: posturelab strategy --translation backward --speeds 0.05:0.6:8 --json
         posturelab strategy --oscillation 0.05 --frequencies 0.1:1.25:6 --plot map.png
"""


def _grid(text: str, flag: str, unit: str = "", low: float = 0.0, high: float | None = None,
          why: str = ""):
    """``LO:HI:N`` of ``flag`` as N values: 0 < ``low`` <= LO <= HI <= ``high`` [``unit``]
    (``why``: what sets ``low``), the user's values named in a refusal."""
    parts = text.split(":")
    try:
        lo, hi, n = float(parts[0]), float(parts[1]), int(parts[2])
    except (IndexError, ValueError):
        raise UsageError(f"{flag} must be LO:HI:N (numbers, N an integer), got {text!r}") \
            from None
    import math

    if (len(parts) != 3 or not (math.isfinite(lo) and math.isfinite(hi))
            or not (0 < lo <= hi) or not 1 <= n <= 1000):
        raise UsageError(f"{flag} must be LO:HI:N with finite 0 < LO <= HI and 1 <= N <= 1000, "
                         f"got {text!r}")
    if n == 1 and lo != hi:
        raise UsageError(f"{flag} with N = 1 must have LO = HI (one value), got {text!r}")
    if high is not None and hi > high:
        raise UsageError(f"{flag} HI must be at most {high:g} {unit}, got {parts[1].strip()} "
                         f"in {text!r}")
    if lo < low:
        raise UsageError(f"{flag} LO must be at least {low:.9g} {unit}{why}, got "
                         f"{parts[0].strip()} in {text!r}")
    import numpy as np

    return np.linspace(lo, hi, n)


def _within_platform_acceleration(flag: str, top: float, unit: str, other: str,
                                  other_value: float, other_unit: str, peak, largest
                                  ) -> None:
    """Refuse, naming ``flag`` and ``other``, a grid whose largest value ``top`` needs a peak
    platform acceleration ``peak(top)`` beyond ±MAX_PLATFORM_ACCELERATION [m/s²];
    ``largest(acceleration)`` is the largest value that acceleration allows [``unit``]."""
    from ..model.disturbance import MAX_PLATFORM_ACCELERATION

    if not peak(top) <= MAX_PLATFORM_ACCELERATION:
        raise UsageError(f"{flag} up to {top:g} {unit} with {other} {other_value:g} "
                         f"{other_unit} needs a peak platform acceleration of "
                         f"{peak(top):.4g} m/s²; at most {MAX_PLATFORM_ACCELERATION:g} m/s² "
                         f"(at most {largest(MAX_PLATFORM_ACCELERATION):.4g} {unit} with "
                         f"this {other})")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab strategy``."""
    p.add_argument("--body", default="paper", metavar="PRESET",
                   help="body preset (default paper: the paper's three links).")
    from ..model.controllers import MULTIJOINT_CONTROLLERS

    p.add_argument("--controller", default="multijoint-default", metavar="NAME",
                   help="a multi-joint controller preset: "
                   f"{', '.join(MULTIJOINT_CONTROLLERS)} (default multijoint-default; the "
                   "one-link presets have no hip).")
    p.add_argument("--joint-feedback-scale", type=float, default=1.0, metavar="S",
                   help="factor on the controller's gain matrices (default 1).")
    family = p.add_mutually_exclusive_group(required=True)
    add_flag(family, "--translation", ": transient translations in this direction (with "
             "--speeds)")
    family.add_argument("--oscillation", type=float, metavar="AMPLITUDE",
                        help="sinusoidal translations of this amplitude [m] (with "
                             "--frequencies).")
    add_options(p, {"--speeds": ("LO:HI:N", "peak speeds [m/s]."),
                    "--frequencies": ("LO:HI:N", "frequencies [Hz].")})
    p.add_argument("--displacement", type=float, default=None, metavar="M",
                   help="displacement of each transient translation [m] (default 0.06).")
    limit = p.add_mutually_exclusive_group()
    limit.add_argument("--ankle-torque-limit", type=float, metavar="N·m",
                       help="the ankle's torque limit (default: m g x_toe, the foot's).")
    add_flag(limit, "--ankle-limit-from-foot", "of the literature's foot (0.152 × 1.65 m, "
             "the ankle a quarter of it from the heel)")
    limit.add_argument("--ankle-torque-limits", metavar="LO:HI:N",
                       help="a two-parameter map: the family at each of these ankle torque "
                            "limits [N·m] (each run then carries its ankle_torque_limit).")
    add_flag(p, "--engine", "")
    add_flag(p, "--plot", "the map", former=("--figure",), metavar="MAP.png")
    add_flags(p, "--json")


#: The message prefix of a check deeper in -> the option that gives the value.
FIELD_OPTIONS = {"displacement [m]": "--displacement", "amplitude [m]": "--oscillation",
                 "ankle_torque_limit [N·m]": "--ankle-torque-limit",
                 "joint_feedback_scale": "--joint-feedback-scale"}


def run(args: argparse.Namespace) -> int:
    from ._common import naming_given_options

    with naming_given_options(args, FIELD_OPTIONS):  # (a bad value names its option)
        return _run(args)


def _run(args: argparse.Namespace) -> int:
    from ..linear.lqr import multijoint_controller
    from ..model.body import get_body
    from ..simulation.options import MAX_OUTPUT_SAMPLES
    from ..studies.strategy import (
        MAX_FREQUENCY,
        MAX_SPEED,
        MAX_STUDY_RUNS,
        SETTLE_CYCLES,
        STEADY_CYCLES,
        limit_maps,
        lowest_frequency,
        oscillation_map,
        translation_map,
    )

    if args.translation is not None and args.speeds is None:
        raise UsageError("strategy: --translation needs --speeds LO:HI:N")
    if args.oscillation is not None and args.frequencies is None:
        raise UsageError("strategy: --oscillation needs --frequencies LO:HI:N")
    ignored = ([f for f, v in (("--frequencies", args.frequencies),) if v is not None]
               if args.translation is not None else
               [f for f, v in (("--speeds", args.speeds), ("--displacement", args.displacement))
                if v is not None])
    if ignored:
        family = "--translation" if args.translation is not None else "--oscillation"
        raise UsageError(f"strategy: {ignored[0]} does not apply to {family}; drop it")
    if args.plot:
        from ._common import FIGURE_SUFFIXES, check_writable

        check_writable([args.plot], {args.plot: FIGURE_SUFFIXES})
    body = get_body(args.body)
    controller = multijoint_controller(body, args.controller, args.joint_feedback_scale)
    limit = (controller.effort_limits[0] if args.ankle_torque_limit is None
             else args.ankle_torque_limit)
    if args.ankle_limit_from_foot:
        from ..model.limits import foot_moment_limits
        from ..model.options import FOOT_FROM_LITERATURE as FOOT

        limit = foot_moment_limits(body.total_mass * body.gravity, FOOT.heel, FOOT.toe)
    common = dict(engine=args.engine, **controller.run_options())
    if args.translation is not None:
        values = _grid(args.speeds, "--speeds", "m/s", high=MAX_SPEED)
        displacement = 0.06 if args.displacement is None else args.displacement
        _within_platform_acceleration(
            "--speeds", float(values.max()), "m/s", "--displacement", displacement, "m",
            # ramp-and-hold: peak speed 2D/T, peak acceleration 2πD/T² = π v² / (2D)
            lambda v: math.pi * v * v / (2.0 * displacement),
            lambda most: math.sqrt(2.0 * displacement * most / math.pi)
            if displacement > 0 else math.inf)
        make = functools.partial(translation_map, body, controller.muscles,
                                 values, direction=args.translation,
                                 displacement=displacement, **common)
    else:
        rate = 1000.0  # [Hz] (simulate's default sample rate, the runs')
        least = lowest_frequency(rate)
        values = _grid(args.frequencies, "--frequencies", "Hz", least, MAX_FREQUENCY,
                       f" (each run lasts {SETTLE_CYCLES + STEADY_CYCLES} cycles, "
                       f"{SETTLE_CYCLES + STEADY_CYCLES}/LO s, at most {MAX_OUTPUT_SAMPLES:,} "
                       f"samples at {rate:g} Hz)")
        amplitude = args.oscillation
        _within_platform_acceleration(
            "--frequencies", float(values.max()), "Hz", "--oscillation", amplitude, "m",
            lambda f: amplitude * (2.0 * math.pi * f) ** 2,  # A (2πf)²
            lambda most: math.sqrt(most / amplitude) / (2.0 * math.pi)
            if amplitude > 0 else math.inf)
        make = functools.partial(oscillation_map, body, controller.muscles, args.oscillation,
                                 values, **common)
    limits = (None if args.ankle_torque_limits is None else
              _grid(args.ankle_torque_limits, "--ankle-torque-limits", "N·m"))
    total = values.size * (1 if limits is None else limits.size)
    if total > MAX_STUDY_RUNS:
        given = f"{values.size:,}" + ("" if limits is None else f" × {limits.size:,} limits")
        raise UsageError(f"strategy: {given} = {total:,} runs; at most {MAX_STUDY_RUNS:,} "
                         "(fewer values in --speeds/--frequencies or --ankle-torque-limits; "
                         "sweep --strategy runs larger maps, on Dask with --workers)")
    make = functools.partial(make, progress=_Overall(total, values.size))
    if limits is not None:
        return _two_parameters(args, controller, limit_maps(make, limits))
    result = make(ankle_torque_limit=limit)
    if args.plot:
        from ..viz.maps import strategy_map_figure
        from ..viz.plots import save_figure

        save_figure(strategy_map_figure(result), args.plot)
    out = {**result.to_dict(), **_design(controller),
           "joint_feedback_scale": args.joint_feedback_scale}
    if args.json:
        print_json(out)
        return 0
    shown = (f"{limit:.4g} N·m" if result.ankle_dorsiflexion_limit is None else
             f"{-result.ankle_dorsiflexion_limit:.4g} … {result.ankle_torque_limit:.4g} N·m")
    print(f"{result.profile}; ankle torque limit {shown}; controller {controller.name}")
    for r in result.runs:
        share = "—" if r.outcome != "recovered" else _share(r, "{:6.3f}")
        print(f"  {result.variable} {r.value:8.4g}  hip fraction {share:>6}  "
              f"{r.outcome}{'  (ankle saturated)' if r.ankle_saturated else ''}")
    if result.kind == "oscillation":
        found = result.transition_frequency
        print("transition frequency: " + ("none found (no recovered run with hip fraction "
                                          "> 0.5)" if found is None else f"{found:.4g} Hz"))
    return 0


class _Overall:
    """The progress of every map's runs as one count: after the second run, one line on
    standard error with the runs and about how long they take in all, if over 10 s (as
    :class:`~posturelab.cli._common.ExpectedTime` says it; timed from the end of the first
    run, which also loads the engine)."""

    def __init__(self, total: int, per_map: int, stream=None) -> None:
        self.total, self.per_map, self.maps_done = total, per_map, 0
        self.stream, self.first, self.said = stream, None, False

    def __call__(self, done: int, total: int) -> None:
        import sys
        import time

        overall = self.maps_done * self.per_map + done
        if done >= total:
            self.maps_done += 1
        now = time.perf_counter()
        if self.first is None:
            self.first = now
            return
        if self.said or overall >= self.total:
            return
        self.said = True
        expected = (now - self.first) * (self.total - 1) / (overall - 1)
        if expected > 10.0:
            about = f"{expected / 60:.0f} min" if expected >= 120 else f"{expected:.0f} s"
            print(f"posturelab: strategy: {self.total:,} runs, about {about} in all",
                  file=self.stream or sys.stderr, flush=True)


def _share(run, spec: str) -> str:
    """A run's hip fraction in words when it has none: "fell", "failed" or "none"."""
    if run.outcome != "recovered":
        return run.outcome
    return "none" if run.hip_fraction != run.hip_fraction else spec.format(run.hip_fraction)


def _design(controller) -> dict:
    """The controller's name and its linear design: the delay and the delayed loop's margin
    [s], the designed poles [1/s]."""
    check = controller.check()
    return {"controller": controller.name, "feedback_delay": controller.feedback_delay,
            "delay_margin": check.delay_margin,
            "design_poles": [{"re": float(z.real), "im": float(z.imag)}
                             for z in check.design_poles]}


def _two_parameters(args: argparse.Namespace, controller, maps) -> int:
    """Print (and draw) a map over ankle torque limits."""
    from ..studies.strategy import maps_to_dict

    if args.plot:
        from ..viz.maps import strategy_limit_figure
        from ..viz.plots import save_figure

        save_figure(strategy_limit_figure(maps), args.plot)
    out = {**maps_to_dict(maps), **_design(controller),
           "joint_feedback_scale": args.joint_feedback_scale}
    if args.json:
        print_json(out)
        return 0
    print(f"{out['profile']}; controller {controller.name}")
    for m in maps:
        cells = "  ".join(f"{_share(r, '{:.2f}'):>6}" for r in m.runs)
        print(f"  ankle limit {m.ankle_torque_limit:8.4g} N·m: {cells}")
        if maps[0].kind == "oscillation":
            found = m.transition_frequency
            print("    transition frequency: "
                  + ("none found" if found is None else f"{found:.4g} Hz"))
    print("(hip fraction per " + maps[0].variable + "; fell/failed: the run fell or failed, "
          "none: no sway)")
    return 0
