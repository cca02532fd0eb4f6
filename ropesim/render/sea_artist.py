"""The sea's surface in the pictures, at each frame's time: in a side view (a projection whose vertical axis is
the height) the surface's profile along the view's horizontal axis with the water shaded below it; in the 3-D
view a wireframe of the surface over the run's extent. The section a side view of a 3-D scene cuts is through
the lines: at the frame's nodes' mean position across the view. A view from above draws no surface.

The elevation is the waves' (:func:`ropesim.model.sea_frames.elevation`, their ramp included), flat at the
mean level without ``[waves]``; the browser viewer draws the same surface (:mod:`ropesim.viewer.content`).
"""

from __future__ import annotations

import numpy as np

from ..model.sea_frames import elevation
from .framing import Projection

SURFACE_COLOR = "#2a7ab8"
WATER_COLOR = "#cfe4f3"
PROFILE_SAMPLES = 400    # points along a side view's profile: a wave is drawn smooth at any zoom of the run
GRID_LINES = 25          # lines each way of the 3-D view's wireframe


class SeaProfile:
    """The surface and the water below it in a side view on ``ax`` (whose limits are set): nothing for a scene
    without a ``[sea]`` or a view from above (``active`` False)."""

    def __init__(self, ax, scene, proj: Projection, animated: bool = False):
        from matplotlib.lines import Line2D
        from matplotlib.patches import Polygon

        self.scene, self.ax = scene, ax
        self.along = proj.axes[0]
        self.active = scene.sea is not None and proj.axes[1] == 1
        self.artists = []
        if not self.active:
            return
        self.water = ax.add_patch(Polygon(np.zeros((3, 2)), closed=True, facecolor=WATER_COLOR, edgecolor="none",
                                          alpha=0.6, zorder=0.5))
        self.surface = ax.add_line(Line2D([], [], color=SURFACE_COLOR, linewidth=1.2, zorder=0.6))
        self.artists = [self.water, self.surface]
        for artist in self.artists:
            artist.set_animated(animated)

    def show(self, t: float, x: np.ndarray, offset: np.ndarray | None = None) -> None:
        """The surface at time ``t`` [s], its section through the nodes ``x`` (N, D) [m]; ``offset`` (2,) [m] the
        view's shift (minus the followed node's position)."""
        if not self.active:
            return
        shift = np.zeros(2) if offset is None else np.asarray(offset, dtype=float)
        lo, hi = self.ax.get_xlim()
        u = np.linspace(lo, hi, PROFILE_SAMPLES)
        world = u - shift[0]
        across = 0.0
        if x.shape[1] == 3:
            finite = x[np.isfinite(x).all(axis=1)]
            across = float(finite[:, 2 - self.along].mean()) if len(finite) else 0.0
        px, pz = (world, across) if self.along == 0 else (across, world)
        v = self.scene.sea.level + elevation(self.scene, t, px, pz) + shift[1]
        bottom = min(self.ax.get_ylim()[0], float(v.min())) - 1.0
        self.surface.set_data(u, v)
        self.water.set_xy(np.concatenate([np.column_stack([u, v]), [[hi, bottom], [lo, bottom]]]))


class SeaWireframe:
    """The surface as a wireframe over the 3-D view's box ``box`` (scene axes [[x0, x1], [y0, y1], [z0, z1]])."""

    def __init__(self, ax, scene, box: np.ndarray):
        from mpl_toolkits.mplot3d.art3d import Line3DCollection

        self.scene = scene
        self.active = scene.sea is not None
        self.artists = []
        if not self.active:
            return
        self.gx = np.linspace(*box[0], GRID_LINES)
        self.gz = np.linspace(*box[2], GRID_LINES)
        self.mesh = Line3DCollection(self._segments(np.full((GRID_LINES, GRID_LINES), scene.sea.level),
                                                    np.zeros(3)),
                                     colors=SURFACE_COLOR, linewidths=0.5, alpha=0.55, zorder=1.5)
        ax.add_collection3d(self.mesh, autolim=False)
        self.artists = [self.mesh]

    def _segments(self, height: np.ndarray, shift: np.ndarray) -> list:
        """The wireframe's lines (each grid row and column) of surface heights (G, G) over the shifted grid."""
        from .view3d import plotted

        X, Z = np.meshgrid(self.gx, self.gz, indexing="ij")
        grid = np.stack(plotted(np.stack([X, height, Z], axis=-1)), axis=-1)   # (G, G, 3)
        return list(grid) + list(grid.transpose(1, 0, 2))

    def show(self, t: float, shift: np.ndarray | None = None) -> None:
        """The surface at time ``t`` [s]; ``shift`` (3,) [m] the followed nodes' centre."""
        if not self.active:
            return
        s = np.zeros(3) if shift is None else np.asarray(shift, dtype=float)
        X, Z = np.meshgrid(self.gx, self.gz, indexing="ij")
        height = self.scene.sea.level + elevation(self.scene, t, X + s[0], Z + s[2]) - s[1]
        self.mesh.set_segments(self._segments(height, s))
