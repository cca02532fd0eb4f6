"""The towed rope: a line held at one end (pinned, or driven at constant velocity V: the helicopter).

In steady state every node moves with V, so node j feels its weight m_j g (down) and its drag -b_j V. The
segment above node i carries the weight and drag of everything below it, T_i = sum_{j >= i} (b_j V + m_j g y),
and points along T_i, stretched to l + |T_i| / k. Summing segments from the held end gives the exact discrete
steady state, node by node. Its angle from vertical is tan(theta_i) = sum b_j |V| / sum m_j g: constant for a
uniform rope (a straight line at tan(theta) = b V / (m g)), steeper at the bottom with an end mass, flatter
with an end parachute.
"""

from __future__ import annotations

import numpy as np

from ..model.build import Model
from ..scene.schema import Scene

STRAIGHT_TOLERANCE_DEG = 1.0


def towed_end(scene: Scene) -> int | None:
    """The held end of a towed rope (0 or N-1), or None if the scene is not one.

    A towed rope is an open line with exactly one held node, at one of its ends, driven at a constant nonzero
    velocity (a pin is not a tow: a chain let go from a pin swings, and its steady state, hanging straight
    down, says nothing of it), and no bending (neither [bending] nor rope.EI), thrower, guides, seabed,
    moving drive or fluid terms but the linear [drag] (so the steady state above is exact).
    """
    if scene.is_system:
        return None
    n = scene.rope.nodes
    held = [scene.node(i) for i in (scene.pinned.nodes if scene.pinned else ())]
    for drive in scene.driven:
        held += [scene.node(i) for i in drive.nodes]
    if scene.rope.closed or len(held) != 1 or held[0] not in (0, n - 1):
        return None
    if scene.bending is not None or scene.thrower is not None or scene.guides or scene.seabed is not None:
        return None
    if scene.rope.EI is not None:
        return None   # a bending rope (a cantilever) holds a shape the steady state above knows nothing of
    if any(drive.moving for drive in scene.driven):
        return None   # the steady state needs a constant tow velocity
    if not any(any(drive.velocity) for drive in scene.driven):
        return None   # pinned, or driven at rest: nothing tows it
    if any(getattr(scene, part) is not None for part in ("flow", "fluid_drag", "viscous_drag", "buoyancy",
                                                          "added_mass")) or scene.bodies:
        return None   # the closed form below is for linear drag in still air; see tests/references/towed_cable.py
    return held[0]


def tow_velocity(model: Model) -> np.ndarray:
    """The held end's constant velocity V [m/s] (zero when pinned)."""
    return model.held_v[:, 0].copy()


def _from_top(model: Model, arr: np.ndarray) -> np.ndarray:
    """Reorder nodes (axis -2) so index 0 is the held end."""
    return arr if towed_end(model.scene) == 0 else arr[..., ::-1, :]


def travel_direction(model: Model) -> np.ndarray:
    """Unit horizontal direction of travel (+x when the rope is not moving sideways)."""
    v = tow_velocity(model)
    horizontal = v.copy()
    horizontal[1] = 0.0
    norm = np.linalg.norm(horizontal)
    if norm == 0:
        horizontal[:] = 0.0
        horizontal[0] = 1.0
        return horizontal
    return horizontal / norm


def segment_angles(model: Model, x: np.ndarray) -> np.ndarray:
    """Angle from vertical [deg] of every segment, from the held end down; positive when trailing behind.

    ``x`` is one frame (N, D) or many (F, N, D); the result has one fewer entry along the node axis.
    """
    x = _from_top(model, np.asarray(x))
    seg = x[..., 1:, :] - x[..., :-1, :]
    behind = -seg @ travel_direction(model)
    down = -seg[..., 1]
    return np.degrees(np.arctan2(behind, down))


def exact_steady_state(model: Model) -> np.ndarray | None:
    """Node positions (N, D) [m] relative to the held end in the exact discrete steady state, ordered from the
    held end; None when the rope feels neither gravity nor drag (no direction is preferred)."""
    scene = model.scene
    order = np.arange(model.nodes) if towed_end(scene) == 0 else np.arange(model.nodes)[::-1]
    mass, drag = model.mass[order], model.drag[order]
    g = scene.gravity.g if scene.gravity is not None else 0.0
    V = tow_velocity(model)
    up = np.zeros(model.dim)
    up[1] = 1.0
    per_node = drag[:, None] * V[None, :] + (mass * g)[:, None] * up[None, :]  # force the rope above supplies
    tension = np.cumsum(per_node[::-1], axis=0)[::-1][1:]  # segment i (above node i+1) carries nodes i+1..N-1
    magnitude = np.linalg.norm(tension, axis=1)
    if np.any(magnitude == 0):
        return None
    length = scene.rope.segment_length + magnitude / scene.rope.stiffness
    steps = -tension / magnitude[:, None] * length[:, None]
    out = np.zeros((model.nodes, model.dim))
    out[1:] = np.cumsum(steps, axis=0)
    return out


def shape_verdict(angles: np.ndarray, tolerance: float = STRAIGHT_TOLERANCE_DEG) -> str:
    """'straight', 'steeper at the bottom' or 'flatter at the bottom', from the top and bottom angles [deg]."""
    top, bottom = float(angles[0]), float(angles[-1])
    if abs(bottom - top) <= tolerance:
        return "straight"
    return "steeper at the bottom" if abs(bottom) < abs(top) else "flatter at the bottom"


def towed_figures(model: Model, x_final: np.ndarray) -> dict:
    """The towed rope's summary: top and bottom angles, shape, and the exact steady state's for comparison."""
    angles = segment_angles(model, x_final)
    out = {
        "top_angle_deg": round(float(angles[0]), 4),
        "bottom_angle_deg": round(float(angles[-1]), 4),
        "shape": shape_verdict(angles),
    }
    steady = exact_steady_state(model)
    if steady is not None:
        steady_angles = segment_angles(model, steady if towed_end(model.scene) == 0 else steady[::-1])
        rel = _from_top(model, np.asarray(x_final)) - _from_top(model, np.asarray(x_final))[0]
        out.update({
            "steady_top_angle_deg": round(float(steady_angles[0]), 4),
            "steady_bottom_angle_deg": round(float(steady_angles[-1]), 4),
            "steady_shape": shape_verdict(steady_angles),
            "distance_from_steady_state_m": float(np.max(np.linalg.norm(rel - steady, axis=1))),
        })
    return out
