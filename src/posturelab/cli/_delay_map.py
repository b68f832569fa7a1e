"""``posturelab stability-map`` with a feedback delay: the D-subdivision map."""

from __future__ import annotations

import argparse
import io
import math

from ..errors import ParameterError
from ..parameters import check_value
from ._common import body_from_args, feedback_options_from_args, muscles_from_args


def _axis(text: str, flag: str, pairs) -> tuple[str, str, float, float]:
    """``QUANTITY[:PAIR]:LO:HI`` -> (quantity, pair, LO, HI), the name the table's."""
    from ..parameters import resolve

    parts = str(text).split(":")
    if len(parts) not in (3, 4):
        raise ParameterError(f"{flag} must be NAME:LO:HI (e.g. active_stiffness:ankle:0:1700), "
                             f"got {text!r}")
    given = ":".join(parts[:-2]).strip().lower()
    if given.partition(":")[0] not in ("active_stiffness", "active_viscosity"):
        raise ParameterError(f"{flag}: with a delayed map both axes are active_stiffness:PAIR "
                             f"and active_viscosity:PAIR, got {given!r}")
    name, _, pair = resolve(given, pairs, (), what=f"{flag} parameter").partition(":")
    try:
        low, high = float(parts[-2]), float(parts[-1])
    except ValueError:
        raise ParameterError(f"{flag} LO and HI must be numbers, got {text!r}") from None
    if not (math.isfinite(low) and math.isfinite(high) and 0 <= low < high):
        raise ParameterError(f"{flag} must have 0 <= LO < HI, got {low:g}:{high:g}")
    check_value(name, high, f"{flag} HI")  # the parameter table's bound
    return name, pair, low, high


def muscles_for_names(body) -> tuple[str, ...]:
    """The pair names of the layout a body's gains have (the paper's five on three links)."""
    from ..model.muscles import PAPER_PAIR_NAMES, joint_pair_names

    return PAPER_PAIR_NAMES if body.n_links == 3 else joint_pair_names(body.n_links)


def run_delay_map(args: argparse.Namespace) -> int:
    """The delayed map: arguments of ``posturelab stability-map``."""
    import sys

    import numpy as np

    from ..linear.delay_batch import MAX_DELAY_MAP_RESOLUTION, delay_stability_map
    from ..simulation.results import atomic_write_files
    from ..studies.sweep import ProgressBar
    from ..viz.plots import plot_delay_stability_map
    from ._common import ExpectedTime
    from .stability_map import output_paths, parse_resolution, parse_viscosity_ratio

    if args.pair is not None:
        raise ParameterError(f"--pair is now part of the axis names: --x active_stiffness:"
                             f"{args.pair}:LO:HI --y active_viscosity:{args.pair}:LO:HI")
    body = body_from_args(args)
    pairs = muscles_for_names(body)
    parsed = [_axis(a, f, pairs) for a, f in ((args.x, "--x"), (args.y, "--y"))]
    axes = {name: (low, high) for name, _, low, high in parsed}
    if len(axes) != 2:
        raise ParameterError("--x and --y must be active_stiffness:PAIR and "
                             "active_viscosity:PAIR")
    if parsed[0][1] != parsed[1][1]:
        raise ParameterError(f"--x and --y must name the same pair, got {parsed[0][1]!r} and "
                             f"{parsed[1][1]!r}")
    pair = parsed[0][1]
    resolution = parse_resolution(args.resolution, MAX_DELAY_MAP_RESOLUTION,
                                  "with a feedback delay")
    delay = feedback_options_from_args(args).get("feedback_delay")
    if delay is None:
        raise ParameterError("a map over active gains needs --feedback-delay S [s]")
    figure_path, csv_path, fmt = output_paths(args.out)
    if args.stiffness is None and args.controller is None:
        if body.n_links != 3:
            raise ParameterError("give --stiffness (the intrinsic gains) or --controller for "
                                 "this body")
    else:
        args.case = None  # (--case has a default: the paper's Table I case 1)
    args.viscosity_ratio = parse_viscosity_ratio(args.viscosity_ratio)
    muscles = muscles_from_args(args, body)
    if args.progress or sys.stderr.isatty():
        bar = ProgressBar(resolution**2, unit="sets")

        def progress(done: int, total: int) -> None:
            bar.update(done)
    else:
        bar, progress = None, ExpectedTime("stability-map", "sets", min_total=2500)
    try:
        dmap = delay_stability_map(body, muscles, delay, axes["active_stiffness"],
                                   axes["active_viscosity"], resolution, pair=pair,
                                   progress=progress)
    finally:
        if bar is not None:
            bar.close()
    x_first = parsed[0][0] == "active_stiffness"
    fig = plot_delay_stability_map(dmap)
    kx, vy = np.meshgrid(dmap.active_stiffness, dmap.active_viscosity)
    table = np.column_stack([kx.ravel(), vy.ravel(), dmap.max_real_part.ravel(),
                             dmap.stable.ravel()])
    buf = io.StringIO()
    np.savetxt(buf, table, delimiter=",", fmt=["%.17g", "%.17g", "%.17g", "%d"],
               header=f"active_stiffness:{pair},active_viscosity:{pair},max_real_part,stable",
               comments="")
    image = io.BytesIO()
    fig.savefig(image, format=fmt, dpi=110)
    atomic_write_files({csv_path: buf.getvalue().encode("utf-8"), figure_path: image.getvalue()})
    print(f"wrote {figure_path} and {csv_path}: {resolution} × {resolution} sets of the "
          f"{dmap.pair} pair's active gains at τ = {delay:g} s, "
          f"{100 * float(np.mean(dmap.stable)):.1f}% stable"
          + ("" if x_first else " (x is always the active stiffness)"))
    return 0

