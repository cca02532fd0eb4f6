"""A system's checks and defaults: lines between points, points fixed, free, driven or on rigid bodies.

:func:`resolve_system` takes a scene the loader has read key by key (every value already checked on its own)
and checks what involves several keys: each name once, each reference to a point, body or line type real,
each line's material complete, each point and body given only the keys its kind uses. It returns the scene with
every default filled in (a line's material from its type, a point's kind, a body's zeros, a driven point's or
body's motion completed and its path read), so the resolved scene shows every value and loads back to itself.
The refusals are one line each, naming the key: ``t.toml: lines.2.start: no point 'fairled3' in [[points]]; did
you mean 'fairlead3'? points: anchor1, ...``.
"""

from __future__ import annotations

import difflib
from dataclasses import replace
from pathlib import Path

from . import schema as S
from .material import mass_per_length, per_node, resolve_axial_damping
from .motion import complete_motion
from .values import MIN_POSITIVE, check_name, count_of, dof_labels, show

ROPE_ONLY_INSTEAD = {   # a one-rope table in a system: what to use instead
    "rope": "a system has no [rope]: each [[lines]] entry gives its own material, or names a [line_types] entry",
    "pinned": "a system holds no node by its index: end the line on a fixed point ([[points]] with kind = 'fixed')",
    "driven": "a system moves no node by its index: end the line on a driven point ([[points]] with kind = "
              "'driven' and the motion keys), or on a point of a driven body",
    "overrides": "a system's lines have no per-node overrides: a mass where lines meet is a free point with mass "
                 "(a clump weight: [[points]] with kind = 'free')",
    "thrower": "the string shooter's drive acts on one closed rope ([rope]); a system has none",
    "guides": "guide circles act on the string shooter's rope ([rope]); a system has none",
    "drag": "[drag] is the per-node form's linear drag; a system's lines take [viscous_drag] (per metre) or "
            "[fluid_drag]",
    "bending": "[bending] is the per-node form's second-neighbour springs; give a system's lines bending "
               "stiffness EI (on the line or its line type)",
}
SYSTEM_ONLY_INSTEAD = {  # a system's table in a one-rope scene
    "points": "[[points]] join a system's lines: a scene with them needs [[lines]] between them (one rope holds "
              "its nodes with [pinned] and [[driven]])",
    "line_types": "[line_types] name the materials of a system's [[lines]]: a scene with them needs [[lines]] (one "
                  "rope gives its material in [rope])",
}
POINT_BODY_IN_A_SYSTEM = ("a body on a node belongs to a one-rope scene; in a system, a rigid body has an id (its "
                          "points name it), and a point mass is a free point with mass ([[points]], kind = 'free')")
RIGID_BODY_IN_A_ROPE = ("a rigid body (an entry with an id) belongs to a system ([[lines]] between [[points]]); one "
                        "rope's [[bodies]] sit on its nodes (node = ...)")

POINT_FREE_KEYS = ("mass", "volume", "cd_area", "ca")
MOTION_KEYS = ("velocity", "amplitude", "period", "phase", "path", "path_table")
BODY_MOTION_KEYS = ("velocity", "angular_velocity", *MOTION_KEYS[1:])
FLUID_COEFFICIENTS = {"cd_normal": "fluid_drag", "cd_tangential": "fluid_drag", "ca_normal": "added_mass",
                      "ca_tangential": "added_mass"}


def resolve_system(scene: S.Scene, base_dir: Path, fail) -> S.Scene:
    """The system checked across its keys and completed (see the module's docstring); ``fail(key, message)``
    refuses. Fluid, flow and seabed checks shared with one rope are the loader's."""
    for what in ("lines", "points", "rigid_bodies"):
        _check_ids(getattr(scene, what), "bodies" if what == "rigid_bodies" else what, fail)
    bodies = tuple(_resolve_body(scene, j, body, base_dir, fail) for j, body in enumerate(scene.rigid_bodies))
    points = tuple(_resolve_point(scene, j, point, base_dir, fail) for j, point in enumerate(scene.points))
    lines = tuple(_resolve_line(scene, i, line, fail) for i, line in enumerate(scene.lines))
    scene = replace(scene, lines=lines, points=points, rigid_bodies=bodies)
    _check_every_point_and_body_used(scene, fail)
    _check_something_moves(scene, fail)
    return scene


ONE = {"lines": "line", "points": "point", "bodies": "body"}


def _check_ids(items, key: str, fail) -> None:
    seen: dict[str, int] = {}
    for j, item in enumerate(items):
        check_name(item.id, f"{key}.{j}.id", fail, f"a plain name (it names the {ONE[key]} in outputs)")
        if item.id in seen:
            fail(f"{key}.{j}.id", f"'{item.id}' is already the id of {key}.{seen[item.id]}; give each its own")
        seen[item.id] = j


def _missing(what: str, name: str, table: str, known, plural: str = "") -> str:
    """'no point 'x' in [[points]]; did you mean 'y'? (points: a, b, c)'."""
    known = list(known)
    near = difflib.get_close_matches(name, known, n=1, cutoff=0.6)
    hint = f"; did you mean '{near[0]}'?" if near else ""
    listed = ", ".join(known[:20]) + (", ..." if len(known) > 20 else "")
    return f"no {what} {show(name)} in {table}{hint} ({plural or what + 's'}: {listed or 'none'})"


# ------------------------------------------------------------------------------------------- lines


def _resolve_line(scene: S.Scene, i: int, line: S.Line, fail) -> S.Line:
    """The line's ends on real points, its material its type's overridden by its own keys, completed."""
    key = f"lines.{i}"
    point_ids = [p.id for p in scene.points]
    for end in ("start", "end"):
        if getattr(line, end) not in point_ids:
            fail(f"{key}.{end}", _missing("point", getattr(line, end), "[[points]]", point_ids))
    if line.start == line.end:
        fail(f"{key}.end", f"is also its start, '{line.start}'; a line joins two different points")
    types = dict(scene.line_types)
    kind = None
    if line.type is not None:
        if line.type not in types:
            fail(f"{key}.type", _missing("line type", line.type, "[line_types]", types))
        kind = types[line.type]
    material = {k: getattr(line, k) if getattr(line, k) is not None or kind is None else getattr(kind, k)
                for k in S.MATERIAL_KEYS}

    def where(k: str) -> str:
        """The key a material value came from: the line's own, or its type's."""
        return f"{key}.{k}" if getattr(line, k) is not None or kind is None else f"line_types.{line.type}.{k}"

    def fail_line(k: str, message: str):
        fail(f"{key}.{k}", message)

    given_in = f" (on the line or its line type '{line.type}')" if kind is not None else ""
    if material["EA"] is None:
        fail(f"{key}.EA", f"missing: the line's axial stiffness EA [N]{given_in}")
    per_metre = mass_per_length(material["mass_per_length"], material["diameter"], material["density"], fail_line,
                                given_in)
    per_node(line.length, line.segments, material["EA"], per_metre, fail_line)
    material["axial_damping"] = _line_damping(line, kind, material, per_metre, key, fail)
    for k, table in FLUID_COEFFICIENTS.items():
        part = getattr(scene, table)
        if part is None and material[k] is not None:
            fail(where(k), f"is used only with [{table}]: declare [{table}], or leave {k} out")
        if part is not None and material[k] is None:
            material[k] = getattr(part, k)
    material.update(mass_per_length=per_metre, compression=bool(material["compression"]))
    return replace(line, **material)


def _line_damping(line: S.Line, kind: S.LineType | None, material: dict, per_metre: float, key: str, fail):
    """The line's axial damping BA [N s], from a coefficient or a damping ratio: the line's own key wins over its
    type's (a type's ratio gives each line the coefficient of its own segment length)."""
    own = [k for k in ("axial_damping", "axial_damping_ratio") if getattr(line, k) is not None]
    source, where = (line, key) if own or kind is None else (kind, f"line_types.{line.type}")
    coefficient, ratio = source.axial_damping, source.axial_damping_ratio
    if own == ["axial_damping"]:
        ratio = None
    material["axial_damping_ratio"] = ratio
    return resolve_axial_damping(coefficient, ratio, line.segment_length, material["EA"], per_metre,
                                 lambda k, message: fail(f"{where}.{k}", message))


# ------------------------------------------------------------------------------------------ points


def _resolve_point(scene: S.Scene, j: int, point: S.Point, base_dir: Path, fail) -> S.Point:
    """The point's kind (body when it names a body, else fixed), its keys those of its kind, its motion complete."""
    key = f"points.{j}"
    kind = point.kind or ("body" if point.body is not None else "fixed")
    body_ids = [b.id for b in scene.rigid_bodies]
    if kind == "body":
        if point.body is None:
            fail(f"{key}.body", "missing: a point of kind 'body' sits on a rigid body; name it (an id in [[bodies]])")
        if point.body not in body_ids:
            fail(f"{key}.body", _missing("body", point.body, "[[bodies]]", body_ids, "bodies"))
    elif point.body is not None:
        fail(f"{key}.body", f"is given, but the point's kind is '{kind}'; only a point of kind 'body' (the default "
                            f"with body) sits on a body")
    if kind != "free":
        for k in POINT_FREE_KEYS:
            if getattr(point, k) is not None:
                fail(f"{key}.{k}", f"only a free point carries a {k}; this point is '{kind}': {_held_by(kind)}")
    else:
        point = replace(point, **{k: 0.0 for k in POINT_FREE_KEYS if getattr(point, k) is None})
        if point.ca > 0.0 and point.volume == 0.0:
            fail(f"{key}.ca", "an added-mass coefficient needs the point's volume")
    if kind != "driven":
        given = [k for k in (*MOTION_KEYS, "ramp_time") if getattr(point, k) is not None]
        if given:
            instead = ("drive its body instead" if kind == "body" else
                       "the coupled program gives its motion at every step" if kind == "coupled" else
                       "set kind = 'driven' to move it so")
            fail(f"{key}.{given[0]}", f"is a driven point's motion; this point is '{kind}' ({instead})")
        return replace(point, kind=kind)
    labels = ("dx", "dy", "dz")[: scene.dimension]
    point = replace(point, kind=kind, ramp_time=point.ramp_time or 0.0)
    return complete_motion(point, key, labels, scene.dimension, base_dir, scene.integrator.t_end, fail, "point")


def _held_by(kind: str) -> str:
    return {"fixed": "it stays where it is, whatever acts on it",
            "coupled": "the program it is coupled to moves it (a run of the scene alone holds it still)",
            "driven": "it follows its prescribed motion, whatever acts on it",
            "body": "it moves with its body (give the body its mass, volume and drag)"}[kind]


# ------------------------------------------------------------------------------------------ bodies


def _resolve_body(scene: S.Scene, j: int, body: S.RigidBody, base_dir: Path, fail) -> S.RigidBody:
    """The body's zeros filled in; a free one has a mass and an inertia; a driven one its motion complete."""
    key, dim = f"bodies.{j}", scene.dimension
    zeros, turns = (0.0,) * dim, (0.0,) * count_of("angles", dim)
    body = replace(body, **{k: zeros for k in ("center_of_gravity", "center_of_buoyancy", "cd_area", "added_mass")
                            if getattr(body, k) is None},
                   **{k: turns for k in ("orientation", "cd_rotation", "added_inertia") if getattr(body, k) is None})
    if body.kind == "free":
        if not body.mass >= MIN_POSITIVE:
            fail(f"{key}.mass", f"missing: a free body needs its mass (at least {MIN_POSITIVE:g} kg; a fixed or "
                                f"driven body need not have one), got {body.mass:g}")
        if body.inertia is None:
            fail(f"{key}.inertia", "missing: a free body needs its moments of inertia about its centre of gravity "
                                   f"[kg m^2] ({'Ixx, Iyy, Izz' if dim == 3 else 'Izz'})")
    if body.kind != "free":
        for k in ("stiffness", "damping"):
            if getattr(body, k) is not None:
                fail(f"{key}.{k}", f"acts on a free body; this body is '{body.kind}' and does not move by its forces")
    if body.height is not None and body.kind != "free":
        fail(f"{key}.height", f"is where a [sea]'s surface cuts a free body; this body is '{body.kind}' and feels "
                              f"no forces of its own")
    if body.height is not None and scene.sea is None:
        fail(f"{key}.height", "is where a [sea]'s surface cuts the body: it needs a [sea] (or leave it out)")
    for k in ("stiffness", "damping"):
        if getattr(body, k) is not None and min(getattr(body, k)) < 0:
            fail(f"{key}.{k}", f"must be at least 0 along every axis, got {list(getattr(body, k))}")
    if body.kind == "free":   # its velocities at t = 0, at rest unless given
        body = replace(body, velocity=body.velocity if body.velocity is not None else zeros,
                       angular_velocity=body.angular_velocity if body.angular_velocity is not None else turns)
    if body.kind != "driven":
        starts = ("velocity", "angular_velocity") if body.kind == "free" else ()
        given = [k for k in (*BODY_MOTION_KEYS, "ramp_time") if getattr(body, k) is not None and k not in starts]
        if given:
            fail(f"{key}.{given[0]}", f"is a driven body's motion; this body is '{body.kind}' (set kind = 'driven' "
                                      f"to move it so)")
        return body
    body = complete_motion(replace(body, ramp_time=body.ramp_time or 0.0), key, dof_labels(dim), dim, base_dir,
                           scene.integrator.t_end, fail, "body")
    return replace(body, angular_velocity=body.angular_velocity if body.angular_velocity is not None else turns)


# ------------------------------------------------------------------------------------------- whole


def _check_every_point_and_body_used(scene: S.Scene, fail) -> None:
    """Every point carries a line end; every body that is not free carries a point (else it does nothing)."""
    ends = {p for line in scene.lines for p in (line.start, line.end)}
    for j, point in enumerate(scene.points):
        if point.id in ends:
            continue
        if point.kind == "free" and point.mass == 0.0:
            fail(f"points.{j}", f"'{point.id}' is a free point with no mass and no line: nothing to move; end a line "
                                f"on it (its start or end), or leave it out")
        fail(f"points.{j}", f"no line starts or ends at '{point.id}'; end a line on it, or leave it out")
    carried = {p.body for p in scene.points if p.body is not None}
    for j, body in enumerate(scene.rigid_bodies):
        if body.kind != "free" and body.id not in carried:
            fail(f"bodies.{j}", f"'{body.id}' is {body.kind} and no point sits on it, so it does nothing; put a line's "
                                f"point on it (a point with body = '{body.id}'), or leave it out")


def _check_something_moves(scene: S.Scene, fail) -> None:
    """At least one node, point or body is free to move (a line of one segment has no node of its own)."""
    if (any(line.segments > 1 for line in scene.lines) or any(p.kind == "free" for p in scene.points)
            or any(b.kind == "free" for b in scene.rigid_bodies)):
        return
    fail("lines", "nothing is free to move: every line is one segment between points that are held (fixed, driven, "
                  "or on a body that is not free); cut a line into more segments, or free a point or a body")
