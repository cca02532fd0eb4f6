"""Planning a sweep: the ``--set KEY=VALUES`` axes, their values, and every combination resolved to a scene.

A key's values are a list (``0.1,0.4,1.0``), an inclusive range ``start:stop:count`` (evenly spaced as
numpy.linspace; whole numbers for integer keys, inner values to 12 significant digits) or a single value,
which then applies to every run. Every combination is resolved to a complete scene before anything runs, so
a bad key or value stops the sweep with one line (:class:`SweepError`).
"""

from __future__ import annotations

import itertools
import math
import re
import tomllib
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from ..scene import schema as S
from ..scene.loader import SceneError, load_scene, parse_override, scene_from_toml


class SweepError(ValueError):
    """A sweep that cannot start (a bad --set, scene, folder or figure); ``str()`` is one line."""


@dataclass(frozen=True)
class Axis:
    """One ``--set KEY=VALUES``: the dotted key and its values as TOML-typed Python values."""

    key: str
    values: tuple

    @property
    def swept(self) -> bool:
        return len(self.values) > 1


@dataclass(frozen=True)
class Point:
    """One combination: its folder name, swept values, the ``--set`` items making it, and the resolved scene."""

    name: str
    params: dict
    sets: tuple[str, ...]
    scene_toml: str


# ----------------------------------------------------------------------------------- --set values


def parse_axis(item: str) -> Axis:
    """``KEY=VALUES`` -> :class:`Axis`. VALUES: ``a,b,c``, ``start:stop:count`` or one value."""
    key, sep, text = item.partition("=")
    key, text = key.strip(), text.strip()
    if not sep or not key or not text:
        raise SweepError(f"--set {item!r}: expected KEY=VALUES, e.g. drag.b=0.1,0.4,1.0 (a list), "
                         f"drag.b=0.05:1.5:10 (start:stop:count, inclusive) or integrator.t_end=20")
    values = _range(key, text)
    if values is None:
        values = _list(text)
    return Axis(key, tuple(values))


def _toml(text: str) -> Any:
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except RecursionError:
        raise SweepError(f"--set value {text[:40]}...: nested too deeply to read") from None


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _range(key: str, text: str) -> list | None:
    """The values of ``start:stop:count``, or None if ``text`` is not of that form."""
    parts = text.split(":")
    if len(parts) != 3:
        return None
    try:
        start, stop, count = (_toml(p.strip()) for p in parts)
    except tomllib.TOMLDecodeError:
        return None
    if not (_is_number(start) and _is_number(stop) and _is_number(count)):
        return None
    if not isinstance(count, int) or count < 1:
        raise SweepError(f"--set {key}={text}: the count in start:stop:count must be a whole number >= 1, "
                         f"got {parts[2].strip()}")
    import numpy as np

    values = np.linspace(start, stop, count)
    if _spec_kind(key) == "int":
        ints = [int(round(v)) for v in values]
        if len(set(ints)) < len(ints):
            raise SweepError(f"--set {key}={text}: {key} is an integer and this range repeats whole numbers "
                             f"({', '.join(map(str, ints))}); use fewer values or a wider range")
        return ints
    # Inner values to 12 significant digits, so 0:1.5:16 steps by 0.1 and not to 0.30000000000000004.
    return [float(start)] + [float(f"{v:.12g}") for v in values[1:-1]] + ([float(stop)] if count > 1 else [])


def _list(text: str) -> list:
    """``a,b,c`` as TOML values (so ``[1,0],[2,0]`` is two vectors); bare words are strings."""
    try:
        return list(_toml(f"[{text}]"))
    except tomllib.TOMLDecodeError:
        return [parse_override(f"v={part}")[1] for part in text.split(",")]


def key_spec(key: str) -> S.Spec | None:
    """The schema's :class:`Spec` (kind, doc, unit) of a dotted scene key, or None if it names no single key."""
    parts = key.split(".")
    if len(parts) == 1:
        return S.TOP_LEVEL_SCALARS.get(parts[0])
    head, rest = parts[0], parts[1:]
    if head in S.ARRAYS_OF_TABLES:
        classes = [S.ARRAYS_OF_TABLES[head]]
        rest = rest[1:] if rest[0].isdigit() else rest
    elif head == "initial":
        classes = list(S.INITIAL_SHAPES.values())
    elif S.TABLES.get(head) is not None:
        classes = [S.TABLES[head]]
    else:
        return None
    if len(rest) != 1:
        return None
    for cls in classes:
        for f in fields(cls):
            if f.name == rest[0] and "spec" in f.metadata:
                return f.metadata["spec"]
    return None


def _spec_kind(key: str) -> str | None:
    """The schema kind ("int", "float", ...) of a dotted scene key, or None if it names no single key."""
    spec = key_spec(key)
    return spec.kind if spec else None


def toml_value(value) -> str:
    """A value as TOML text on one line (floats exactly, as Python's shortest repr)."""
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        import tomli_w

        return tomli_w.dumps({"v": value})[len("v = "):].rstrip("\n")
    return repr(value)


def _label(value, exact: bool) -> str:
    if isinstance(value, (list, tuple)):
        return ",".join(_label(v, exact) for v in value)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value) if exact else f"{value:.6g}"
    return str(value)


def _folder_names(axes: list[Axis], combos: list[tuple]) -> list[str]:
    """Folder names from the swept values, short (6 significant digits) unless that makes two the same."""
    swept = [i for i, a in enumerate(axes) if a.swept]
    if not swept:
        return ["run"] * len(combos)
    for exact in (False, True):
        names = ["_".join(f"{axes[i].key}={_label(combo[i], exact)}" for i in swept) for combo in combos]
        names = [re.sub(r"[^A-Za-z0-9._=,+-]", "-", n) for n in names]
        if len(set(names)) == len(names):
            return names
    raise SweepError("two combinations give the same run folder name; give each value a distinct spelling")


# ------------------------------------------------------------------------------------- planning


MAX_RUNS = 100_000   # combinations in one sweep; more is a typo in a range (or a week of computing): split it


def parse_axes(sets: list[str]) -> list[Axis]:
    """The ``--set`` items as axes, each key once, at most MAX_RUNS combinations; raises :class:`SweepError`."""
    axes = [parse_axis(item) for item in sets]
    seen = set()
    for axis in axes:
        if axis.key in seen:
            raise SweepError(f"--set {axis.key}: given twice; list all its values in one --set")
        seen.add(axis.key)
    count = math.prod(len(a.values) for a in axes)
    if count > MAX_RUNS:
        raise SweepError(f"--set: {count:,} combinations; a sweep runs at most {MAX_RUNS:,} (split it into several "
                         f"sweeps, or use fewer values)")
    return axes


def plan(scene_file: str | Path, sets: list[str], on_point=None) -> tuple[S.Scene, list[Axis], list[Point]]:
    """Parse the ``--set`` items and resolve every combination to a scene; raises :class:`SweepError`.

    Returns the scene with the single values applied, the axes in the order given, and one point per
    combination in product order (the first key varies slowest). ``on_point(i, n)`` is told of each point
    resolved (planning 10^4 points takes seconds).
    """
    axes = parse_axes(sets)
    fixed = [f"{a.key}={toml_value(a.values[0])}" for a in axes if not a.swept]
    try:
        base = load_scene(scene_file, fixed)
    except SceneError as exc:
        raise SweepError(str(exc)) from None
    text = Path(scene_file).read_text(encoding="utf-8")
    combos = list(itertools.product(*(a.values for a in axes)))
    names = _folder_names(axes, combos)
    from ..scene.schema import scene_to_toml

    points = []
    for combo, name in zip(combos, names):
        sets_here = tuple(f"{a.key}={toml_value(v)}" for a, v in zip(axes, combo))
        try:
            scene = scene_from_toml(text, source=str(scene_file), default_name=Path(scene_file).stem,
                                    overrides=sets_here)
        except SceneError as exc:
            raise SweepError(str(exc)) from None
        params = {a.key: v for a, v in zip(axes, combo) if a.swept}
        points.append(Point(name=name, params=params, sets=sets_here, scene_toml=scene_to_toml(scene)))
        if on_point is not None:
            on_point(len(points), len(combos))
    return base, axes, points


def _numeric_axis(axis: Axis) -> bool:
    return all(_is_number(v) for v in axis.values)



