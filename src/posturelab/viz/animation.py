"""Stick-figure animation of a run, written as an animated GIF.

The view follows the platform: the ankle stays at the centre, the platform
moves under a row of lab-fixed floor marks that scroll by the platform
displacement x_d(t) (printed in the corner). Links are drawn from the ankle
with the body's lengths and the run's absolute angles θ_i (forward, +x, to the
right); the foot is a triangle heel–ankle–toe; the centre of gravity is a dot
with its ground projection, red when it lies outside the foot. A fall is
marked from its time on.

Frames are taken every ``speed / fps`` seconds of simulated time (at most
``max_frames`` of them), so a 5 s run at 25 frames/s is 126 frames of a small
figure; the last frame is held for one second.
"""

from __future__ import annotations

import math
import textwrap
from pathlib import Path

import numpy as np
from matplotlib.animation import PillowWriter
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from PIL import Image

from .._files import atomic_outputs
from .._validation import float_in_range, positive_float
from ..errors import ParameterError, PostureLabError
from ..model.body import Body
from ..model.options import BaseOfSupport, base_of_support_for_height
from ..simulation.results import SimulationResult

_FALL_RED = "#c00000"
_COG_YELLOW = "#f2a900"
_BODY_BLUE = "#1f3b73"
_FOOT_BROWN = "#8c6d46"
#: Colours that must be exact in every frame, whatever the first frame shows. [RGB 0–255]
_KEY_RGB = ((192, 0, 0), (242, 169, 0), (31, 59, 115), (140, 109, 70), (0, 0, 0),
            (255, 255, 255))

__all__ = ["animate", "frame_times", "joint_positions", "ANKLE_HEIGHT_FRACTION_OF_HEIGHT"]

#: Ankle height above the sole as a fraction of body height, 0.039 H (Winter 2009,
#: Fig. 4.1, after Drillis and Contini). Used for drawing only. [-]
ANKLE_HEIGHT_FRACTION_OF_HEIGHT = 0.039
#: The paper body's links (leg 0.401 + thigh 0.412 + torso 0.619 = 1.432 m) stand for a
#: stature of about 1.65 m (see posturelab.simulate.FOOT_FROM_LITERATURE); for drawing a foot
#: for any body we take stature = total link length / this ratio. [-]
_LINKS_FRACTION_OF_HEIGHT = 1.432 / 1.65


def joint_positions(body: Body, theta: np.ndarray) -> np.ndarray:
    """Positions of the ankle and every upper joint, relative to the ankle.

    Parameters
    ----------
    body : Body
    theta : array_like, shape (..., N)
        Absolute link angles. [rad]

    Returns
    -------
    numpy.ndarray, shape (..., N + 1, 2)
        (x, y) of the ankle (zeros) and of the top of links 1 … N. [m]
    """
    theta = np.asarray(theta, dtype=float)
    lengths = body.lengths
    seg = np.stack([lengths * np.sin(theta), lengths * np.cos(theta)], axis=-1)  # (..., N, 2)
    tips = np.cumsum(seg, axis=-2)
    zeros = np.zeros(tips.shape[:-2] + (1, 2))
    return np.concatenate([zeros, tips], axis=-2)


def frame_times(time: np.ndarray, fps: float, speed: float, max_frames: int) -> tuple[
        np.ndarray, float]:
    """Sample indices of the animation frames and the frame rate to play them at.

    Parameters
    ----------
    time : numpy.ndarray, shape (T,)
        Sample times of the run. [s]
    fps : float
        Wanted frame rate. [1/s]
    speed : float
        Simulated seconds per second of playback. [-]
    max_frames : int
        Upper limit on the number of frames.

    Returns
    -------
    (numpy.ndarray of int, float)
        Indices into ``time`` and the playback frame rate [1/s] (lowered when
        ``max_frames`` caps the count, so playback keeps ``speed``).
    """
    t0, t1 = float(time[0]), float(time[-1])
    span = t1 - t0
    wanted = int(math.floor(span / speed * fps + 1e-9)) + 1
    n = max(1, min(wanted, int(max_frames)))
    if n == 1:
        return np.array([len(time) - 1]), float(fps)
    targets = np.linspace(t0, t1, n)
    idx = np.clip(np.searchsorted(time, targets - 1e-12), 0, len(time) - 1)
    play_fps = (n - 1) / (span / speed) if span > 0 else float(fps)
    return idx, play_fps


def _default_foot(body: Body) -> BaseOfSupport:
    stature = float(np.clip(body.lengths.sum() / _LINKS_FRACTION_OF_HEIGHT, 0.5, 2.5))
    return base_of_support_for_height(stature)


def animate(
    result: SimulationResult,
    body: Body,
    path: str | Path,
    fps: float = 25,
    speed: float = 1.0,
    *,
    base_of_support: BaseOfSupport | None = None,
    max_frames: int = 250,
    dpi: float = 80,
    title: str | None = None,
) -> Path:
    """Write a stick-figure GIF of ``result`` to ``path``, atomically.

    Parameters
    ----------
    result : SimulationResult
        The run to show.
    body : Body
        The body that was simulated (for the link lengths).
    path : str or Path
        Output file; must end in ``.gif``. Written through a temporary file in
        the same directory and a rename, so it is never half-written.
    fps : float
        Frames per second of playback. [1/s]
    speed : float
        Playback speed: simulated seconds per second of playback (0.5 = slow
        motion). [-]
    base_of_support : BaseOfSupport, optional
        The foot to draw; by default a literature foot scaled to the body
        (Winter 2009: foot length 0.152 × stature, see
        :func:`posturelab.simulate.base_of_support_for_height`).
    max_frames : int
        At most this many frames (the playback frame rate drops to keep
        ``speed``).
    dpi : float
        Resolution of the frames. [dots/inch]
    title : str, optional
        Text above the figure; by default the run's description.

    Returns
    -------
    Path
        The GIF written.

    Raises
    ------
    ParameterError
        Bad ``fps``, ``speed``, ``max_frames``, a body that does not match the
        run, or a path that does not end in ``.gif``.
    PostureLabError
        The file cannot be written.
    """
    if not isinstance(result, SimulationResult):
        raise ParameterError(f"result must be a SimulationResult, got {type(result).__name__}")
    if body.n_links != result.n_links:
        raise ParameterError(f"body has {body.n_links} links but the run has {result.n_links}")
    if result.time.size == 0:
        raise ParameterError("result holds no samples to animate")
    fps = float_in_range("fps [1/s]", fps, 1.0, 100.0)
    speed = positive_float("speed [-]", speed)
    if int(max_frames) < 2:
        raise ParameterError(f"max_frames must be >= 2, got {max_frames!r}")
    dpi = float_in_range("dpi", dpi, 20.0, 300.0)
    path = Path(path)
    if path.suffix.lower() != ".gif":
        raise ParameterError(f"animation file {str(path)!r} must end in .gif")
    directory = path.parent if str(path.parent) else Path(".")
    if not directory.is_dir():
        raise PostureLabError(
            f"cannot write {str(path)!r}: directory {str(directory)!r} does not exist")
    foot = base_of_support or _default_foot(body)

    idx, play_fps = frame_times(result.time, fps, speed, int(max_frames))
    theta = result.theta[idx]
    time = result.time[idx]
    stature = body.lengths.sum() / _LINKS_FRACTION_OF_HEIGHT
    ankle_h = ANKLE_HEIGHT_FRACTION_OF_HEIGHT * stature
    joints = joint_positions(body, theta)
    joints[..., 1] += ankle_h
    cog = result.cog_position[idx].copy()
    cog[:, 1] += ankle_h
    xd = result.platform_position[idx, 0]
    yd = result.platform_position[idx, 1]

    reach = float(body.lengths.sum())
    x_lo = min(foot.heel, float(joints[..., 0].min())) - 0.15
    x_hi = max(foot.toe, float(joints[..., 0].max())) + 0.15
    y_lo = -0.12
    y_hi = ankle_h + reach + 0.12
    # a platform-following view, at least 0.8 times as wide as high so the figure is not a sliver
    height = y_hi - y_lo
    if x_hi - x_lo < 0.8 * height:
        pad = 0.5 * (0.8 * height - (x_hi - x_lo))
        x_lo, x_hi = x_lo - pad, x_hi + pad
    width = x_hi - x_lo

    fig = Figure(figsize=(min(8.0, 1.2 + 4.0 * width / height), 5.0))
    ax = fig.add_axes((0.15, 0.1, 0.8, 0.74))
    ax.set_xlim(x_lo, x_hi)
    ax.set_ylim(y_lo, y_hi)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x, forward, from the ankle [m]")
    ax.set_ylabel("y, up, from the platform [m]")
    head = title or result.description or "posturelab run"
    fig.suptitle(textwrap.shorten(head, 110, placeholder=" …"), fontsize=8, wrap=True)

    # platform (moves with the view) and lab-fixed floor marks that scroll past
    ax.fill_between([x_lo - 1, x_hi + 1], [-0.05, -0.05], [0, 0], color="0.55", zorder=1)
    ax.fill_between([x_lo - 1, x_hi + 1], [y_lo - 1, y_lo - 1], [-0.05, -0.05],
                    color="0.88", zorder=0)
    (floor_marks,) = ax.plot([], [], color="0.35", lw=1.0, zorder=1)
    foot_patch = ax.fill([foot.heel, 0.0, foot.toe], [0.0, ankle_h, 0.0], color=_FOOT_BROWN,
                         zorder=3)[0]
    (links_line,) = ax.plot([], [], "-o", color=_BODY_BLUE, lw=3.5, ms=5, zorder=4,
                            solid_capstyle="round")
    (cog_dot,) = ax.plot([], [], "o", color=_COG_YELLOW, mec="k", ms=9, zorder=6)
    (cog_proj,) = ax.plot([], [], "^", color=_COG_YELLOW, mec="k", ms=7, zorder=6)
    (cog_drop,) = ax.plot([], [], ":", color="0.4", lw=0.8, zorder=2)
    stamp = ax.text(0.02, 0.97, "", transform=ax.transAxes, va="top", fontsize=9,
                    family="monospace")
    fall_text = ax.text(0.5, 1.01, "", transform=ax.transAxes, va="bottom", ha="center",
                        fontsize=10, color=_FALL_RED, weight="bold")
    ax.plot([], [], "o", color=_COG_YELLOW, mec="k", label="centre of gravity (CoG)")
    ax.plot([], [], "^", color=_FALL_RED, mec="k", label="CoG beyond the foot")
    ax.legend(loc="upper right", fontsize=7, framealpha=0.8)

    spacing = 0.1
    fall_t = result.fall_time if result.fell else None

    def draw(k: int) -> None:
        pts = joints[k]
        links_line.set_data(pts[:, 0], pts[:, 1])
        cx, cy = cog[k]
        cog_dot.set_data([cx], [cy])
        cog_proj.set_data([cx], [0.0])
        cog_drop.set_data([cx, cx], [0.0, cy])
        outside = not (foot.heel <= cx <= foot.toe)
        cog_proj.set_color(_FALL_RED if outside else _COG_YELLOW)
        # floor marks at lab-fixed positions k·spacing, seen from the moving ankle
        first = math.floor((x_lo - 1 + xd[k]) / spacing)
        last = math.ceil((x_hi + 1 + xd[k]) / spacing)
        xs = np.arange(first, last + 1) * spacing - xd[k]
        mx = np.repeat(xs, 3)
        my = np.tile([-0.05, -0.10, np.nan], len(xs))
        mx[2::3] = np.nan
        floor_marks.set_data(mx, my)
        stamp.set_text(f"t   = {time[k]:5.2f} s\nx_d = {xd[k]:+6.3f} m"
                       + (f"\ny_d = {yd[k]:+6.3f} m" if np.any(yd) else ""))
        if fall_t is not None and time[k] >= fall_t - 1e-9:
            fall_text.set_text(f"FELL at t = {fall_t:.2f} s")
            links_line.set_color(_FALL_RED)
        else:
            fall_text.set_text("")
            links_line.set_color(_BODY_BLUE)
        foot_patch.set_zorder(3)

    hold = max(1, int(round(play_fps)))  # hold the last frame ~1 s
    moving = [links_line, cog_dot, cog_proj, cog_drop, floor_marks, stamp, fall_text]
    with atomic_outputs([path], suffix=".gif") as (tmp,):
        writer = _BlittingPillowWriter(moving, fps=play_fps)
        with writer.saving(fig, str(tmp), dpi):
            for k in range(len(idx)):
                draw(k)
                writer.grab_frame()
            for _ in range(hold):
                writer.grab_frame()
    return path


class _BlittingPillowWriter(PillowWriter):
    """matplotlib's Pillow GIF writer, drawing only the moving artists after frame one.

    The axes, ticks, labels and the platform are rendered once; each frame
    restores that background and draws the moving artists on it (matplotlib
    blitting), which is several times faster than a full redraw per frame.
    All frames share one palette (from the first frame), which keeps colours
    steady and the GIF small.
    """

    def __init__(self, artists, **kwargs) -> None:
        super().__init__(**kwargs)
        self._artists = list(artists)
        self._background = None
        self._palette = None
        self._images: list = []

    def setup(self, fig, outfile, dpi=None) -> None:
        super().setup(fig, outfile, dpi=dpi)
        FigureCanvasAgg(fig)  # attach an Agg canvas; no pyplot involved
        fig.set_dpi(self.dpi)
        self._background = None
        self._palette = None
        self._images = []

    def grab_frame(self, **savefig_kwargs) -> None:
        canvas = self.fig.canvas
        if self._background is None:
            for a in self._artists:
                a.set_visible(False)
            canvas.draw()
            self._background = canvas.copy_from_bbox(self.fig.bbox)
            for a in self._artists:
                a.set_visible(True)
        canvas.restore_region(self._background)
        for a in self._artists:
            self.fig.draw_artist(a)
        w, h = canvas.get_width_height(physical=True)
        im = Image.frombuffer("RGBA", (w, h), bytes(canvas.buffer_rgba()), "raw", "RGBA", 0, 1)
        im = im.convert("RGB")
        if self._palette is None:
            # the first frame's 48 main colours plus the key colours, exactly
            first = im.quantize(colors=48, method=Image.Quantize.MEDIANCUT)
            pal = first.getpalette()[: 3 * 48]
            pal += [c for rgb in _KEY_RGB for c in rgb]
            self._palette = Image.new("P", (1, 1))
            self._palette.putpalette(pal)
        self._images.append(im.quantize(palette=self._palette, dither=Image.Dither.NONE))

    def finish(self) -> None:
        self._images[0].save(self.outfile, format="GIF", save_all=True,
                             append_images=self._images[1:],
                             duration=int(round(1000 / self.fps)), loop=0, optimize=False)
