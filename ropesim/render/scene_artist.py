"""The scene drawn on a matplotlib Axes: its fixed geometry once, the rope's moving parts per frame.

Fixed: the seabed, the thrower box, the guide circles (dashed when one-sided), the pinned nodes (a system's
fixed points). Moving: the rope (a line through its nodes, closed for a loop; a system's lines each in its own
colour), the driven nodes, heavier nodes (the end mass, drawn larger as the square root of its mass ratio),
nodes with extra drag (the parachute, a canopy), a system's free and driven points, and its rigid bodies, each
drawn as a glyph: spokes from its reference point to the points on it, and its axes (x red, y green, z blue).
Every artist is drawn through its own translation, so a view that follows the driven node moves them all
without re-laying the axes: for an animation only the moving artists are redrawn each frame over a saved
background.
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
from .marks import NODE_SIZE, Mark, moving_marks, pinned_mark

ROPE_COLOR = "#1f77b4"
LINE_COLORS = (ROPE_COLOR, "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22",
               "#7f7f7f")   # a system's lines, in turn (matplotlib's tab10 without the driven marker's red)
AXIS_COLORS = ("#d62728", "#2ca02c", "#1f77b4")   # a body's x, y and z axes
BODY_COLOR = "0.3"
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
        pinned = pinned_mark(model)
        if pinned is not None:
            u, v = model.x0[proj.axes[0], pinned.nodes], model.x0[proj.axes[1], pinned.nodes]
            self.artists.append(ax.add_line(Line2D(u, v, linestyle="none", **mark_style(pinned))))
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


MARKERS = {"pinned": "s", "driven": "v", "heavy": "o", "parachute": CANOPY, "point": "o"}
ZORDER = {"pinned": 5, "driven": 6, "heavy": 5, "parachute": 5, "point": 5}


def mark_style(mark: Mark) -> dict:
    """The matplotlib marker style of a :class:`ropesim.render.marks.Mark`."""
    return {"marker": MARKERS[mark.kind], "markersize": mark.size, "color": mark.color, "zorder": ZORDER[mark.kind]}


def special_nodes(model: Model) -> list[tuple[str, np.ndarray, dict]]:
    """(label, node indices, marker style) of the nodes drawn apart from the rope, in drawing order (the pinned
    ones are drawn with the fixed geometry)."""
    return [(mark.label, mark.nodes, mark_style(mark)) for mark in moving_marks(model)]


def line_color(k: int) -> str:
    """The colour of a system's line ``k``."""
    return LINE_COLORS[k % len(LINE_COLORS)]


class RopeArtist:
    """One state of the rope (a system's lines) on ``ax``: each line and its nodes, the special nodes, and the
    rigid bodies. ``color`` draws every line in one colour (the overlay's fading); by default a rope is
    ROPE_COLOR and a system's lines take LINE_COLORS in turn."""

    def __init__(self, ax, model: Model, proj: Projection, animated: bool = False, alpha: float = 1.0,
                 color: str | None = None):
        self.shift, transform = _shifted(ax)
        self.cols = list(proj.axes)
        marker = "o" if model.nodes <= MARKED_NODES else "None"
        self.lines = []
        for k, line in enumerate(model.lines):
            shade = color or (line_color(k) if model.scene.is_system else ROPE_COLOR)
            artist = Line2D([], [], color=shade, linewidth=1.4, marker=marker, markersize=NODE_SIZE, alpha=alpha,
                            zorder=3, label=line.id if color is None else f"_{line.id}")   # a shade: unnamed
            self.lines.append((slice(line.first, line.end), line.closed, artist))
        self.line = self.lines[0][2]
        self.special = [(idx, Line2D([], [], linestyle="none", alpha=alpha, **style))
                        for _, idx, style in special_nodes(model)]
        self.bodies = BodyGlyphs(model, proj, alpha) if model.scene.rigid_bodies else None
        self.artists = [artist for _, _, artist in self.lines] + [line for _, line in self.special]
        self.artists += self.bodies.artists if self.bodies is not None else []
        for artist in self.artists:
            ax.add_line(artist)
            artist.set_transform(transform)
            artist.set_animated(animated)

    def show(self, x: np.ndarray, offset: np.ndarray | None = None, bodies=None) -> None:
        """Show positions ``x`` (N, D) [m] (and ``bodies``, (body_x (B, D), body_q (B, 4)) of the same frame),
        shifted by ``offset`` (2,) [m] if given."""
        p = np.asarray(x)[:, self.cols]
        for part, closed, artist in self.lines:
            q = p[part]
            if closed:
                q = np.concatenate([q, q[:1]])
            artist.set_data(q[:, 0], q[:, 1])
        for idx, line in self.special:
            line.set_data(p[idx, 0], p[idx, 1])
        if self.bodies is not None:
            self.bodies.show(bodies)
        if offset is not None:
            self.shift.clear().translate(*offset)


class BodyGlyphs:
    """A system's rigid bodies, each drawn as its :class:`ropesim.analysis.objects.Glyph`: spokes from its
    reference point to the points on it (dark grey, the reference point a ring) and its axes (x red, y green,
    z blue; a 2-D body's x and y)."""

    def __init__(self, model: Model, proj: Projection, alpha: float = 1.0):
        from ..analysis.objects import body_glyphs
        from ..analysis.rotation import rotation_matrix

        self.rotation_matrix = rotation_matrix
        self.glyphs = body_glyphs(model.scene)
        self.cols, self.dim = list(proj.axes), model.scene.dimension
        self.spokes = Line2D([], [], color=BODY_COLOR, linewidth=2.6, alpha=alpha, zorder=4, solid_capstyle="round")
        self.centres = Line2D([], [], linestyle="none", marker="o", markersize=5.0, markerfacecolor="white",
                              markeredgecolor=BODY_COLOR, markeredgewidth=1.4, alpha=alpha, zorder=6)
        self.axes = [Line2D([], [], color=c, linewidth=1.4, alpha=alpha, zorder=5) for c in AXIS_COLORS[:self.dim]]
        self.artists = [self.spokes, *self.axes, self.centres]

    def shapes(self, state) -> tuple[np.ndarray, list[np.ndarray], np.ndarray]:
        """The glyphs of body state ``state`` ((B, D) positions, (B, 4) quaternions) in scene coordinates: the
        spokes as one polyline (NaN between spokes), each axis's segments (NaN between bodies), the reference
        points (B, D)."""
        position, quaternion = (np.asarray(a, dtype=float) for a in state)
        rotation = self.rotation_matrix(quaternion, self.dim)
        spokes, axes = [], [[] for _ in range(self.dim)]
        for glyph, where, turn in zip(self.glyphs, position, rotation):
            body_spokes, body_axes = glyph.segments(where, turn)
            spokes += [broken_polyline(body_spokes)]
            for k in range(self.dim):
                axes[k].append(broken_polyline(body_axes[k:k + 1]))
        return (np.concatenate(spokes), [np.concatenate(a) for a in axes], position)

    def show(self, state) -> None:
        """Draw the bodies at ``state`` ((B, D), (B, 4)); None hides them (a run without body states)."""
        if state is None:
            for artist in self.artists:
                artist.set_data([], [])
            return
        spokes, axes, centres = self.shapes(state)
        u, v = self.cols
        self.spokes.set_data(spokes[:, u], spokes[:, v])
        for artist, segments in zip(self.axes, axes):
            artist.set_data(segments[:, u], segments[:, v])
        self.centres.set_data(centres[:, u], centres[:, v])


def broken_polyline(pairs: np.ndarray) -> np.ndarray:
    """(from, to) pairs (K, 2, D) as one polyline that matplotlib breaks at the NaN rows between them."""
    gap = np.full((len(pairs), 1, pairs.shape[-1]), np.nan)
    return np.concatenate([pairs, gap], axis=1).reshape(-1, pairs.shape[-1])


def body_state(traj, i: int):
    """Frame ``i``'s rigid-body state (body_x (B, D), body_q (B, 4)) of a run, or None without one."""
    if getattr(traj, "body_x", None) is None or getattr(traj, "body_q", None) is None:
        return None
    return np.asarray(traj.body_x[i]), np.asarray(traj.body_q[i])


LEGEND_MARKER = 8.0  # [pt] the largest marker in a legend: a line of 7 pt text holds it (the end mass's disc
                     # in the view may be larger)


def legend_handles(model: Model) -> list[Line2D]:
    """Legend entries: a system's lines by id, then the nodes drawn apart from the rope (none for a plain rope),
    then the pinned nodes (a system's fixed points)."""
    handles = []
    if model.scene.is_system:
        handles += [Line2D([], [], color=line_color(k), linewidth=1.4, label=line.id)
                    for k, line in enumerate(model.lines)]
    entries = [(label, style) for label, _, style in special_nodes(model)]
    pinned = pinned_mark(model)
    if pinned is not None:
        entries.append((pinned.label, mark_style(pinned)))
    return handles + [Line2D([], [], linestyle="none", label=label,
                             **{**style, "markersize": min(style["markersize"], LEGEND_MARKER)})
                      for label, style in entries]


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
