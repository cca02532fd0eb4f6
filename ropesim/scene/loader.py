"""Read a scene file (TOML) strictly into a :class:`ropesim.scene.Scene`.

Every refusal is a :class:`SceneError` whose message is one line: the file, the key path and what is
allowed, e.g. ``scenarios/x.toml: rope.mass: must be a number > 0, got -1``.
"""

from __future__ import annotations

import difflib
import math
import tomllib
from dataclasses import fields, replace
from pathlib import Path
from typing import Any

from . import schema as S
from .builtin import resolve
from .errors import SceneError


MAX_STEPS = 1e12  # a run of more steps would take days; t_end / dt beyond it is a typo, not a plan
MAX_MAGNITUDE = 1e12  # in SI units: 7 AU, 30 000 years, a 1e12 N/m spring; no rope scene needs more
MIN_POSITIVE = 1e-12  # the least value of a quantity that must be > 0, so that ratios such as k / m stay finite
MAX_SCENE_BYTES = 16 * 2 ** 20   # a scene file is a few kB; an inline path table of 100 000 rows about 5 MB
MAX_TEXT = 1000       # characters of any text value (a description is one line)
MAX_NAME_BYTES = 200  # a scene's name names its run folder; 255 bytes is the usual file-name limit
MAX_PATH_ROWS = 100_000  # rows of a driven node's path (a 3-hour path every 0.1 s); scene.toml stores them
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
    return scene_from_toml(text, source=source, default_name=path.stem, overrides=overrides,
                           base_dir=path.resolve().parent)


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
    """Validate a raw TOML dict into a :class:`Scene`; raises :class:`SceneError`."""
    allowed = list(S.TOP_LEVEL_SCALARS) + list(S.TABLES) + list(S.ARRAYS_OF_TABLES)
    for key in raw:
        if key not in allowed:
            raise SceneError(source, key, _unknown(key, allowed, "a top-level key or table"))
    for key in S.REQUIRED_TABLES:
        if key not in raw:
            raise SceneError(source, key, f"missing: every scene needs a [{key}] table")

    top = {}
    for key, sp in S.TOP_LEVEL_SCALARS.items():
        if key in raw:
            top[key] = _value(raw[key], sp, key, source, dim=0)
    dim = top.get("dimension", 2)
    ctx = _Ctx(source, dim)

    rope = _resolve_rope(ctx.table(raw, "rope", S.Rope), source)
    parts: dict[str, Any] = {"rope": rope}
    for key, cls in S.TABLES.items():
        if key not in ("rope", "initial") and key in raw:
            parts[key] = ctx.table(raw, key, cls)
    for key, cls in S.ARRAYS_OF_TABLES.items():
        if key in raw:
            items = raw[key]
            if isinstance(items, dict):
                items = [items]
            if not isinstance(items, list):
                raise SceneError(source, key, f"must be an array of tables ([[{key}]]), got {_show(items)}")
            parts[key] = tuple(ctx.table(items, i, cls, prefix=key) for i in range(len(items)))
    parts["initial"] = ctx.initial(raw)

    scene = S.Scene(
        name=top.get("name", default_name),
        description=top.get("description", ""),
        dimension=dim,
        **parts,
    )
    return _check_scene(scene, source, Path(base_dir) if base_dir is not None else Path.cwd())


class _Ctx:
    def __init__(self, source: str, dim: int):
        self.source, self.dim = source, dim

    def table(self, container, key, cls, prefix: str = ""):
        path = f"{prefix}.{key}" if prefix else str(key)
        raw = container[key]
        if not isinstance(raw, dict):
            raise SceneError(self.source, path, f"must be a table, got {_show(raw)}")
        return self.build(raw, cls, path)

    def build(self, raw: dict, cls, path: str, skip: tuple = (), what: str = ""):
        specs = {f.name: f.metadata["spec"] for f in fields(cls) if "spec" in f.metadata}
        for key in raw:
            if key not in specs and key not in skip:
                raise SceneError(self.source, f"{path}.{key}",
                                 _unknown(key, list(skip) + list(specs), what or f"a key of [{path}]"))
        values = {}
        for name, sp in specs.items():
            if name in raw:
                values[name] = _value(raw[name], sp, f"{path}.{name}", self.source, self.dim)
            elif sp.required:
                raise SceneError(self.source, f"{path}.{name}", f"missing: {sp.doc}{_unit(sp)}")
        return cls(**values)

    def initial(self, raw: dict):
        init = raw["initial"]
        if not isinstance(init, dict):
            raise SceneError(self.source, "initial", f"must be a table, got {_show(init)}")
        shape_spec = S.Spec("str", "initial shape", choices=tuple(S.INITIAL_SHAPES))
        if "shape" not in init:
            raise SceneError(self.source, "initial.shape", f"missing: one of {_choices(shape_spec.choices)}")
        shape = _value(init["shape"], shape_spec, "initial.shape", self.source, self.dim)
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


def _check_scene(scene: S.Scene, source: str, base_dir: Path) -> S.Scene:
    """Checks that involve more than one key; returns the scene with the defaults that depend on others filled."""
    def fail(key, message):
        raise SceneError(source, key, message)

    _check_name_and_length(scene, fail)
    _check_topology(scene, fail)
    _check_nodes(scene, fail)
    _check_fluid(scene, fail)
    scene = _resolve_driven(scene, base_dir, fail)
    scene = _resolve_initial(_read_start(scene, base_dir, fail), fail)
    scene = _resolve_omegas(scene, fail)
    _check_flow_covers_the_rope(scene, fail)
    _check_seabed(scene, fail)
    return scene


def _resolve_driven(scene: S.Scene, base_dir: Path, fail) -> S.Scene:
    """Each drive's defaults (no velocity: still; no phase: 0), its sinusoid complete, its path read."""
    zeros = (0.0,) * scene.dimension
    drives = []
    for g, drive in enumerate(scene.driven):
        key = f"driven.{g}"
        drive = replace(drive, velocity=drive.velocity if drive.velocity is not None else zeros)
        if drive.amplitude is not None:
            if drive.period is None:
                fail(f"{key}.period", "missing: a sinusoid needs its period per axis (with amplitude)")
            if any(a != 0.0 and not T > 0.0 for a, T in zip(drive.amplitude, drive.period)):
                fail(f"{key}.period", f"must be > 0 on every axis that moves, got {list(drive.period)}")
            drive = replace(drive, phase=drive.phase if drive.phase is not None else zeros)
        elif drive.period is not None or drive.phase is not None:
            fail(f"{key}.{'period' if drive.period is not None else 'phase'}", "is used only with amplitude")
        if drive.path is not None and drive.path_table is not None:
            fail(f"{key}.path_table", "give the path either as a CSV file (path) or inline (path_table), not both")
        if drive.path is not None:
            drive = replace(drive, path=None, path_table=_read_path(drive.path, base_dir, scene, f"{key}.path", fail))
        if drive.path_table is not None:
            _check_path(drive.path_table, scene, f"{key}.path_table", "", fail)
        drives.append(drive)
    return replace(scene, driven=tuple(drives))


def _read_path(name: str, base_dir: Path, scene: S.Scene, key: str, fail) -> tuple:
    """The CSV path's rows (t, dx, dy[, dz]), checked like an inline ``path_table``; the file name is taken
    relative to the scene file's folder."""
    import csv

    path = Path(name)
    path = path if path.is_absolute() else (base_dir / path)
    try:
        size = path.stat().st_size
        if size > MAX_SCENE_BYTES and path.is_file():
            fail(key, f"{path} is {size / 1e6:.3g} MB; a path is at most {MAX_PATH_ROWS:,} rows "
                      f"({MAX_SCENE_BYTES / 1e6:.3g} MB): resample it")
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        fail(key, f"cannot read {path} ({exc.__class__.__name__})")
    columns = scene.dimension + 1
    rows = []
    for number, row in enumerate(csv.reader(text.splitlines()), start=1):
        if not row or row[0].lstrip().startswith("#"):
            continue
        if len(rows) == MAX_PATH_ROWS:
            fail(key, f"{path}: more than {MAX_PATH_ROWS:,} rows; a path is at most that many (the run folder's "
                      f"scene.toml keeps them): resample it")
        try:
            values = [float(v) for v in row]
        except ValueError:
            if not rows:
                continue   # a header line
            fail(key, f"{path}, line {number}: not numbers: {_show(row)}")
        if len(values) != columns or not all(math.isfinite(v) for v in values):
            fail(key, f"{path}, line {number}: needs {columns} finite numbers (t, dx, dy{', dz' if columns == 4 else ''}), "
                      f"got {_show(row)}")
        if any(abs(v) > MAX_MAGNITUDE for v in values):
            fail(key, f"{path}, line {number}: numbers must be at most {MAX_MAGNITUDE:g} in magnitude (s, m), as "
                      f"in a scene file; got {_show(row)}")
        rows.append(tuple(values))
    _check_path(rows, scene, key, f"{path}: ", fail)
    return tuple(rows)


def _check_path(rows, scene: S.Scene, key: str, where: str, fail) -> None:
    """At least two rows, times increasing from at most 0 to at least t_end, no displacement at t = 0."""
    if len(rows) < 2:
        fail(key, f"{where}needs at least two rows of t, dx, dy{', dz' if scene.dimension == 3 else ''}")
    times = [r[0] for r in rows]
    for a, b in zip(times, times[1:]):
        if not b > a:
            fail(key, f"{where}times must increase, but {b:g} s follows {a:g} s")
    if times[0] > 0.0 or times[-1] < scene.integrator.t_end:
        fail(key, f"{where}covers t = {times[0]:g} to {times[-1]:g} s, but the run goes from 0 to "
                  f"{scene.integrator.t_end:g} s")
    start = [float(v) for v in _interpolate(rows, 0.0)]
    if any(abs(v) > 1e-12 for v in start):
        fail(key, f"{where}the displacement at t = 0 is {start}, not zero (the path moves the node from where "
                  f"the scene starts it)")


def _interpolate(rows, t: float) -> tuple:
    import numpy as np

    table = np.asarray(rows)
    return tuple(np.interp(t, table[:, 0], table[:, c]) for c in range(1, table.shape[1]))


def _check_seabed(scene: S.Scene, fail) -> None:
    """A seabed needs a footprint, and no held node may start below it (an anchor sits on or above it)."""
    bed = scene.seabed
    if bed is None:
        return
    if bed.contact_width is None and scene.rope.diameter is None:
        fail("seabed.contact_width", "missing: the seabed pushes on a footprint contact_width x node length; give "
                                     "it, or rope.diameter")
    from .shapes import initial_positions

    x = initial_positions(scene)   # the held nodes where the scene puts them (the sagging guess keeps its ends)
    slope = math.radians(bed.slope)
    below = (bed.height + math.tan(slope) * x[0] - x[1]) * math.cos(slope)
    held = set(scene.pinned.nodes if scene.pinned else ()) | {i for d in scene.driven for i in d.nodes}
    for i in sorted(scene.node(i) for i in held):
        if below[i] > 1e-9 * max(1.0, abs(bed.height)):
            fail("seabed.height", f"puts the seabed {below[i]:.6g} m above held node {i} (at y = {x[1][i]:.6g} m): "
                                  f"an anchor sits on the seabed or above it")


PER_NODE_KEYS = ("nodes", "segment_length", "stiffness", "mass")
PHYSICAL_KEYS = ("length", "segments", "mass_per_length", "density", "EA")
AGREE = 1e-9   # relative: a resolved scene's derived values agree with their physical form to rounding


def _resolve_rope(rope: S.Rope, source: str) -> S.Rope:
    """The rope with both forms filled: the per-node values derived from the physical ones when those are given
    (and checked against any per-node values also given), the compression default set."""
    def fail(key, message):
        raise SceneError(source, f"rope.{key}", message)

    if not any(getattr(rope, k) is not None for k in PHYSICAL_KEYS):
        for key in PER_NODE_KEYS:
            if getattr(rope, key) is None:
                spec = {f.name: f.metadata["spec"] for f in fields(S.Rope)}[key]
                fail(key, f"missing: {spec.doc}{_unit(spec)}; or give the rope in physical units (length, "
                          f"segments, mass_per_length, EA)")
        return replace(rope, compression=True if rope.compression is None else rope.compression)
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
    per_metre = rope.mass_per_length
    if rope.density is not None:
        if rope.diameter is None:
            fail("diameter", "missing: with density, the mass per metre is density x pi d^2 / 4")
        from_density = rope.density * math.pi * rope.diameter ** 2 / 4.0
        if per_metre is not None and not _agree(per_metre, from_density):
            fail("mass_per_length", f"{per_metre:g} kg/m contradicts density x pi d^2 / 4 = {from_density:g} kg/m; "
                                    f"give one of them")
        per_metre = from_density if per_metre is None else per_metre
    if per_metre is None:
        fail("mass_per_length", "missing: give mass_per_length, or diameter and density")
    l0 = rope.length / segments
    derived = {"nodes": segments if rope.closed else segments + 1, "segment_length": l0,
               "stiffness": rope.EA / l0, "mass": per_metre * l0}
    for key, value in derived.items():
        given = getattr(rope, key)
        if given is not None and not _agree(given, value):
            fail(key, f"{given:g} contradicts the physical form, which gives {value:g}; give one form, or both "
                      f"consistently")
    origin = {"segment_length": ("length", "length / segments"), "stiffness": ("EA", "EA / l"),
              "mass": ("mass_per_length", "mass_per_length x l")}
    for key, (physical, how) in origin.items():   # the derived per-node values obey the per-node keys' limits
        value, spec = derived[key], {f.name: f.metadata["spec"] for f in fields(S.Rope)}[key]
        if not MIN_POSITIVE <= value <= MAX_MAGNITUDE:
            fail(physical, f"gives {key} = {how} = {value:g}{_unit(spec)}, outside {MIN_POSITIVE:g} to "
                           f"{MAX_MAGNITUDE:g} (its products and ratios would overflow)")
    return replace(rope, segments=segments, mass_per_length=per_metre,
                   compression=False if rope.compression is None else rope.compression, **derived)


def _agree(a: float, b: float) -> bool:
    return abs(a - b) <= AGREE * max(abs(a), abs(b))


def _check_fluid(scene: S.Scene, fail) -> None:
    """The fluid terms have what they act with: a fluid, a diameter, gravity for buoyancy, a drag for a flow."""
    needs_fluid = [k for k in ("fluid_drag", "buoyancy", "added_mass") if getattr(scene, k) is not None]
    if any(b.volume > 0 or b.cd_area > 0 for b in scene.bodies):
        needs_fluid.append("bodies")
    if needs_fluid and scene.fluid is None:
        fail(needs_fluid[0], "needs a [fluid] table with the fluid's density (air 1.225, sea water 1025 kg/m^3)")
    for key in ("fluid_drag", "buoyancy", "added_mass"):
        if getattr(scene, key) is not None and scene.rope.diameter is None:
            fail("rope.diameter", f"missing: [{key}] acts on the rope's diameter")
    if scene.buoyancy is not None and scene.gravity is None:
        fail("buoyancy", "needs [gravity]: buoyancy is the fluid's weight displaced")
    drags = [k for k in ("drag", "fluid_drag", "viscous_drag") if getattr(scene, k) is not None]
    inertia = scene.flow is not None and scene.flow.ramp_time > 0 and (
        scene.buoyancy is not None or scene.added_mass is not None or any(b.ca > 0 for b in scene.bodies))
    if scene.flow is not None and not drags and not inertia and not any(b.cd_area > 0 for b in scene.bodies):
        fail("flow", "moves the rope only through drag (and, while it ramps in, through buoyancy or added "
                     "mass): add [drag], [fluid_drag], [viscous_drag] or a body "
                     "with cd_area")
    flow = scene.flow
    if flow is not None:
        _check_flow(flow, scene.dimension, fail)
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
            fail("flow.heights", f"must increase strictly, got {_show(list(flow.heights))}")


def _check_flow_covers_the_rope(scene: S.Scene, fail) -> None:
    """A table profile must cover the heights the rope starts at (beyond its rows the flow is held constant)."""
    flow = scene.flow
    if flow is None or flow.profile != "table":
        return
    from .shapes import initial_positions

    y = initial_positions(scene)[1]
    low, high = float(y.min()), float(y.max())
    if low < flow.heights[0] or high > flow.heights[-1]:
        fail("flow.heights", f"cover y = {flow.heights[0]:g} to {flow.heights[-1]:g} m, but the rope starts at "
                             f"y = {low:g} to {high:g} m; extend the table to the rope's range")


def _check_name_and_length(scene: S.Scene, fail) -> None:
    name = scene.name
    if not name or name in (".", "..") or "/" in name or "\\" in name or not name.isprintable():
        fail("name", f"must be a plain folder name (runs go to runs/<name>/): printable, without / or \\, "
                     f"not '.' or '..'; got {_show(name)}")
    if len(name.encode("utf-8")) > MAX_NAME_BYTES:
        fail("name", f"must be at most {MAX_NAME_BYTES} bytes in UTF-8 (it names the run folder), got "
                     f"{len(name.encode('utf-8'))}")
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
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
        fail("initial.time", f"{folder}'s frame at t = {t[k]:g} s is not finite (the run blew up); choose an "
                             f"earlier one")
    velocities = (None if init.at_rest else tuple(tuple(float(c) for c in row) for row in v))
    start = S.PointsStart(points=tuple(tuple(float(c) for c in row) for row in x),
                          velocity=(0.0,) * dim if init.at_rest else None, velocities=velocities)
    return replace(scene, initial=start)


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


# ------------------------------------------------------------------------------ single values


def _value(value: Any, sp: S.Spec, key: str, source: str, dim: int):
    def bad(what):
        raise SceneError(source, key, f"{what}{_unit(sp)}, got {_show(value)}")

    if sp.kind == "bool":
        if not isinstance(value, bool):
            bad("must be true or false")
        return value
    if sp.kind == "str":
        if not isinstance(value, str):
            bad(f"must be one of {_choices(sp.choices)}" if sp.choices else "must be a string")
        if len(value) > MAX_TEXT:
            raise SceneError(source, key, f"must be at most {MAX_TEXT} characters, got {len(value):,}")
        if sp.choices and value not in sp.choices:
            near = difflib.get_close_matches(value, sp.choices, n=1)
            hint = f" (did you mean '{near[0]}'?)" if near else ""
            raise SceneError(source, key, f"must be one of {_choices(sp.choices)}, got {_show(value)}{hint}")
        return value
    if sp.kind == "int":
        if isinstance(value, bool) or not isinstance(value, int):
            bad(f"must be one of {_choices(sp.choices)}" if sp.choices else f"must be {_range(sp, 'an integer')}")
        if sp.choices and value not in sp.choices:
            bad(f"must be one of {_choices(sp.choices)}")
        _bounds(value, sp, key, source, "an integer")
        return value
    if sp.kind == "float":
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            bad(f"must be {_range(sp, 'a number')}")
        if not _finite(value):
            bad("must be a finite number")
        value = float(value)
        _bounds(value, sp, key, source, "a number")
        _magnitude(value, sp, key, source)
        return value
    if sp.kind == "vector":
        return _vector(value, dim, key, source, sp)
    if sp.kind == "int_list":
        if isinstance(value, int) and not isinstance(value, bool):
            value = [value]
        if not isinstance(value, list) or not value or not all(
                isinstance(v, int) and not isinstance(v, bool) for v in value):
            bad("must be a non-empty list of node indices (integers)")
        return tuple(value)
    if sp.kind == "float_list":
        if not isinstance(value, list) or not value or not all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and _finite(v) for v in value):
            bad("must be a non-empty list of finite numbers")
        for v in value:
            _magnitude(float(v), sp, key, source, shown=value)
        return tuple(float(v) for v in value)
    if sp.kind == "points":
        if not isinstance(value, list) or not value:
            bad(f"must be a list of points, each a list of {dim} numbers")
        return tuple(_vector(p, dim, f"{key}[{i}]", source, sp) for i, p in enumerate(value))
    if sp.kind == "rows":
        ok = isinstance(value, list) and value and all(
            isinstance(row, list) and len(row) == dim + 1 and all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and _finite(v) for v in row) for row in value)
        if not ok:
            bad(f"must be a list of rows, each {dim + 1} finite numbers (t, then one per axis)")
        if len(value) > MAX_PATH_ROWS:
            raise SceneError(source, key, f"must be at most {MAX_PATH_ROWS:,} rows, got {len(value):,}")
        for row in value:
            for v in row:
                _magnitude(float(v), sp, key, source, shown=row)
        return tuple(tuple(float(v) for v in row) for row in value)
    raise AssertionError(sp.kind)


def _vector(value, dim, key, source, sp):
    ok = isinstance(value, list) and len(value) == dim and all(
        isinstance(v, (int, float)) and not isinstance(v, bool) and _finite(v) for v in value)
    if not ok:
        raise SceneError(source, key, f"must be a list of {dim} finite numbers (dimension = {dim}){_unit(sp)}, "
                                      f"got {_show(value)}")
    vector = tuple(float(v) for v in value)
    for v in vector:
        _magnitude(v, sp, key, source, shown=value)
    return vector


def _finite(v) -> bool:
    try:
        return math.isfinite(v)
    except OverflowError:  # an integer beyond the float range
        return False


def _bounds(value, sp: S.Spec, key, source, what):
    low_ok = sp.low is None or (value > sp.low if sp.open_low else value >= sp.low)
    high_ok = sp.high is None or value <= sp.high
    if not (low_ok and high_ok):
        raise SceneError(source, key, f"must be {_range(sp, what)}{_unit(sp)}, got {_show(value)}")


def _magnitude(value: float, sp: S.Spec, key, source, shown: Any = None):
    """Refuse numbers whose products would overflow: |value| <= MAX_MAGNITUDE, and >= MIN_POSITIVE when > 0 is
    required (the products and ratios of a few such numbers stay far inside the float range)."""
    if abs(value) > MAX_MAGNITUDE:
        raise SceneError(source, key, f"must be at most {MAX_MAGNITUDE:g} in magnitude{_unit(sp)} (larger numbers "
                                      f"overflow in products), got {_show(value if shown is None else shown)}")
    if sp.open_low and sp.low == 0 and value < MIN_POSITIVE:
        raise SceneError(source, key, f"must be at least {MIN_POSITIVE:g}{_unit(sp)} (smaller ones make ratios "
                                      f"such as k / m overflow), got {_show(value if shown is None else shown)}")


def _range(sp: S.Spec, what: str) -> str:
    parts = []
    if sp.low is not None:
        parts.append(f"{'>' if sp.open_low else '>='} {sp.low:g}")
    if sp.high is not None:
        parts.append(f"<= {sp.high:g}")
    return f"{what} {' and '.join(parts)}" if parts else what


def _unit(sp: S.Spec) -> str:
    return f" [{sp.unit}]" if sp.unit else ""


def _choices(choices) -> str:
    return ", ".join(repr(c) if isinstance(c, str) else str(c) for c in choices)


def _unknown(key: str, allowed: list[str], what: str) -> str:
    near = difflib.get_close_matches(str(key), allowed, n=1, cutoff=0.6)
    hint = f"did you mean '{near[0]}'? " if near else ""
    return f"unknown key, not {what}; {hint}allowed: {', '.join(allowed)}"


def _show(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
