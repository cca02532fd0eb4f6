"""One TOML value read against its :class:`~ropesim.scene.schema.Spec`, and the limits every number obeys.

Each refusal is a :class:`SceneError` naming the file and the key: ``t.toml: rope.mass: must be a number > 0
[kg], got -1``. The loader (:mod:`ropesim.scene.loader`) and a system's checks (:mod:`ropesim.scene.system`)
both read values through :func:`parse_value`.
"""

from __future__ import annotations

import difflib
import math
from typing import Any

from . import schema as S
from .errors import SceneError

MAX_MAGNITUDE = 1e12  # in SI units: 7 AU, 30 000 years, a 1e12 N/m spring; no rope scene needs more
MIN_POSITIVE = 1e-12  # the least value of a quantity that must be > 0, so that ratios such as k / m stay finite
MAX_SCENE_BYTES = 16 * 2 ** 20   # a scene file is a few kB; an inline path table of 100 000 rows about 5 MB
MAX_TEXT = 1000       # characters of any text value (a description is one line)
MAX_NAME_BYTES = 200  # a scene's name names its run folder; 255 bytes is the usual file-name limit
MAX_PATH_ROWS = 100_000  # rows of a driven node's path (a 3-hour path every 0.1 s); scene.toml stores them
INERTIA_RATIO = 1e-12  # a tensor's least principal moment must exceed this fraction of its largest (rounding)


def count_of(kind: str, dim: int) -> int:
    """How many numbers a vector-like kind holds in ``dim`` dimensions: a vector one per axis, the angles one per
    axis of rotation (3 in 3-D, 1 about z in 2-D), the degrees of freedom of a rigid body (6 in 3-D, 3 in 2-D)."""
    rotations = 3 if dim == 3 else 1
    return {"vector": dim, "angles": rotations, "dofs": dim + rotations}[kind]


def dof_labels(dim: int) -> tuple[str, ...]:
    """The degrees of freedom of a rigid body as a path's columns name them: translations, then rotations."""
    return ("dx", "dy", "dz", "rx", "ry", "rz") if dim == 3 else ("dx", "dy", "rz")


_WHAT = {   # what each number of a vector-like kind is, for the refusal's "(...)"
    "vector": lambda dim: f"dimension = {dim}",
    "angles": lambda dim: f"one angle per axis of rotation, {'x, y, z' if dim == 3 else 'z'}: dimension = {dim}",
    "dofs": lambda dim: (f"one per degree of freedom, {', '.join(dof_labels(dim))}: translations, then rotations; "
                         f"dimension = {dim}"),
}


def parse_value(value: Any, sp: S.Spec, key: str, source: str, dim: int):
    """``value`` checked against ``sp`` and converted (ints to floats where numbers are meant, lists to tuples)."""
    def bad(what):
        raise SceneError(source, key, f"{what}{unit_of(sp)}, got {show(value)}")

    if sp.kind == "bool":
        if not isinstance(value, bool):
            bad("must be true or false")
        return value
    if sp.kind == "str":
        if not isinstance(value, str):
            bad(f"must be one of {choices_text(sp.choices)}" if sp.choices else "must be a string")
        if len(value) > MAX_TEXT:
            raise SceneError(source, key, f"must be at most {MAX_TEXT} characters, got {len(value):,}")
        if sp.choices and value not in sp.choices:
            near = difflib.get_close_matches(value, sp.choices, n=1)
            hint = f" (did you mean '{near[0]}'?)" if near else ""
            raise SceneError(source, key, f"must be one of {choices_text(sp.choices)}, got {show(value)}{hint}")
        return value
    if sp.kind == "int":
        if isinstance(value, bool) or not isinstance(value, int):
            bad(f"must be one of {choices_text(sp.choices)}" if sp.choices else
                f"must be {range_text(sp, 'an integer')}")
        if sp.choices and value not in sp.choices:
            bad(f"must be one of {choices_text(sp.choices)}")
        check_bounds(value, sp, key, source, "an integer")
        return value
    if sp.kind == "float":
        if not is_number(value):
            bad(f"must be {range_text(sp, 'a number')}")
        if not is_finite(value):
            bad("must be a finite number")
        value = float(value)
        check_bounds(value, sp, key, source, "a number")
        check_magnitude(value, sp, key, source)
        return value
    if sp.kind in ("vector", "angles", "dofs"):
        n = count_of(sp.kind, dim)
        if n == 1 and is_number(value):   # one angle in 2-D may be written bare
            value = [value]
        return numbers_of(value, n, key, source, sp, _WHAT[sp.kind](dim))
    if sp.kind == "inertia":
        return _inertia(value, sp, key, source, dim)
    if sp.kind == "int_list":
        if isinstance(value, int) and not isinstance(value, bool):
            value = [value]
        if not isinstance(value, list) or not value or not all(
                isinstance(v, int) and not isinstance(v, bool) for v in value):
            bad("must be a non-empty list of node indices (integers)")
        return tuple(value)
    if sp.kind == "float_list":
        if not isinstance(value, list) or not value or not all(is_number(v) and is_finite(v) for v in value):
            bad("must be a non-empty list of finite numbers")
        for v in value:
            check_magnitude(float(v), sp, key, source, shown=value)
        return tuple(float(v) for v in value)
    if sp.kind == "points":
        if not isinstance(value, list) or not value:
            bad(f"must be a list of points, each a list of {dim} numbers")
        return tuple(vector_of(p, dim, f"{key}[{i}]", source, sp) for i, p in enumerate(value))
    if sp.kind == "horizontal":
        n = dim - 1
        if isinstance(value, list) and n == 1:   # 2-D: x alone may be written bare
            value = [[v] if is_number(v) else v for v in value]
        if not isinstance(value, list) or not value or len(value) > MAX_PATH_ROWS:
            bad(f"must be a list of horizontal positions, each {'x' if n == 1 else 'a list of 2 numbers'} "
                f"(at most {MAX_PATH_ROWS:,})")
        return tuple(numbers_of(p, n, f"{key}[{i}]", source, sp, "x" if n == 1 else "the horizontal axes")
                     for i, p in enumerate(value))
    if sp.kind == "wave_rows":
        ok = isinstance(value, list) and value and all(isinstance(row, list) for row in value)
        if not ok:
            bad("must be a list of rows, each 4 finite numbers (amplitude, angular frequency, phase, direction)")
        if len(value) > MAX_PATH_ROWS:
            raise SceneError(source, key, f"must be at most {MAX_PATH_ROWS:,} rows, got {len(value):,}")
        return tuple(numbers_of(row, 4, f"{key}[{i}]", source, sp, "amplitude, angular frequency, phase, direction")
                     for i, row in enumerate(value))
    if sp.kind in ("rows", "dof_rows"):
        n, what = (dim, "one per axis") if sp.kind == "rows" else (count_of("dofs", dim), "one per degree of freedom")
        ok = isinstance(value, list) and value and all(
            isinstance(row, list) and len(row) == n + 1 and all(is_number(v) and is_finite(v) for v in row)
            for row in value)
        if not ok:
            bad(f"must be a list of rows, each {n + 1} finite numbers (t, then {what})")
        if len(value) > MAX_PATH_ROWS:
            raise SceneError(source, key, f"must be at most {MAX_PATH_ROWS:,} rows, got {len(value):,}")
        for row in value:
            for v in row:
                check_magnitude(float(v), sp, key, source, shown=row)
        return tuple(tuple(float(v) for v in row) for row in value)
    raise AssertionError(sp.kind)


def vector_of(value, dim, key, source, sp):
    """A list of ``dim`` finite numbers (a position, a velocity)."""
    return numbers_of(value, dim, key, source, sp, f"dimension = {dim}")


def numbers_of(value, n: int, key, source, sp, what: str) -> tuple:
    """A list of ``n`` finite numbers, each within the magnitude limits; ``what`` says what they are."""
    ok = isinstance(value, list) and len(value) == n and all(is_number(v) and is_finite(v) for v in value)
    if not ok:
        got = f" ({len(value)} numbers)" if isinstance(value, list) and len(value) != n else ""
        raise SceneError(source, key, f"must be a list of {n} finite number{'s' * (n != 1)} ({what}){unit_of(sp)}, "
                                      f"got {show(value)}{got}")
    numbers = tuple(float(v) for v in value)
    for v in numbers:
        check_magnitude(v, sp, key, source, shown=value)
    return numbers


def _inertia(value, sp: S.Spec, key, source, dim: int) -> tuple:
    """Principal moments (3-D: Ixx Iyy Izz; 2-D: Izz), each > 0, or in 3-D the whole tensor as its six
    entries Ixx Iyy Izz Ixy Ixz Iyz, symmetric by construction and required positive definite."""
    if dim == 3:
        if not (isinstance(value, list) and len(value) in (3, 6)):
            raise SceneError(source, key, f"must be a list of 3 principal moments (Ixx, Iyy, Izz) or the tensor's 6 "
                                          f"entries (Ixx, Iyy, Izz, Ixy, Ixz, Iyz){unit_of(sp)}, got {show(value)}")
        moments = numbers_of(value, len(value), key, source, sp,
                             "Ixx, Iyy, Izz" if len(value) == 3 else "Ixx, Iyy, Izz, Ixy, Ixz, Iyz")
    else:
        moments = numbers_of([value] if is_number(value) else value, 1, key, source, sp,
                             "the moment of inertia Izz about the axis out of the plane: dimension = 2")
    if any(not m >= MIN_POSITIVE for m in moments[:3]):
        raise SceneError(source, key, f"must have moments of inertia Ixx, Iyy, Izz of at least {MIN_POSITIVE:g}"
                                      f"{unit_of(sp)} (a body resists turning about every axis), got {show(value)}"
                         if dim == 3 else f"must be at least {MIN_POSITIVE:g}{unit_of(sp)}, got {show(value)}")
    if len(moments) == 6:
        import numpy as np

        xx, yy, zz, xy, xz, yz = moments
        principal = np.linalg.eigvalsh(np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]))
        if not principal[0] > max(MIN_POSITIVE, INERTIA_RATIO * principal[-1]):
            raise SceneError(source, key, f"is not positive definite: the tensor [[Ixx, Ixy, Ixz], [Ixy, Iyy, Iyz], "
                                          f"[Ixz, Iyz, Izz]] has principal moments "
                                          f"{', '.join(f'{p:.6g}' for p in principal)}{unit_of(sp)}; all must be > 0 "
                                          f"(products of inertia too large for the moments)")
    return moments


def check_name(name: str, key: str, fail, what: str = "a plain folder name (runs go to runs/<name>/)") -> None:
    """A name that may name a folder or a file: printable, no / or \\, not '.' or '..', at most MAX_NAME_BYTES."""
    if not name or name in (".", "..") or "/" in name or "\\" in name or not name.isprintable():
        fail(key, f"must be {what}: printable, without / or \\, not '.' or '..'; got {show(name)}")
    if len(name.encode("utf-8")) > MAX_NAME_BYTES:
        fail(key, f"must be at most {MAX_NAME_BYTES} bytes in UTF-8 (it names files and folders), got "
                  f"{len(name.encode('utf-8'))}")


def is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def is_finite(v) -> bool:
    try:
        return math.isfinite(v)
    except OverflowError:  # an integer beyond the float range
        return False


def check_bounds(value, sp: S.Spec, key, source, what):
    low_ok = sp.low is None or (value > sp.low if sp.open_low else value >= sp.low)
    high_ok = sp.high is None or value <= sp.high
    if not (low_ok and high_ok):
        raise SceneError(source, key, f"must be {range_text(sp, what)}{unit_of(sp)}, got {show(value)}")


def check_magnitude(value: float, sp: S.Spec, key, source, shown: Any = None):
    """Refuse numbers whose products would overflow: |value| <= MAX_MAGNITUDE, and >= MIN_POSITIVE when > 0 is
    required (the products and ratios of a few such numbers stay far inside the float range)."""
    if abs(value) > MAX_MAGNITUDE:
        raise SceneError(source, key, f"must be at most {MAX_MAGNITUDE:g} in magnitude{unit_of(sp)} (larger numbers "
                                      f"overflow in products), got {show(value if shown is None else shown)}")
    if sp.open_low and sp.low == 0 and value < MIN_POSITIVE:
        raise SceneError(source, key, f"must be at least {MIN_POSITIVE:g}{unit_of(sp)} (smaller ones make ratios "
                                      f"such as k / m overflow), got {show(value if shown is None else shown)}")


def range_text(sp: S.Spec, what: str) -> str:
    parts = []
    if sp.low is not None:
        parts.append(f"{'>' if sp.open_low else '>='} {sp.low:g}")
    if sp.high is not None:
        parts.append(f"<= {sp.high:g}")
    return f"{what} {' and '.join(parts)}" if parts else what


def unit_of(sp: S.Spec) -> str:
    return f" [{sp.unit}]" if sp.unit else ""


def choices_text(choices) -> str:
    return ", ".join(repr(c) if isinstance(c, str) else str(c) for c in choices)


def unknown_key(key: str, allowed: list[str], what: str) -> str:
    near = difflib.get_close_matches(str(key), allowed, n=1, cutoff=0.6)
    hint = f"did you mean '{near[0]}'? " if near else ""
    return f"unknown key, not {what}; {hint}allowed: {', '.join(allowed)}"


def show(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
