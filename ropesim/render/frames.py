"""`ropesim frames`: one PNG of selected frames, side by side or overlaid with fading (the write-up's figures
3-5 and 8-10).

Every panel (or every overlaid rope) uses the same fixed limits, from the whole run, so shapes compare
directly; in the overlay older frames are lighter and fainter, the last one solid. A sea's surface is drawn at
each panel's time (an overlay's: at its last frame's; :mod:`ropesim.render.sea_artist`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import RenderError
from ..model.build import build
from ..io.trajectory import Trajectory
from .framing import figure_inches, fit_box, followed_nodes, origin, projection, view_aspect, view_box
from .output import output_path, save_png
from .scene_artist import Geometry, RopeArtist, body_state, legend_handles, style_axes
from .sea_artist import SeaProfile, SeaWireframe
from .style import OUTSIDE_RIGHT, title_text, with_picture_text
from .timeline import chosen_frames
from .view3d import wants_3d

DPI = 100
PANEL_SIDE = 300      # [px] default longer side of one side-by-side panel's view
OVERLAY_SIDE = 600    # [px] default longer side of an overlay's view
MAX_COLUMNS = 4
MIN_WIDTH = 360       # [px] default pictures are at least this wide, so the title and legend fit
TICK_ROOM = 50        # [px] per panel: its tick labels across
TITLE_ROOM = 44       # [px] per panel row: its title and tick labels
HEADER_ROOM = 40      # [px] the figure's title and legend
LEGEND_ROOM = 90      # [px] an overlay's legend, beside its view
FADE = (0.35, 1.0)    # colour-map position and opacity of the first and the last overlaid frame


@dataclass(frozen=True)
class Sheet:
    """What :func:`frame_sheet` wrote."""

    path: Path
    times: tuple[float, ...]   # the saved times shown [s]
    size: tuple[int, int]      # (width, height) [px]


def default_columns(frames: int, aspect: float) -> int:
    """Panels per row: up to 4 for tall views (the shooter's loop), 2 for wide ones (a towed rope in the lab),
    spread evenly over the rows."""
    most = MAX_COLUMNS if aspect > 1.2 else 3 if aspect > 0.6 else 2
    return math.ceil(frames / math.ceil(frames / most))


@with_picture_text
def frame_sheet(traj: Trajectory, out: str | Path, *, times: list[float] | None = None, count: int | None = None,
                overlay: bool = False, follow: bool = False, view: str | None = None, columns: int | None = None,
                width: int | None = None) -> Sheet:
    """Write a PNG of the frames nearest to ``times`` [s] (or ``count`` evenly spaced ones, default 6).

    overlay: all frames on one view, fading from the first to the last; follow: the view from the driven
    node; view: the projection of a 3-D scene, or "3d" (the default for a 3-D system); columns: panels per row;
    width: the picture's width [px].
    """
    out = Path(out)
    real, _ = output_path(out, (".png",))
    indices = chosen_frames(traj.t, times, count)
    if columns is not None and columns < 1:
        raise RenderError(f"--columns {columns}: must be at least 1")
    if width is not None and width < 200:
        raise RenderError(f"--width {width}: must be at least 200 px")
    frame = traj.frame
    traj = traj.internal                     # drawn in the y-up frame the model's geometry is in
    model = build(traj.scene, solve=False)   # the frames hold the shape: no static solve
    nodes = followed_nodes(model, follow)
    if wants_3d(view, traj.scene):
        if traj.scene.dimension != 3:
            raise RenderError(f"--view {view}: the 3-D view is for 3-D scenes; this one is "
                              f"{traj.scene.dimension}-D (its view is xy)")
        return _sheet_3d(traj, model, real, out, indices, nodes, overlay, columns, width)
    proj = projection(view, traj.scene.dimension, frame)
    box = view_box(model, traj.x, proj, nodes, traj.body_x)
    aspect = view_aspect(box)
    box = fit_box(box, 1.0, aspect)
    frames = [np.asarray(traj.x[i]) for i in indices]
    states = [body_state(traj, i) for i in indices]
    offsets = [None if nodes is None else -origin(x, nodes)[list(proj.axes)] for x in frames]

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    cols = 1 if overlay else (columns or default_columns(len(indices), aspect))
    rows = math.ceil(len(indices) / cols) if not overlay else 1
    side = OVERLAY_SIDE if overlay else PANEL_SIDE
    beside = LEGEND_ROOM if overlay else 0   # an overlay's legend stands beside its view
    px_width = width or cols * int(TICK_ROOM + side * min(1.0, 1.0 / aspect)) + beside
    view_width = px_width / cols - TICK_ROOM - beside   # what is left for each view: it sets the height
    px_height = int(round(HEADER_ROOM + rows * (view_width * aspect + TITLE_ROOM)))
    px_width = max(px_width, MIN_WIDTH)  # wider only: the views keep their size, centred
    fig = Figure(figsize=figure_inches(px_width, px_height, DPI), dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, cols, sharex=True, sharey=True, squeeze=False).ravel()
    for ax in axes:
        style_axes(ax, proj, box, nodes is not None)
        ax.set_aspect("equal", adjustable="box")
    shown = [float(traj.t[i]) for i in indices]
    if overlay:
        _overlay(axes[0], model, proj, frames, offsets, shown, states)
    else:
        for ax, x, offset, t, state in zip(axes, frames, offsets, shown, states):
            geometry = Geometry(ax, model, proj)
            if offset is not None:
                geometry.move(offset)
            SeaProfile(ax, model.scene, proj).show(t, x, offset)
            RopeArtist(ax, model, proj).show(x, offset, state)
            ax.set_title(f"t = {t:.2f} s", fontsize=9, pad=3)
        for ax in axes[len(frames):]:
            ax.set_visible(False)
        fig.supylabel(axes[0].get_ylabel(), fontsize=8)
        for ax in axes:
            ax.label_outer()   # x labels stay under the bottom row, where the layout leaves the legend room
            ax.set_ylabel("")
    header = model.scene.name + (f"  ·  view {''.join(proj.names)}" if traj.scene.dimension == 3 else "")
    fig.suptitle(title_text(header), x=0.01, ha="left", fontsize=10, fontweight="bold")
    handles = legend_handles(model)
    if handles:
        fig.legend(handles=handles, loc="outside lower center", ncol=len(handles), frameon=False, fontsize=7)
    save_png(fig, real, DPI)
    return Sheet(path=out, times=tuple(shown), size=(px_width, px_height))


SIDE_3D = 380      # [px] default width of one panel of the 3-D view
ASPECT_3D = 0.7    # its height / width


def _sheet_3d(traj, model, real, out, indices, nodes, overlay, columns, width) -> Sheet:
    """:func:`frame_sheet` in the 3-D view (:mod:`ropesim.render.view3d`): a 3-D axes per frame, or one for all."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from .view3d import Geometry3D, State3D, axes_3d, azimuth, run_box

    box = run_box(traj.x, nodes, traj.body_x)
    azim = azimuth(model, np.asarray(traj.x[0]))
    cols = 1 if overlay else (columns or math.ceil(len(indices) / math.ceil(len(indices) / 3)))
    rows = 1 if overlay else math.ceil(len(indices) / cols)
    side = OVERLAY_SIDE if overlay else SIDE_3D
    beside = LEGEND_ROOM if overlay else 0
    px_width = max(width or cols * side + beside, MIN_WIDTH)
    px_height = int(round(HEADER_ROOM + rows * ((px_width - beside) / cols * ASPECT_3D + TITLE_ROOM / 2)))
    fig = Figure(figsize=figure_inches(px_width, px_height, DPI), dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    grid = fig.add_gridspec(rows, cols)
    shown = [float(traj.t[i]) for i in indices]
    frames = [(np.asarray(traj.x[i]), body_state(traj, i)) for i in indices]
    shifts = [None if nodes is None else origin(x, nodes) for x, _ in frames]
    if overlay:
        from matplotlib import colormaps
        from matplotlib.lines import Line2D

        ax = axes_3d(fig, grid[0, 0], box, nodes is not None, azim=azim, up=model.scene.up)
        geometry = Geometry3D(ax, model, box)
        if shifts[-1] is not None:
            geometry.move(shifts[-1])
        SeaWireframe(ax, model.scene, box).show(shown[-1], shifts[-1])   # the sea of the solid, last frame
        fades = np.linspace(*FADE, len(frames)) if len(frames) > 1 else np.array([FADE[1]])
        handles = []
        for (x, state), shift, t, f in zip(frames, shifts, shown, fades):
            color = colormaps["Blues"](f)
            State3D(ax, model, alpha=float(f), color=color).show(x, shift, state)
            handles.append(Line2D([], [], color=color, alpha=float(f), label=f"t = {t:.2f} s"))
        ax.legend(handles=handles, fontsize=7, **OUTSIDE_RIGHT)
    else:
        for k, ((x, state), shift, t) in enumerate(zip(frames, shifts, shown)):
            ax = axes_3d(fig, grid[k // cols, k % cols], box, nodes is not None, fontsize=7, azim=azim, up=model.scene.up)
            geometry = Geometry3D(ax, model, box)
            if shift is not None:
                geometry.move(shift)
            SeaWireframe(ax, model.scene, box).show(t, shift)
            State3D(ax, model).show(x, shift, state)
            ax.set_title(f"t = {t:.2f} s", fontsize=9, pad=0)
    fig.suptitle(f"{model.scene.name}  ·  view 3d", x=0.01, ha="left", fontsize=10, fontweight="bold")
    handles = legend_handles(model)
    if handles:
        fig.legend(handles=handles, loc="outside lower center", ncol=len(handles), frameon=False, fontsize=7)
    save_png(fig, real, DPI)
    return Sheet(path=out, times=tuple(shown), size=(px_width, px_height))


def _overlay(ax, model, proj, frames, offsets, times, states) -> None:
    """All ``frames`` on ``ax``, fading from light and faint (first) to dark and solid (last)."""
    from matplotlib import colormaps
    from matplotlib.lines import Line2D

    cmap = colormaps["Blues"]
    geometry = Geometry(ax, model, proj)
    if offsets[-1] is not None:
        geometry.move(offsets[-1])
    SeaProfile(ax, model.scene, proj).show(times[-1], frames[-1], offsets[-1])   # the sea of the solid, last frame
    fades = np.linspace(*FADE, len(frames)) if len(frames) > 1 else np.array([FADE[1]])
    handles = []
    for x, offset, t, f, state in zip(frames, offsets, times, fades, states):
        color = cmap(f)
        RopeArtist(ax, model, proj, alpha=float(f), color=color).show(x, offset, state)
        handles.append(Line2D([], [], color=color, alpha=float(f), label=f"t = {t:.2f} s"))
    ax.legend(handles=handles, fontsize=7, **OUTSIDE_RIGHT)
