"""``posturelab stability-map`` with a feedback delay: the D-subdivision map."""

from __future__ import annotations

import argparse
import io
import math

from ..errors import ParameterError
from ._common import body_from_args, feedback_options_from_args, muscles_from_args


def _axis(text: str, flag: str) -> tuple[str, float, float]:
    parts = str(text).split(":")
    if len(parts) != 3:
        raise ParameterError(f"{flag} must be NAME:LO:HI, got {text!r}")
    name = parts[0].strip().lower()
    if name not in ("active_stiffness", "active_viscosity"):
        raise ParameterError(f"{flag}: with a delayed map both axes are active_stiffness and "
                             f"active_viscosity, got {parts[0].strip()!r}")
    try:
        low, high = float(parts[1]), float(parts[2])
    except ValueError:
        raise ParameterError(f"{flag} LO and HI must be numbers, got {text!r}") from None
    if not (math.isfinite(low) and math.isfinite(high) and 0 <= low < high):
        raise ParameterError(f"{flag} must have 0 <= LO < HI, got {low:g}:{high:g}")
    return name, low, high


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

    axes = {name: (low, high) for name, low, high in
            (_axis(a, f) for a, f in ((args.x, "--x"), (args.y, "--y")))}
    if len(axes) != 2:
        raise ParameterError("--x and --y must be active_stiffness and active_viscosity")
    resolution = parse_resolution(args.resolution, MAX_DELAY_MAP_RESOLUTION,
                                  "with a feedback delay")
    delay = feedback_options_from_args(args).get("feedback_delay")
    if delay is None:
        raise ParameterError("a map over active gains needs --feedback-delay S [s]")
    figure_path, csv_path, fmt = output_paths(args.out)
    body = body_from_args(args)
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
                                   axes["active_viscosity"], resolution, pair=args.pair,
                                   progress=progress)
    finally:
        if bar is not None:
            bar.close()
    x_first = str(args.x).split(":")[0].strip().lower() == "active_stiffness"
    fig = plot_delay_stability_map(dmap)
    kx, vy = np.meshgrid(dmap.active_stiffness, dmap.active_viscosity)
    table = np.column_stack([kx.ravel(), vy.ravel(), dmap.max_real_part.ravel(),
                             dmap.stable.ravel()])
    buf = io.StringIO()
    np.savetxt(buf, table, delimiter=",", fmt=["%.17g", "%.17g", "%.17g", "%d"],
               header="active_stiffness,active_viscosity,max_real_part,stable", comments="")
    image = io.BytesIO()
    fig.savefig(image, format=fmt, dpi=110)
    atomic_write_files({csv_path: buf.getvalue().encode("utf-8"), figure_path: image.getvalue()})
    print(f"wrote {figure_path} and {csv_path}: {resolution} × {resolution} sets of the "
          f"{dmap.pair} pair's active gains at τ = {delay:g} s, "
          f"{100 * float(np.mean(dmap.stable)):.1f}% stable"
          + ("" if x_first else " (x is always the active stiffness)"))
    return 0

