"""``posturelab stability-map``: stability of the linearised model over two parameters, the
pair stiffnesses (:func:`posturelab.linear.batch.stability_map`) or, with a feedback delay, one
pair's active gains (:func:`posturelab.linear.delay_batch.delay_stability_map`); the figures
are drawn by :mod:`posturelab.viz.maps`."""

from __future__ import annotations

import argparse
import io
import math
import re
from concurrent.futures import ThreadPoolExecutor, wait
from pathlib import Path

from ..errors import ParameterError, UnknownNameError
from ..parameters import PAPER_PAIRS, check_value, names_for, resolve
from ._common import ExpectedTime, load_compiled

#: Axis names, the parameter table's: the paper's five pair stiffnesses stiffness:PAIR
#: [N·m/rad] and the viscosity ratio [s] (posturelab.linear.batch.GRID_PARAMETERS).
PARAMETER_NAMES: tuple[str, ...] = names_for(PAPER_PAIRS, (), ("stiffness", "viscosity_ratio"))

DESCRIPTION = """\
Map the stability of the paper's three-link biped (or any body: --body, --height/--mass)
linearised about upright over two parameters. Each axis is NAME:LO:HI with NAME one of
(the parameter table's names, as for sweep --vary)
  stiffness:PAIR     a muscle pair's stiffness [N·m/rad]; PAIR ankle, knee, hip,
                     quadriceps or gastrocnemius (for a body of other than three links,
                     its pairs: ankle for one link, ankle and hip for two, ankle, knee,
                     hip, joint4, ... beyond)
  viscosity_ratio    pair viscosity / pair stiffness [s]
Every other parameter is taken from a Table I case (--case, default 1; three links) or
from --stiffness (one value per pair, any body), with viscosity = 0.25 × stiffness unless
--viscosity-ratio is given.

Writes the figure --out (colour = largest real part of the poles [1/s], stable region
outlined, Table I cases that lie in the plane marked) and a CSV beside it with the same
stem (columns: x name, y name, max_real_part [1/s], stable [1 or 0]; it replaces an earlier
map's CSV only: another file there is refused, --csv PATH names the CSV). Stable means every
pole has real part < -δ, δ = 1e-9 × the poles' magnitude scale [1/s] (a set with
undamped poles on the imaginary axis is not stable; see posturelab.linear.batch).

Example: posturelab stability-map --x stiffness:ankle:0:2000 \\
             --y stiffness:gastrocnemius:0:1000 --out map.png

With a feedback delay, the D-subdivision map: --x active_stiffness:PAIR:LO:HI --y
active_viscosity:PAIR:LO:HI [N·m/rad, N·m·s/rad] of one pair (:PAIR may be left out on a
one-pair body) at --feedback-delay S, for any body and gains (--body, --height/--mass,
--stiffness, --controller, ...: the other gains as in posturelab simulate; with
--torque-feedback-gain K the filter states of Peterka 2002's torque feedback join the
model). Colour is the real part of the rightmost characteristic root; the CSV has
active_stiffness:PAIR,
active_viscosity:PAIR, max_real_part [1/s], stable [1 or 0].

Example: posturelab stability-map --body paper-1link --stiffness 28 --viscosity 11 \\
             --x active_stiffness:ankle:0:1700 --y active_viscosity:ankle:0:680 \\
             --feedback-delay 0.15 --out dmap.png
"""

MAX_RESOLUTION = 1414  # 1414² = 1,999,396 CSV rows: at most the rows posturelab reads back
#: Axes of the delayed (D-subdivision) map: one pair's active stiffness [N·m/rad] and
#: active viscosity [N·m·s/rad].
DELAYED_AXES = ("active_stiffness", "active_viscosity")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab stability-map``."""
    from ._common import add_muscle_arguments, add_torque_feedback_arguments
    from ._flags import add_flags

    p.add_argument("--x", required=True, metavar="NAME:LO:HI",
                   help="horizontal axis: parameter name and range (e.g. stiffness:ankle:0:2000).")
    p.add_argument("--y", required=True, metavar="NAME:LO:HI",
                   help="vertical axis: parameter name and range (e.g. "
                   "stiffness:gastrocnemius:0:1000).")
    p.add_argument("--resolution", default="200", metavar="R",
                   help=f"grid points per axis, 2..{MAX_RESOLUTION} (default 200).")
    p.add_argument("--out", required=True, metavar="FILE",
                   help="figure file (.png, .pdf, .svg, ...); the CSV is written beside it "
                   "as FILE with suffix .csv, replacing only an earlier map's CSV (any "
                   "other file there is refused: choose the CSV with --csv).")
    p.add_argument("--csv", default=None, metavar="PATH",
                   help="the map's CSV (default: --out with suffix .csv, refused if it "
                   "exists; a PATH given is written even if it exists).")
    p.add_argument("--case", default="1", metavar="CASE",
                   help="Table I case for the parameters not swept (default 1).")
    p.add_argument("--viscosity-ratio", default=None, metavar="R",
                   help="pair viscosity = R × pair stiffness [s] when viscosity_ratio is not "
                   "an axis (default 0.25, as in the paper).")
    add_flags(p, "--progress")
    p.add_argument("--pair", metavar="NAME",
                   help="former option: the pair is now part of the axis names "
                   "(active_stiffness:PAIR:LO:HI).")
    add_muscle_arguments(p, own_case=True)
    add_torque_feedback_arguments(p)


# ---- argument parsing -------------------------------------------------------


def parse_axis(text: str, flag: str, pairs: tuple[str, ...] = PAPER_PAIRS):
    """Parse ``NAME:LO:HI`` into a :class:`posturelab.linear.batch.ParameterRange`; ``pairs``
    are the body's pairs (NAME is ``stiffness:PAIR`` or ``viscosity_ratio``)."""
    from ..linear.batch import ParameterRange

    parts = str(text).split(":")
    if len(parts) not in (3, 4):
        raise ParameterError(f"{flag} must be NAME:LO:HI (e.g. stiffness:ankle:0:2000), got "
                             f"{text!r}")
    if len(parts) == 3 and re.fullmatch(r"\s*[A-Za-z_]+\s*", parts[1]):  # a name, no HI
        raise ParameterError(f"{flag} must be NAME:LO:HI (e.g. stiffness:ankle:0:2000), got "
                             f"{text!r}")
    given = ":".join(parts[:-2]).strip().lower().replace("-", "_")
    parts = [given, *parts[-2:]]
    try:
        name = resolve(given, pairs, (), accepts=("stiffness", "viscosity_ratio"),
                       what=f"{flag} parameter")
    except UnknownNameError:
        known = names_for(pairs, (), ("stiffness", "viscosity_ratio"))
        raise UnknownNameError(
            f"{flag}: unknown parameter {given!r}; known parameters: {', '.join(known)}"
        ) from None
    bounds = []
    for label, value in (("LO", parts[1]), ("HI", parts[2])):
        try:
            number = float(value)
        except ValueError:
            raise ParameterError(
                f"{flag} {label} must be a number, got {value.strip()!r} in {text!r}"
            ) from None
        if not math.isfinite(number):
            raise ParameterError(f"{flag} {label} must be finite, got {value.strip()!r}")
        bounds.append(number)
    low, high = bounds
    unit = "s" if name == "viscosity_ratio" else "N·m/rad"
    if low >= 0:
        check_value(name, high, f"{flag} HI")  # the parameter table's bound
    if low < 0:
        raise ParameterError(f"{flag} LO must be >= 0 [{unit}], got {low:g}")
    if not low < high:
        raise ParameterError(f"{flag} must have LO < HI [{unit}], got {low:g}:{high:g}")
    return ParameterRange(name, low, high)


def parse_resolution(text: str, maximum: int = MAX_RESOLUTION, which: str = "") -> int:
    """``--resolution``: an integer in [2, ``maximum``] (``which`` map, for the message)."""
    where = f" {which}" if which else ""
    try:
        value = int(str(text).strip())
    except ValueError:
        raise ParameterError(
            f"--resolution must be an integer in [2, {maximum}]{where}, got {text!r}"
        ) from None
    if not 2 <= value <= maximum:
        raise ParameterError(f"--resolution must be in [2, {maximum}]{where}, got {text}")
    return value


def parse_viscosity_ratio(text: str | None) -> float | None:
    """``--viscosity-ratio``: a finite number >= 0 [s], or None for the paper's 0.25."""
    if text is None:
        return None
    try:
        value = float(text)
    except ValueError:
        raise ParameterError(f"--viscosity-ratio must be a number [s], got {text!r}") from None
    if not math.isfinite(value) or value < 0:
        raise ParameterError(f"--viscosity-ratio must be a finite number >= 0 [s], got {text}")
    return value


#: Figure formats (file suffixes) that matplotlib writes, known without importing it (a test
#: checks them against matplotlib's list); another suffix is checked with matplotlib itself.
FIGURE_FORMATS = frozenset({"eps", "jpeg", "jpg", "pdf", "pgf", "png", "ps", "raw", "rgba",
                            "svg", "svgz", "tif", "tiff", "webp"})


#: The end of a map CSV's header (both kinds of map): a file beside --out with it is an
#: earlier map, replaced on a rerun; any other file there is refused, never overwritten.
MAP_CSV_HEADER_END = ",max_real_part,stable"


def _is_a_map_csv(path: Path) -> bool:
    """Whether ``path`` is a regular file whose first line is a stability map's header."""
    try:
        if not path.is_file() or path.is_symlink():
            return False
        with open(path, "rb") as stream:
            head = stream.readline(4096)
    except OSError:
        return False
    return head.rstrip(b"\r\n").endswith(MAP_CSV_HEADER_END.encode())


def output_paths(out: str, csv: str | None = None) -> tuple[Path, Path, str]:
    """Figure path, CSV path (``csv``, or beside the figure: refused if that exists, an
    unrelated file is never overwritten) and the figure format; checks the directories."""
    figure = Path(out)
    fmt = figure.suffix.lower().lstrip(".")
    if fmt not in FIGURE_FORMATS:
        from matplotlib.backend_bases import FigureCanvasBase

        supported = FigureCanvasBase.get_supported_filetypes()
        if fmt not in supported or fmt == "csv":
            raise ParameterError(
                "--out must end in a figure suffix "
                f"({', '.join('.' + s for s in sorted(supported))}), got {out!r}"
            )
    directory = figure.parent
    if not directory.is_dir():
        raise ParameterError(f"--out directory {str(directory)!r} does not exist")
    if figure.is_dir():
        raise ParameterError(f"--out {out!r} is a directory")
    from ._common import check_writable

    if csv is None:
        table = figure.with_suffix(".csv")
        if (table.is_file() or table.is_symlink()) and not _is_a_map_csv(table):
            raise ParameterError(
                f"{str(table)!r} exists: the map's CSV is written beside --out and never "
                f"overwrites a file; remove it, or choose the CSV with --csv PATH")
    else:
        table = Path(csv)
        if table.suffix.lower() != ".csv":
            raise ParameterError(f"--csv must end in .csv, got {csv!r}")
    check_writable([str(figure), str(table)])  # both, before any work
    return figure, table, fmt


# ---- run ------------------------------------------------------------------------


def _base_muscles(args: argparse.Namespace, body):
    """The base muscle set of the pair map: None for a Table I case (three links; --case),
    else --stiffness on this body (one value per pair)."""
    if args.stiffness is None:
        if body.n_links != 3:
            from ..model.muscles import joint_pair_names

            names = joint_pair_names(body.n_links)
            raise ParameterError(
                f"--case is a Table I set for three links; this body has {body.n_links}: give "
                f"--stiffness ({len(names)} value{'s' if len(names) > 1 else ''}: "
                f"{', '.join(names)}), the pairs not on an axis keep theirs")
        return None
    from ..scenarios._parse import muscles_from_table
    from ._common import FLAG_NAMES

    return muscles_from_table({"stiffness": args.stiffness}, body, "", FLAG_NAMES)[0]


def _import_plotting() -> None:
    """Import what :func:`posturelab.viz.maps.plot_stability_map` uses (matplotlib's figure,
    Agg, fonts)."""
    from matplotlib import font_manager
    from matplotlib.backends import backend_agg  # noqa: F401

    from ..viz import maps  # noqa: F401

    font_manager.fontManager  # noqa: B018 (loads the font list)


def _write_csv(smap, path: Path, show: bool) -> None:
    """Write ``smap``'s CSV to ``path`` (a progress bar on standard error if ``show``)."""
    from .._progress import Progress

    bar = Progress(label="writing CSV", unit="rows") if show else None
    try:
        with open(path, "w", encoding="utf-8", newline="") as stream:
            smap.write_csv(stream, progress=bar or ExpectedTime(
                "stability-map: writing the CSV", "rows", min_total=250_000))
    finally:
        if bar is not None:
            bar.close()


def run(args: argparse.Namespace) -> int:
    names = {str(a).split(":")[0].strip().lower() for a in (args.x, args.y)}
    if names & set(DELAYED_AXES):
        return _run_delayed_map(args)
    return _run_pair_map(args)


def _run_pair_map(args: argparse.Namespace) -> int:
    """The map over pair stiffnesses (or the viscosity ratio), without a delay."""
    from .._files import atomic_outputs
    from .._progress import Progress, shown

    model = [f for f in ("controller", "viscosity", "active_stiffness", "active_viscosity",
                         "active_viscosity_ratio", "feedback_delay", "proprioceptive_weight",
                         "pair", "torque_feedback_gain", "torque_feedback_time_constant")
             if getattr(args, f, None) is not None]
    if model:
        raise ParameterError(
            f"--{model[0].replace('_', '-')} is for the delayed map (axes "
            "active_stiffness:PAIR:LO:HI and active_viscosity:PAIR:LO:HI with --feedback-delay); "
            "the map "
            "over pair stiffnesses takes --body or --height/--mass, --case or --stiffness, and "
            "--viscosity-ratio")
    if args.gastrocnemius != "two-sided":
        raise ParameterError(
            f"--gastrocnemius {args.gastrocnemius}: the map is of the linearisation with every "
            "pair acting; upright is a one-sided pair's switching point (posturelab poles "
            "gives both of its sides)")
    from ._common import body_from_args

    body = body_from_args(args)
    base = _base_muscles(args, body)
    pairs = PAPER_PAIRS if base is None else tuple(base.names)
    x = parse_axis(args.x, "--x", pairs)
    y = parse_axis(args.y, "--y", pairs)
    if x.name == y.name:
        raise ParameterError(f"--x and --y must be different parameters, both are {x.name!r}")
    resolution = parse_resolution(args.resolution)
    ratio = parse_viscosity_ratio(args.viscosity_ratio)
    if ratio is not None and "viscosity_ratio" in (x.name, y.name):
        raise ParameterError(
            "--viscosity-ratio cannot be given when viscosity_ratio is an axis"
        )
    figure_path, csv_path, fmt = output_paths(args.out, args.csv)

    from ..linear.batch import parameter_grid, stability_map

    where = dict(case=args.case, viscosity_ratio=ratio, body=body, muscles=base)
    parameter_grid(x, y, resolution, case=args.case, viscosity_ratio=ratio,
                   muscles=base)  # validates --case
    load_compiled(lambda: stability_map(x, y, 2, **where).write_csv(io.StringIO()),
                  "the stability evaluator")

    show = shown(args.progress)
    # Created first: an unwritable directory fails before the computation.
    with atomic_outputs([figure_path, csv_path], what="--out ",
                        error=ParameterError) as (tmp_figure, tmp_csv):
        bar = Progress(label="stability-map", unit="sets") if show else None
        try:
            # The compiled map and CSV writer release the GIL: each runs on a worker thread
            # while this one imports matplotlib and then draws the figure.
            with ThreadPoolExecutor(max_workers=1) as worker:
                computing = worker.submit(stability_map, x, y, resolution, progress=bar or
                                          ExpectedTime("stability-map", "parameter sets",
                                                       min_total=250_000), **where)
                _import_plotting()
                smap = computing.result()
                if bar is not None:
                    bar.close()
                writing = worker.submit(_write_csv, smap, tmp_csv, show)
                try:
                    from ..viz.maps import plot_stability_map

                    plot_stability_map(smap).savefig(tmp_figure, format=fmt, dpi=150)
                finally:
                    wait([writing])  # before the temporaries may be removed
                writing.result()
        finally:
            if bar is not None:
                bar.close()
    ny, nx = smap.grid.shape
    on = "" if body.name == "paper" else f" of body {body.name}"
    print(f"wrote {figure_path} and {csv_path}: {nx} × {ny} parameter sets{on}, "
          f"{100 * smap.stable_fraction:.1f}% stable "
          f"(largest real part {smap.max_real_part.min():.3g} .. "
          f"{smap.max_real_part.max():.3g} 1/s)")
    return 0


# ---- the delayed map -------------------------------------------------------------


def _delayed_axis(text: str, flag: str, pairs) -> tuple[str, str, float, float]:
    """``QUANTITY[:PAIR]:LO:HI`` -> (quantity, pair, LO, HI), the name the table's."""
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


def _gain_pair_names(body) -> tuple[str, ...]:
    """The pair names of the layout a body's gains have (the paper's five on three links)."""
    from ..model.muscles import PAPER_PAIR_NAMES, joint_pair_names

    return PAPER_PAIR_NAMES if body.n_links == 3 else joint_pair_names(body.n_links)


def _run_delayed_map(args: argparse.Namespace) -> int:
    """The D-subdivision map of one pair's active gains with a feedback delay."""
    import numpy as np

    from .._files import atomic_write_files
    from .._progress import Progress, shown
    from ..linear.delay_batch import MAX_DELAY_MAP_RESOLUTION, delay_stability_map
    from ..viz.maps import plot_delay_stability_map
    from ._common import (
        body_from_args,
        feedback_given,
        muscles_and_delay_from_args,
        torque_feedback_options_from_args,
    )

    if args.pair is not None:
        raise ParameterError(f"--pair is now part of the axis names: --x active_stiffness:"
                             f"{args.pair}:LO:HI --y active_viscosity:{args.pair}:LO:HI")
    if args.stiffness is not None or args.controller is not None:
        args.case = None  # (--case has a default: the paper's Table I case 1)
    args.viscosity_ratio = parse_viscosity_ratio(args.viscosity_ratio)
    body = body_from_args(args)
    if args.case is not None and body.n_links != 3:
        raise ParameterError("give --stiffness (the intrinsic gains) or --controller for "
                             "this body")
    pairs = _gain_pair_names(body)
    parsed = [_delayed_axis(a, f, pairs) for a, f in ((args.x, "--x"), (args.y, "--y"))]
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
    if not feedback_given(args):
        raise ParameterError("a map over active gains needs --feedback-delay S [s]")
    figure_path, csv_path, fmt = output_paths(args.out, args.csv)
    muscles, delay = muscles_and_delay_from_args(args, body)
    torque_feedback = torque_feedback_options_from_args(args)
    bar = Progress(resolution**2, label="stability-map", unit="sets") \
        if shown(args.progress) else None
    try:
        dmap = delay_stability_map(body, muscles, delay, axes["active_stiffness"],
                                   axes["active_viscosity"], resolution, pair=pair,
                                   progress=bar or ExpectedTime("stability-map", "sets",
                                                                min_total=2500),
                                   **torque_feedback)
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

