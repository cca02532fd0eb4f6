"""What a run shows: a general description of a run's moving and fixed parts, for the browser viewer.

A :class:`RunContent` holds, for one run, its saved times and

- ``lines``: polylines (open or closed) of N nodes, their positions per frame, and fields to colour them by,
  per segment (tension, strain) or per node (speed);
- ``points``: glyphs at points, either nodes of a line (a driven node, an end mass: they move with it) or
  positions of their own;
- ``bodies``: rigid bodies drawn as boxes: a size, and a position and an orientation (a unit quaternion w, x, y,
  z turning the body's axes into the scene's) either fixed or per frame;
- ``shapes``: fixed geometry that is not a box (the string shooter's guide circles: cylinders along an axis);
- ``water`` and ``seabed``: a surface each, flat (a level, or a plane) or a height grid (waves: per frame);
- ``series``: time series for the panel under the view (a line's end tensions; a shooter's loop inclination);
- ``summary``: the run's summary as (what, figures) rows.

Positions are in metres, in the scene's axes (y up); a 2-D run's are (x, y). Every per-frame array has the run's
frames on its first axis and may be a memory map: nothing is read here, so the packer can thin the frames first.

:func:`run_content` is the one function that reads a run folder into this structure: one rope is one line; a
system of lines fills a line per line (each coloured by its own tension, strain or speed), its points as glyphs
(fixed, driven, free, and the points on its bodies), and its rigid bodies as boxes: the scene gives a body no
shape, so it is drawn as the box around its reference point and the points on it, in its own axes (each side at
least a tenth of its longest), turning with it; a sea surface would fill more entries of it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol

import numpy as np

from ..scene.schema import STILL_KINDS


class FrameArray(Protocol):
    """A per-frame array, read lazily: ``a[frame_indices]`` is an ndarray with the frames on axis 0."""

    shape: tuple

    def __getitem__(self, index): ...


@dataclass(frozen=True)
class Field:
    """A quantity to colour a line by: ``values`` (F, S) per segment or (F, N) per node (``per``), in ``unit``."""

    name: str
    unit: str
    per: str                   # "segment" or "node"
    values: FrameArray


@dataclass(frozen=True)
class Line:
    """A polyline of nodes: positions (F, N, D) [m]; a closed one joins its last node to its first."""

    name: str
    positions: FrameArray
    closed: bool = False
    fields: tuple[Field, ...] = ()

    @property
    def nodes(self) -> int:
        return self.positions.shape[1]

    @property
    def segments(self) -> int:
        return self.nodes if self.closed else self.nodes - 1


@dataclass(frozen=True)
class Points:
    """Glyphs with a legend label: at nodes ``nodes`` of line ``line`` (they move with it), or at ``positions``
    (F, K, D) [m] of their own. ``kind`` is the glyph: pinned (square), driven (triangle down), heavy (disc),
    parachute (canopy), point (small disc); ``size`` [px] on the screen."""

    name: str
    kind: str
    color: str
    size: float
    line: int | None = None
    nodes: tuple[int, ...] = ()
    positions: FrameArray | None = None


@dataclass(frozen=True)
class Body:
    """A rigid body drawn as a box of ``size`` (3,) [m] along its own axes: centre ``position`` (D,) or (F, D)
    [m] and ``orientation`` (4,) or (F, 4), unit quaternions (w, x, y, z); ``fixed`` ones are scene geometry
    (drawn grey, like the thrower box in `ropesim animate`)."""

    name: str
    size: tuple[float, float, float]
    position: np.ndarray | FrameArray
    orientation: np.ndarray | FrameArray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0, 0.0]))
    fixed: bool = False
    color: str = "#e6e6e6"


@dataclass(frozen=True)
class Shape:
    """Fixed geometry other than a box: a ``cylinder`` of ``radius`` [m] about ``axis`` through ``center`` (a
    circle in a 2-D scene, unbounded along its axis in 3-D); ``dashed`` draws it dashed (a one-sided guide)."""

    name: str
    kind: str
    center: tuple[float, ...]
    radius: float
    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    dashed: bool = False


@dataclass(frozen=True)
class Surface:
    """The water surface or the seabed: the plane y = height + tan(slope) x (``slope_deg`` [deg], rising towards
    +x), or a height grid: ``heights`` (len(x), len(z)) [m] over the grid ``x``, ``z`` [m], or (F, len(x),
    len(z)) per frame (waves)."""

    height: float = 0.0
    slope_deg: float = 0.0
    x: np.ndarray | None = None
    z: np.ndarray | None = None
    heights: np.ndarray | FrameArray | None = None


@dataclass(frozen=True)
class Series:
    """A time series for the panel under the view: ``values`` (F,) in ``unit``."""

    name: str
    unit: str
    values: np.ndarray


@dataclass
class RunContent:
    """Everything the viewer shows of one run (see the module)."""

    name: str
    dimension: int
    t: np.ndarray                                # (F,) [s]
    lines: list[Line] = field(default_factory=list)
    points: list[Points] = field(default_factory=list)
    bodies: list[Body] = field(default_factory=list)
    shapes: list[Shape] = field(default_factory=list)
    water: Surface | None = None
    seabed: Surface | None = None
    series: list[Series] = field(default_factory=list)
    summary: list[tuple[str, str]] = field(default_factory=list)
    description: str = ""
    where: str = ""                              # the run folder, or "in memory"
    axes: tuple = ("x", "y", "z")                # the scene's names of the drawn axes (a z-up scene's: x, z, -y)

    @property
    def frames(self) -> int:
        return len(self.t)


class Speed:
    """Each node's speed |v| (F, N) [m/s], computed from the velocities (F, N, D) when read; the blocks read
    last are kept (the packer reads each block twice: for the range, then to store it)."""

    KEEP_BYTES = 64 * 2 ** 20

    def __init__(self, v: FrameArray):
        self.v = v
        self.shape = tuple(v.shape[:2])
        self._kept: dict[bytes, np.ndarray] = {}

    def __getitem__(self, index):
        key = np.asarray(index).tobytes() if not isinstance(index, slice) else None
        if key is not None and key in self._kept:
            return self._kept[key]
        v = np.asarray(self.v[index], dtype=float)
        speed = np.sqrt(np.einsum("...d,...d->...", v, v))
        if key is not None and speed.nbytes + sum(a.nbytes for a in self._kept.values()) <= self.KEEP_BYTES:
            self._kept[key] = speed
        return speed


class WaveHeights:
    """The sea's surface height [m] (F, len(x), len(z)) over a grid, computed from the scene's waves for the
    frames read (:class:`ropesim.model.waves.WaveField`)."""

    def __init__(self, field, t: np.ndarray, x: np.ndarray, z: np.ndarray):
        self.field, self.t, self.x, self.z = field, t, x, z
        self.shape = (len(t), len(x), len(z))
        self.ndim = 3

    def __getitem__(self, index):
        t = np.asarray(self.t[index], dtype=float)
        return self.field.level + self.field.elevation(self.x[None, :, None], t[..., None, None],
                                                       self.z[None, None, :])


def _water(scene, traj) -> Surface:
    """The sea's surface: flat at its level, or in 3-D with waves a 33 x 33 grid over the run's extent and the
    viewer's margin around it (0.6 of its size), moving frame by frame."""
    from ..model.waves import wave_field

    field = wave_field(scene)
    if field is None or scene.dimension == 2:   # the 2-D view draws the mean level
        return Surface(height=scene.sea.level)
    frames = np.arange(0, len(traj.t), max(1, len(traj.t) // 100))   # the extent, from a hundred frames
    x = np.asarray(traj.x[frames], dtype=float)
    lo, hi = x.min(axis=(0, 1)), x.max(axis=(0, 1))
    pad = 0.6 * float(np.max(hi - lo))
    grid_x = np.linspace(lo[0] - pad, hi[0] + pad, 33)
    grid_z = np.linspace(lo[2] - pad, hi[2] + pad, 33)
    return Surface(height=scene.sea.level, x=grid_x, z=grid_z,
                   heights=WaveHeights(field, np.asarray(traj.t, dtype=float), grid_x, grid_z))


class Scaled:
    """``values`` times ``factor`` when read (strain as a percentage)."""

    def __init__(self, values: FrameArray, factor: float):
        self.values, self.factor = values, factor
        self.shape = tuple(values.shape)

    def __getitem__(self, index):
        return np.asarray(self.values[index], dtype=float) * self.factor


def run_content(run) -> RunContent:
    """The :class:`RunContent` of a run: a run folder (a path; finished, interrupted or still running: its
    frames up to the last checkpoint) or a :class:`ropesim.Trajectory`. Raises RunFolderError (one line) for a
    folder that is not a run's."""
    from ..io.trajectory import Trajectory
    from ..model.build import build

    traj = run if isinstance(run, Trajectory) else Trajectory.open(Path(run))
    traj = traj.internal    # drawn in the y-up frame the model's geometry is in (the viewer's y is up)
    scene = traj.scene
    model = build(scene, solve=False)    # node masses and the marks; the frames hold the shape
    fields = []
    if traj.tension is not None:
        fields.append(Field("tension", "N", "segment", traj.tension))
    if traj.strain is not None:
        fields.append(Field("strain", "%", "segment", Scaled(traj.strain, 100.0)))
    fields.append(Field("speed", "m/s", "node", Speed(traj.v)))
    content = RunContent(name=scene.name, dimension=scene.dimension, t=np.asarray(traj.t, dtype=float),
                         axes=("x", "z", "-y") if scene.up == "z" else ("x", "y", "z"),
                         description=scene.description,
                         where=str(traj.folder) if traj.folder is not None else "in memory")
    if scene.is_system:
        content.lines.extend(_system_lines(traj, model))
        content.points.extend(_system_points(traj, model))
        content.bodies.extend(_rigid_bodies(traj))
    else:
        content.lines.append(Line("rope", traj.x, closed=scene.rope.closed, fields=tuple(fields)))
        content.points.extend(_marks(model))
    content.bodies.extend(_thrower(scene))
    content.shapes.extend(Shape("guide circle", "cylinder", _padded(g.center), g.radius, dashed=g.one_sided)
                          for g in scene.guides)
    if scene.seabed is not None:
        content.seabed = Surface(height=scene.seabed.height, slope_deg=scene.seabed.slope)
    if scene.sea is not None:
        content.water = _water(scene, traj)
    content.series.extend(_series(traj, model))
    content.summary.extend(_summary(traj, content))
    return content


def _system_lines(traj, model) -> list[Line]:
    """Each line of a system, its positions and fields views of the run's (nothing read here)."""
    out, first_segment = [], 0
    for line in model.lines:
        nodes, segments = slice(line.first, line.end), slice(first_segment, first_segment + line.segments)
        first_segment += line.segments
        fields = []
        if traj.tension is not None:
            fields.append(Field("tension", "N", "segment", traj.tension[:, segments]))
        if traj.strain is not None:
            fields.append(Field("strain", "%", "segment", Scaled(traj.strain[:, segments], 100.0)))
        fields.append(Field("speed", "m/s", "node", Speed(traj.v[:, nodes])))
        out.append(Line(line.id, traj.x[:, nodes], closed=line.closed, fields=tuple(fields)))
    return out


class NodeSubset:
    """The positions (F, K, D) of nodes ``nodes`` of a run's (F, N, D), read when indexed by frames."""

    def __init__(self, x: FrameArray, nodes):
        self.x, self.nodes = x, list(nodes)
        self.shape = (x.shape[0], len(self.nodes), x.shape[2])
        self.ndim = 3

    def __getitem__(self, index):
        return np.asarray(self.x[index])[..., self.nodes, :]


def _system_points(traj, model) -> list[Points]:
    """A system's marks (fixed, free and driven points, as `ropesim animate` marks them), then the points on its
    rigid bodies, each a glyph at its own positions (the first of its line ends)."""
    from ..model.layout import point_ends
    from ..render.marks import moving_marks, pinned_mark

    out = [Points(m.label, m.kind, m.css_color, _screen_size(m.size), positions=NodeSubset(traj.x, m.nodes))
           for m in (pinned_mark(model), *moving_marks(model)) if m is not None]
    ends = point_ends(model.scene, model.lines)
    on_bodies = [ends[p.id][0] for p in model.scene.points if p.kind == "body"]
    if on_bodies:
        out.append(Points("point on a body", "point", BODY_POINT_CSS, _screen_size(5.0),
                          positions=NodeSubset(traj.x, on_bodies)))
    return out


BODY_POINT_CSS = "#4d4d4d"
BODY_CSS = "#a6bddb"
MIN_SIDE = 0.1     # a body's box: no side shorter than this fraction of its longest


class BoxCentre:
    """The centre (F, D) [m] of body ``b``'s box, ``offset`` (D,) [m] from its reference point in its own
    axes: x_b + R(q) offset, read when indexed by frames."""

    def __init__(self, traj, b: int, offset: np.ndarray):
        self.traj, self.b, self.offset = traj, b, np.asarray(offset, dtype=float)
        self.shape = (len(traj.t), traj.body_x.shape[2])
        self.ndim = 2

    def __getitem__(self, index):
        from ..analysis.rotation import rotation_matrix

        dim = self.shape[1]
        x = np.asarray(self.traj.body_x[index], dtype=float)[..., self.b, :]
        turn = rotation_matrix(np.asarray(self.traj.body_q[index])[..., self.b, :], dim)
        return x + turn @ self.offset


def _rigid_bodies(traj) -> list[Body]:
    """A system's rigid bodies as boxes around their reference points and their points (see the module)."""
    if traj.body_x is None:
        return []
    scene = traj.scene
    dim = scene.dimension
    out = []
    for b, body in enumerate(scene.rigid_bodies):
        local = np.array([np.zeros(dim)] + [p.position for p in scene.points if p.kind == "body"
                                            and p.body == body.id], dtype=float)
        lo, hi = local.min(axis=0), local.max(axis=0)
        side = np.maximum(hi - lo, MIN_SIDE * float(np.max(hi - lo)) or 1.0)
        size = tuple(float(v) for v in side) + ((0.0,) if dim == 2 else ())
        out.append(Body(body.id, size, BoxCentre(traj, b, (lo + hi) / 2), traj.body_q[:, b],
                        fixed=body.kind in STILL_KINDS, color=BODY_CSS))
    return out


def _padded(v) -> tuple[float, float, float]:
    """A 2-D or 3-D point as three coordinates (z = 0 in a 2-D scene)."""
    v = tuple(float(c) for c in v)
    return v + (0.0,) * (3 - len(v))


def _marks(model) -> list[Points]:
    """The nodes `ropesim animate` marks, as points on line 0: pinned nodes, heavy nodes, parachutes, bodies,
    driven nodes (:mod:`ropesim.render.marks`)."""
    from ..render.marks import moving_marks, pinned_mark

    marks = [m for m in (pinned_mark(model), *moving_marks(model)) if m is not None]
    return [Points(m.label, m.kind, m.css_color, _screen_size(m.size), line=0, nodes=tuple(int(i) for i in m.nodes))
            for m in marks]


PX_PER_PT = 1.6   # markers read on a screen at about the size they have in a 640-px animation


def _screen_size(points: float) -> float:
    return round(PX_PER_PT * points, 1)


def _thrower(scene) -> list[Body]:
    """The string shooter's thrower box: |x - cx| < L/2 across its length, W/2 across (in 3-D in z too), turned
    by its launch angle about z."""
    t = scene.thrower
    if t is None:
        return []
    half = math.radians(t.angle) / 2
    depth = t.width if scene.dimension == 3 else 0.0
    return [Body("thrower box", (t.length, t.width, depth), np.array(_padded(t.center)),
                 np.array([math.cos(half), 0.0, 0.0, math.sin(half)]), fixed=True)]


def _series(traj, model) -> list[Series]:
    """The panel's series: an open line's end tensions, or a string shooter's loop inclination."""
    scene = model.scene
    if scene.thrower is not None and model.lines[0].closed:
        from ..analysis.shooter import loop_inclination

        return [Series("loop inclination", "deg", _blockwise(traj.x, lambda x: loop_inclination(model, x)))]
    if traj.tension is None:
        return []
    tension = traj.tension
    if scene.is_system:
        from ..analysis.tension import end_columns

        return [Series(f"tension at {label}", "N", np.asarray(tension[:, column], dtype=float))
                for label, column in end_columns(model)]
    if scene.rope.closed:
        return [Series("largest tension", "N", _blockwise(tension, lambda block: np.nanmax(block, axis=1)))]
    last = tension.shape[1] - 1
    out = [Series("tension at node 0 (segment 0)", "N", np.asarray(tension[:, 0], dtype=float))]
    if last > 0:
        out.append(Series(f"tension at node {last + 1} (segment {last})", "N",
                          np.asarray(tension[:, last], dtype=float)))
    return out


def _blockwise(frames: FrameArray, fn) -> np.ndarray:
    """``fn`` of a (possibly memory-mapped) per-frame array, read in blocks of frames, joined."""
    from ..analysis.summary import block_frames

    step = block_frames(np.asarray(frames[:1]).nbytes)
    return np.concatenate([np.asarray(fn(np.asarray(frames[s:s + step], dtype=float)), dtype=float)
                           for s in range(0, len(frames), step)])


def _summary(traj, content: RunContent) -> list[tuple[str, str]]:
    """The rows of the summary table: what the run is, then `ropesim run`'s own summary rows."""
    from ..analysis.objects import made_of
    from ..cli.report import summary_rows

    scene, summary = traj.scene, traj.summary
    status = summary.get("status", "completed")
    rows = [("scene", scene.name + (f": {scene.description}" if scene.description else "")),
            ("status", status),
            ("nodes", f"{traj.nodes} ({made_of(scene)}, {scene.dimension}-D)"),
            ("frames", f"{traj.frames}, t = {float(traj.t[0]):.6g} .. {float(traj.t[-1]):.6g} s")]
    rows += [row for row in summary_rows(summary) if row[0] != "simulated" or status != "incomplete"]
    rows.append(("stored", content.where))
    return rows
