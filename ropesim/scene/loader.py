"""Read a scene file (TOML) strictly into a :class:`ropesim.scene.Scene`.

Every refusal is a :class:`SceneError` whose message is one line: the file, the key path and what is
allowed, e.g. ``scenarios/x.toml: rope.mass: must be a number > 0, got -1``.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import fields, replace
from pathlib import Path
from typing import Any

from . import schema as S
from .builtin import resolve
from .errors import SceneError
from .material import agree, mass_per_length, per_node, resolve_axial_damping
from .motion import complete_motion
from .sea import resolve_sea
from .system import (POINT_BODY_IN_A_SYSTEM, RIGID_BODY_IN_A_ROPE, ROPE_ONLY_INSTEAD, SYSTEM_ONLY_INSTEAD,
                     resolve_system)
from .values import (MAX_MAGNITUDE, MAX_SCENE_BYTES, MIN_POSITIVE, check_name, choices_text, parse_value, show,
                     unit_of, unknown_key)


MAX_STEPS = 1e12  # a run of more steps would take days; t_end / dt beyond it is a typo, not a plan
BOM = "\ufeff"        # a UTF-8 byte-order mark, which some Windows editors put first; TOML does not allow it


def load_scene(path: str | Path, overrides: list[str] | tuple[str, ...] = ()) -> S.Scene:
    """Load and validate a scene file, or a built-in scene by name ("helicopter_mass"; a file that exists
    wins, see :mod:`ropesim.scene.builtin`), applying ``--set`` style ``KEY=VALUE`` overrides first."""
    found = resolve(path)
    path = found.path
    source = found.label
    try:
        size = path.stat().st_size
        if size > MAX_SCENE_BYTES and path.is_file():
            raise SceneError(source, "", f"is {size / 1e6:.3g} MB; a scene file is at most "
                                         f"{MAX_SCENE_BYTES / 1e6:.3g} MB (give a long driven path as a CSV "
                                         f"file, driven.path)")
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SceneError(source, "", "no such scene file") from None
    except IsADirectoryError:
        raise SceneError(source, "", "is a folder, not a scene file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(source, "", f"cannot be read ({exc.__class__.__name__})") from None
    if path.suffix.lower() != ".toml":
        from .moordyn import looks_like_moordyn

        if looks_like_moordyn(text):
            return scene_from_moordyn(text, source=source, default_name=path.stem, overrides=overrides,
                                      base_dir=path.resolve().parent)
    return scene_from_toml(text, source=source, default_name=path.stem, overrides=overrides,
                           base_dir=path.resolve().parent)


def scene_from_moordyn(text: str, source: str = "<moordyn>", default_name: str = "scene",
                       overrides: list[str] | tuple[str, ...] = (), base_dir: str | Path | None = None) -> S.Scene:
    """The scene of a MoorDyn v2 input file's text (:mod:`ropesim.scene.moordyn`; what it leaves out is in
    ``read_moordyn(text).notes``), with ``--set`` style overrides applied; raises :class:`SceneError`."""
    from .moordyn import read_moordyn

    raw = {"name": default_name, **read_moordyn(text, source, base_dir).scene}
    for item in overrides:
        apply_override(raw, item, source)
    label = f"{source} (imported from MoorDyn{', with --set ' + ' '.join(overrides) if overrides else ''})"
    return scene_from_dict(raw, source=label, default_name=default_name, base_dir=base_dir)


def scene_from_toml(text: str, source: str = "<scene>", default_name: str = "scene",
                    overrides: list[str] | tuple[str, ...] = (), base_dir: str | Path | None = None) -> S.Scene:
    """Parse TOML text into a validated scene (see :func:`load_scene`); files it names (a driven node's
    ``path``) are read relative to ``base_dir`` (default: the current folder). A leading UTF-8 byte-order mark
    is ignored; tables or arrays nested too deeply for Python's parser are refused in one line."""
    try:
        raw = tomllib.loads(text.removeprefix(BOM))
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(source, "", f"not valid TOML: {exc}") from None
    except RecursionError:
        raise SceneError(source, "", "not a scene: its tables or arrays are nested too deeply to read (a scene "
                                     "nests them a few levels)") from None
    for item in overrides:
        apply_override(raw, item, source)
    if overrides:
        source = f"{source} (with --set {' '.join(overrides)})"
    return scene_from_dict(raw, source=source, default_name=default_name, base_dir=base_dir)


def parse_override(item: str, source: str = "--set") -> tuple[list[str], Any]:
    """Split ``a.b.c=VALUE`` into its key path and a TOML-typed value (bare words are strings)."""
    key, sep, text = item.partition("=")
    key = key.strip()
    if not sep or not key:
        raise SceneError(source, "--set", f"expected KEY=VALUE (a dotted key such as integrator.dt=0.002), "
                                          f"got {item!r}")
    try:
        value = tomllib.loads(f"v = {text.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        value = text.strip()
    except RecursionError:
        raise SceneError(source, "--set", f"{key}: the value is nested too deeply to read") from None
    return key.split("."), value


def apply_override(raw: dict, item: str, source: str = "--set") -> None:
    """Set one ``--set KEY=VALUE`` in the raw TOML dict; integer path parts index arrays of tables."""
    parts, value = parse_override(item, source)
    node: Any = raw
    for depth, part in enumerate(parts[:-1]):
        here = ".".join(parts[: depth + 1])
        if isinstance(node, list):
            node = _list_item(node, part, here, source, item)
        elif isinstance(node, dict):
            if part not in node:   # an empty list: its entry 0 is added below, so counts stay true
                node[part] = [] if part in S.ARRAYS_OF_TABLES and _is_index(parts[depth + 1]) else {}
            node = node[part]
        else:
            raise SceneError(source, here, f"is a value, not a table, so --set {item} cannot go inside it")
    last = parts[-1]
    if isinstance(node, list):
        _list_item(node, last, ".".join(parts), source, item)
        node[int(last)] = value
    elif isinstance(node, dict):
        node[last] = value
    else:
        raise SceneError(source, ".".join(parts[:-1]), f"is a value, not a table, so --set {item} cannot go "
                                                       f"inside it")


def _is_index(part: str) -> bool:
    """True for a list index in a dotted key: ASCII digits only (``str.isdigit`` also admits e.g. '²')."""
    return part.isascii() and part.isdigit()


def _list_item(items: list, part: str, here: str, source: str, item: str):
    if not _is_index(part):
        raise SceneError(source, here, f"is a list; address its entries by number (e.g. {here}.0...) in "
                                       f"--set {item}")
    index = int(part)
    if index == len(items):
        items.append({})
    if index > len(items):
        n, base = len(items), here.rpartition(".")[0]
        have = (f"has no entries; --set can add {base}.0" if n == 0 else
                f"has 1 entry; --set can change {base}.0 or add {base}.1" if n == 1 else
                f"has {n} entries; --set can change {base}.0 to {base}.{n - 1} or add {base}.{n}")
        raise SceneError(source, here, have)
    return items[index]


# ------------------------------------------------------------------------------------ validation


def scene_from_dict(raw: dict, source: str = "<scene>", default_name: str = "scene",
                    base_dir: str | Path | None = None) -> S.Scene:
    """Validate a raw TOML dict into a :class:`Scene`; raises :class:`SceneError`. A scene with ``[[lines]]`` is a
    system (see :mod:`ropesim.scene.system`); any other is one rope."""
    allowed = list(S.TOP_LEVEL_SCALARS) + list(S.TABLES) + list(S.ARRAYS_OF_TABLES) + list(S.NAMED_TABLES)
    for key in raw:
        if key not in allowed:
            raise SceneError(source, key, unknown_key(key, allowed, "a top-level key or table"))
    is_system = "lines" in raw
    refused = ROPE_ONLY_INSTEAD if is_system else SYSTEM_ONLY_INSTEAD
    for key in raw:
        if key in refused:
            raise SceneError(source, key, refused[key])
    for key in S.SYSTEM_REQUIRED_TABLES if is_system else S.REQUIRED_TABLES:
        if key not in raw:
            raise SceneError(source, key, f"missing: a system's lines end on [[{key}]]" if key == "points" else
                             f"missing: every scene needs a [{key}] table")

    top = {}
    for key, sp in S.TOP_LEVEL_SCALARS.items():
        if key in raw:
            top[key] = parse_value(raw[key], sp, key, source, dim=0)
    dim = top.get("dimension", 2)
    up = top.get("up", "y")
    if up == "z" and dim != 3:
        raise SceneError(source, "up", f"a {dim}-D scene is drawn in x and y with y up; up = 'z' is for 3-D "
                                       f"scenes (dimension = 3)")
    ctx = _Ctx(source, dim)

    parts: dict[str, Any] = {"rope": None if is_system else _resolve_rope(ctx.table(raw, "rope", S.Rope), source)}
    for key, cls in S.TABLES.items():
        if key not in ("rope", "initial") and key in raw:
            parts[key] = ctx.table(raw, key, cls)
    for key, cls in S.ARRAYS_OF_TABLES.items():
        if key in raw:
            items = raw[key]
            if isinstance(items, dict):
                items = [items]
            if not isinstance(items, list):
                raise SceneError(source, key, f"must be an array of tables ([[{key}]]), got {show(items)}")
            if is_system and key in S.SYSTEM_VARIANTS:
                cls = S.SYSTEM_VARIANTS[key]
            parts[key] = tuple(ctx.entry(items, i, cls, key, is_system) for i in range(len(items)))
    for key, cls in S.NAMED_TABLES.items():
        if key in raw:
            parts[key] = ctx.named(raw, key, cls)
    if is_system:
        if not parts["lines"]:
            raise SceneError(source, "lines", "has no entries; a system needs at least one [[lines]] entry")
        parts["rigid_bodies"] = parts.pop("bodies", ())
        parts["initial"] = ctx.system_initial(raw)
    else:
        parts["initial"] = ctx.initial(raw)

    scene = S.Scene(
        name=top.get("name", default_name),
        description=top.get("description", ""),
        dimension=dim,
        up=up,
        **parts,
    )
    base = Path(base_dir) if base_dir is not None else Path.cwd()
    if up == "z":
        from .frame import twin_of

        def fail(key, message):
            raise SceneError(source, key, message)

        scene = twin_of(scene, base, fail)
    return _check_system(scene, source, base) if is_system else _check_scene(scene, source, base)


class _Ctx:
    def __init__(self, source: str, dim: int):
        self.source, self.dim = source, dim

    def table(self, container, key, cls, prefix: str = ""):
        path = f"{prefix}.{key}" if prefix else str(key)
        raw = container[key]
        if not isinstance(raw, dict):
            raise SceneError(self.source, path, f"must be a table, got {show(raw)}")
        return self.build(raw, cls, path)

    def entry(self, items: list, i: int, cls, key: str, is_system: bool):
        """Entry ``i`` of the array of tables ``key``: a rope's point body is refused in a system and a rigid body
        (an entry with an id) in a rope scene, each in a line saying what to use instead."""
        item = items[i]
        if key == "bodies" and isinstance(item, dict):
            if is_system and "node" in item and "id" not in item:
                raise SceneError(self.source, f"bodies.{i}.node", POINT_BODY_IN_A_SYSTEM)
            if not is_system and "id" in item:
                raise SceneError(self.source, f"bodies.{i}.id", RIGID_BODY_IN_A_ROPE)
        if key == "points" and isinstance(item, dict) and "body" in item:
            return self.body_point(items, i)
        return self.table(items, i, cls, prefix=key)

    def body_point(self, items: list, i: int):
        """A point on a rigid body: its position is in the body's frame, given in the scene's dimensions."""
        try:
            return self.table(items, i, S.Point, prefix="points")
        except SceneError as exc:
            if exc.key != f"points.{i}.position":
                raise
            raise SceneError(self.source, exc.key, f"{exc.message}; a point on body {show(items[i]['body'])} is "
                                                   f"placed in the body's frame, in the scene's {self.dim} "
                                                   f"dimensions") from None

    def named(self, raw: dict, key: str, cls) -> tuple:
        """A table of named tables (``[line_types.chain]``, ...): (name, entry) pairs in file order."""
        table = raw[key]
        if not isinstance(table, dict):
            raise SceneError(self.source, key, f"must be a table of named tables ([{key}.NAME]), got {show(table)}")
        out = []
        for name in table:
            check_name(name, f"{key}.{name}", self.fail, "a plain name (lines name it as their type)")
            if "." in name:
                self.fail(f"{key}.{name}", f"must not contain '.' (--set addresses it as {key}.NAME.KEY)")
            out.append((name, self.table(table, name, cls, prefix=key)))
        return tuple(out)

    def fail(self, key, message):
        raise SceneError(self.source, key, message)

    def system_initial(self, raw: dict):
        """A system's start: ``lines`` (the default, also without an [initial] table) or ``equilibrium``."""
        init = raw.get("initial", {})
        if not isinstance(init, dict):
            raise SceneError(self.source, "initial", f"must be a table, got {show(init)}")
        shape_spec = S.Spec("str", "initial shape", choices=tuple(S.SYSTEM_INITIAL_SHAPES))
        shape = init.get("shape", "lines")
        if isinstance(shape, str) and shape in S.INITIAL_SHAPES and shape not in S.SYSTEM_INITIAL_SHAPES:
            self.fail("initial.shape", f"'{shape}' starts one rope; a system starts as "
                                       f"{choices_text(S.SYSTEM_INITIAL_SHAPES)} (its points and bodies where the "
                                       f"scene puts them)")
        shape = parse_value(shape, shape_spec, "initial.shape", self.source, self.dim)
        return self.build(init, S.SYSTEM_INITIAL_SHAPES[shape], "initial", skip=("shape",),
                          what=f"a key of a system's [initial] with shape = '{shape}'")

    def build(self, raw: dict, cls, path: str, skip: tuple = (), what: str = ""):
        specs = {f.name: f.metadata["spec"] for f in fields(cls) if "spec" in f.metadata}
        for key in raw:
            if key not in specs and key not in skip:
                raise SceneError(self.source, f"{path}.{key}",
                                 unknown_key(key, list(skip) + list(specs), what or f"a key of [{path}]"))
        values = {}
        for name, sp in specs.items():
            if name in raw:
                values[name] = parse_value(raw[name], sp, f"{path}.{name}", self.source, self.dim)
            elif sp.required:
                raise SceneError(self.source, f"{path}.{name}", f"missing: {sp.doc}{unit_of(sp)}")
        return cls(**values)

    def initial(self, raw: dict):
        init = raw["initial"]
        if not isinstance(init, dict):
            raise SceneError(self.source, "initial", f"must be a table, got {show(init)}")
        shape_spec = S.Spec("str", "initial shape", choices=tuple(S.INITIAL_SHAPES))
        if "shape" not in init:
            raise SceneError(self.source, "initial.shape", f"missing: one of {choices_text(shape_spec.choices)}")
        shape = parse_value(init["shape"], shape_spec, "initial.shape", self.source, self.dim)
        start = self.build(init, S.INITIAL_SHAPES[shape], "initial", skip=("shape",),
                           what=f"a key of [initial] with shape = '{shape}'")
        zeros = (0.0,) * self.dim
        if isinstance(start, S.PointsStart) and start.velocities is not None:
            if start.velocity is not None:
                raise SceneError(self.source, "initial.velocities", "give one velocity for every node "
                                 "(velocity) or one per node (velocities), not both")
        elif hasattr(start, "velocity") and start.velocity is None:
            start = replace(start, velocity=zeros)
        if isinstance(start, S.HangingStart) and start.top is None:
            start = replace(start, top=zeros)
        return start


def _check_system(scene: S.Scene, source: str, base_dir: Path) -> S.Scene:
    """A system's checks that involve more than one key; returns it with every default filled in."""
    def fail(key, message):
        raise SceneError(source, key, message)

    _check_name_and_length(scene, fail)
    _check_integrator(scene, fail)
    scene = resolve_system(scene, base_dir, fail)
    _check_fluid(scene, fail)
    _check_flow_covers_the_start(scene, fail)
    _check_seabed(scene, fail)
    return resolve_sea(scene, base_dir, fail)


def _check_scene(scene: S.Scene, source: str, base_dir: Path) -> S.Scene:
    """Checks that involve more than one key; returns the scene with the defaults that depend on others filled."""
    def fail(key, message):
        raise SceneError(source, key, message)

    _check_name_and_length(scene, fail)
    _check_integrator(scene, fail)
    _check_topology(scene, fail)
    _check_nodes(scene, fail)
    _check_fluid(scene, fail)
    scene = _resolve_driven(scene, base_dir, fail)
    scene = _resolve_initial(_read_start(scene, base_dir, fail), fail)
    scene = _resolve_omegas(scene, fail)
    _check_flow_covers_the_start(scene, fail)
    _check_seabed(scene, fail)
    return resolve_sea(scene, base_dir, fail)


def _check_integrator(scene: S.Scene, fail) -> None:
    """galpha's keys only with galpha (the other methods take fixed steps), and relative_tolerance only with
    tolerance."""
    method = scene.integrator.method
    for key in ("rho_inf", "tolerance", "relative_tolerance"):
        if getattr(scene.integrator, key) is not None and method != "galpha":
            fail(f"integrator.{key}", f"is generalized-alpha's (method = \"galpha\"); method {method} has no {key}")
    if scene.integrator.relative_tolerance is not None and scene.integrator.tolerance is None:
        fail("integrator.relative_tolerance", "needs integrator.tolerance (the absolute part, in metres) too")


def _resolve_driven(scene: S.Scene, base_dir: Path, fail) -> S.Scene:
    """Each drive's defaults (no velocity: still; no phase: 0), its sinusoid complete, its path read."""
    labels = ("dx", "dy", "dz")[: scene.dimension]
    drives = tuple(complete_motion(drive, f"driven.{g}", labels, scene.dimension, base_dir, scene.integrator.t_end,
                                   fail) for g, drive in enumerate(scene.driven))
    return replace(scene, driven=drives)


def _check_seabed(scene: S.Scene, fail) -> None:
    """A seabed needs a footprint, and nothing held (a pinned or driven node, a fixed or driven point) may start
    below it (an anchor sits on or above it)."""
    bed = scene.seabed
    if bed is None:
        return
    if scene.is_system:
        bare = [i for i, line in enumerate(scene.lines) if line.diameter is None]
        if bed.contact_width is None and bare:
            fail("seabed.contact_width", f"missing: the seabed pushes on a footprint contact_width x node length; "
                                         f"give it, or every line's diameter (lines.{bare[0]} has none)")
        held = [(f"{p.kind} point '{p.id}' (points.{j}, at {scene.up} = {p.position[1]:.6g} m)", p.position[0],
                 p.position[1])
                for j, p in enumerate(scene.points) if p.kind in (*S.STILL_KINDS, "driven")]
    else:
        if bed.contact_width is None and scene.rope.diameter is None:
            fail("seabed.contact_width", "missing: the seabed pushes on a footprint contact_width x node length; "
                                         "give it, or rope.diameter")
        from .shapes import initial_positions

        x = initial_positions(scene)   # the held nodes where the scene puts them (the sagging guess keeps its ends)
        nodes = set(scene.pinned.nodes if scene.pinned else ()) | {i for d in scene.driven for i in d.nodes}
        held = [(f"held node {i} (at {scene.up} = {x[1][i]:.6g} m)", x[0][i], x[1][i])
                for i in sorted(scene.node(i) for i in nodes)]
    slope = math.radians(bed.slope)
    for what, x, y in held:
        below = (bed.height + math.tan(slope) * x - y) * math.cos(slope)
        if below > 1e-9 * max(1.0, abs(bed.height)):
            fail("seabed.height", f"puts the seabed {below:.6g} m above {what}: an anchor sits on the seabed or "
                                  f"above it")


PER_NODE_KEYS = ("nodes", "segment_length", "stiffness", "mass")
PHYSICAL_KEYS = ("length", "segments", "mass_per_length", "density", "EA")


def _resolve_rope(rope: S.Rope, source: str) -> S.Rope:
    """The rope with both forms filled: the per-node values derived from the physical ones when those are given
    (and checked against any per-node values also given), the compression default set."""
    def fail(key, message):
        raise SceneError(source, f"rope.{key}", message)

    if not any(getattr(rope, k) is not None for k in PHYSICAL_KEYS):
        for key in PER_NODE_KEYS:
            if getattr(rope, key) is None:
                spec = {f.name: f.metadata["spec"] for f in fields(S.Rope)}[key]
                fail(key, f"missing: {spec.doc}{unit_of(spec)}; or give the rope in physical units (length, "
                          f"segments, mass_per_length, EA)")
        l0 = rope.segment_length
        damping = resolve_axial_damping(rope.axial_damping, rope.axial_damping_ratio, l0, rope.stiffness * l0,
                                        rope.mass / l0, fail)
        return replace(rope, compression=True if rope.compression is None else rope.compression,
                       axial_damping=damping)
    for key in ("length", "EA"):
        if getattr(rope, key) is None:
            fail(key, f"missing: a rope in physical units needs length, EA, segments (or nodes) and "
                      f"mass_per_length (or diameter and density)")
    segments = rope.segments
    from_nodes = None if rope.nodes is None else (rope.nodes if rope.closed else rope.nodes - 1)
    if segments is None and from_nodes is None:
        fail("segments", "missing: how many segments the rope is cut into (or give nodes)")
    if segments is not None and from_nodes is not None and segments != from_nodes:
        fail("nodes", f"{rope.nodes} nodes contradict segments = {segments} (a {'loop' if rope.closed else 'line'} "
                      f"of {segments} segments has {segments if rope.closed else segments + 1} nodes)")
    segments = segments if segments is not None else from_nodes
    if rope.closed and segments < 3 or segments < 1:
        fail("segments", f"a {'closed loop needs at least 3' if rope.closed else 'line needs at least 1'}, "
                         f"got {segments}")
    per_metre = mass_per_length(rope.mass_per_length, rope.diameter, rope.density, fail)
    derived = {"nodes": segments if rope.closed else segments + 1,
               **per_node(rope.length, segments, rope.EA, per_metre, fail)}
    for key, value in derived.items():
        given = getattr(rope, key)
        if given is not None and not agree(given, value):
            fail(key, f"{given:g} contradicts the physical form, which gives {value:g}; give one form, or both "
                      f"consistently")
    damping = resolve_axial_damping(rope.axial_damping, rope.axial_damping_ratio, derived["segment_length"],
                                    rope.EA, per_metre, fail)
    return replace(rope, segments=segments, mass_per_length=per_metre, axial_damping=damping,
                   compression=False if rope.compression is None else rope.compression, **derived)


def _check_fluid(scene: S.Scene, fail) -> None:
    """The fluid terms have what they act with: a fluid, a diameter, gravity for buoyancy, a drag for a flow."""
    tables = [k for k in ("fluid_drag", "buoyancy", "added_mass") if getattr(scene, k) is not None]
    parts = _fluid_parts(scene)
    needs_fluid = tables + [key for key, uses, _, _ in parts if uses]
    if needs_fluid and scene.fluid is None:
        fail(needs_fluid[0], "needs a [fluid] table with the fluid's density (air 1.225, sea water 1025 kg/m^3)")
    for key in tables:
        if not scene.is_system and scene.rope.diameter is None:
            fail("rope.diameter", f"missing: [{key}] acts on the rope's diameter")
        for i, line in enumerate(scene.lines):
            if line.diameter is None:
                fail(f"lines.{i}.diameter", f"missing: [{key}] acts on each line's diameter; give it on the line or "
                                            f"its line type")
    if scene.buoyancy is not None and scene.gravity is None:
        fail("buoyancy", "needs [gravity]: buoyancy is the fluid's weight displaced")
    drags = [k for k in ("drag", "fluid_drag", "viscous_drag") if getattr(scene, k) is not None]
    inertia = scene.flow is not None and scene.flow.ramp_time > 0 and (
        scene.buoyancy is not None or scene.added_mass is not None or any(a for _, _, _, a in parts))
    if scene.flow is not None and not drags and not inertia and not any(d for _, _, d, _ in parts):
        fail("flow", "moves the system only through drag (and, while it ramps in, through buoyancy or added mass): "
                     "add [fluid_drag], [viscous_drag] or a point or body with cd_area" if scene.is_system else
                     "moves the rope only through drag (and, while it ramps in, through buoyancy or added mass): add "
                     "[drag], [fluid_drag], [viscous_drag] or a body with cd_area")
    flow = scene.flow
    if flow is not None:
        _check_flow(flow, scene.dimension, fail)
    if scene.is_system:
        return
    index = _node_index(scene.rope.nodes, fail)
    seen: dict[int, str] = {}
    for j, body in enumerate(scene.bodies):
        node = index(f"bodies.{j}.node", body.node)
        if node in seen:
            fail(f"bodies.{j}.node", f"node {node} already carries {seen[node]}; give each node one body")
        seen[node] = f"bodies.{j}"
        if body.mass == body.volume == body.cd_area == 0.0:
            fail(f"bodies.{j}", "has no mass, volume or cd_area; give at least one")
        if body.ca > 0 and body.volume == 0:
            fail(f"bodies.{j}.ca", "an added-mass coefficient needs the body's volume")


def _fluid_parts(scene: S.Scene) -> list[tuple[str, bool, bool, bool]]:
    """The bodies and points the fluid acts on: (key, uses the fluid, feels drag, feels a flow's acceleration)."""
    if not scene.is_system:
        return [("bodies", b.volume > 0 or b.cd_area > 0, b.cd_area > 0, b.ca > 0) for b in scene.bodies]
    parts = [(f"points.{j}.{'volume' if p.volume > 0 else 'cd_area'}", p.volume > 0 or p.cd_area > 0, p.cd_area > 0,
              p.ca > 0) for j, p in enumerate(scene.points) if p.kind == "free"]
    for j, b in enumerate(scene.rigid_bodies):
        used = [k for k in ("volume", "cd_area", "cd_rotation", "added_mass", "added_inertia")
                if any(v != 0 for v in (getattr(b, k) if isinstance(getattr(b, k), tuple) else (getattr(b, k),)))]
        parts.append((f"bodies.{j}.{used[0] if used else 'volume'}", bool(used),
                      bool({"cd_area", "cd_rotation"} & set(used)), bool({"added_mass", "added_inertia"} & set(used))))
    return parts


def _check_flow(flow: S.Flow, dim: int, fail) -> None:
    need = {"uniform": ("velocity",), "power_law": ("velocity", "reference_height", "exponent"),
            "table": ("heights", "velocities")}[flow.profile]
    for key in need:
        if getattr(flow, key) is None:
            fail(f"flow.{key}", f"missing: profile = '{flow.profile}' needs {', '.join(need)}")
    unused = [k for k in ("velocity", "reference_height", "exponent", "heights", "velocities")
              if k not in need and getattr(flow, k) is not None]
    if unused:
        fail(f"flow.{unused[0]}", f"is not used by profile = '{flow.profile}' (it uses {', '.join(need)})")
    if flow.profile == "table":
        if len(flow.heights) != len(flow.velocities):
            fail("flow.velocities", f"has {len(flow.velocities)} rows but flow.heights has {len(flow.heights)}; "
                                    f"give one velocity per height")
        if any(b <= a for a, b in zip(flow.heights, flow.heights[1:])):
            fail("flow.heights", f"must increase strictly, got {show(list(flow.heights))}")


def _check_flow_covers_the_start(scene: S.Scene, fail) -> None:
    """A table profile must cover the heights the rope starts at (beyond its rows the flow is held constant); in a
    system, the heights of its points (those on bodies: their bodies' reference points) and bodies."""
    flow = scene.flow
    if flow is None or flow.profile != "table":
        return
    if scene.is_system:
        y = [p.position[1] for p in scene.points if p.kind != "body"] + [b.position[1] for b in scene.rigid_bodies]
        what, whose = "system's points and bodies start", "system"
    else:
        from .shapes import initial_positions

        y, what, whose = initial_positions(scene)[1], "rope starts", "rope"
    low, high = float(min(y)), float(max(y))
    if low < flow.heights[0] or high > flow.heights[-1]:
        up = scene.up    # the twin's y is the height, named as the scene names it
        fail("flow.heights", f"cover {up} = {flow.heights[0]:g} to {flow.heights[-1]:g} m, but the {what} at "
                             f"{up} = {low:g} to {high:g} m; extend the table to the {whose}'s range")


def _check_name_and_length(scene: S.Scene, fail) -> None:
    check_name(scene.name, "name", fail)
    steps = scene.integrator.t_end / scene.integrator.dt
    if steps > MAX_STEPS:
        fail("integrator.t_end", f"t_end / dt = {steps:.3g} steps; at most {MAX_STEPS:.0e} are allowed "
                                 f"(t_end = {scene.integrator.t_end:g} s, dt = {scene.integrator.dt:g} s)")


def _check_topology(scene: S.Scene, fail) -> None:
    rope, n = scene.rope, scene.rope.nodes
    if rope.closed and n < 3:
        fail("rope.nodes", f"a closed loop needs at least 3 nodes, got {n}")
    if scene.bending is not None:
        if rope.closed and n < 5:
            fail("bending", f"bending springs on a loop need at least 5 nodes (with fewer, second neighbours "
                            f"are also first neighbours), got {n}")
        if not rope.closed and n < 3:
            fail("bending", f"bending springs need at least 3 nodes on a line, got {n}")


def _node_index(n: int, fail):
    """A checker of node indices for a rope of ``n`` nodes: the non-negative index, or a refusal naming the key."""
    def index(key, i):
        if not -n <= i < n:
            fail(key, f"node index {i} is past the rope's end: allowed -{n} to {n - 1}")
        return i % n
    return index


def _check_nodes(scene: S.Scene, fail) -> None:
    """Held (pinned, driven) and overridden nodes: on the rope, each held once, at least one free."""
    n = scene.rope.nodes
    index = _node_index(n, fail)
    held: dict[int, str] = {}
    if scene.pinned is not None:
        for j, i in enumerate(scene.pinned.nodes):
            key = f"pinned.nodes[{j}]"
            node = index(key, i)
            if node in held:
                fail(key, f"node {node} is listed twice (also {held[node]})")
            held[node] = key
    for g, drive in enumerate(scene.driven):
        for j, i in enumerate(drive.nodes):
            key = f"driven.{g}.nodes[{j}]"
            node = index(key, i)
            if node in held:
                fail(key, f"node {node} is already held by {held[node]}; a node is pinned or driven, not both")
            held[node] = key
    if len(held) == n:
        fail("pinned" if scene.pinned else "driven", "every node is held; at least one must be free to move")
    for j, i in enumerate(scene.pinned.clamped or () if scene.pinned else ()):
        key = f"pinned.clamped[{j}]"
        node = index(key, i)
        if scene.rope.closed or node not in (0, n - 1):
            fail(key, f"node {node} is not an end of an open line; only a line's end can be clamped")
        if node not in {index("pinned.nodes", k) for k in scene.pinned.nodes}:
            fail(key, f"node {node} is clamped but not pinned; list it in pinned.nodes too")
        if not scene.rope.EI:
            fail(key, "a clamp holds the end's direction against bending: it needs rope.EI")

    seen: dict[int, str] = {}
    for j, o in enumerate(scene.overrides):
        key = f"overrides.{j}.index"
        node = index(key, o.index)
        if node in seen:
            fail(key, f"node {node} is already overridden by {seen[node]}; give each node one entry")
        seen[node] = f"overrides.{j}"
        if o.mass is None and o.drag is None:
            fail(f"overrides.{j}", "sets neither mass nor drag; give at least one")


def _read_start(scene: S.Scene, base_dir: Path, fail) -> S.Scene:
    """An ``initial.shape = "from_run"`` start read from its run folder into a ``points`` start."""
    init = scene.initial
    if not isinstance(init, S.FromRunStart):
        return scene
    import numpy as np

    from ..io.frames import read_run
    from ..io.runfolder import RunFolderError

    folder = Path(init.run)
    folder = folder if folder.is_absolute() else base_dir / folder
    try:
        arrays = read_run(folder)[0]
    except RunFolderError as exc:
        fail("initial.run", f"cannot start from it: {exc}")
    if not {"t", "x", "v"} <= arrays.keys():
        fail("initial.run", f"cannot start from it: {folder} saved no t, x and v arrays")
    t, xs, vs = arrays["t"], arrays["x"], arrays["v"]
    n, dim = scene.rope.nodes, scene.dimension
    if xs.ndim != 3 or vs.shape != xs.shape or xs.shape[0] != len(t):
        fail("initial.run", f"cannot start from it: {folder}'s arrays do not fit together: t {t.shape}, x "
                            f"{xs.shape}, v {vs.shape}")
    if xs.shape[1:] != (n, dim):
        fail("initial.run", f"{folder} holds {xs.shape[1]} nodes in {xs.shape[2]}-D, but this rope has {n} nodes in "
                            f"{dim}-D")
    t = np.asarray(t)
    if init.time is None:
        k = len(t) - 1
    else:
        k = int(np.argmin(np.abs(t - init.time)))
        if abs(t[k] - init.time) > 1e-9 * max(1.0, abs(init.time)):
            step = f", every {t[1] - t[0]:.6g} s" if len(t) > 1 else ""
            fail("initial.time", f"{folder} saved no frame at t = {init.time:g} s; it saved frames from "
                                 f"{t[0]:g} to {t[-1]:g} s{step} (nearest: {t[k]:.6g} s)")
    x, v = np.asarray(xs[k], dtype=float), np.asarray(vs[k], dtype=float)
    if _up_of_run(folder) != scene.up:
        fail("initial.run", f"{folder} was run with up = '{_up_of_run(folder)}' and this scene has up = "
                            f"'{scene.up}'; start from a run in the same frame")
    from .frame import frame_of

    x, v = frame_of(scene).into(x), frame_of(scene).into(v)     # the run's frames are in its scene's frame
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
        fail("initial.time", f"{folder}'s frame at t = {t[k]:g} s is not finite (the run blew up); choose an "
                             f"earlier one")
    velocities = (None if init.at_rest else tuple(tuple(float(c) for c in row) for row in v))
    start = S.PointsStart(points=tuple(tuple(float(c) for c in row) for row in x),
                          velocity=(0.0,) * dim if init.at_rest else None, velocities=velocities)
    return replace(scene, initial=start)


def _up_of_run(folder: Path) -> str:
    """The ``up`` of the scene a run folder was run with (y when its scene.toml does not say)."""
    from ..io.runfolder import SCENE

    try:
        return str(tomllib.loads((folder / SCENE).read_text(encoding="utf-8")).get("up", "y"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return "y"


def _resolve_initial(scene: S.Scene, fail) -> S.Scene:
    """The initial shape fits the rope; the square loop's default centre is the thrower's."""
    rope, n, init = scene.rope, scene.rope.nodes, scene.initial
    if isinstance(init, (S.HangingStart, S.LineStart)) and rope.closed:
        fail("initial.shape", f"'{init.shape}' makes an open line; a closed loop starts as 'square_loop' or "
                              f"'points'")
    if isinstance(init, S.SquareLoopStart):
        if not rope.closed:
            fail("initial.shape", "'square_loop' needs a closed loop (rope.closed = true)")
        if init.top_center is None:
            if scene.thrower is None:
                fail("initial.top_center", "missing: needed when there is no [thrower] to centre the square on")
            scene = replace(scene, initial=replace(init, top_center=scene.thrower.center))
    if isinstance(init, S.PointsStart):
        if len(init.points) != n:
            fail("initial.points", f"has {len(init.points)} points but rope.nodes is {n}; give one per node")
        if init.velocities is not None and len(init.velocities) != n:
            fail("initial.velocities", f"has {len(init.velocities)} velocities but rope.nodes is {n}; give one "
                                       f"per node")
        pts = init.points
        pairs = [(i, i + 1) for i in range(n - 1)] + ([(n - 1, 0)] if rope.closed else [])
        for i, j in pairs:
            if pts[i] == pts[j]:
                fail("initial.points", f"nodes {i} and {j} coincide; a spring between them has no direction")
    if isinstance(init, (S.LineStart, S.EquilibriumStart)) and init.start == init.end:
        fail("initial.end", "equals initial.start; a line needs two distinct ends")
    if isinstance(init, S.EquilibriumStart) and rope.closed:
        fail("initial.shape", "'equilibrium' starts an open line between two ends; a loop starts as "
                              "'square_loop' or 'points'")
    return scene


def _resolve_omegas(scene: S.Scene, fail) -> S.Scene:
    """The thrower's default omega0, and each guide's default (the thrower's)."""
    if scene.thrower is not None and scene.thrower.omega0 is None:
        w = scene.thrower.resolved_omega0
        if not MIN_POSITIVE <= w <= MAX_MAGNITUDE:
            fail("thrower.omega0", f"missing: its default 4 pi |v_max| / length is {w:g} rad/s here; give an "
                                   f"omega0 from {MIN_POSITIVE:g} to {MAX_MAGNITUDE:g}")
        scene = replace(scene, thrower=replace(scene.thrower, omega0=w))
    guides = []
    for j, guide in enumerate(scene.guides):
        if guide.omega0 is None:
            if scene.thrower is None:
                fail(f"guides.{j}.omega0", "missing: needed when there is no [thrower] to take it from")
            guide = replace(guide, omega0=scene.thrower.omega0)
        guides.append(guide)
    return replace(scene, guides=tuple(guides))
