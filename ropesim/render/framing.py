"""Where the picture looks: the projection, the followed node, the scene's fixed outline, and view limits.

A 2-D scene is drawn as it is (x across, y up). A 3-D scene is drawn projected on two of its axes, chosen by
``view`` ("xy": side view, y up; "xz": from above; "zy": from the front; the first letter runs across; in a z-up
scene "xz" is the side view and "xy" the view from above). Pictures are drawn from the run in ropesim's y-up frame
(:attr:`ropesim.Trajectory.internal`), labelled with the scene's own axes.
With ``follow`` every position is taken relative to the driven nodes' centre, the view from the helicopter.
Limits are fixed from the whole run, read in blocks of frames so a long run is never loaded at once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import SIZE_RANGE, RenderError
from ..analysis.summary import FRAME_BLOCK, block_frames
from ..model.build import Model

AXIS_NAMES = "xyz"
MAX_ASPECT = 3.0          # the view's height / width stays within [1 / MAX_ASPECT, MAX_ASPECT]
MARGIN = 0.05             # padding around the run's extent, as a fraction of its span
BAND_REACH = 1e6          # [m] how far a guide cylinder seen side-on is drawn along its axis


@dataclass(frozen=True)
class Projection:
    """Which scene axes run across (``axes[0]``) and up (``axes[1]``) the picture."""

    axes: tuple[int, int]
    labels: tuple[str, str] | None = None   # the scene's own names of the axes (a z-up scene's), if not x, y, z

    @property
    def names(self) -> tuple[str, str]:
        return self.labels or (AXIS_NAMES[self.axes[0]], AXIS_NAMES[self.axes[1]])


def projection(view: str | None, dim: int, frame=None) -> Projection:
    """The projection for ``view`` (default "xy", the side view; "xz" in a z-up scene) on a ``dim``-dimensional
    scene, whose frames are drawn in ropesim's y-up frame. In a z-up scene (``frame``) the view names the scene's
    own axes: x, z (up, the y-up frame's y) and y (the y-up frame's -z: a view across y is labelled -y)."""
    turned = frame is not None and frame.turned
    view = ("xz" if turned else "xy") if view is None else view.strip().lower()
    allowed = AXIS_NAMES[:dim]
    if len(view) != 2 or view[0] == view[1] or any(c not in allowed for c in view):
        side, above, front = ("xz", "xy", "yz") if turned else ("xy", "xz", "zy")
        example = (f"{side} (side view), {above} (from above) or {front} (from the front), or 3d for a 3-D view"
                   if dim == 3 else "xy")
        raise RenderError(f"--view {view}: choose two different axes of this {dim}-D scene from "
                          f"{', '.join(allowed)}, e.g. {example}")
    if turned:
        axes = ("xzy".index(view[0]), "xzy".index(view[1]))
        return Projection(axes, (frame.axis_name(axes[0]), frame.axis_name(axes[1])))
    return Projection((allowed.index(view[0]), allowed.index(view[1])))


def followed_nodes(model: Model, follow: bool) -> np.ndarray | None:
    """Indices of the driven nodes whose centre the view follows (a system's: the line ends on its driven
    points and on its driven bodies), or None for the lab frame."""
    if not follow:
        return None
    scene = model.scene
    if scene.is_system:
        from ..model.layout import point_ends

        driven_bodies = {b.id for b in scene.rigid_bodies if b.kind in ("driven", "coupled")}
        ends = point_ends(scene, model.lines)
        nodes = sorted(i for p in scene.points if p.kind in ("driven", "coupled") or (p.kind == "body" and p.body in driven_bodies)
                       for i in ends[p.id])
        if not nodes:
            raise RenderError(f"--follow: scene '{scene.name}' has no driven point or body to follow")
        return np.asarray(nodes, dtype=np.int64)
    nodes = sorted({model.scene.node(i) for drive in model.scene.driven for i in drive.nodes})
    if not nodes:
        raise RenderError(f"--follow: scene '{model.scene.name}' has no driven node to follow "
                          f"(only scenes with [[driven]] nodes, like the helicopter ones)")
    return np.asarray(nodes, dtype=np.int64)


def origin(x: np.ndarray, nodes: np.ndarray | None) -> np.ndarray:
    """The view's origin for frames ``x`` (..., N, D): the followed nodes' centre, or zero (lab frame)."""
    x = np.asarray(x)
    if nodes is None:
        return np.zeros(x.shape[:-2] + x.shape[-1:])
    return x[..., nodes, :].mean(axis=-2)


# ------------------------------------------------------------------------------------- fixed outline


@dataclass(frozen=True)
class Box:
    """A rectangle in the picture's coordinates [m] (the thrower box): half-sides ``half`` along its own axes,
    turned by ``angle`` [deg] counter-clockwise about its centre (0: axis-aligned)."""

    center: tuple[float, float]
    half: tuple[float, float]
    angle: float = 0.0

    def corners(self) -> np.ndarray:
        """The four corners (4, 2) [m]."""
        a = np.radians(self.angle)
        rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
        local = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * np.asarray(self.half)
        return np.asarray(self.center) + local @ rot.T


@dataclass(frozen=True)
class Circle:
    """A circle in the picture's coordinates [m] (a guide seen along its axis)."""

    center: tuple[float, float]
    radius: float
    one_sided: bool = False


@dataclass(frozen=True)
class Band:
    """A guide cylinder seen side-on: |u - center| < half across picture axis ``axis``, unbounded along the
    other."""

    axis: int
    center: float
    half: float
    one_sided: bool = False


@dataclass(frozen=True)
class Ground:
    """A seabed seen edge-on: the line v = height + slope u across the picture, the ground below it."""

    height: float
    slope: float


def outline(model: Model, proj: Projection) -> list:
    """The scene's fixed geometry projected on ``proj``: the seabed, the thrower box, then the guide circles.

    The box is |x - cx| < L/2, |y - cy| < W/2 (and |z - cz| < W/2), turned by its launch angle in x-y: drawn
    turned in the x-y view, and as the extent of the turned box in a view along x or y; a guide is a circle in
    x-y, a cylinder along z in 3-D. The seabed, the plane y = height + tan(slope) x, is drawn edge-on in the
    side view (x across, y up), and in the front view (z across) when it is flat; not from above.
    """
    scene = model.scene
    a, b = proj.axes
    shapes: list = []
    bed = scene.seabed
    if bed is not None and b == 1 and (a == 0 or bed.slope == 0.0):
        shapes.append(Ground(bed.height, math.tan(math.radians(bed.slope)) if a == 0 else 0.0))
    if scene.thrower is not None:
        t = scene.thrower
        if t.angle == 0.0:
            half = (t.length / 2, t.width / 2, t.width / 2)
            shapes.append(Box((t.center[a], t.center[b]), (half[a], half[b])))
        elif proj.axes in ((0, 1), (1, 0)):
            sign = 1.0 if proj.axes == (0, 1) else -1.0    # the y-x view mirrors the turn
            shapes.append(Box((t.center[a], t.center[b]), (t.length / 2, t.width / 2), sign * t.angle))
        else:
            c, s = (abs(f) for f in t.direction)
            half = (c * t.length / 2 + s * t.width / 2, s * t.length / 2 + c * t.width / 2, t.width / 2)
            shapes.append(Box((t.center[a], t.center[b]), (half[a], half[b])))
    for g in scene.guides:
        if 2 not in proj.axes:
            shapes.append(Circle((g.center[a], g.center[b]), g.radius, g.one_sided))
        else:
            across = 0 if a != 2 else 1
            shapes.append(Band(across, g.center[proj.axes[across]], g.radius, g.one_sided))
    return shapes


def outline_extent(shapes: list) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners [m] of the bounded parts of ``shapes`` (inf/-inf where none)."""
    lo, hi = np.full(2, np.inf), np.full(2, -np.inf)
    for s in shapes:
        if isinstance(s, Box):
            corners = s.corners()
            lo, hi = np.minimum(lo, corners.min(axis=0)), np.maximum(hi, corners.max(axis=0))
        elif isinstance(s, Circle):
            c = np.asarray(s.center)
            lo, hi = np.minimum(lo, c - s.radius), np.maximum(hi, c + s.radius)
        elif isinstance(s, Ground):
            continue   # unbounded: the rope on it sets the view
        else:
            lo[s.axis] = min(lo[s.axis], s.center - s.half)
            hi[s.axis] = max(hi[s.axis], s.center + s.half)
    return lo, hi


# ------------------------------------------------------------------------------------------ limits


def frame_blocks(frames: int, block: int | None = None, frame_nbytes: int = 0):
    """Slices covering ``range(frames)`` in blocks (default FRAME_BLOCK frames, fewer for frames of
    ``frame_nbytes`` bytes each when that many would exceed BLOCK_BYTES), for reading a memory-mapped
    trajectory lazily."""
    block = block_frames(frame_nbytes, block or FRAME_BLOCK)
    for start in range(0, frames, block):
        yield slice(start, min(start + block, frames))


def run_extent(x: np.ndarray, proj: Projection, nodes: np.ndarray | None,
               bodies: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners [m] of every finite projected node position over all frames of ``x`` (and of the
    rigid bodies' reference points ``bodies`` (F, B, D), if given)."""
    lo, hi = np.full(2, np.inf), np.full(2, -np.inf)
    cols = list(proj.axes)
    for sl in frame_blocks(len(x), frame_nbytes=x[0].nbytes):
        block = np.asarray(x[sl])
        if bodies is not None:
            block = np.concatenate([block, np.asarray(bodies[sl])], axis=1)
        p = (block - origin(block, nodes)[:, None, :])[:, :, cols]
        p = p[np.isfinite(p).all(axis=-1)]
        if len(p):
            lo, hi = np.minimum(lo, p.min(axis=0)), np.maximum(hi, p.max(axis=0))
    if not np.all(np.isfinite(lo)):
        raise RenderError("the run has no finite frame to show")
    return lo, hi


def view_box(model: Model, x: np.ndarray, proj: Projection, nodes: np.ndarray | None,
             bodies: np.ndarray | None = None) -> np.ndarray:
    """The view [[x0, x1], [y0, y1]] [m]: every node of the whole run (and the rigid bodies' reference points
    ``bodies`` (F, B, D), and, in the lab frame, the fixed outline), padded by MARGIN and at least one segment
    length across."""
    lo, hi = run_extent(x, proj, nodes, bodies)
    if nodes is None:
        olo, ohi = outline_extent(outline(model, proj))
        lo, hi = np.fmin(lo, olo), np.fmax(hi, ohi)
    centre, span = (lo + hi) / 2, hi - lo
    span = np.maximum(span, min(line.segment_length for line in model.lines)) * (1 + 2 * MARGIN)
    return np.stack([centre - span / 2, centre + span / 2], axis=1)


def fit_box(box: np.ndarray, width: float, height: float) -> np.ndarray:
    """``box`` grown along one axis so that one metre spans as many pixels across as up (equal axes) in an
    area ``width`` x ``height`` px."""
    centre = box.mean(axis=1)
    span = box[:, 1] - box[:, 0]
    scale = max(span[0] / width, span[1] / height)  # metres per pixel
    half = np.array([width, height]) * scale / 2
    return np.stack([centre - half, centre + half], axis=1)


def view_aspect(box: np.ndarray) -> float:
    """Height / width of ``box``, kept within [1 / MAX_ASPECT, MAX_ASPECT]."""
    span = box[:, 1] - box[:, 0]
    return float(min(max(span[1] / span[0], 1 / MAX_ASPECT), MAX_ASPECT))


@dataclass(frozen=True)
class Layout:
    """A single-view picture: its size [px], the axes' place in it [px from the left and bottom], and limits."""

    width: int
    height: int
    axes: tuple[int, int, int, int]   # left, bottom, width, height [px]
    box: np.ndarray                   # [[x0, x1], [y0, y1]] [m]

    @property
    def axes_fraction(self) -> list[float]:
        left, bottom, w, h = self.axes
        return [left / self.width, bottom / self.height, w / self.width, h / self.height]


PAD = {"left": 58, "right": 12, "bottom": 36, "top": 22}  # [px] room for tick labels and the title line
LEGEND_LINE = 16  # [px] more at the top when there is a legend line under the title
MACRO_BLOCK = 16  # picture sizes are whole multiples of this, so video encoders never rescale
MIN_SIDE = SIZE_RANGE[0]   # [px] no side shorter, so the title and legend fit


def single_view(box: np.ndarray, size: int, legend: bool = False) -> Layout:
    """A picture whose longer side is about ``size`` px, holding ``box`` with equal axes."""
    aspect = view_aspect(box)
    top = PAD["top"] + (LEGEND_LINE if legend else 0)
    pad_w, pad_h = PAD["left"] + PAD["right"], PAD["bottom"] + top
    axes_width = min(size - pad_w, (size - pad_h) / aspect)  # the largest view that fits a size x size square
    width, height = axes_width + pad_w, axes_width * aspect + pad_h
    width, height = (MACRO_BLOCK * math.ceil(max(v, MIN_SIDE) / MACRO_BLOCK) for v in (width, height))
    axes = (PAD["left"], PAD["bottom"], width - pad_w, height - pad_h)
    return Layout(width=width, height=height, axes=axes, box=fit_box(box, axes[2], axes[3]))


def figure_inches(width: int, height: int, dpi: float) -> tuple[float, float]:
    """Figure size [in] for exactly ``width`` x ``height`` px: matplotlib truncates inches * dpi to whole
    pixels, so a quarter pixel is added against rounding down (4.64 * 100 = 463.99...)."""
    return (width + 0.25) / dpi, (height + 0.25) / dpi
