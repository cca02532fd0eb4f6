"""Parameter sweeps: one scene run over the Cartesian product of ``--set`` values, in parallel, resumable.

``ropesim sweep SCENE --set drag.b=0.05:1.5:10 --set rope.nodes=21,41`` runs every combination. A key's
values are a list (``0.1,0.4,1.0``), an inclusive range ``start:stop:count`` (evenly spaced as numpy.linspace;
whole numbers for integer keys, inner values to 12 significant digits) or a single value, which then
applies to every run.

Every combination is resolved to a complete scene before anything runs, so a bad key or value stops the sweep
with one line. Each run is the same :func:`ropesim.run.simulate` that ``ropesim run`` calls, in a process of
its own (or on a Dask cluster, :mod:`ropesim.sweep_dask`), into ``DIR/<key=value_...>/``. The table
``DIR/results.csv`` lists each run's swept values, status and error, then its ``summary.json`` flattened
(nested keys joined by dots: ``final_energy_J.total``, ``towed.top_angle_deg``,
``shooter.mean_loop_inclination_deg``, ...), one row per combination in the order of the product.

Rerun, a sweep resumes: a run folder whose summary says completed and whose scene.toml equals the resolved
scene is kept; any other (crashed, interrupted, blown up, or made from other parameters) runs again.
"""

from __future__ import annotations

import csv
import io
import itertools
import json
import math
import multiprocessing
import os
import re
import signal
import tomllib
from contextlib import closing
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator

from ..scene import schema as S
from ..scene.loader import SceneError, load_scene, parse_override, scene_from_toml
from ..io.trajectory import SCENE, SUMMARY, TRAJECTORY, write_text_atomic

RESULTS = "results.csv"
FIXED_COLUMNS = ("run", "status", "error")
TIMING_COLUMNS = ("wall_time_s", "compile_time_s", "steps_per_second", "node_steps_per_second")
ERROR = "error"  # status of a run whose process raised instead of returning a summary


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


@dataclass
class SweepResult:
    """What a sweep did: one row per combination (product order), where the table and plots went."""

    rows: list[dict]
    csv_path: Path
    swept: list[str]
    plots: list[Path] = field(default_factory=list)
    ran: int = 0
    skipped: int = 0
    interrupted: bool = False

    @property
    def failed(self) -> list[dict]:
        return [r for r in self.rows if r["status"] != "completed"]


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
    return tomllib.loads(f"v = {text}")["v"]


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


def plan(scene_file: str | Path, sets: list[str]) -> tuple[S.Scene, list[Axis], list[Point]]:
    """Parse the ``--set`` items and resolve every combination to a scene; raises :class:`SweepError`.

    Returns the scene with the single values applied, the axes in the order given, and one point per
    combination in product order (the first key varies slowest).
    """
    axes = [parse_axis(item) for item in sets]
    seen = set()
    for axis in axes:
        if axis.key in seen:
            raise SweepError(f"--set {axis.key}: given twice; list all its values in one --set")
        seen.add(axis.key)
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
    return base, axes, points


def is_finished(folder: Path, scene_toml: str) -> bool:
    """True when ``folder`` holds a completed run of exactly this resolved scene."""
    try:
        summary = json.loads((folder / SUMMARY).read_text(encoding="utf-8"))
        scene = (folder / SCENE).read_text(encoding="utf-8")
    except (OSError, ValueError):
        return False
    return summary.get("status") == "completed" and scene == scene_toml and (folder / TRAJECTORY).is_file()


# -------------------------------------------------------------------------------------- running


def run_point(scene_toml: str, folder: str) -> dict:
    """Run one resolved scene into ``folder``, exactly as ``ropesim run`` does; returns its summary."""
    from ..run import simulate

    scene = scene_from_toml(scene_toml, source=str(Path(folder) / SCENE))
    return simulate(scene, folder).summary


def run_point_safely(scene_toml: str, folder: str) -> tuple[dict | None, str]:
    """:func:`run_point` in a worker: (summary, "") or (None, the error in one line).

    The error travels as text because not every exception survives pickling back from a worker process.
    """
    try:
        return run_point(scene_toml, folder), ""
    except Exception as exc:  # a run's own failure is recorded in the table; the sweep goes on
        return None, describe(exc)


def describe(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {' '.join(str(exc).split())}"


def _ignore_sigint() -> None:
    """Worker start-up: Ctrl-C reaches a worker only while it integrates, where the run stops cleanly."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


Outcome = tuple[Point, dict | None, str]  # the point, its summary (None if it raised), the error text


def run_local(todo: list[tuple[Point, Path]], jobs: int) -> Iterator[Outcome]:
    """Run points in a pool of ``jobs`` fresh processes; yields each outcome as it finishes.

    Closing the generator early (Ctrl-C) cancels the runs not yet started and waits for those in progress,
    which saw the same Ctrl-C and stop at their next chunk, keeping what they computed.
    """
    context = multiprocessing.get_context("spawn")
    pool = ProcessPoolExecutor(max_workers=jobs, mp_context=context, initializer=_ignore_sigint)
    futures = {pool.submit(run_point_safely, p.scene_toml, str(folder)): p for p, folder in todo}
    try:
        for future in as_completed(futures):
            yield _outcome(futures[future], future.result)
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _outcome(point: Point, result: Callable[[], tuple[dict | None, str]]) -> Outcome:
    """The outcome of a finished future; a worker that died (killed, out of memory) counts as an error too."""
    try:
        summary, error = result()
    except Exception as exc:
        summary, error = None, describe(exc)
    return point, summary, error


# ---------------------------------------------------------------------------------------- table


def flatten(summary: dict, prefix: str = "") -> dict:
    """Nested summary keys joined by dots: {"towed": {"top_angle_deg": 3}} -> {"towed.top_angle_deg": 3}."""
    out = {}
    for key, value in summary.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(flatten(value, f"{name}."))
        else:
            out[name] = value
    return out


def make_row(point: Point, summary: dict | None, error: str) -> dict:
    """One table row: run name, swept values, status and error, then the flattened summary."""
    row: dict = {"run": point.name, **point.params}
    if summary is None:
        row.update(status=ERROR, error=error)
        return row
    status = summary.get("status", ERROR)
    row.update(status=status, error=summary.get("message", "") if status != "completed" else "")
    row.update({k: v for k, v in flatten(summary).items() if k not in ("status", "message")})
    return row


def write_table(rows: list[dict], swept: list[str], path: Path) -> None:
    """The rows as CSV, atomically; columns: run, swept keys, status, error, then summary keys as first seen."""
    columns = ["run", *swept, "status", "error"]
    for row in rows:
        columns += [k for k in row if k not in columns]
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=columns, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: toml_value(v) if isinstance(v, (list, tuple)) else v for k, v in row.items()})
    write_text_atomic(path, buffer.getvalue())


def read_table(path: str | Path) -> list[dict]:
    """results.csv back as dicts of strings (as csv.DictReader gives them)."""
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


# ----------------------------------------------------------------------------------------- sweep


def run_sweep(scene_file: str | Path, sets: list[str], out: str | Path | None = None, jobs: int | None = None,
              scheduler: str | None = None, plots: Iterable[str] = (), quiet: bool = False) -> SweepResult:
    """Run the sweep (see the module doc) and return its rows; raises :class:`SweepError` on bad input.

    Runs go to ``jobs`` local processes (default: one per core), or to the Dask scheduler at ``scheduler``.
    A Ctrl-C stops the sweep after the runs in progress have stopped cleanly; the table is written anyway.
    """
    plots = list(plots)
    if jobs is not None and jobs < 1:
        raise SweepError(f"--jobs {jobs}: must be at least 1")
    base, axes, points = plan(scene_file, sets)
    swept = [a.key for a in axes if a.swept]
    if plots and not any(_numeric_axis(a) for a in axes if a.swept):
        raise SweepError("--plot needs a swept parameter with numeric values (give a --set KEY with several "
                         "numbers)")
    root = Path(out) if out is not None else Path("runs") / f"sweep-{base.name}"
    if root.exists() and not root.is_dir():
        raise SweepError(f"--out {root}: exists and is not a folder")

    folders = {p.name: root / p.name for p in points}
    done = {p.name for p in points if is_finished(folders[p.name], p.scene_toml)}
    todo = [(p, folders[p.name]) for p in points if p.name not in done]
    try:
        for _, folder in todo:
            folder.mkdir(parents=True, exist_ok=True)
            (folder / SUMMARY).unlink(missing_ok=True)  # a run killed midway must never look finished
    except OSError as exc:
        raise SweepError(f"--out {root}: cannot write the run folders ({exc.strerror or exc})") from None

    outcomes: dict[str, Outcome] = {}
    result = SweepResult(rows=[], csv_path=root / RESULTS, swept=swept, skipped=len(done), ran=len(todo))
    from .progress import SweepProgress

    with SweepProgress(len(points), quiet) as progress:
        progress.skipped(len(done), root)
        try:
            if todo:
                if scheduler is not None:
                    from .dask import run_dask

                    results = run_dask(todo, scheduler)
                else:
                    results = run_local(todo, min(jobs or os.cpu_count() or 1, len(todo)))
                with closing(results):
                    for outcome in results:
                        outcomes[outcome[0].name] = outcome
                        progress.finished(*outcome)
        except KeyboardInterrupt:
            result.interrupted = True
        finally:
            result.rows = [_final_row(p, folders[p.name], outcomes.get(p.name)) for p in points]
            root.mkdir(parents=True, exist_ok=True)
            write_table(result.rows, swept, result.csv_path)
    if not result.interrupted:
        from .plot import plot_figure

        for figure in plots:
            result.plots.append(plot_figure(result.rows, axes, figure, root, title=base.name))
    return result


def _numeric_axis(axis: Axis) -> bool:
    return all(_is_number(v) for v in axis.values)


def _final_row(point: Point, folder: Path, outcome: Outcome | None) -> dict:
    """The row of a point: from the run just done, or from its folder (a finished run kept on resume)."""
    if outcome is not None:
        return make_row(*outcome)
    try:
        summary = json.loads((folder / SUMMARY).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return make_row(point, None, "not run (the sweep was interrupted first)")
    return make_row(point, summary, "")


def number(value: str) -> float:
    """A table cell as a float (NaN when empty or not a number)."""
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan
