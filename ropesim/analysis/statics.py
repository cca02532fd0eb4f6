"""A scene's static shape and what an engineer reads from it: support forces, tensions, the length on the seabed.

:func:`equilibrium` solves the shape with :mod:`ropesim.model.statics` (every force balanced at every free node:
weight, buoyancy, springs, bending, the seabed's contact, drag in the flow at its full strength) from the
scene's initial shape, the held nodes where the scene holds them at t = 0, and reports:

- ``supports``: the force [N] each support exerts on its held node, minus the net force of the other terms
  on it at rest (the flow's push on the linear [drag] included) (so a fairlead's is the line's pull on the vessel, reversed);
- ``tension``: each segment's axial force [N] (spring and damping, zero in a slack segment);
- with a ``[seabed]``: the nodes resting on it (sunk below its plane), the length of rope they carry, and the
  touchdown point, the grounded node next to the suspended part;
- a system's figures per point and per line: each fixed and driven point's support force (the sum over its
  line ends), each free point's static position; each line's tensions at its two ends and its largest, its
  slack segments, the length of it on the seabed and its touchdown node;
- each rigid body's pose (its reference point, orientation as a unit quaternion and as the scene's angles) and
  the force and moment (about its reference point) each line puts on it: the line's end segment's tension along
  that segment, summed over the line's ends on the body, as a run's results give it
  (:class:`ropesim.analysis.objects.BodyResults`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..model.build import Model, build
from ..model.layout import point_ends
from ..model.statics import _steady_time, solve_equilibrium
from ..model.tension import line_segments
from ..scene import schema as S


@dataclass(frozen=True)
class PointFigures:
    """A system point at rest: its kind, its position [m] and, for a fixed or driven point, the force [N] it
    exerts on its lines' ends together (the lines' pull on it, reversed)."""

    id: str
    kind: str
    position: np.ndarray        # (D,)
    force: np.ndarray | None    # (D,), None for a free point


@dataclass(frozen=True)
class BodyFigures:
    """A rigid body at rest: its kind, its reference point's position [m], its orientation (a unit quaternion
    (4,), w first, and the scene's angles [deg]), and the force [N] (D,) and moment [N m] about its reference
    point ((3,) in 3-D, (1,) about z in 2-D) of each line with an end on it."""

    id: str
    kind: str
    position: np.ndarray
    quaternion: np.ndarray
    angles: np.ndarray
    line_forces: dict
    line_moments: dict


@dataclass(frozen=True)
class LineFigures:
    """A line at rest: its tension [N] at its start and its end (its first and last segments), its largest and in
    which of its segments, how many of its segments are slack, the length of it resting on the seabed [m] and
    its touchdown node (the grounded node next to its suspended part), or None."""

    id: str
    start_tension: float
    end_tension: float
    largest: float
    largest_segment: int
    slack: int
    grounded_length: float
    touchdown: int | None


@dataclass(frozen=True)
class StaticShape:
    """The static shape of a scene and its figures (see the module doc); arrays in ropesim's frame layout."""

    model: Model
    x: np.ndarray               # (N, D) node positions [m]
    residual: float             # the largest force left on a free node [N]
    scale: float                # the largest force a term puts on a node [N]: the residual is relative to it
    iterations: int
    converged: bool
    held: np.ndarray            # (H,) the held nodes
    supports: np.ndarray        # (H, D) the force each support exerts on its node [N]
    tension: np.ndarray         # (S,) each segment's tension [N]
    grounded: np.ndarray        # indices of the nodes resting on the seabed (empty without one)
    grounded_length: float      # the rope they carry [m]
    touchdown: int | None       # the grounded node next to the suspended rope, or None
    lines: tuple[LineFigures, ...] = ()     # every line's figures (a rope: one)
    points: tuple[PointFigures, ...] = ()   # a system's points (a rope: none)
    bodies: tuple[BodyFigures, ...] = ()    # a system's rigid bodies (free ones at their static poses)

    def in_scene_frame(self) -> "StaticShape":
        """These figures in the scene's own frame (a z-up scene's turned out of its y-up twin, as its runs' outputs
        are: :mod:`ropesim.scene.frame`); the shape itself for a y-up scene."""
        from dataclasses import replace

        from .rotation import angles_from_quaternion
        from ..scene.frame import frame_of

        frame = frame_of(self.model.scene)
        if not frame.turned:
            return self
        out = frame.out
        points = tuple(replace(p, position=out(p.position), force=out(p.force)) for p in self.points)
        bodies = tuple(replace(b, position=out(b.position), quaternion=frame.quaternion_out(b.quaternion),
                               angles=angles_from_quaternion(frame.quaternion_out(b.quaternion)),
                               line_forces={k: out(f) for k, f in b.line_forces.items()},
                               line_moments={k: out(m) for k, m in b.line_moments.items()}) for b in self.bodies)
        return replace(self, x=out(self.x), supports=out(self.supports), points=points, bodies=bodies)


def equilibrium(scene: S.Scene) -> StaticShape:
    """Solve ``scene``'s static shape from its initial shape (an ``equilibrium`` start from its sagging guess)."""
    model = build(scene, solve=False)
    result = solve_equilibrium(model)
    scene = model.scene
    x = np.ascontiguousarray(result.x)
    supports, tension = static_loads(model, x)
    grounded, length, touchdown = _on_the_seabed(model, x)
    lines = tuple(_line_figures(model, x, line, tension[part], grounded)
                  for line, part in zip(model.lines, line_segments(model)))
    points = _point_figures(model, x, supports) if scene.is_system else ()
    bodies = _body_figures(model, x, tension, result.pose) if scene.is_system else ()
    return StaticShape(model, x.T.copy(), result.residual, result.scale, result.iterations, result.converged,
                       model.held_idx.copy(), supports, tension, grounded, length, touchdown, lines, points, bodies)


def _body_figures(model: Model, x: np.ndarray, tension: np.ndarray, pose: np.ndarray) -> tuple[BodyFigures, ...]:
    """Each rigid body's pose (free ones at ``pose`` (7, B), the others where the scene puts them at t = 0) and
    each line's force and moment on it (see the module doc)."""
    from ..analysis.objects import attached_ends, end_force, moment
    from ..analysis.rotation import angles_from_quaternion
    from ..model.bodies import initial_pose

    scene, dim = model.scene, model.dim
    layouts = {line.id: (line, part) for line, part in zip(model.lines, line_segments(model))}
    out, free = [], 0
    for body in scene.rigid_bodies:
        if body.kind == "free":
            at, free = pose[:, free], free + 1
        else:
            at = initial_pose(body, dim)
        forces, moments = {}, {}
        for point in (p.id for p in scene.points if p.body == body.id):
            for line_id, which in attached_ends(scene, point):
                line, part = layouts[line_id]
                node, neighbour, k = ((line.first, line.first + 1, part.start) if which == "start"
                                      else (line.end - 1, line.end - 2, part.stop - 1))
                force = end_force(x.T[None], tension[None, k], node, neighbour)[0]
                turn = moment(x[:, node] - at[:dim], force)
                forces[line_id] = forces.get(line_id, 0.0) + force
                moments[line_id] = moments.get(line_id, 0.0) + turn
        out.append(BodyFigures(body.id, body.kind, at[:dim].copy(), at[3:7].copy(),
                               angles_from_quaternion(at[3:7], dim), forces, moments))
    return tuple(out)


def _line_figures(model: Model, x: np.ndarray, line, tension: np.ndarray, grounded: np.ndarray) -> LineFigures:
    """One line's figures (see :class:`LineFigures`) from its segments' tensions and the grounded nodes."""
    k = int(np.argmax(tension))
    mine = grounded[(grounded >= line.first) & (grounded < line.end)]
    length = float(model.params.node_length[mine].sum())
    touchdown = None
    if mine.size and mine.size < line.nodes:
        on = np.zeros(model.nodes, dtype=bool)
        on[mine] = True
        ends = [i for i in mine if (i > line.first and not on[i - 1]) or (i < line.end - 1 and not on[i + 1])]
        touchdown = int(ends[-1]) if ends else None
    return LineFigures(line.id, float(tension[0]), float(tension[-1]), float(tension[k]), k,
                       int(np.count_nonzero(tension <= 0.0)), length, touchdown)


def _point_figures(model: Model, x: np.ndarray, supports: np.ndarray) -> tuple[PointFigures, ...]:
    """Each system point with a line end on it: where it rests and, held, the force it exerts on its ends."""
    row = {int(node): j for j, node in enumerate(model.held_idx)}
    out = []
    for point in model.scene.points:
        ends = point_ends(model.scene, model.lines)[point.id]
        if not ends:
            continue
        force = None
        if point.kind in (*S.STILL_KINDS, "driven"):
            force = sum(supports[row[i]] for i in ends)
        out.append(PointFigures(point.id, point.kind, x[:, ends[0]].copy(), force))
    return tuple(out)


def static_loads(model: Model, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The support forces (H, D) [N] and segment tensions [N] of the nodes at rest at ``x`` (D, N)."""
    from ..model.forces.springs import segment_forces
    from ..model.tension import held_linear_drag
    from ..model.terms import accelerations

    v, acc = np.zeros_like(x), np.zeros_like(x)
    t = _steady_time(model.scene)
    model.kernel(accelerations)(x, v, acc, model.params, t)
    idx = model.held_idx
    supports = -(model.mass[idx][:, None] * acc[:, idx].T + held_linear_drag(model, t, x, v))
    tension = segment_forces(model, x.T[None], v.T[None])[0]
    return supports, tension


def _on_the_seabed(model: Model, x: np.ndarray) -> tuple[np.ndarray, float, int | None]:
    bed = model.scene.seabed
    if bed is None:
        return np.zeros(0, dtype=int), 0.0, None
    bed_x, area = model.params.seabed
    sunk = (bed_x[0] + bed_x[1] * x[0] - x[1]) * bed_x[2]
    grounded = np.flatnonzero(sunk > 0.0)
    length = float(model.params.node_length[grounded].sum())
    touchdown = None
    if grounded.size and grounded.size < model.nodes and not model.scene.is_system:   # a system's: per line
        lifted = sunk <= 0.0
        ends = [i for i in grounded if (i > 0 and lifted[i - 1]) or (i < model.nodes - 1 and lifted[i + 1])]
        touchdown = int(ends[-1]) if ends else None
    return grounded, length, touchdown


def as_points_scene(shape: StaticShape) -> S.Scene:
    """The scene with its static shape as a ``points`` start, every node at rest but the driven ones: run it and
    the dynamics begin without a transient. (An ``equilibrium`` start gives the same in one file; this writes
    the shape out, to read or to edit.)"""
    scene = shape.model.scene
    points = tuple(tuple(float(c) for c in row) for row in shape.x)
    return replace(scene, initial=S.PointsStart(points=points, velocity=(0.0,) * scene.dimension))
