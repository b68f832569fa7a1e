"""``posturelab stability-map``: stability of the linearised model over two parameters."""

from __future__ import annotations

import argparse
import io
import math
import os
import re
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor, wait
from pathlib import Path
from typing import IO

from ..errors import ParameterError, UnknownNameError
from ..parameters import PAPER_PAIRS, check_value, names_for, resolve
from . import CONVENTIONS_EPILOG, SUBCOMMAND_HELP
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
stem (columns: x name, y name, max_real_part [1/s], stable [1 or 0]). Stable means every
pole has real part < -δ, δ = 1e-9 × the poles' magnitude scale [1/s] (a set with
undamped poles on the imaginary axis is not stable; see posturelab.linear.batch).

Example: posturelab stability-map --x stiffness:ankle:0:2000 \\
             --y stiffness:gastrocnemius:0:1000 --out map.png

With a feedback delay, the D-subdivision map: --x active_stiffness:PAIR:LO:HI --y
active_viscosity:PAIR:LO:HI [N·m/rad, N·m·s/rad] of one pair (:PAIR may be left out on a
one-pair body) at --feedback-delay S, for any body and gains (--body, --height/--mass,
--stiffness, --controller, ...: the other gains as in posturelab simulate). Colour is the
real part of the rightmost characteristic root; the CSV has active_stiffness:PAIR,
active_viscosity:PAIR, max_real_part [1/s], stable [1 or 0].

Example: posturelab stability-map --body paper-1link --stiffness 28 --viscosity 11 \\
             --x active_stiffness:ankle:0:1700 --y active_viscosity:ankle:0:680 \\
             --feedback-delay 0.15 --out dmap.png
"""

MAX_RESOLUTION = 5000
#: Axes of the delayed (D-subdivision) map: one pair's active stiffness [N·m/rad] and
#: active viscosity [N·m·s/rad].
DELAYED_AXES = ("active_stiffness", "active_viscosity")


def add_parser(sub, name: str) -> argparse.ArgumentParser:
    p = sub.add_parser(
        name, help=SUBCOMMAND_HELP[name],
        description=DESCRIPTION, epilog=CONVENTIONS_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--x", required=True, metavar="NAME:LO:HI",
                   help="horizontal axis: parameter name and range (e.g. stiffness:ankle:0:2000).")
    p.add_argument("--y", required=True, metavar="NAME:LO:HI",
                   help="vertical axis: parameter name and range (e.g. "
                   "stiffness:gastrocnemius:0:1000).")
    p.add_argument("--resolution", default="200", metavar="R",
                   help=f"grid points per axis, 2..{MAX_RESOLUTION} (default 200).")
    p.add_argument("--out", required=True, metavar="FILE",
                   help="figure file (.png, .pdf, .svg, ...); the CSV is written beside it "
                   "as FILE with suffix .csv.")
    p.add_argument("--case", default="1", metavar="CASE",
                   help="Table I case for the parameters not swept (default 1).")
    p.add_argument("--viscosity-ratio", default=None, metavar="R",
                   help="pair viscosity = R × pair stiffness [s] when viscosity_ratio is not "
                   "an axis (default 0.25, as in the paper).")
    p.add_argument("--progress", action="store_true",
                   help="show a progress bar on standard error even when it is not a terminal.")
    p.add_argument("--pair", metavar="NAME",
                   help="former option: the pair is now part of the axis names "
                   "(active_stiffness:PAIR:LO:HI).")
    from ._common import add_muscle_arguments

    add_muscle_arguments(p, own_case=True)
    return p


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


def output_paths(out: str) -> tuple[Path, Path, str]:
    """Figure path, CSV path beside it, and the figure format; checks the directory."""
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

    check_writable([str(figure), str(figure.with_suffix(".csv"))])  # both, before any work
    return figure, figure.with_suffix(".csv"), fmt


# ---- progress bar -------------------------------------------------------------


class ProgressBar:
    """A one-line text progress bar, redrawn in place with carriage returns.

    Parameters
    ----------
    stream : text stream
        Where to draw (standard error).
    label : str
        Text before the bar.
    unit : str
        What is counted, e.g. "sets" or "rows".
    width : int
        Bar width in characters.
    """

    def __init__(self, stream: IO[str], label: str, unit: str = "sets", width: int = 30) -> None:
        self.stream = stream
        self.label = label
        self.unit = unit
        self.width = width
        self._shown = -1

    def __call__(self, done: int, total: int) -> None:
        permille = 1000 if total <= 0 else int(1000 * done / total)
        if permille == self._shown:
            return
        self._shown = permille
        filled = self.width * permille // 1000
        bar = "#" * filled + "-" * (self.width - filled)
        self.stream.write(f"\r{self.label} [{bar}] {permille / 10:5.1f}% "
                          f"({done:,}/{total:,} {self.unit})")
        if done >= total:
            self.stream.write("\n")
        self.stream.flush()


# ---- figure -------------------------------------------------------------------


def plot_stability_map(smap, figure_file, fmt: str) -> None:
    """Draw ``smap`` (a :class:`posturelab.linear.batch.StabilityMap`) to ``figure_file``.

    Colour is the largest real part of the poles [1/s] (diverging at 0: blue decays,
    red grows); the stable region is outlined in black; Table I cases lying in the
    plane are marked.
    """
    from matplotlib.colors import TwoSlopeNorm
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    grid = smap.grid
    xs, ys = grid.x_values, grid.y_values
    values = smap.max_real_part
    low, high = float(values.min()), float(values.max())
    if low < 0.0 < high:
        norm = TwoSlopeNorm(vmin=low, vcenter=0.0, vmax=high)
    else:
        span = max(abs(low), abs(high), 1e-12)
        norm = TwoSlopeNorm(vmin=-span, vcenter=0.0, vmax=span)
    dx, dy = xs[1] - xs[0], ys[1] - ys[0]
    extent = (xs[0] - dx / 2, xs[-1] + dx / 2, ys[0] - dy / 2, ys[-1] + dy / 2)

    fig = Figure(figsize=(7.5, 5.8), layout="constrained")
    ax = fig.add_subplot()
    image = ax.imshow(values, origin="lower", extent=extent, aspect="auto",
                      interpolation="nearest", cmap="RdBu_r", norm=norm)
    fig.colorbar(image, ax=ax, label="largest real part of the poles [1/s]")
    handles = []
    if smap.stable.any() and not smap.stable.all():
        ax.contour(xs, ys, smap.stable.astype(float), levels=[0.5], colors="k", linewidths=1.5)
        handles.append(Line2D([], [], color="k", lw=1.5, label="stable region boundary"))
    points = grid.table_i_points()
    if points:
        px = [p[1] for p in points]
        py = [p[2] for p in points]
        ax.plot(px, py, "o", ms=7, mfc="gold", mec="k", clip_on=False, zorder=5)
        for case, x, y in points:
            ax.annotate(f"case {case}", (x, y), xytext=(5, 5), textcoords="offset points",
                        fontsize=9, annotation_clip=False,
                        bbox=dict(boxstyle="round,pad=0.2", fc="w", alpha=0.7))
        handles.append(Line2D([], [], ls="", marker="o", ms=7, mfc="gold", mec="k",
                              label="Table I cases"))
    ax.set_xlabel(grid.x.label)
    ax.set_ylabel(grid.y.label)
    fixed = []
    if "viscosity_ratio" not in (grid.x.name, grid.y.name):
        fixed.append(f"viscosity ratio {grid.base_viscosity_ratio:g} s")
    others = [f"{n} {v:g}" for n, v in zip(grid.pair_names, grid.base_stiffness, strict=True)
              if f"stiffness:{n}" not in (grid.x.name, grid.y.name)]
    if others:
        fixed.insert(0, f"{', '.join(others)} N·m/rad")
    source = (f"others from Table I case {grid.base_case}" if grid.base_case is not None
              else "others fixed" if fixed else "")
    ax.set_title(
        f"Linearised stability about upright of body {smap.body_name}"
        f"{'; ' + source if source else ''}\n"
        f"{'(' + '; '.join(fixed) + '); ' if fixed else ''}"
        f"{100 * smap.stable_fraction:.1f}% stable",
        fontsize=9,
    )
    if handles:
        ax.legend(handles=handles, loc="upper right", fontsize=8, framealpha=0.8)
    state = "all stable" if smap.stable.all() else "none stable" if not smap.stable.any() else ""
    if state:
        ax.text(0.02, 0.02, state, transform=ax.transAxes, fontsize=9,
                bbox=dict(boxstyle="round", fc="w", alpha=0.8))
    fig.savefig(figure_file, format=fmt, dpi=150)


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
    from ..model.muscles import muscles_for
    from ._common import _pairs, parse_float_list

    stiffness = parse_float_list(args.stiffness, "--stiffness [N·m/rad]", _pairs(body))
    return muscles_for(body.n_links, stiffness)


def _temporary_beside(path: Path) -> Path:
    """Create an empty temporary file in ``path``'s directory (checks it is writable).

    It gets the permissions a newly created file would (0666 minus the umask),
    not mkstemp's private 0600, since it replaces the output.
    """
    try:
        fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as exc:
        raise ParameterError(
            f"cannot write --out {str(path)!r}: {exc.strerror or exc}"
        ) from None
    try:
        umask = os.umask(0)
        os.umask(umask)
        os.fchmod(fd, 0o666 & ~umask)
    finally:
        os.close(fd)
    return Path(name)


def _import_plotting() -> None:
    """Import what :func:`plot_stability_map` uses (matplotlib's figure, Agg, fonts)."""
    from matplotlib import font_manager
    from matplotlib.backends import backend_agg  # noqa: F401
    from matplotlib.figure import Figure  # noqa: F401

    font_manager.fontManager  # noqa: B018 (loads the font list)


def _write_csv(smap, path: Path, show: bool) -> None:
    """Write ``smap``'s CSV to ``path`` (a progress bar on standard error if ``show``)."""
    with open(path, "w", encoding="utf-8", newline="") as stream:
        smap.write_csv(stream, progress=ProgressBar(sys.stderr, "writing CSV  ", "rows")
                       if show else ExpectedTime("stability-map: writing the CSV", "rows",
                                                 min_total=250_000))


def run(args: argparse.Namespace) -> int:
    names = {str(a).split(":")[0].strip().lower() for a in (args.x, args.y)}
    if names & set(DELAYED_AXES):
        from ._delay_map import run_delay_map

        return run_delay_map(args)
    model = [f for f in ("controller", "viscosity", "active_stiffness", "active_viscosity",
                         "active_viscosity_ratio", "feedback_delay", "proprioceptive_weight",
                         "pair")
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
    figure_path, csv_path, fmt = output_paths(args.out)

    from ..linear.batch import parameter_grid, stability_map

    where = dict(case=args.case, viscosity_ratio=ratio, body=body, muscles=base)
    parameter_grid(x, y, resolution, case=args.case, viscosity_ratio=ratio,
                   muscles=base)  # validates --case
    load_compiled(lambda: stability_map(x, y, 2, **where).write_csv(io.StringIO()),
                  "the stability evaluator")

    temporaries: list[Path] = []
    try:
        # Created first: an unwritable directory fails before the computation.
        tmp_figure = _temporary_beside(figure_path)
        temporaries.append(tmp_figure)
        tmp_csv = _temporary_beside(csv_path)
        temporaries.append(tmp_csv)

        show = args.progress or sys.stderr.isatty()
        progress = ProgressBar(sys.stderr, "stability-map") if show else \
            ExpectedTime("stability-map", "parameter sets", min_total=250_000)
        # The compiled map and CSV writer release the GIL: each runs on a worker thread
        # while this one imports matplotlib and then draws the figure.
        with ThreadPoolExecutor(max_workers=1) as worker:
            computing = worker.submit(stability_map, x, y, resolution, progress=progress,
                                      **where)
            _import_plotting()
            smap = computing.result()
            writing = worker.submit(_write_csv, smap, tmp_csv, show)
            try:
                with open(tmp_figure, "wb") as stream:
                    plot_stability_map(smap, stream, fmt)
            finally:
                wait([writing])  # before the temporaries may be removed
            writing.result()
        os.replace(tmp_csv, csv_path)
        temporaries.remove(tmp_csv)
        os.replace(tmp_figure, figure_path)
        temporaries.remove(tmp_figure)
    except OSError as exc:
        raise ParameterError(f"cannot write --out {args.out!r}: {exc.strerror or exc}") from None
    finally:
        for tmp in temporaries:
            tmp.unlink(missing_ok=True)
    ny, nx = smap.grid.shape
    on = "" if body.name == "paper" else f" of body {body.name}"
    print(f"wrote {figure_path} and {csv_path}: {nx} × {ny} parameter sets{on}, "
          f"{100 * smap.stable_fraction:.1f}% stable "
          f"(largest real part {smap.max_real_part.min():.3g} .. "
          f"{smap.max_real_part.max():.3g} 1/s)")
    return 0
