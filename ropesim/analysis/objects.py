"""A run's results per object: each line's, point's and rigid body's, by its id.

:meth:`ropesim.Trajectory.line`, :meth:`~ropesim.Trajectory.point` and :meth:`~ropesim.Trajectory.body` return
the classes below. Their arrays have the run's frames on the first axis; a line's are views of the trajectory's
(memory-mapped for a run folder, so nothing is read until used), the forces are computed when first asked for.
SI units throughout, angles in degrees as the scene writes them.

The force a line end puts on what it is attached to (a point, a body, a support) is its end segment's axial
force, the tension T of :mod:`ropesim.model.tension` (the spring's k (r - l0), none while a slack segment is
short, plus the axial damping), along the segment towards the line: F = T (x_n - x_e) / |x_n - x_e|, x_e the
end node and x_n its neighbour on the line. A line in tension pulls what it is attached to towards itself; a
line that pushes (a segment in compression, where its material allows it) pushes it away. The end node itself
(half a segment's mass, weight, buoyancy and drag) moves with the point or body it sits on, so its own forces
are not in F: F is what a load cell in the line just below the attachment would read, MoorDyn's fairlead
tension.

A body's force is the sum of the end forces of every line end on its points; its moment, about the body's
reference point (the ``position`` its motion is reported at), is the sum of (x_e - x_b) x F over those ends,
x_b the reference point. In 2-D the moment is the z component alone. Rotational quantities have one component
per axis of rotation, as the scene's angles do: 3 in 3-D (about x, y, z), 1 in 2-D (about z).
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..model.body_sea import body_fraction
from ..model.forces.springs import segment_forces, segment_strains
from ..model.layout import LineLayout, line_layouts
from .rotation import angles_from_quaternion, continuous_angles, rotation_matrix

_Lines = namedtuple("_Lines", ["lines"])   # what segment_forces and segment_strains read of a model


def line_ids(scene) -> tuple[str, ...]:
    """The ids of a scene's lines in order: a rope is the one line "rope"."""
    return tuple(line.id for line in line_layouts(scene))


def made_of(scene) -> str:
    """What a scene's nodes make, in a phrase: "open line", "closed loop", or a system's "2 lines, 3 points"
    (and its rigid bodies)."""
    if not scene.is_system:
        return "closed loop" if scene.rope.closed else "open line"

    def count(n: int, one: str, many: str) -> str:
        return f"{n} {one if n == 1 else many}"
    parts = [count(len(scene.lines), "line", "lines"), count(len(scene.points), "point", "points")]
    if scene.rigid_bodies:
        parts.append(count(len(scene.rigid_bodies), "rigid body", "rigid bodies"))
    return ", ".join(parts)


def _unknown(what: str, key: str, known) -> KeyError:
    known = list(known)
    listed = ", ".join(repr(k) for k in known) if known else "none"
    return KeyError(f"no {what} {key!r} in this run; its {what}s: {listed}")


def _segment_offsets(lines: tuple[LineLayout, ...]) -> list[int]:
    """Where each line's segments start in the frames' tension and strain arrays (line after line)."""
    out, first = [], 0
    for line in lines:
        out.append(first)
        first += line.segments
    return out


def end_force(x, tension, node: int, neighbour: int) -> np.ndarray:
    """The force [N] (F, D) a line end at ``node`` puts on what it is attached to: its end segment's tension
    ``tension`` (F,) [N] along the segment towards ``neighbour`` (0 where the two nodes coincide)."""
    d = np.asarray(x[:, neighbour], dtype=float) - np.asarray(x[:, node], dtype=float)
    length = np.linalg.norm(d, axis=-1, keepdims=True)
    unit = np.divide(d, length, out=np.zeros_like(d), where=length > 0)
    return np.asarray(tension, dtype=float)[:, None] * unit


def moment(arm: np.ndarray, force: np.ndarray) -> np.ndarray:
    """The moment [N m] of ``force`` (..., D) [N] at ``arm`` (..., D) [m] from the point it is taken about:
    (..., 3) in 3-D, (..., 1), its z component, in 2-D."""
    if arm.shape[-1] == 2:
        return (arm[..., 0] * force[..., 1] - arm[..., 1] * force[..., 0])[..., None]
    return np.cross(arm, force)


class LineResults:
    """One line's results: its nodes ``first`` .. ``first + nodes - 1`` of the trajectory, in order from its
    start to its end, and its segments (segment j joins its nodes j and j + 1).

    - ``positions``, ``velocities`` (F, n, D) [m, m/s];
    - ``tension`` (F, S) [N] (positive when it pulls) and ``strain`` (F, S) [-], r / l0 - 1;
    - ``start_tension``, ``end_tension`` (F,) [N]: its first and last segments';
    - ``start_force``, ``end_force`` (F, D) [N]: the force its start and its end put on what they are attached
      to (see the module: the end segment's tension along it, towards the line); None for a closed loop;
    - ``start``, ``end``: the ids of the points it joins (None for a rope);
    - with a ``[sea]``: ``submerged`` (F, n), each node's fraction below the surface, and ``submerged_total``
      (F,), the line's fraction of its length (:mod:`ropesim.model.sea_frames`); None without one.
    """

    def __init__(self, traj, layout: LineLayout, segment0: int, start: str | None, end: str | None,
                 index: int = 0):
        self.traj, self.layout, self.index = traj, layout, index
        self.id, self.start, self.end = layout.id, start, end
        self.first, self.nodes, self.closed = layout.first, layout.nodes, layout.closed
        self.segments = slice(segment0, segment0 + layout.segments)   # in the trajectory's tension and strain
        self.t = traj.t

    def __repr__(self) -> str:
        joins = f", {self.start} -> {self.end}" if self.start is not None else ""
        return (f"LineResults({self.id!r}{joins}, nodes {self.first} .. {self.first + self.nodes - 1}, "
                f"{self.layout.segments} segments, {len(self.t)} frames)")

    @property
    def positions(self) -> np.ndarray:
        return self.traj.x[:, self.first:self.first + self.nodes]

    @property
    def velocities(self) -> np.ndarray:
        return self.traj.v[:, self.first:self.first + self.nodes]

    @property
    def submerged(self) -> np.ndarray | None:
        if self.traj.submerged is None:
            return None
        return self.traj.submerged[:, self.first:self.first + self.nodes]

    @property
    def submerged_total(self) -> np.ndarray | None:
        if self.traj.line_submerged is None:
            return None
        return self.traj.line_submerged[:, self.index]

    @cached_property
    def tension(self) -> np.ndarray:
        if self.traj.tension is not None:
            return self.traj.tension[:, self.segments]
        return segment_forces(_Lines((self._local(),)), self.positions, self.velocities)

    @cached_property
    def strain(self) -> np.ndarray:
        if self.traj.strain is not None:
            return self.traj.strain[:, self.segments]
        return segment_strains(_Lines((self._local(),)), self.positions)

    def _local(self) -> LineLayout:
        """This line laid out on its own nodes (from node 0)."""
        from dataclasses import replace
        return replace(self.layout, first=0)

    @property
    def start_tension(self) -> np.ndarray:
        return self.tension[:, 0]

    @property
    def end_tension(self) -> np.ndarray:
        return self.tension[:, -1]

    @cached_property
    def start_force(self) -> np.ndarray | None:
        if self.closed:
            return None
        return end_force(self.traj.x, self.start_tension, self.first, self.first + 1)

    @cached_property
    def end_force(self) -> np.ndarray | None:
        if self.closed:
            return None
        last = self.first + self.nodes - 1
        return end_force(self.traj.x, self.end_tension, last, last - 1)

    def force_at(self, which: str) -> np.ndarray:
        """``start_force`` or ``end_force`` by ``which`` ("start" or "end")."""
        return self.start_force if which == "start" else self.end_force

    def node_at(self, which: str) -> int:
        """The trajectory's node at the line's ``which`` end ("start" or "end")."""
        return self.first if which == "start" else self.first + self.nodes - 1


def every_line(traj) -> dict[str, LineResults]:
    """Every line's :class:`LineResults` by id, in the scene's order."""
    scene = traj.scene
    layouts = line_layouts(scene)
    ends = [(line.start, line.end) for line in scene.lines] if scene.is_system else [(None, None)]
    return {layout.id: LineResults(traj, layout, s0, *joins, index=k)
            for k, (layout, s0, joins) in enumerate(zip(layouts, _segment_offsets(layouts), ends))}


def line_results(traj, id: str) -> LineResults:
    """Line ``id``'s :class:`LineResults`; KeyError (naming the run's lines) for an unknown id."""
    lines = every_line(traj)
    if id not in lines:
        raise _unknown("line", id, lines)
    return lines[id]


def attached_ends(scene, owner: str) -> list[tuple[str, str]]:
    """The line ends (line id, "start" or "end") on point ``owner``, in line order."""
    return [(line.id, which) for line in scene.lines for which in ("start", "end") if getattr(line, which) == owner]


class PointResults:
    """One point's results (``kind``: fixed, free, driven or body):

    - ``position``, ``velocity`` (F, D) [m, m/s]: where the point is, its line ends' nodes (which move as one;
      a free point's mass sits on the first of them; every point has a line);
    - ``ends``: the line ends on it, (line id, "start" or "end"); ``nodes`` their nodes in the trajectory;
    - ``line_forces``: {line id: (F, D) [N]}, the force each line puts on the point (both its ends, if it has
      two here); ``force`` (F, D) [N] their sum. On a fixed or driven point the support holds against it; on a
      free point it balances the point's weight, drag and inertia;
    - ``held_force`` (F, D) [N]: on a held point (fixed, driven, coupled, or on a body that is not free) the net
      force on its line ends' nodes without their inertia, as MoorDyn reports a point's force
      (``Point::getFnet``): the lines' pull plus the weight, buoyancy, drag and seabed push on the half
      segments the point carries (None on a free point, or for a run folder written before ropesim stored it).
    """

    def __init__(self, traj, point, lines: dict[str, LineResults]):
        self.traj, self.scene_point = traj, point
        self.id, self.kind, self.body = point.id, point.kind, point.body
        self.ends = tuple(attached_ends(traj.scene, point.id))
        self._lines = lines
        self.nodes = tuple(lines[line].node_at(which) for line, which in self.ends)
        self.t = traj.t

    def __repr__(self) -> str:
        on = f" on {self.body!r}" if self.body else ""
        return f"PointResults({self.id!r}, {self.kind}{on}, {len(self.ends)} line ends, {len(self.t)} frames)"

    @property
    def position(self) -> np.ndarray:
        return self.traj.x[:, self.nodes[0]]

    @property
    def velocity(self) -> np.ndarray:
        return self.traj.v[:, self.nodes[0]]

    @cached_property
    def line_forces(self) -> dict[str, np.ndarray]:
        out: dict[str, np.ndarray] = {}
        for line, which in self.ends:
            force = self._lines[line].force_at(which)
            out[line] = out[line] + force if line in out else force
        return out

    @cached_property
    def force(self) -> np.ndarray:
        total = np.zeros((len(self.t), self.traj.scene.dimension))
        for force in self.line_forces.values():
            total = total + force
        return total

    @cached_property
    def held_force(self) -> np.ndarray | None:
        stored = self.traj.held_force
        if stored is None:
            return None
        held = held_rows(self.traj.scene)
        if any(node not in held for node in self.nodes):
            return None
        return sum(np.asarray(stored[:, held[node]]) for node in self.nodes)


def held_rows(scene) -> dict[int, int]:
    """{node: its row in the support and held_force arrays} of a system's held nodes, as the model orders them."""
    from ..model.build import build

    model = build(scene, solve=False)
    return {int(node): j for j, node in enumerate(model.held_idx)}


def point_results(traj, id: str) -> PointResults:
    """Point ``id``'s :class:`PointResults`; KeyError (naming the run's points) for an unknown id."""
    points = {p.id: p for p in traj.scene.points}
    if id not in points:
        raise _unknown("point", id, points)
    return PointResults(traj, points[id], every_line(traj))


class BodyResults:
    """One rigid body's results (``kind``: free, fixed or driven), its frames read from the trajectory's body
    state:

    - ``position``, ``velocity`` (F, D) [m, m/s]: its reference point (the origin of its frame);
    - ``quaternion`` (F, 4): its orientation (w, x, y, z), turning its frame into the world's;
      ``rotation`` (F, D, D): the same as rotation matrices, v_world = R v_body (2-D: the turn in the plane);
      ``angles`` (F, 3) [deg]: as the scene writes an orientation, about x, then y, then z (R = Rz Ry Rx), or
      (F, 1) about z in 2-D; continuous in time (a body that turns a full turn reads 360);
    - ``angular_velocity`` (F, 3) [rad/s] in world axes ((F, 1), about z, in 2-D);
    - ``points``: the ids of the points on it;
    - ``line_forces`` {line id: (F, D) [N]} and ``line_moments`` {line id: (F, 3) [N m] ((F, 1) in 2-D)}: what
      each line attached to it puts on it, the moment about its reference point; ``force`` and ``moment`` their
      sums (see the module for the sign conventions);
    - ``submerged`` (F,): a free body's fraction of its displaced volume below the instantaneous surface, under a
      ``[sea]``, as its loads take it (:mod:`ropesim.model.body_sea`: vertical-walled, its ``height`` about its
      centre of buoyancy; 1 under MoorDyn's rule); None without a sea or for a fixed or driven body.
    """

    def __init__(self, traj, index: int):
        self.traj, self.index = traj, index
        body = traj.scene.rigid_bodies[index]
        self.id, self.kind = body.id, body.kind
        self.points = tuple(p.id for p in traj.scene.points if p.kind == "body" and p.body == body.id)
        self.dim = traj.scene.dimension
        self.t = traj.t
        if traj.body_x is None:
            raise ValueError(f"body {self.id!r}: this run holds no rigid-body states (body_x, body_q); it was made "
                             f"by a ropesim without rigid bodies")

    def __repr__(self) -> str:
        return f"BodyResults({self.id!r}, {self.kind}, {len(self.points)} points, {len(self.t)} frames)"

    @property
    def position(self) -> np.ndarray:
        return self.traj.body_x[:, self.index]

    @property
    def velocity(self) -> np.ndarray:
        return self.traj.body_v[:, self.index]

    @property
    def quaternion(self) -> np.ndarray:
        return self.traj.body_q[:, self.index]

    @cached_property
    def rotation(self) -> np.ndarray:
        return rotation_matrix(self.quaternion, self.dim)

    @cached_property
    def angles(self) -> np.ndarray:
        return continuous_angles(angles_from_quaternion(self.quaternion, self.dim), axis=0)

    @property
    def angular_velocity(self) -> np.ndarray:
        w = self.traj.body_w[:, self.index]
        return w if self.dim == 3 else w[:, 2:3]

    @cached_property
    def _wrench(self) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
        lines = every_line(self.traj)
        forces: dict[str, np.ndarray] = {}
        moments: dict[str, np.ndarray] = {}
        x_b = np.asarray(self.position, dtype=float)
        for point in self.points:
            for line, which in attached_ends(self.traj.scene, point):
                results = lines[line]
                force = results.force_at(which)
                arm = np.asarray(self.traj.x[:, results.node_at(which)], dtype=float) - x_b
                turn = moment(arm, force)
                forces[line] = forces[line] + force if line in forces else force
                moments[line] = moments[line] + turn if line in moments else turn
        return forces, moments

    @property
    def line_forces(self) -> dict[str, np.ndarray]:
        return self._wrench[0]

    @property
    def line_moments(self) -> dict[str, np.ndarray]:
        return self._wrench[1]

    @cached_property
    def submerged(self) -> np.ndarray | None:
        scene = self.traj.scene
        if scene.sea is None or self.kind != "free":
            return None
        run = self.traj.internal   # the y-up frame the model computes in
        return body_fraction(scene, scene.rigid_bodies[self.index], run.t, run.body_x[:, self.index],
                             run.body_q[:, self.index])

    @cached_property
    def force(self) -> np.ndarray:
        return sum(self.line_forces.values(), np.zeros((len(self.t), self.dim)))

    @cached_property
    def moment(self) -> np.ndarray:
        return sum(self.line_moments.values(), np.zeros((len(self.t), 3 if self.dim == 3 else 1)))


def body_results(traj, id: str) -> BodyResults:
    """Rigid body ``id``'s :class:`BodyResults`; KeyError (naming the run's bodies) for an unknown id."""
    ids = [b.id for b in traj.scene.rigid_bodies]
    if id not in ids:
        raise _unknown("body", id, ids)
    return BodyResults(traj, ids.index(id))


# ------------------------------------------------------------------------------------------ drawing


@dataclass(frozen=True)
class Glyph:
    """How a rigid body is drawn (the scene gives it no shape): spokes from its reference point to the points
    on it, ``points`` (K, D) [m] in its frame, and its axes from the reference point, each ``axis_length`` [m]
    long: half its farthest point's distance, or a tenth of its system's mean line length without points."""

    points: np.ndarray
    axis_length: float

    def segments(self, position, rotation) -> tuple[np.ndarray, np.ndarray]:
        """The glyph at ``position`` (D,) [m] turned by ``rotation`` (D, D): its spokes (K, 2, D) and its axes
        (D, 2, D) as (from, to) pairs [m], axis k along the rotation's column k."""
        position, rotation = np.asarray(position, dtype=float), np.asarray(rotation, dtype=float)
        tips = position + self.points @ rotation.T
        spokes = np.stack([np.broadcast_to(position, tips.shape), tips], axis=1)
        ends = position + self.axis_length * rotation.T
        axes = np.stack([np.broadcast_to(position, ends.shape), ends], axis=1)
        return spokes, axes


def body_glyphs(scene) -> list[Glyph]:
    """Each rigid body's :class:`Glyph`, in the scene's order."""
    mean_length = float(np.mean([line.length for line in scene.lines])) if scene.lines else 1.0
    out = []
    for body in scene.rigid_bodies:
        local = np.array([p.position for p in scene.points if p.kind == "body" and p.body == body.id],
                         dtype=float).reshape(-1, scene.dimension)
        reach = float(np.linalg.norm(local, axis=1).max()) if len(local) else 0.0
        out.append(Glyph(local, 0.5 * reach if reach > 0 else 0.1 * mean_length))
    return out
