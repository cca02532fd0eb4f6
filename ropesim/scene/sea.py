"""A scene's ``[sea]`` and ``[waves]``, checked across their keys and completed: the parts they need, what a sea
does not combine with (yet), each kind of wave's own keys, the breaking limit and the component table (inline or
from a CSV file). One rope and a system are checked alike (:mod:`ropesim.scene.loader` calls
:func:`resolve_sea`)."""

from __future__ import annotations

import csv
import math
from dataclasses import replace
from pathlib import Path


from . import schema as S
from .values import MAX_MAGNITUDE, MAX_PATH_ROWS, MAX_SCENE_BYTES, show

KIND_KEYS = {"regular": ("height", "period", "phase"),
             "jonswap": ("significant_height", "peak_period", "gamma", "components", "seed", "frequency_range"),
             "pierson_moskowitz": ("significant_height", "peak_period", "components", "seed", "frequency_range"),
             "table": ("table", "table_file")}
NEEDED = {"regular": ("height", "period"), "jonswap": ("significant_height", "peak_period"),
          "pierson_moskowitz": ("significant_height", "peak_period"), "table": ()}
DEFAULTS = {"phase": 0.0, "seed": 0, "direction": 0.0}   # keys with a schema default: "unused" only when changed
TABLE_COLUMNS = ("amplitude", "frequency", "phase", "direction")
DEFAULT_COMPONENTS = 100
NOT_WITH_A_SEA = {
    "drag": "[drag] is one linear coefficient with no fluid property in it, so nothing says how it changes from "
            "the water below a [sea]'s surface to the air above; use [fluid_drag], which the surface splits",
    "viscous_drag": "[viscous_drag] is one linear coefficient with no fluid property in it, so nothing says how it "
                    "changes from the water below a [sea]'s surface to the air above; use [fluid_drag], which "
                    "the surface splits",
}


def resolve_sea(scene: S.Scene, base_dir: Path, fail) -> S.Scene:
    """The scene with its ``[sea]`` and ``[waves]`` checked and their defaults filled (DNV's gamma, the number of
    components and the frequency range of a spectrum, a table file read into ``table``)."""
    sea, waves = scene.sea, scene.waves
    if waves is not None and sea is None:
        fail("waves", "needs a [sea] table: waves move its free surface (give at least [sea] with its level)")
    if sea is None:
        return scene
    if scene.fluid is None:
        fail("sea", "needs a [fluid] table with the water's density (sea water 1025 kg/m^3)")
    if scene.gravity is None:
        fail("sea", "needs [gravity]: the surface is where the water's weight balances (buoyancy, waves)")
    for key, why in NOT_WITH_A_SEA.items():
        if getattr(scene, key) not in (None, ()):
            fail(key, why)
    _check_bodies(scene, fail)
    depth = _depth(scene, fail)
    if sea.probes is not None:
        _check_probes(scene, fail)
    if waves is not None:
        waves = _resolve_waves(waves, scene.dimension, base_dir, fail)
        _check_breaking(waves, depth, scene.gravity.g, fail)
        scene = replace(scene, waves=waves)
    return scene


def _check_bodies(scene: S.Scene, fail) -> None:
    """A free body under the surface needs the height of its displaced volume (its waterplane area is volume /
    height), unless ``fraction = "moordyn"`` keeps it wholly submerged, as MoorDyn's body is."""
    for i, body in enumerate(scene.rigid_bodies):
        if body.kind != "free" or body.height is not None or scene.sea.fraction == "moordyn":
            continue
        fail(f"bodies.{i}.height", f"missing: free body '{body.id}' under a [sea] needs the height of its "
                                    f"displaced volume [m] (a vertical-walled body centred on its centre of "
                                    f"buoyancy; waterplane area = volume / height), or [sea] fraction = "
                                    f"'moordyn' for MoorDyn's always-submerged body")


def _depth(scene: S.Scene, fail) -> float:
    sea = scene.sea
    if sea.depth is not None:
        return sea.depth
    if scene.seabed is None:
        return math.inf
    depth = sea.level - scene.seabed.height
    if not depth > 0:
        fail("sea.level", f"puts the mean water level at y = {sea.level:g} m, not above the seabed at y = "
                          f"{scene.seabed.height:g} m")
    return depth


def _check_probes(scene: S.Scene, fail) -> None:
    """The probes' domain is the water: wherever the seabed (its plane, sloping along x) lies below the mean
    level, or everywhere without a seabed. A probe on the dry side of the shoreline is refused."""
    bed = scene.seabed
    if bed is None:
        return
    rise = math.tan(math.radians(bed.slope))
    for i, probe in enumerate(scene.sea.probes):
        x = probe[0]
        floor = bed.height + rise * x
        if not floor < scene.sea.level:
            shore = (scene.sea.level - bed.height) / rise if rise else None
            where = (f"the water ends at the shoreline x = {shore:.6g} m; keep x {'<' if rise > 0 else '>'} "
                     f"{shore:.6g} m" if shore is not None else "the seabed is not below the mean level anywhere")
            fail(f"sea.probes[{i}]", f"at x = {x:g} m is outside the sea: the seabed there (y = {floor:.6g} m) is "
                                     f"not below the mean level y = {scene.sea.level:g} m ({where})")


def _resolve_waves(waves: S.Waves, dim: int, base_dir: Path, fail) -> S.Waves:
    kind = waves.kind
    for key in NEEDED[kind]:
        if getattr(waves, key) is None:
            fail(f"waves.{key}", f"missing: kind = '{kind}' needs {', '.join(NEEDED[kind])}")
    for key in sorted({k for keys in KIND_KEYS.values() for k in keys} - set(KIND_KEYS[kind])):
        value = getattr(waves, key)
        if value is not None and value != DEFAULTS.get(key, None):
            fail(f"waves.{key}", f"is not used by kind = '{kind}' (it uses {', '.join(KIND_KEYS[kind])})"
                 + (": a Pierson-Moskowitz sea is a JONSWAP sea with gamma = 1" if key == "gamma" else ""))
    if kind == "table" and waves.direction != 0.0:
        fail("waves.direction", "is not used by kind = 'table': each component gives its own direction")
    if dim == 2:
        _check_planar(waves.direction, "waves.direction", fail)
    if kind == "jonswap" and waves.gamma is None:
        from ..model.waves import dnv_gamma

        waves = replace(waves, gamma=dnv_gamma(waves.significant_height, waves.peak_period))
    if kind in ("jonswap", "pierson_moskowitz"):
        waves = replace(waves, components=waves.components or DEFAULT_COMPONENTS,
                        frequency_range=_frequency_range(waves, fail))
    if kind == "table":
        waves = _resolve_table(waves, dim, base_dir, fail)
    return waves


def _check_planar(direction: float, key: str, fail) -> None:
    if direction % 180.0 != 0.0:
        fail(key, f"must be 0 (along +x) or 180 (along -x) in 2-D, got {direction:g} deg; waves in other "
                  f"directions need dimension = 3")


def _frequency_range(waves: S.Waves, fail) -> tuple:
    from ..model.waves import default_range

    if waves.frequency_range is None:
        return default_range(waves.peak_period)
    lo_hi = waves.frequency_range
    if len(lo_hi) != 2 or not 0 < lo_hi[0] < lo_hi[1]:
        fail("waves.frequency_range", f"must be two angular frequencies, the lowest and the highest, 0 < low < high "
                                      f"[rad/s], got {show(list(lo_hi))}")
    return lo_hi


def _resolve_table(waves: S.Waves, dim: int, base_dir: Path, fail) -> S.Waves:
    if waves.table is None and waves.table_file is None:
        fail("waves.table", "missing: kind = 'table' needs its components, inline (table) or from a CSV file "
                            "(table_file)")
    if waves.table is not None and waves.table_file is not None:
        fail("waves.table", "give the components either inline (table) or as a CSV file (table_file), not both")
    rows = waves.table if waves.table is not None else read_table(waves.table_file, base_dir, fail)
    key = "waves.table" if waves.table is not None else "waves.table_file"
    for i, (amplitude, omega, _, direction) in enumerate(rows):
        if not amplitude > 0 or not omega > 0:
            fail(f"{key}", f"row {i + 1}: the amplitude and the angular frequency must be > 0, got "
                           f"{show(list(rows[i]))}")
        if dim == 2:
            _check_planar(direction, f"{key} (row {i + 1}, direction)", fail)
    return replace(waves, table=tuple(rows), table_file=None)


def read_table(name: str, base_dir: Path, fail) -> tuple:
    """A component table's rows from a CSV file whose header names its columns: amplitude [m], frequency (the
    angular frequency) [rad/s], phase [deg] and direction [deg], in any order (other columns are ignored)."""
    key = "waves.table_file"
    path = Path(name)
    path = path if path.is_absolute() else base_dir / path
    try:
        size = path.stat().st_size
        if size > MAX_SCENE_BYTES and path.is_file():
            fail(key, f"{path} is {size / 1e6:.3g} MB; a component table is at most {MAX_PATH_ROWS:,} rows")
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        fail(key, f"cannot read {path} ({exc.__class__.__name__})")
    lines = [row for row in csv.reader(text.splitlines()) if row and not row[0].lstrip().startswith("#")]
    if not lines:
        fail(key, f"{path} is empty; it needs a header naming {', '.join(TABLE_COLUMNS)} and a row per component")
    header = [name.strip().lower() for name in lines[0]]
    missing = [c for c in TABLE_COLUMNS if c not in header]
    if missing:
        fail(key, f"{path} has no {', '.join(repr(m) for m in missing)} column{'s' * (len(missing) > 1)}: its "
                  f"header must name {', '.join(TABLE_COLUMNS)} (amplitude [m], angular frequency [rad/s], phase "
                  f"[deg], direction [deg]); it names {show(lines[0])}")
    where = [header.index(c) for c in TABLE_COLUMNS]
    rows = []
    for number, row in enumerate(lines[1:], start=2):
        if len(rows) == MAX_PATH_ROWS:
            fail(key, f"{path}: more than {MAX_PATH_ROWS:,} components")
        try:
            values = tuple(float(row[c]) for c in where)
        except (ValueError, IndexError):
            fail(key, f"{path}, row {number}: needs a number in each of {', '.join(TABLE_COLUMNS)}, got {show(row)}")
        if not all(math.isfinite(v) and abs(v) <= MAX_MAGNITUDE for v in values):
            fail(key, f"{path}, row {number}: numbers must be finite and at most {MAX_MAGNITUDE:g}, got {show(row)}")
        rows.append(values)
    if not rows:
        fail(key, f"{path} has a header but no components")
    return tuple(rows)


def _check_breaking(waves: S.Waves, depth: float, g: float, fail) -> None:
    """No wave steeper than the breaking limit H / L = 1/7: a regular wave, a spectrum's significant wave at its
    peak period, or any component of a table."""
    from ..model.waves import BREAKING_STEEPNESS, components_of, steepest, wave_number

    where = "in deep water" if math.isinf(depth) else f"in {depth:g} m of water"
    if waves.kind in ("jonswap", "pierson_moskowitz"):
        k = float(wave_number(2 * math.pi / waves.peak_period, depth, g))
        steep, length = waves.significant_height * k / (2 * math.pi), 2 * math.pi / k
        if steep > BREAKING_STEEPNESS:
            fail("waves.significant_height", f"Hs / L = {steep:.3g} is above the breaking limit 1/7 (L = "
                                             f"{length:.4g} m at Tp = {waves.peak_period:g} s {where}): lower Hs "
                                             f"below {length / 7:.4g} m or lengthen Tp")
        return
    comps = components_of(waves, depth, g)
    steep, j = steepest(comps)
    if steep > BREAKING_STEEPNESS:
        length = 2 * math.pi / comps.k[j]
        period = 2 * math.pi / comps.omega[j]
        if waves.kind == "regular":
            fail("waves.height", f"H / L = {steep:.3g} is above the breaking limit 1/7 (L = {length:.4g} m at T = "
                                 f"{period:g} s {where}): lower H below {length / 7:.4g} m or lengthen T")
        fail("waves.table", f"row {j + 1}: H / L = 2 a / L = {steep:.3g} is above the breaking limit 1/7 (L = "
                            f"{length:.4g} m at w = {comps.omega[j]:g} rad/s {where})")
