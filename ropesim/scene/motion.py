"""Prescribed motions, completed and checked the same way wherever a scene gives one: a rope's ``[[driven]]``
nodes, a system's driven points (one number per axis) and driven rigid bodies (one per degree of freedom:
translations in m, then rotations in degrees).

A motion is a constant velocity, a sinusoid per axis (amplitude, period, phase) and a piecewise-linear path of
displacements (a CSV file, read here into the inline ``path_table``, so a resolved scene carries its path)."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

from .values import MAX_MAGNITUDE, MAX_PATH_ROWS, MAX_SCENE_BYTES, show


def complete_motion(drive, key: str, labels: tuple[str, ...], dim: int, base_dir: Path, t_end: float, fail,
                    what: str = "node"):
    """``drive`` (any dataclass with velocity, amplitude, period, phase, path and path_table) with its defaults
    filled (no velocity: still; no phase: 0 where there is an amplitude), its sinusoid complete and its path
    read and checked. ``labels`` name the path's columns after t (dx, dy, ... or a body's dx ... rz); ``key`` is
    the entry's dotted key for refusals; ``what`` the thing moved ("node", "point", "body")."""
    per = "axis" if len(labels) == dim else "degree of freedom"
    drive = replace(drive, velocity=drive.velocity if drive.velocity is not None else (0.0,) * dim)
    if drive.amplitude is not None:
        if drive.period is None:
            fail(f"{key}.period", f"missing: a sinusoid needs its period per {per} (with amplitude)")
        if any(a != 0.0 and not T > 0.0 for a, T in zip(drive.amplitude, drive.period)):
            fail(f"{key}.period", f"must be > 0 on every {per} that moves, got {list(drive.period)}")
        drive = replace(drive, phase=drive.phase if drive.phase is not None else (0.0,) * len(labels))
    elif drive.period is not None or drive.phase is not None:
        fail(f"{key}.{'period' if drive.period is not None else 'phase'}", "is used only with amplitude")
    if drive.path is not None and drive.path_table is not None:
        fail(f"{key}.path_table", "give the path either as a CSV file (path) or inline (path_table), not both")
    if drive.path is not None:
        rows = read_path(drive.path, base_dir, labels, t_end, f"{key}.path", fail, what)
        drive = replace(drive, path=None, path_table=rows)
    if drive.path_table is not None:
        check_path(drive.path_table, labels, t_end, f"{key}.path_table", "", fail, what)
    return drive


def read_path(name: str, base_dir: Path, labels: tuple[str, ...], t_end: float, key: str, fail,
              what: str = "node") -> tuple:
    """The CSV path's rows (t, then one number per label), checked like an inline ``path_table``; the file name
    is taken relative to the scene file's folder."""
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
    columns = len(labels) + 1
    units = "s, m, deg" if any(label.startswith("r") for label in labels) else "s, m"
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
            fail(key, f"{path}, line {number}: not numbers: {show(row)}")
        if len(values) != columns or not all(math.isfinite(v) for v in values):
            fail(key, f"{path}, line {number}: needs {columns} finite numbers (t, {', '.join(labels)}), "
                      f"got {show(row)}")
        if any(abs(v) > MAX_MAGNITUDE for v in values):
            fail(key, f"{path}, line {number}: numbers must be at most {MAX_MAGNITUDE:g} in magnitude ({units}), as "
                      f"in a scene file; got {show(row)}")
        rows.append(tuple(values))
    check_path(rows, labels, t_end, key, f"{path}: ", fail, what)
    return tuple(rows)


def check_path(rows, labels: tuple[str, ...], t_end: float, key: str, where: str, fail, what: str = "node") -> None:
    """At least two rows, times increasing from at most 0 to at least t_end, no displacement at t = 0."""
    if len(rows) < 2:
        fail(key, f"{where}needs at least two rows of t, {', '.join(labels)}")
    times = [r[0] for r in rows]
    for a, b in zip(times, times[1:]):
        if not b > a:
            fail(key, f"{where}times must increase, but {b:g} s follows {a:g} s")
    if times[0] > 0.0 or times[-1] < t_end:
        fail(key, f"{where}covers t = {times[0]:g} to {times[-1]:g} s, but the run goes from 0 to {t_end:g} s")
    start = [float(v) for v in interpolate(rows, 0.0)]
    if any(abs(v) > 1e-12 for v in start):
        fail(key, f"{where}the displacement at t = 0 is {start}, not zero (the path moves the {what} from where "
                  f"the scene starts it)")


def interpolate(rows, t: float) -> tuple:
    """Each column after t, interpolated linearly at time ``t``."""
    import numpy as np

    table = np.asarray(rows)
    return tuple(np.interp(t, table[:, 0], table[:, c]) for c in range(1, table.shape[1]))
