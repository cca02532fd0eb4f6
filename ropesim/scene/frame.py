"""Which axis is up: a scene's own frame against the frame ropesim computes in.

ropesim computes with y up. A 3-D scene may say ``up = "z"`` (MoorDyn's and OrcaFlex's frame): the loader then
turns it into its y-up twin, the same scene turned by P, a rotation of -90 degrees about x,

    (x, y, z) -> (x, z, -y),

and every output (trajectory arrays, exports, the Python API's results) is turned back by P^T: (x, y, z) ->
(x, -z, y). Both are exact in floating point (a permutation and a sign), so a z-up scene and its y-up twin give
the same numbers. How each key turns is set by what it means, not only by its kind:

- a vector (a position, a velocity, an amplitude, a point in a body's frame, an angular velocity): P v;
- per-axis magnitudes (drag areas, added masses, periods, phases, springs along each world axis): permuted,
  (x, y, z) -> (x, z, y), no sign;
- an inertia tensor: P I P^T; an orientation: the rotation P R P^T, then ropesim's angles (R = Rz Ry Rx), which
  is the angle vector turned as a vector when the angle about y or about z is 0;
- heights and the seabed's plane (height, slope along x) are the same numbers in both frames.

A driven body's angles move one by one (R = Rz(c) Ry(b) Rx(a) with a, b, c each a function of time), and P R P^T
of such a rotation is again of that form only when the angle about y or the one about z stays 0: a z-up scene's
driven body turns about x and at most one of y and z (one line says so otherwise).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

UP_AXES = ("y", "z")

VECTOR, AXES, ORIENTATION, INERTIA = "vector", "axes", "orientation", "inertia"
TURNS = {
    # vectors: positions, velocities, displacements, points in a body's frame, angular velocities
    "position": VECTOR, "velocity": VECTOR, "velocities": VECTOR, "amplitude": VECTOR, "path_table": VECTOR,
    "center_of_gravity": VECTOR, "center_of_buoyancy": VECTOR, "angular_velocity": VECTOR, "top": VECTOR,
    "start": VECTOR, "end": VECTOR, "points": VECTOR, "top_center": VECTOR, "center": VECTOR, "wind": VECTOR,
    "probes": VECTOR,
    # one magnitude per axis (body axes or world axes): permuted
    "cd_area": AXES, "added_mass": AXES, "cd_rotation": AXES, "added_inertia": AXES, "stiffness": AXES,
    "damping": AXES, "period": AXES, "phase": AXES,
    "orientation": ORIENTATION, "inertia": INERTIA,
}
"""How each key of a geometric kind (vector, points, rows, angles, dofs, dof_rows, inertia) turns; a test checks
that every such key of the schema is here."""
GEOMETRIC_KINDS = ("vector", "points", "rows", "angles", "dofs", "dof_rows", "inertia", "horizontal")

# P: the z-up scene's coordinates -> the y-up twin's
P = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


def _neg(c: float) -> float:
    return 0.0 - c     # -c, but 0.0 for 0.0 (no negative zeros in a scene)


def vector_in(v):
    """A z-up vector (x, y, z) in the y-up twin: (x, z, -y)."""
    x, y, z = v
    return (x, z, _neg(y))


def vector_out(v):
    """A y-up twin's vector (x, y, z) in the z-up scene: (x, -z, y)."""
    x, y, z = v
    return (x, _neg(z), y)


def axes_turn(v):
    """Per-axis magnitudes, either way: (x, y, z) -> (x, z, y)."""
    x, y, z = v
    return (x, z, y)


def _tensor(i6):
    xx, yy, zz, xy, xz, yz = i6
    return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]], dtype=float)


def inertia_turn(inertia, into: bool):
    """Principal moments are permuted; a full tensor (Ixx Iyy Izz Ixy Ixz Iyz) becomes P I P^T (into the twin)
    or P^T I P (out of it), entry for entry exact."""
    if len(inertia) == 3:
        return axes_turn(inertia)
    m = P @ _tensor(inertia) @ P.T if into else P.T @ _tensor(inertia) @ P
    return tuple(float(c) + 0.0 for c in (m[0, 0], m[1, 1], m[2, 2], m[0, 1], m[0, 2], m[1, 2]))


def orientation_turn(angles, into: bool):
    """Orientation angles [deg] (about x, then y, then z) of the same rotation in the other frame: the angle vector
    turned as a vector when its angle about y or about z is 0 (exact), else through the rotation matrix."""
    a, b, c = angles
    if b == 0 or c == 0:
        return vector_in(angles) if into else vector_out(angles)
    from ..analysis.rotation import angles_from_quaternion
    from ..model.rotation import quaternion_from_angles, quaternion_from_matrix, rotation_matrix

    r = rotation_matrix(quaternion_from_angles(angles))
    turned = P @ r @ P.T if into else P.T @ r @ P
    return tuple(float(x) + 0.0 for x in angles_from_quaternion(quaternion_from_matrix(turned)))


def turn_value(name: str, kind: str, value, into: bool):
    """The value of key ``name`` (of Spec kind ``kind``) in the other frame: into the y-up twin, or out of it."""
    how = TURNS[name]
    if how == INERTIA:
        return inertia_turn(value, into)
    if how == ORIENTATION:
        return orientation_turn(value, into)
    one = axes_turn if how == AXES else (vector_in if into else vector_out)
    if kind in ("vector", "angles"):
        return one(value)
    if kind == "points":
        return tuple(one(p) for p in value)
    if kind == "horizontal":   # (x,) in 2-D; 3-D: a z-up scene's (x, y) is the twin's (x, z) = (x, -y)
        return tuple(p if len(p) == 1 else (p[0], _neg(p[1])) for p in value)
    if kind == "dofs":
        return one(value[:3]) + one(value[3:])
    if kind == "rows":
        return tuple((r[0],) + one(r[1:]) for r in value)
    if kind == "dof_rows":
        return tuple((r[0],) + one(r[1:4]) + one(r[4:]) for r in value)
    raise ValueError(f"{name}: no turn for kind {kind}")


@dataclass(frozen=True)
class Frame:
    """A scene's own frame: ``up`` "y" (ropesim's, nothing turns) or "z" (outputs turned out of the y-up twin).

    Arrays hold vectors on their last axis. ``out`` and ``into`` return the array itself for a y-up scene (no
    copy, so a y-up run's outputs are its arrays bit for bit)."""

    up: str = "y"

    @property
    def turned(self) -> bool:
        return self.up == "z"

    @property
    def up_index(self) -> int:
        """The index of the height axis in the scene's own arrays (1: y, 2: z)."""
        return 2 if self.turned else 1

    def out(self, a):
        """Vectors (..., 3) of the y-up twin in the scene's frame."""
        if not self.turned or a is None:
            return a
        a = np.asarray(a)
        return np.stack([a[..., 0], 0.0 - a[..., 2], a[..., 1]], axis=-1)

    def into(self, a):
        """Vectors (..., 3) in the scene's frame, in the y-up twin."""
        if not self.turned or a is None:
            return a
        a = np.asarray(a)
        return np.stack([a[..., 0], a[..., 2], 0.0 - a[..., 1]], axis=-1)

    def quaternion_out(self, q):
        """Orientation quaternions (..., 4) (w, x, y, z) of the twin in the scene's frame: the rotation P^T R P,
        whose axis is the twin's axis turned out (exact)."""
        if not self.turned or q is None:
            return q
        q = np.asarray(q)
        return np.stack([q[..., 0], q[..., 1], 0.0 - q[..., 3], q[..., 2]], axis=-1)

    def quaternion_into(self, q):
        if not self.turned or q is None:
            return q
        q = np.asarray(q)
        return np.stack([q[..., 0], q[..., 1], q[..., 3], 0.0 - q[..., 2]], axis=-1)

    def arrays_out(self, arrays: dict) -> dict:
        """A run's named per-frame arrays (``x``, ``v``, ``support``, ``held_force``, ``body_*``; the others are
        scalars) in the scene's frame."""
        return self._arrays(arrays, self.out, self.quaternion_out)

    def arrays_into(self, arrays: dict) -> dict:
        return self._arrays(arrays, self.into, self.quaternion_into)

    def _arrays(self, arrays: dict, vector, quaternion) -> dict:
        if not self.turned:
            return arrays
        out = dict(arrays)
        for name in VECTOR_ARRAYS:
            if out.get(name) is not None:
                out[name] = vector(out[name])
        if out.get("body_q") is not None:
            out["body_q"] = quaternion(out["body_q"])
        return out

    def axis_name(self, internal: int) -> str:
        """The scene's name of the twin's axis ``internal`` (0 x, 1 the height, 2 across): for z up, x, z, -y."""
        return ("x", "z", "-y")[internal] if self.turned else "xyz"[internal]


VECTOR_ARRAYS = ("x", "v", "support", "held_force", "body_x", "body_v", "body_w")
"""A run's per-frame arrays of vectors (the last axis: x, y, z)."""


def frame_of(scene) -> Frame:
    """The frame of a scene (a scene without the key, or from before it, is y-up)."""
    return Frame(getattr(scene, "up", "y"))


# ------------------------------------------------------------------------------------- the scene's twin


def _turn_part(part, into: bool):
    """A scene's table (a dataclass of the schema) with every geometric key turned into (or out of) the twin."""
    from dataclasses import fields, replace

    changes = {}
    for f in fields(part):
        spec = f.metadata.get("spec")
        value = getattr(part, f.name)
        if spec is None or value is None or spec.kind not in GEOMETRIC_KINDS:
            continue
        changes[f.name] = turn_value(f.name, spec.kind, value, into)
    return replace(part, **changes) if changes else part


def _parts(scene, into: bool) -> dict:
    """Every table of ``scene`` turned, as keyword arguments of ``dataclasses.replace``."""
    from . import schema as S

    out = {}
    for key in (*S.TABLES, "initial"):
        part = getattr(scene, key, None)
        if part is not None:
            out[key] = _turn_part(part, into)
    for key in (*S.ARRAYS_OF_TABLES, "rigid_bodies"):
        items = getattr(scene, key)
        if items:
            out[key] = tuple(_turn_part(item, into) for item in items)
    return out


def twin_of(scene, base_dir, fail):
    """The y-up twin of a z-up scene read from its file (see the module's docstring), before the checks that
    involve more than one key (they check the twin). A driven path given as a CSV file is read here (its columns
    are the scene's axes) and kept inline, turned, as ``path_table``; the scene keeps its rigid bodies' orientations
    as the file gave them (``given_orientations``), which the resolved scene writes back exactly."""
    from dataclasses import replace

    from .motion import read_path
    from .values import dof_labels

    t_end = scene.integrator.t_end
    labels = {"driven": ("dx", "dy", "dz"), "points": ("dx", "dy", "dz"), "rigid_bodies": dof_labels(3)}
    read = {}
    for key, what in (("driven", "node"), ("points", "point"), ("rigid_bodies", "body")):
        items = list(getattr(scene, key))
        for j, item in enumerate(items):
            if item.path is not None and item.path_table is None:
                name = f"{'bodies' if key == 'rigid_bodies' else key}.{j}"
                rows = read_path(item.path, base_dir, labels[key], t_end, f"{name}.path", fail, what)
                items[j] = replace(item, path=None, path_table=rows)
        read[key] = tuple(items)
    scene = replace(scene, **read)
    for j, body in enumerate(scene.rigid_bodies):
        if body.kind == "driven":
            _check_driven_turns(body, f"bodies.{j}", fail)
    twin = replace(scene, **_parts(scene, into=True))
    return replace(twin, given_orientations=tuple(b.orientation for b in scene.rigid_bodies))


def scene_out(scene):
    """The twin's tables turned back into the scene's own frame (for writing the scene back); orientations as the
    file gave them."""
    from dataclasses import replace

    if not frame_of(scene).turned:
        return scene
    turned = replace(scene, **_parts(scene, into=False))
    given = scene.given_orientations
    if len(given) != len(scene.rigid_bodies):
        return turned
    bodies = tuple(replace(b, orientation=g) if g is not None and b.orientation is not None and
                   _same_rotation(g, twin.orientation) else b
                   for b, twin, g in zip(turned.rigid_bodies, scene.rigid_bodies, given))
    return replace(turned, rigid_bodies=bodies)


def _same_rotation(given, twin) -> bool:
    """True when the file's angles ``given`` still turn into the twin's ``twin`` (a body not changed since)."""
    return tuple(orientation_turn(given, into=True)) == tuple(twin)


def _check_driven_turns(body, key: str, fail) -> None:
    """A driven body's angles turn one by one only while its angle about y or the one about z stays 0."""
    def still(axis: int) -> bool:
        values = [body.orientation[axis] if body.orientation else 0.0,
                  body.angular_velocity[axis] if body.angular_velocity else 0.0,
                  body.amplitude[3 + axis] if body.amplitude else 0.0]
        values += [row[4 + axis] for row in body.path_table or ()]
        return all(v == 0 for v in values)

    if not (still(1) or still(2)):
        fail(key, "a driven body of a z-up scene turns about x and at most one of y and z (its orientation, "
                  "angular_velocity, amplitude and path give 0 about y, or 0 about z): ropesim moves the angles one "
                  "by one in its y-up frame, R = Rz Ry Rx, and a turn about both y and z is not of that form there")
