"""`ropesim animate`: a run folder's trajectory as a GIF or MP4, chosen by the output file's extension.

The figure is laid out and drawn once (axes, ticks, the thrower box and guide circles, the legend); that
background is saved, and each frame restores it and draws only the moving artists (the rope, its special
nodes, the time stamp) with the Agg renderer, straight into an RGB array for the encoder. In a view that
follows the driven node the fixed geometry moves too, so it is redrawn with the rope.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterable, Iterator, Protocol

import numpy as np

from ..model.build import Model, build
from ..scene.schema import Scene
from . import SIZE_RANGE, RenderError
from .encode import ANIMATION_TYPES, GIF_MAX_FPS, gif_fps, write_gif, write_mp4
from .framing import Projection, figure_inches, followed_nodes, origin, projection, single_view, view_box
from ..io.atomic import atomic_output
from .output import output_path
from .scene_artist import Geometry, RopeArtist, body_state, legend_handles, style_axes
from .sea_artist import SeaProfile, SeaWireframe
from .style import title_text, with_picture_text
from .timeline import animation_plan
from .view3d import wants_3d

DPI = 100
PALETTE_SAMPLES = 5  # frames, evenly spread, whose colours make a GIF's palette


class Frames(Protocol):
    """What an animation needs of a run; a :class:`ropesim.Trajectory` is one (and this module need not import
    it, which would close a circle: ``Trajectory.animate`` draws with this module)."""

    scene: Scene
    t: np.ndarray   # (F,) [s]
    x: np.ndarray   # (F, N, D) [m]
    # and, for a system with rigid bodies, body_x (F, B, D) [m] and body_q (F, B, 4) (read with getattr)


@dataclass(frozen=True)
class Animation:
    """What :func:`animate` wrote."""

    path: Path
    frames: int
    fps: float
    size: tuple[int, int]  # (width, height) [px]


class FrameRenderer:
    """Renders saved frame i of a trajectory to an RGBA array (H, W, 4) uint8, redrawing only what moves."""

    def __init__(self, traj: Frames, model: Model, proj: Projection, nodes: np.ndarray | None, size: int):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        self.traj, self.nodes, self.cols = traj, nodes, list(proj.axes)
        box = view_box(model, traj.x, proj, nodes, getattr(traj, "body_x", None))
        self.layout = layout = single_view(box, size, legend=bool(legend_handles(model)))
        self.size = (layout.width, layout.height)
        fig = Figure(figsize=figure_inches(layout.width, layout.height, DPI), dpi=DPI)
        self.canvas = FigureCanvasAgg(fig)
        self.ax = ax = fig.add_axes(layout.axes_fraction)
        follow = nodes is not None
        style_axes(ax, proj, layout.box, follow)
        picture_title(fig, model, proj)
        self.geometry = Geometry(ax, model, proj, animated=follow)
        self.sea = SeaProfile(ax, model.scene, proj, animated=True)
        self.rope = RopeArtist(ax, model, proj, animated=True)
        # the time stamp, at the right of the title line: outside the view, so it never hides the rope
        self.stamp = fig.text(1 - 6 / layout.width, 1 - 3 / layout.height, "", ha="right", va="top", fontsize=9,
                              animated=True)
        self.moving = self.sea.artists + (self.geometry.artists if follow else []) + self.rope.artists + [self.stamp]
        self.canvas.draw()
        self.background = self.canvas.copy_from_bbox(fig.bbox)

    def render(self, i: int) -> np.ndarray:
        x = np.asarray(self.traj.x[i])
        offset = None
        if self.nodes is not None:
            offset = -origin(x, self.nodes)[self.cols]
            self.geometry.move(offset)
        self.canvas.restore_region(self.background)
        self.sea.show(float(self.traj.t[i]), x, offset)
        self.rope.show(x, offset, body_state(self.traj, i))
        self.stamp.set_text(f"t = {self.traj.t[i]:.2f} s")
        for artist in self.moving:
            artist.draw(self.canvas.get_renderer())
        return np.array(self.canvas.buffer_rgba())  # a plain copy: RGBA -> RGB is left to the encoder (in C)


class FrameRenderer3D:
    """Renders saved frame i of a 3-D run in the 3-D view (:mod:`ropesim.render.view3d`) to an RGBA array
    (H, W, 4) uint8, redrawing only what moves: the view is fixed, so the axes keep the projection of their one
    full drawing (in a view that follows the driven node the fixed parts move too, and are redrawn)."""

    def __init__(self, traj: Frames, model: Model, nodes: np.ndarray | None, size: int):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        from .framing import MACRO_BLOCK
        from .view3d import Geometry3D, State3D, axes_3d, azimuth, run_box

        self.traj, self.nodes = traj, nodes
        width = MACRO_BLOCK * round(size / MACRO_BLOCK)
        height = MACRO_BLOCK * round(0.8 * size / MACRO_BLOCK)
        self.size = (width, height)
        fig = Figure(figsize=figure_inches(width, height, DPI), dpi=DPI)
        self.canvas = FigureCanvasAgg(fig)
        top = (22 + (16 if legend_handles(model) else 0)) / height
        box = run_box(traj.x, nodes, getattr(traj, "body_x", None))
        self.ax = axes_3d(fig, [0.02, 0.02, 0.96, 0.96 - top], box, nodes is not None,
                          azim=azimuth(model, np.asarray(traj.x[0])), up=model.scene.up)
        picture_title(fig, model, VIEW_3D)
        self.geometry = Geometry3D(self.ax, model, box)
        self.sea = SeaWireframe(self.ax, model.scene, box)
        self.state = State3D(self.ax, model)
        self.stamp = fig.text(1 - 6 / width, 1 - 3 / height, "", ha="right", va="top", fontsize=9)
        fixed = self.geometry.artists if nodes is not None else [a for a in self.geometry.artists
                                                                  if a is self.geometry.pinned]
        # in zorder, as a full drawing would: the fixed points' markers over the lines that end on them
        self.moving = sorted(fixed + self.sea.artists + self.state.artists, key=lambda a: a.get_zorder()) + [self.stamp]
        for artist in self.moving:
            artist.set_animated(True)
        self.canvas.draw()     # the axes, their projection and the fixed parts, once
        self.background = self.canvas.copy_from_bbox(fig.bbox)

    def render(self, i: int) -> np.ndarray:
        x = np.asarray(self.traj.x[i])
        shift = None
        if self.nodes is not None:
            shift = origin(x, self.nodes)
            self.geometry.move(shift)
        self.sea.show(float(self.traj.t[i]), shift)
        self.state.show(x, shift, body_state(self.traj, i))
        self.stamp.set_text(f"t = {self.traj.t[i]:.2f} s")
        self.canvas.restore_region(self.background)
        renderer = self.canvas.get_renderer()
        for artist in self.moving:
            artist.draw(renderer)
        return np.array(self.canvas.buffer_rgba())


VIEW_3D = None   # picture_title's projection for the 3-D view


def picture_title(fig, model: Model, proj: Projection | None) -> None:
    """The scene's name (and the view of a 3-D scene: a projection, or None for the 3-D view) at the top left,
    the legend on a line below it."""
    parts = [model.scene.name]
    if model.scene.dimension == 3:
        parts.append(f"view {''.join(proj.names)}" if proj is not None else "view 3d")
    height = fig.bbox.height
    fig.text(4 / fig.bbox.width, 1 - 3 / height, title_text("  ·  ".join(parts)), ha="left", va="top", fontsize=9,
             fontweight="bold")
    handles = legend_handles(model)
    if handles:
        fig.legend(handles=handles, loc="upper left", bbox_to_anchor=(4 / fig.bbox.width, 1 - 17 / height),
                   ncol=len(handles), frameon=False, fontsize=7, handletextpad=0.2, columnspacing=1.0,
                   borderaxespad=0.0, borderpad=0.2)


@with_picture_text
def animate(traj: Frames, out: str | Path, *, fps: float = 25.0, speed: float = 1.0,
            start: float | None = None, end: float | None = None, follow: bool = False, view: str | None = None,
            size: int = 640, progress: bool = False, note: Callable[[str], None] | None = None) -> Animation:
    """Write an animation of ``traj`` to ``out`` (.gif or .mp4) and say what was written.

    fps: video frames per second; speed: simulated seconds per second of video; start/end: the time range
    [s] (default the whole run); follow: the view from the driven node; view: the projection of a 3-D scene
    ("xy", "xz", "zy", ...) or "3d" (:mod:`ropesim.render.view3d`; the default for a 3-D system);
    size: the picture's longer side [px]; note: receives one-line remarks (too few saved frames, GIF rate).
    Raises :class:`ropesim.render.RenderError` for a request that cannot be met, before writing anything.
    """
    out = Path(out)
    real, kind = output_path(out, ANIMATION_TYPES)
    if not 1 <= size <= SIZE_RANGE[1]:    # (the command line asks for at least SIZE_RANGE[0], what is drawn)
        raise RenderError(f"--size {size}: must be a number of pixels from {SIZE_RANGE[0]} to {SIZE_RANGE[1]}")
    remarks = []
    rate = fps
    if kind == ".gif" and fps > 0:
        rate = gif_fps(fps)
        if fps > GIF_MAX_FPS:
            remarks.append(f"a GIF plays at most {GIF_MAX_FPS:g} fps: using {rate:g} (write an .mp4 for more)")
    plan = animation_plan(traj.t, rate, speed, start, end)
    frame = getattr(traj, "frame", None)
    traj = getattr(traj, "internal", traj)    # drawn in the y-up frame the model's geometry is in
    model = build(traj.scene, solve=False)   # the frames hold the shape: no static solve
    three_d = wants_3d(view, traj.scene)
    proj = None if three_d else projection(view, traj.scene.dimension, frame)
    if three_d and traj.scene.dimension != 3:
        raise RenderError(f"--view {view}: the 3-D view is for 3-D scenes; this one is {traj.scene.dimension}-D "
                          f"(its view is xy)")
    nodes = followed_nodes(model, follow)
    if plan.note:
        remarks.append(plan.note)
    for remark in remarks:
        if note is not None:
            note(remark)
    check_memory(size * size, f"--size {size}")     # the picture is at most size x size px
    renderer = (FrameRenderer3D(traj, model, nodes, size) if three_d else
                FrameRenderer(traj, model, proj, nodes, size))
    frames = _tracked((renderer.render(i) for i in plan.indices), len(plan.indices), f"encoding {out.name}",
                      progress)
    with atomic_output(real) as tmp:
        if kind == ".gif":
            spread = plan.indices[np.linspace(0, len(plan.indices) - 1, PALETTE_SAMPLES).round().astype(int)]
            write_gif(frames, tmp, plan.fps, [_sample(renderer.render(i)) for i in spread])
        else:
            write_mp4(frames, tmp, plan.fps, renderer.size)
    played = gif_fps(plan.fps) if kind == ".gif" else plan.fps
    return Animation(path=out, frames=len(plan.indices), fps=played, size=renderer.size)


BYTES_PER_PIXEL = 24   # the canvas, its saved background, the frame's copy, its RGB and palette images, the
                       # previous frame, and the palette's pixel samples (measured: 1.2 GB at --size 8192)


def check_memory(pixels: int, option: str) -> None:
    """Refuse (before drawing anything) a picture whose frames would need more than half the free memory."""
    needed = BYTES_PER_PIXEL * pixels
    free = available_memory()
    if free and needed > free / 2:
        side = int((free / 2 / BYTES_PER_PIXEL) ** 0.5)
        raise RenderError(f"{option}: a {pixels / 1e6:.3g} megapixel animation needs about {needed / 1e9:.2g} GB of "
                          f"memory and {free / 1e9:.2g} GB is free; at most about {side} px a side here")


def available_memory() -> int:
    """Bytes of memory free for a new allocation (Linux: MemAvailable), or 0 when unknown."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):
        return 0


def _sample(frame: np.ndarray) -> np.ndarray:
    """A palette sample of a frame: its pixels (at most PALETTE_PIXELS, evenly strided) as (P, 1, 4)."""
    from .encode import PALETTE_PIXELS

    flat = frame.reshape(-1, frame.shape[-1])
    return np.ascontiguousarray(flat[::max(1, len(flat) // PALETTE_PIXELS)])[:, None, :]


def _tracked(frames: Iterable[np.ndarray], total: int, label: str, enabled: bool) -> Iterator[np.ndarray]:
    """``frames`` with a rich progress bar on stderr when ``enabled``."""
    if not enabled:
        return iter(frames)
    from rich.console import Console
    from rich.progress import track

    return iter(track(frames, total=total, description=label, console=Console(stderr=True), transient=True))

