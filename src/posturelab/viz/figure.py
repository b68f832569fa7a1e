"""Figures without pyplot (the shared pieces of :mod:`posturelab.viz`): a new Figure, the
colours every figure uses, one legend entry per label, and rendering or saving a Figure
(atomically, through :mod:`posturelab._files`)."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from .._files import atomic_write_bytes
from ..errors import ParameterError

__all__ = ["new_figure", "unique_legend", "figure_bytes", "save_figure", "LINK_COLORS",
           "PAIR_COLORS", "RUN_COLORS", "RUN_LINESTYLES"]

#: One colour per link, the same in every figure (link 1 = leg first). [-]
LINK_COLORS: tuple[str, ...] = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#8c564b",
                                "#e377c2", "#7f7f7f", "#bcbd22")
#: One colour per paper muscle pair, the same in every figure.
PAIR_COLORS: dict[str, str] = {
    "ankle": "#1f77b4",
    "knee": "#ff7f0e",
    "hip": "#2ca02c",
    "quadriceps": "#9467bd",
    "gastrocnemius": "#d62728",
}
#: Line style of each run when several runs share an Axes (run 1 solid). [-]
RUN_LINESTYLES: tuple = ("-", "--", ":", "-.", (0, (5, 1, 1, 1)), (0, (1, 3)))
#: Colour of each run where the colour is free (the CoG phase plane, compare). [-]
RUN_COLORS: tuple[str, ...] = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e",
                               "#8c564b", "#17becf")


def new_figure(nrows: int = 1, ncols: int = 1, *, figsize: tuple[float, float] = (7.0, 4.5),
               sharex: bool = False) -> tuple[Figure, Axes | np.ndarray]:
    """A new pyplot-free Figure (constrained layout) and its Axes.

    Parameters
    ----------
    nrows, ncols : int
        Grid of axes.
    figsize : (float, float)
        Width and height. [inch]
    sharex : bool
        Share the x axis between the panels.

    Returns
    -------
    (Figure, Axes or numpy.ndarray of Axes)
    """
    fig = Figure(figsize=figsize, layout="constrained")
    axes = fig.subplots(nrows, ncols, sharex=sharex, squeeze=True)
    return fig, axes


def unique_legend(ax: Axes, **kwargs) -> None:
    """A legend with one entry per label (the first artist drawn with it).

    Overlays drawn by repeated calls on the same Axes repeat their labels;
    this keeps each label once.

    Parameters
    ----------
    ax : Axes
        The Axes whose artists are listed.
    **kwargs
        Passed on to :meth:`matplotlib.axes.Axes.legend`.
    """
    handles, labels = ax.get_legend_handles_labels()
    seen: dict[str, object] = {}
    for h, lab in zip(handles, labels, strict=True):
        seen.setdefault(lab, h)
    if seen:
        ax.legend(list(seen.values()), list(seen), **kwargs)


def figure_bytes(fig: Figure, fmt: str = "png", dpi: float = 110) -> bytes:
    """Render ``fig`` to bytes (PNG, SVG, PDF, …) without pyplot.

    Dates and other volatile metadata are left out so equal figures give
    equal bytes.

    Parameters
    ----------
    fig : Figure
    fmt : str
        A matplotlib output format: "png", "svg", "pdf".
    dpi : float
        Resolution of raster output. [dots/inch]
    """
    import matplotlib

    buf = io.BytesIO()
    meta = {"png": {"Software": None}, "svg": {"Date": None}, "pdf": {"CreationDate": None}}
    with matplotlib.rc_context({"svg.hashsalt": "posturelab", "svg.fonttype": "path"}):
        fig.savefig(buf, format=fmt, dpi=dpi, metadata=meta.get(fmt))
    return buf.getvalue()


def save_figure(fig: Figure, path: str | Path, dpi: float = 110) -> Path:
    """Save ``fig`` atomically (temporary file, then rename); format from the suffix.

    Parameters
    ----------
    fig : Figure
    path : str or Path
        Output file; ``.png``, ``.svg`` or ``.pdf``.
    dpi : float
        Resolution of raster output. [dots/inch]

    Returns
    -------
    Path
        The written file.

    Raises
    ------
    ParameterError
        An unsupported suffix.
    PostureLabError
        The file cannot be written (the message names it).
    """
    path = Path(path)
    fmt = path.suffix.lower().lstrip(".")
    if fmt not in ("png", "svg", "pdf"):
        raise ParameterError(f"figure file {str(path)!r} must end in .png, .svg or .pdf")
    atomic_write_bytes(path, figure_bytes(fig, fmt, dpi))
    return path
