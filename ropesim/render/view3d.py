"""A 3-D scene drawn in perspective-free 3-D axes (matplotlib's mplot3d, orthographic): ``--view 3d``, the
default for a 3-D system of lines.

Why: a spread mooring's or a sling's lines lie in several vertical planes, so any one of the side, top or front
projections puts some of them on top of each other (OC3-Hywind's lines 2 and 3 coincide seen from the side);
a view from above and aside shows every line and how a body turns. Orthographic, so lengths along each axis
read alike everywhere in the picture, with equal scales on the three axes.

The scene's y points up, so it is drawn on matplotlib's vertical axis: a scene point (x, y, z) is plotted at
(x, -z, y), a proper rotation (the picture is not mirrored), and the axis across the back is labelled z with
its ticks showing z. The seabed is a translucent plane under the run's extent. The view does not move during an
animation, so its axes, panes, grid and fixed parts are drawn once and kept, and each frame draws only what
moves over them, in the view's projection (as the projections' animations do).
"""

from __future__ import annotations

import numpy as np

from ..model.build import Model
from .framing import frame_blocks, origin
from .marks import NODE_SIZE
from .scene_artist import (AXIS_COLORS, BODY_COLOR, GEOMETRY, MARKED_NODES, ROPE_COLOR, broken_polyline, line_color,
                           mark_style, special_nodes)

VIEW = "3d"
ELEVATION = 24.0                    # [deg] the camera above the horizon
AZIMUTHS = np.arange(-85.0, -4.0, 5.0)   # [deg] the camera's bearings to choose from (matplotlib's azimuth)
MARGIN = 0.04


def wants_3d(view: str | None, scene) -> bool:
    """True when the picture is the 3-D view: asked for (``--view 3d``), or by default for a 3-D system."""
    if view is not None:
        return view.strip().lower() == VIEW
    return scene.dimension == 3 and scene.is_system


def plotted(p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Scene points (..., 3) as matplotlib's (X, Y, Z) = (x, -z, y)."""
    p = np.asarray(p, dtype=float)
    return p[..., 0], -p[..., 2], p[..., 1]


def run_box(x, nodes: np.ndarray | None, bodies=None) -> np.ndarray:
    """The run's extent [[x0, x1], [y0, y1], [z0, z1]] [m] in scene axes, every finite node (and body reference
    point) over every frame, relative to the followed nodes when given; padded by MARGIN, equal-sided enough
    that a flat run is still seen (each side at least a fifth of the largest)."""
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for sl in frame_blocks(len(x), frame_nbytes=x[0].nbytes):
        block = np.asarray(x[sl])
        if bodies is not None:
            block = np.concatenate([block, np.asarray(bodies[sl])], axis=1)
        p = block - origin(block, nodes)[:, None, :]
        p = p[np.isfinite(p).all(axis=-1)]
        if len(p):
            lo, hi = np.minimum(lo, p.min(axis=0)), np.maximum(hi, p.max(axis=0))
    if not np.all(np.isfinite(lo)):
        from . import RenderError

        raise RenderError("the run has no finite frame to show")
    centre, span = (lo + hi) / 2, hi - lo
    span = np.maximum(span, max(span.max() / 5, 1e-6)) * (1 + 2 * MARGIN)
    return np.stack([centre - span / 2, centre + span / 2], axis=1)


def azimuth(model: Model, x0: np.ndarray) -> float:
    """The camera's bearing [deg] (matplotlib's azimuth) that looks along no line: of AZIMUTHS, the one farthest
    from every line's horizontal direction (its chord from start to end in frame ``x0`` (N, 3)), seen either way
    along it, so that no line is foreshortened to a point or hidden behind another (a spread mooring's lines
    120 deg apart are all seen side-on). Lines shorter across than a tenth of the longest do not count."""
    bearings, sizes = [], []
    for line in model.lines:
        chord = np.asarray(x0[line.end - 1] - x0[line.first], dtype=float)
        X, Y, _ = plotted(chord)
        bearings.append(np.degrees(np.arctan2(Y, X)))
        sizes.append(np.hypot(X, Y))
    sizes = np.asarray(sizes)
    bearings = np.asarray(bearings)[sizes >= 0.1 * sizes.max()] if sizes.max() > 0 else np.zeros(0)
    if bearings.size == 0:
        return float(AZIMUTHS[len(AZIMUTHS) // 2])
    apart = np.abs((AZIMUTHS[:, None] - bearings[None, :] + 90.0) % 180.0 - 90.0)   # 0 .. 90 deg, either way
    return float(AZIMUTHS[int(np.argmax(apart.min(axis=1)))])


def axes_3d(fig, rect_or_spec, box: np.ndarray, follow: bool, fontsize: float = 8, azim: float = -60.0,
            up: str = "y"):
    """A 3-D axes on ``fig`` (at a [left, bottom, width, height] fraction, or a subplot spec) showing the scene
    box ``box`` (of the run in ropesim's y-up frame) with equal scales, labelled in the scene's own axes (``up``
    "z": matplotlib's (X, Y, Z) = (x, -z, y) of the y-up frame are the z-up scene's (x, y, z) themselves), seen
    from bearing ``azim`` [deg]."""
    from matplotlib.ticker import FuncFormatter

    if isinstance(rect_or_spec, (list, tuple)):
        ax = fig.add_axes(rect_or_spec, projection="3d", proj_type="ortho")
    else:
        ax = fig.add_subplot(rect_or_spec, projection="3d", proj_type="ortho")
    ax.set_xlim(*box[0])
    ax.set_ylim(-box[2][1], -box[2][0])
    ax.set_zlim(*box[1])
    spans = box[:, 1] - box[:, 0]
    ax.set_box_aspect((spans[0], spans[2], spans[1]), zoom=1.05)
    ax.computed_zorder = False     # drawn in zorder: the seabed under the lines that rest on it
    ax.view_init(elev=ELEVATION, azim=azim)
    delta = "Δ" if follow else ""
    names = ("x", "y", "z") if up == "z" else ("x", "z", "y")
    if up != "z":    # matplotlib's Y is -z
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{-v:g}" if v else "0"))
    for axis, name in zip((ax.xaxis, ax.yaxis, ax.zaxis), names):
        axis.set_label_text(f"{delta}{name} [m]", fontsize=fontsize)
        axis.labelpad = 0
    ax.tick_params(labelsize=fontsize - 1, pad=0)
    return ax


class Geometry3D:
    """The scene's fixed parts in the 3-D view: the seabed as a translucent plane under the view's box, the fixed
    points (pinned nodes)."""

    def __init__(self, ax, model: Model, box: np.ndarray):
        from mpl_toolkits.mplot3d.art3d import Poly3DCollection

        from .marks import pinned_mark

        self.artists = []
        self.ax, self.box = ax, box
        bed = model.scene.seabed
        self.slope = np.tan(np.radians(bed.slope)) if bed is not None else 0.0
        self.height = bed.height if bed is not None else 0.0
        self.bed = None
        if bed is not None:
            self.bed = Poly3DCollection([self._bed_corners(np.zeros(3))], facecolor=GEOMETRY["facecolor"],
                                        edgecolor=GEOMETRY["edgecolor"], linewidth=0.6, alpha=0.55, zorder=1)
            ax.add_collection3d(self.bed)
            self.artists.append(self.bed)
        pinned = pinned_mark(model)
        self.pinned = None
        if pinned is not None:
            self.fixed = np.asarray(model.x0[:, pinned.nodes].T)
            (self.pinned,) = ax.plot(*plotted(self.fixed), linestyle="none", **mark_style(pinned))
            self.artists.append(self.pinned)

    def _bed_corners(self, shift: np.ndarray) -> np.ndarray:
        (x0, x1), _, (z0, z1) = self.box
        corners = np.array([[x0, 0.0, z0], [x1, 0.0, z0], [x1, 0.0, z1], [x0, 0.0, z1]])
        corners[:, 1] = self.height + self.slope * (corners[:, 0] - shift[0]) - shift[1]
        return np.stack(plotted(corners), axis=-1)

    def move(self, shift: np.ndarray) -> None:
        """Draw the fixed parts relative to ``shift`` (3,) [m] (the followed nodes' centre)."""
        if self.bed is not None:
            self.bed.set_verts([self._bed_corners(shift)])
        if self.pinned is not None:
            self.pinned.set_data_3d(*plotted(self.fixed - shift))


class State3D:
    """One state of the lines, their special nodes and the rigid bodies in a 3-D axes (as
    :class:`ropesim.render.scene_artist.RopeArtist` draws them in a projection)."""

    def __init__(self, ax, model: Model, alpha: float = 1.0, color: str | None = None):
        from ..analysis.objects import body_glyphs
        from ..analysis.rotation import rotation_matrix

        self.rotation_matrix = rotation_matrix
        marker = "o" if model.nodes <= MARKED_NODES else "None"
        self.lines = []
        for k, line in enumerate(model.lines):
            shade = color or (line_color(k) if model.scene.is_system else ROPE_COLOR)
            (artist,) = ax.plot([], [], [], color=shade, linewidth=1.8, marker=marker, markersize=NODE_SIZE,
                                alpha=alpha, label=line.id if color is None else f"_{line.id}", zorder=3)
            self.lines.append((slice(line.first, line.end), line.closed, artist))
        self.special = [(idx, ax.plot([], [], [], linestyle="none", alpha=alpha, **style)[0])
                        for _, idx, style in special_nodes(model)]
        self.glyphs = body_glyphs(model.scene) if model.scene.rigid_bodies else []
        self.spokes = self.centres = None
        self.axes = []
        if self.glyphs:
            (self.spokes,) = ax.plot([], [], [], color=BODY_COLOR, linewidth=2.6, alpha=alpha,
                                     solid_capstyle="round", zorder=4)
            self.axes = [ax.plot([], [], [], color=c, linewidth=1.4, alpha=alpha, zorder=5)[0] for c in AXIS_COLORS]
            (self.centres,) = ax.plot([], [], [], linestyle="none", marker="o", markersize=5.0,
                                      markerfacecolor="white", markeredgecolor=BODY_COLOR, markeredgewidth=1.4,
                                      alpha=alpha, zorder=6)

    @property
    def artists(self) -> list:
        """Everything this state draws, in drawing order."""
        body = [self.spokes, *self.axes, self.centres] if self.glyphs else []
        return [artist for _, _, artist in self.lines] + [artist for _, artist in self.special] + body

    def show(self, x: np.ndarray, shift: np.ndarray | None = None, bodies=None) -> None:
        """Show positions ``x`` (N, 3) [m] (and ``bodies``: body_x (B, 3), body_q (B, 4)), relative to
        ``shift`` (3,) [m] if given."""
        shift = np.zeros(3) if shift is None else np.asarray(shift, dtype=float)
        p = np.asarray(x, dtype=float) - shift
        for part, closed, artist in self.lines:
            q = p[part]
            if closed:
                q = np.concatenate([q, q[:1]])
            artist.set_data_3d(*plotted(q))
        for idx, artist in self.special:
            artist.set_data_3d(*plotted(p[idx]))
        if not self.glyphs:
            return
        if bodies is None:
            for artist in (self.spokes, *self.axes, self.centres):
                artist.set_data_3d([], [], [])
            return
        position = np.asarray(bodies[0], dtype=float) - shift
        rotation = self.rotation_matrix(bodies[1])
        spokes, axes = [], [[] for _ in range(3)]
        for glyph, where, turn in zip(self.glyphs, position, rotation):
            body_spokes, body_axes = glyph.segments(where, turn)
            spokes.append(broken_polyline(body_spokes))
            for k in range(3):
                axes[k].append(broken_polyline(body_axes[k:k + 1]))
        self.spokes.set_data_3d(*plotted(np.concatenate(spokes)))
        for artist, segments in zip(self.axes, axes):
            artist.set_data_3d(*plotted(np.concatenate(segments)))
        self.centres.set_data_3d(*plotted(position))
