"""Turn a validated :class:`Scene` into the arrays the compiled kernel works on.

Nothing here steps time: it lays out the initial state (shape (D, N), structure of arrays), the per-node
masses and drag coefficients, the held (pinned or driven) nodes, the force terms' parameters
(:func:`ropesim.model.terms.model_params`) and the compile-time switches that choose what compiles
(:func:`ropesim.model.terms.switches`, plus prescribed motion).

Node masses: the rope's ``mass`` per node; in physical units an open line's two end nodes carry half of it
(half a segment, as lumped-mass cable codes do); then ``[[overrides]]`` set a node's mass, and a body adds its
own. Each node's share of unstretched length L (what drag, buoyancy and added mass act on) is half of each
segment it touches, in either form.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..scene import schema as S
from ..scene.shapes import initial_positions, sagging_line
from .bodies import attachments, initial_pose, initial_state
from .layout import LineLayout, line_layouts, lumped_bodies, node_lengths, point_ends
from .rotation import rotation_matrix
from .motion import WITH_RIGID_MOTION, Motion, motion_of
from . import jit
from .terms import WITH_APPLIED, WITH_MOTION, WITH_VELOCITY_TERMS, Layout, ModelParams, model_params, switches


@dataclass
class Model:
    """A scene laid out for the kernel. Arrays are float64 unless noted; positions are (D, N)."""

    scene: S.Scene
    x0: np.ndarray            # initial positions [m]
    v0: np.ndarray            # initial velocities [m/s]
    mass: np.ndarray          # (N,) [kg]
    drag: np.ndarray          # (N,) linear drag coefficients b [kg/s]
    held: np.ndarray          # (N,) bool: pinned or driven
    held_idx: np.ndarray      # (H,) int64 indices of held nodes
    held_x0: np.ndarray       # (D, H) their positions at t = 0 [m]
    held_v: np.ndarray        # (D, H) their constant velocities [m/s]
    params: ModelParams       # the force terms' parameters, for the compiled code
    motion: Motion            # the held nodes' prescribed motion beyond x0 + V t (see model/motion.py)
    switches: jit.Switches    # the compile-time switches that are on: the scene's terms, prescribed motion
    lines: tuple[LineLayout, ...]   # each line's nodes and material (a rope: one line)
    body_pose0: np.ndarray    # (7, B) the free rigid bodies' reference points and orientations at t = 0
    body_twist0: np.ndarray   # (6, B) their velocities and angular velocities at t = 0 (model/bodies.py)

    @property
    def dim(self) -> int:
        return self.x0.shape[0]

    @property
    def nodes(self) -> int:
        return self.x0.shape[1]

    def kernel(self, function):
        """``function`` (a compiled template) specialised on this model's switches (see
        :func:`ropesim.model.jit.specialise`): what Python calls of the term list."""
        return jit.specialise(function, self.switches)

    @property
    def velocity_dependent(self) -> bool:
        """True when a force other than the linear [drag] depends on velocity (the thrower, the guide circles,
        fluid drag, axial damping, added mass)."""
        return self.applied or self.velocity_terms

    @property
    def velocity_terms(self) -> bool:
        """True when a term beyond the thrower's and guides' depends on velocity (see Term.velocity)."""
        return WITH_VELOCITY_TERMS.name in self.switches

    @property
    def applied(self) -> bool:
        """True when a term booked as box work is on (the thrower, the guide circles)."""
        return WITH_APPLIED.name in self.switches

    @property
    def has_drag(self) -> bool:
        return bool(np.any(self.drag[~self.held] > 0))

    @property
    def smooth_contacts(self) -> bool:
        """True when the box's or a circle's edges are smoothed: the splitting schemes then kick the nodes they
        touch exactly (:mod:`ropesim.integrate.contact`)."""
        scene = self.scene
        return (scene.thrower is not None and scene.thrower.edge_width > 0) or any(g.edge_width > 0
                                                                                     for g in scene.guides)


@dataclass
class Nodes:
    """What a scene's form decides of its nodes (a rope's, :func:`_rope_nodes`; a system's,
    :func:`_system_nodes`); :func:`build` makes the model from it. Arrays over the N nodes."""

    x0: np.ndarray        # (D, N) initial positions [m]
    v0: np.ndarray        # (D, N) initial velocities [m/s]
    mass: np.ndarray      # (N,) [kg]
    drag: np.ndarray      # (N,) linear drag b [kg/s]
    held_v: np.ndarray    # (D, N) the held nodes' constant velocities [m/s]
    held: np.ndarray      # (N,) bool
    drives: list          # (node indices, drive) of the held nodes' prescribed motions (model/motion.py)
    rigid: list = ()      # (driven rigid body, [(node, arm (3,))]) of the nodes on driven bodies' points


def build(scene: S.Scene, solve: bool = True) -> Model:
    """Lay out ``scene`` for the kernel; an ``equilibrium`` start is solved for its static shape (unless
    ``solve`` is False: it then holds the solver's first guess, see :mod:`ropesim.analysis.statics`)."""
    lines = line_layouts(scene)
    nodes = _system_nodes(scene, lines) if scene.is_system else _rope_nodes(scene)
    x0, v0, mass, held, held_v = nodes.x0, nodes.v0, nodes.mass, nodes.held, nodes.held_v
    for body in lumped_bodies(scene, lines):
        mass[body.node] += body.mass
    held_idx = np.flatnonzero(held).astype(np.int64)
    v0[:, held_idx] = held_v[:, held_idx]

    layout = Layout(mass, held, node_lengths(lines, len(mass)), lines)
    motion = motion_of(scene.dimension, held_idx, nodes.drives, nodes.rigid)
    pose0, twist0 = initial_state(scene)
    model = Model(scene=scene, x0=x0, v0=v0, mass=mass, drag=nodes.drag, held=held, held_idx=held_idx,
                  held_x0=np.ascontiguousarray(x0[:, held_idx]), held_v=np.ascontiguousarray(held_v[:, held_idx]),
                  params=model_params(scene, layout), motion=motion,
                  switches=switches(scene) | ({WITH_MOTION.name} if motion.moving else set())
                  | ({WITH_RIGID_MOTION.name} if nodes.rigid else set()), lines=lines,
                  body_pose0=pose0, body_twist0=twist0)
    if solve and isinstance(scene.initial, (S.EquilibriumStart, S.SystemEquilibriumStart)):
        from .statics import solve_equilibrium

        result = solve_equilibrium(model)
        if not result.converged:
            raise EquilibriumError(f"{scene.name}: initial.shape = 'equilibrium': the static solve did not converge "
                                   f"(largest residual force {result.residual:.3g} N after {result.iterations} "
                                   f"iterations); start from another shape")
        model.x0[:] = result.x
        model.body_pose0[:] = result.pose
    return model


def _rope_nodes(scene: S.Scene) -> Nodes:
    """A rope's nodes: its initial shape, per-node masses (end nodes in physical units half a segment's) with the
    overrides, linear drag, pinned and driven nodes."""
    n, dim = scene.rope.nodes, scene.dimension
    x0 = initial_positions(scene)
    v0 = np.empty((dim, n))
    if getattr(scene.initial, "velocities", None) is not None:
        v0[:] = np.asarray(scene.initial.velocities, dtype=float).T
    else:
        v0[:] = np.asarray(scene.initial.velocity, dtype=float)[:, None]

    mass = np.full(n, scene.rope.mass)
    if scene.rope.physical and not scene.rope.closed:
        mass[[0, -1]] *= 0.5
    drag = np.full(n, scene.drag.b if scene.drag is not None else 0.0)
    for o in scene.overrides:
        i = scene.node(o.index)
        if o.mass is not None:
            mass[i] = o.mass
        if o.drag is not None:
            drag[i] = o.drag

    held_v = np.zeros((dim, n))
    held = np.zeros(n, dtype=bool)
    if scene.pinned is not None:
        held[[scene.node(i) for i in scene.pinned.nodes]] = True
    drives = []
    for drive in scene.driven:
        idx = [scene.node(i) for i in drive.nodes]
        held[idx] = True
        held_v[:, idx] = np.asarray(drive.velocity)[:, None]
        drives.append((idx, drive))
    return Nodes(x0, v0, mass, drag, held_v, held, drives)


def _system_nodes(scene: S.Scene, lines) -> Nodes:
    """A system's nodes: each line from its start point to its end point (straight, or sagging when longer than
    the distance), lumped in physical units (each node half of each segment it touches); the line ends on fixed
    points pinned, on driven points driven with their point; at rest (driven ends at their velocity)."""
    dim = scene.dimension
    n = sum(line.nodes for line in lines)
    points = {p.id: p for p in scene.points}
    x0, v0, mass = np.zeros((dim, n)), np.zeros((dim, n)), np.zeros(n)
    for line, layout in zip(scene.lines, lines):
        part = slice(layout.first, layout.end)
        start, end = (np.asarray(point_position(scene, points[key]), dtype=float) for key in (line.start, line.end))
        x0[:, part] = sagging_line(start, end, layout.nodes, line.length, scene.seabed)
        mass[part] = line.mass_per_length * layout.segment_length
        mass[[layout.first, layout.end - 1]] *= 0.5
    held, held_v, drives = np.zeros(n, dtype=bool), np.zeros((dim, n)), []
    ends = point_ends(scene, lines)
    for point_id, on_point in ends.items():
        point = points[point_id]
        if point.kind in (*S.STILL_KINDS, "driven") and on_point:
            held[on_point] = True
        if point.kind == "driven" and on_point:
            held_v[:, on_point] = np.asarray(point.velocity)[:, None]
            drives.append((on_point, point))
    on_bodies = attachments(scene, ends)
    rigid = [(body, on_bodies[body.id]) for body in scene.rigid_bodies if body.kind in RIGID_MOTION_KINDS]
    for body in scene.rigid_bodies:
        if body.kind != "free":
            held[[node for node, _ in on_bodies[body.id]]] = True
    return Nodes(x0, v0, mass, np.zeros(n), held_v, held, drives, rigid)


def point_position(scene: S.Scene, point: S.Point) -> tuple:
    """A system point's position at t = 0 [m] (a body's point: its body's reference point plus its offset turned
    by the body's orientation)."""
    if point.kind != "body":
        return point.position
    dim = scene.dimension
    body = next(b for b in scene.rigid_bodies if b.id == point.body)
    pose = initial_pose(body, dim)
    arm = np.zeros(3)
    arm[:dim] = point.position
    return tuple((pose[:3] + rotation_matrix(pose[3:]) @ arm)[:dim])


RIGID_MOTION_KINDS = ("driven", "coupled")          # a body that moves its points rigidly (model/motion.py)


class EquilibriumError(ValueError):
    """A scene whose static shape could not be found; ``str()`` is one line for the user."""


def spring_count(n: int, stride: int, closed: bool) -> int:
    return n if closed else max(n - stride, 0)
