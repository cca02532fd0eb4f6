"""What every saved frame stores besides positions and velocities: each segment's tension and strain, the
force each support exerts on its held node, and the net force on each held node without its inertia.

Segment j joins node j and node j + 1 (node 0 for a loop's last segment). Its tension [N] is the axial force
of :func:`ropesim.model.forces.springs.segment_forces` (the spring's k (r - l0), none while a slack segment
is short, plus the axial damping), positive when it pulls; its strain is r / l0 - 1. A support (a pin or a
drive) pushes its held node with m a_p - F, F the net force of every term on the node (the linear drag
included) and a_p its prescribed acceleration: for the fairlead of a mooring line, the line's pull on the
vessel is minus that, and its magnitude the fairlead tension.

The held node's net force F itself (``held_force``) is what MoorDyn reports for a fixed, coupled or vessel point
(``Point::getFnet``): its end segment's pull, the weight and buoyancy of the half segment it carries, the
fluid's drag and the seabed's push on it, without the inertia m a_p of the node's own mass. On a driven
fairlead the two differ by that inertia, F = m a_p - support; on a fixed point they are equal and opposite.
"""

from __future__ import annotations

import numpy as np

from .bodies import body_frames, body_shapes
from .forces.fluid import flow_at
from .forces.springs import segment_forces, segment_strains
from .motion import Held, place_moving
from .sea_frames import sea_frames, sea_shapes
from .terms import accelerations


def segment_count(model) -> int:
    """How many segments the model's lines have, all together."""
    return sum(line.segments for line in model.lines)


def line_segments(model) -> list[slice]:
    """Each line's segments in the frames' tension and strain arrays (line after line)."""
    out, first = [], 0
    for line in model.lines:
        out.append(slice(first, first + line.segments))
        first += line.segments
    return out


def frame_shapes(model) -> dict[str, tuple]:
    """Each stored per-frame array's shape, frame axis left out."""
    shapes = {"tension": (segment_count(model),), "strain": (segment_count(model),)}
    if model.held_idx.size:
        shapes["support"] = (model.held_idx.size, model.dim)
        shapes["held_force"] = (model.held_idx.size, model.dim)
    shapes.update(body_shapes(model))
    shapes.update(sea_shapes(model))
    return shapes


def frame_arrays(model, t: np.ndarray, x: np.ndarray, v: np.ndarray, body: np.ndarray | None = None
                 ) -> dict[str, np.ndarray]:
    """{"tension": (F, S) [N], "strain": (F, S) [-], "support" and "held_force": (F, H, D) [N] if any node is held,
    and with rigid bodies their poses (:func:`ropesim.model.bodies.body_frames`)} for frames at times t (F,) with positions and
    velocities x, v (F, N, D) and the free bodies' states ``body`` (F, 13, B)."""
    out = {"tension": segment_forces(model, x, v), "strain": segment_strains(model, x)}
    if model.held_idx.size:
        out["support"], out["held_force"] = held_forces(model, t, x, v)
    if model.scene.rigid_bodies:
        out.update(body_frames(model, t, body))
    out.update(sea_frames(model, t, x))
    return out


def support_forces(model, t: np.ndarray, x: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The force [N] each support exerts on its held node, m a_p - F, per frame (F, H, D)."""
    return held_forces(model, t, x, v)[0]


def held_forces(model, t: np.ndarray, x: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(the force each support exerts on its held node, m a_p - F; the net force F of every term on it, without
    its inertia: MoorDyn's report), per frame (F, H, D) [N]."""
    idx, m = model.held_idx, model.motion
    mass = model.mass[idx][:, None]
    acc = np.zeros((model.dim, model.nodes))
    out = np.zeros((len(t), idx.size, model.dim))
    net = np.zeros_like(out)
    forces = model.kernel(accelerations)
    if m.moving:   # the prescribed accelerations a_p, as the loops compute them
        held = Held(idx, model.held_x0, model.held_v.copy(), m._replace(accel=np.zeros_like(m.accel)))
        prescribed = model.kernel(place_moving)
    dragged = bool(np.any(model.drag[idx]))   # a linear [drag] on a held node (none: nothing to add)
    for k in range(len(t)):
        xk, vk = np.ascontiguousarray(np.asarray(x[k]).T), np.ascontiguousarray(np.asarray(v[k]).T)
        forces(xk, vk, acc, model.params, float(t[k]))
        net[k] = mass * acc[:, idx].T
        if dragged:
            net[k] += held_linear_drag(model, float(t[k]), xk, vk)
        out[k] = -net[k]
        if m.moving:
            prescribed(xk.copy(), vk.copy(), held, float(t[k]), float(t[k]))
            out[k] += mass * held[3].accel.T
    return out, net


def held_linear_drag(model, t: float, x: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The linear [drag]'s force [N] on each held node, -b (v - U) (H, D), U the [flow]'s velocity at the node
    at time t [s] (none without a flow); ``x``, ``v`` one state (D, N). The compiled terms leave it out on held
    nodes (their kick and the flow's push act on free nodes only), so a support's force adds it here."""
    idx = model.held_idx
    b = model.drag[idx]
    relative = np.asarray(v[:, idx].T, dtype=float).copy()
    if model.scene.flow is not None:
        flow, table = model.params.flow
        for j, i in enumerate(idx):
            relative[j] -= np.asarray(flow_at(float(x[1, i]), t, flow, table))[:model.dim]
    return -b[:, None] * relative


def end_tensions(model, tension: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The tension [N] at the rope's two ends per frame: its first and last segments (a loop: segment 0 twice);
    a system's first line's (:func:`line_end_tensions` gives every line's)."""
    return line_end_tensions(model, tension)[0]


def line_end_tensions(model, tension: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each line's tension [N] at its start and at its end per frame: its first and last segments."""
    return [(tension[..., part.start], tension[..., part.stop - 1]) for part in line_segments(model)]
