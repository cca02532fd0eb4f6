"""The scene drawn on a matplotlib Axes: its fixed geometry once, the rope's moving parts per frame.

Fixed: the seabed, the thrower box, the guide circles (dashed when one-sided), the pinned nodes. Moving: the rope (a line
through its nodes, closed for a loop), the driven nodes, heavier nodes (the end mass, drawn larger as the
square root of its mass ratio) and nodes with extra drag (the parachute, a canopy). Every artist is drawn
through its own translation, so a view that follows the driven node moves them all without re-laying the
axes: for an animation only the moving artists are redrawn each frame over a saved background.
"""

from __future__ import annotations

import numpy as np
from matplotlib.lines import Line2D
from matplotlib.path import Path
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Polygon, Rectangle
from matplotlib.transforms import Affine2D

from ..model.build import Model
from .framing import BAND_REACH, Band, Box, Circle, Ground, Projection, outline
from .marks import NODE_SIZE, Mark, moving_marks

ROPE_COLOR = "#1f77b4"
MARKED_NODES = 200       # ropes with more nodes are drawn as a plain line: markers would merge into a band
CANOPY = Path.wedge(0.0, 180.0)  # the parachute marker: a half disc, open side down
GEOMETRY = {"facecolor": "0.9", "edgecolor": "0.45", "linewidth": 1.0}


def _shifted(ax):
    """A translation (initially none) applied before ``ax``'s data transform, and the composed transform."""
    shift = Affine2D()
    return shift, shift + ax.transData


class Geometry:
    """The scene's fixed outline and pinned nodes on ``ax``."""

    def __init__(self, ax, model: Model, proj: Projection, animated: bool = False):
        self.shift, transform = _shifted(ax)
        self.artists = []
        for shape in outline(model, proj):
            if isinstance(shape, Box):
                (cx, cy), (hx, hy) = shape.center, shape.half
                patch = Rectangle((cx - hx, cy - hy), 2 * hx, 2 * hy, angle=shape.angle, rotation_point="center",
                                  zorder=1, **GEOMETRY)
            elif isinstance(shape, Circle):
                patch = CirclePatch(shape.center, shape.radius, fill=False, zorder=2,
                                    linestyle="--" if shape.one_sided else "-",
                                    edgecolor=GEOMETRY["edgecolor"], linewidth=1.2)
            elif isinstance(shape, Ground):
                patch = _ground(shape)
            else:
                patch = _band(shape)
            self.artists.append(ax.add_patch(patch))
        pinned = model.scene.pinned
        if pinned is not None:
            idx = [model.scene.node(i) for i in pinned.nodes]
            u, v = model.x0[proj.axes[0], idx], model.x0[proj.axes[1], idx]
            self.artists.append(ax.add_line(Line2D(u, v, linestyle="none", **pinned_style())))
        for artist in self.artists:
            artist.set_transform(transform)  # a patch puts its own shape transform in front of this
            artist.set_animated(animated)

    def move(self, offset: np.ndarray) -> None:
        """Draw everything shifted by ``offset`` (2,) [m] (minus the followed node's position)."""
        self.shift.clear().translate(*offset)


def _band(shape: Band) -> Rectangle:
    lo = shape.center - shape.half
    if shape.axis == 0:
        xy, w, h = (lo, -BAND_REACH), 2 * shape.half, 2 * BAND_REACH
    else:
        xy, w, h = (-BAND_REACH, lo), 2 * BAND_REACH, 2 * shape.half
    return Rectangle(xy, w, h, zorder=1, linestyle="--" if shape.one_sided else "-", **GEOMETRY)


def _ground(shape: Ground) -> Polygon:
    """The seabed's line across the whole picture and the ground below it."""
    u = np.array([-BAND_REACH, BAND_REACH])
    v = shape.height + shape.slope * u
    return Polygon([(u[0], v[0]), (u[1], v[1]), (u[1], v[1] - BAND_REACH), (u[0], v[0] - BAND_REACH)],
                   closed=True, zorder=1, **GEOMETRY)


MARKERS = {"pinned": "s", "driven": "v", "heavy": "o", "parachute": CANOPY}
ZORDER = {"pinned": 5, "driven": 6, "heavy": 5, "parachute": 5}


def mark_style(mark: Mark) -> dict:
    """The matplotlib marker style of a :class:`ropesim.render.marks.Mark`."""
    return {"marker": MARKERS[mark.kind], "markersize": mark.size, "color": mark.color, "zorder": ZORDER[mark.kind]}


def pinned_style() -> dict:
    return mark_style(Mark("pinned node", np.array([], dtype=int), "pinned"))


def special_nodes(model: Model) -> list[tuple[str, np.ndarray, dict]]:
    """(label, node indices, marker style) of the nodes drawn apart from the rope, in drawing order (the pinned
    ones are drawn with the fixed geometry)."""
    return [(mark.label, mark.nodes, mark_style(mark)) for mark in moving_marks(model)]


class RopeArtist:
    """One state of the rope on ``ax``: its line and nodes, and its special nodes."""

    def __init__(self, ax, model: Model, proj: Projection, animated: bool = False, alpha: float = 1.0,
                 color: str = ROPE_COLOR):
        self.shift, transform = _shifted(ax)
        self.cols = list(proj.axes)
        self.closed = model.scene.rope.closed
        marker = "o" if model.nodes <= MARKED_NODES else "None"
        self.line = Line2D([], [], color=color, linewidth=1.4, marker=marker, markersize=NODE_SIZE, alpha=alpha,
                           zorder=3)
        self.special = [(idx, Line2D([], [], linestyle="none", alpha=alpha, **style))
                        for _, idx, style in special_nodes(model)]
        self.artists = [self.line] + [line for _, line in self.special]
        for artist in self.artists:
            ax.add_line(artist)
            artist.set_transform(transform)
            artist.set_animated(animated)

    def show(self, x: np.ndarray, offset: np.ndarray | None = None) -> None:
        """Show positions ``x`` (N, D) [m], shifted by ``offset`` (2,) [m] if given."""
        p = np.asarray(x)[:, self.cols]
        if self.closed:
            p = np.concatenate([p, p[:1]])
        self.line.set_data(p[:, 0], p[:, 1])
        for idx, line in self.special:
            line.set_data(p[idx, 0], p[idx, 1])
        if offset is not None:
            self.shift.clear().translate(*offset)


LEGEND_MARKER = 8.0  # [pt] the largest marker in a legend: a line of 7 pt text holds it (the end mass's disc
                     # in the view may be larger)


def legend_handles(model: Model) -> list[Line2D]:
    """Legend entries for the nodes drawn apart from the rope (none for a plain rope)."""
    entries = [(label, style) for label, _, style in special_nodes(model)]
    if model.scene.pinned is not None:
        entries.append(("pinned node", pinned_style()))
    return [Line2D([], [], linestyle="none", label=label,
                   **{**style, "markersize": min(style["markersize"], LEGEND_MARKER)}) for label, style in entries]


def style_axes(ax, proj: Projection, box: np.ndarray, follow: bool, fontsize: float = 8) -> None:
    """Fixed limits ``box`` (already fitted to equal axes), labels and small ticks."""
    ax.set_xlim(*box[0])
    ax.set_ylim(*box[1])
    u, v = proj.names
    if follow:
        ax.set_xlabel(f"Δ{u} from the driven node [m]", fontsize=fontsize)
        ax.set_ylabel(f"Δ{v} [m]", fontsize=fontsize)
    else:
        ax.set_xlabel(f"{u} [m]", fontsize=fontsize)
        ax.set_ylabel(f"{v} [m]", fontsize=fontsize)
    ax.tick_params(labelsize=fontsize, length=3)
    ax.xaxis.labelpad = 1
    ax.yaxis.labelpad = 1
