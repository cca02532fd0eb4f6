"""Parameter sweeps: one scene run over the Cartesian product of ``--set`` values, in parallel, resumable.

``ropesim sweep SCENE --set drag.b=0.05:1.5:10 --set rope.nodes=21,41`` runs every combination. A key's
values are a list (``0.1,0.4,1.0``), an inclusive range ``start:stop:count`` (evenly spaced as numpy.linspace;
whole numbers for integer keys, inner values to 12 significant digits) or a single value, which then
applies to every run.

Every combination is resolved to a complete scene before anything runs, so a bad key or value stops the sweep
with one line. Each run is the same :func:`ropesim.run.simulate` that ``ropesim run`` calls, in a process of
its own (or on a Dask cluster, :mod:`ropesim.sweep.dask`), into ``DIR/<key=value_...>/``. The table
``DIR/results.csv`` lists each run's swept values, status and error, then its ``summary.json`` flattened
(nested keys joined by dots: ``final_energy_J.total``, ``towed.top_angle_deg``,
``shooter.mean_loop_inclination_deg``, ...), one row per combination in the order of the product.

Rerun, a sweep resumes: a run folder whose summary says completed and whose scene.toml equals the resolved
scene is kept; an unfinished run of the same scene (interrupted, killed) continues from its last checkpoint,
bit for bit; any other (blown up, or made from other parameters) runs again. Ctrl-C or SIGTERM stop a sweep
cleanly: no new run starts, the running ones stop at their next chunk keeping their frames, results.csv is
written for what finished, and every worker process has exited; more signals meanwhile change nothing.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
from contextlib import closing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterable

from ..io.atomic import write_text_atomic
from ..io.runfolder import SUMMARY
from ..stop import Stopped
from .plan import Point, SweepError, _numeric_axis, plan, toml_value
from .points import Outcome, is_finished, run_local

RESULTS = "results.csv"
FIXED_COLUMNS = ("run", "status", "error")
TIMING_COLUMNS = ("wall_time_s", "compile_time_s", "steps_per_second", "node_steps_per_second")
ERROR = "error"  # status of a run whose process raised instead of returning a summary
NOT_RUN = "not_run"  # status of a run the sweep never started (it was stopped first)


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
    stopped_by: str = ""

    @property
    def failed(self) -> list[dict]:
        return [r for r in self.rows if r["status"] not in ("completed", NOT_RUN)]

    @property
    def not_run(self) -> int:
        return sum(r["status"] == NOT_RUN for r in self.rows)


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
              scheduler: str | None = None, plots: Iterable[str] = (), quiet: bool = False,
              before: Callable[[int, Path], None] | None = None) -> SweepResult:
    """Run the sweep (see the module doc) and return its rows; raises :class:`SweepError` on bad input.

    Runs go to ``jobs`` local processes (default: one per core), or to the Dask scheduler at ``scheduler``.
    ``before(count, folder)`` is called once the number of runs and the sweep folder are known, before the
    combinations are resolved (the command line says them, and asks before a large sweep). A Ctrl-C stops
    the sweep after the runs in progress have stopped cleanly; the table is written anyway (OSError if it
    cannot be: a full disk).
    """
    from ..io.guard import WriteRefused, output_folder
    from ..run import stop_signals
    from .plan import parse_axes
    from .progress import PLANNING_SHOWN, planning

    plots = list(plots)
    if jobs is not None and jobs < 1:
        raise SweepError(f"--jobs {jobs}: must be at least 1")
    axes = parse_axes(sets)
    if plots and not any(_numeric_axis(a) for a in axes if a.swept):
        raise SweepError("--plot needs a swept parameter with numeric values (give a --set KEY with several "
                         "numbers)")
    root = Path(out) if out is not None else Path("runs") / f"sweep-{_base_name(scene_file, axes)}"
    try:
        root = output_folder(root, "sweep")
    except WriteRefused as exc:
        raise SweepError(str(exc)) from None
    count = math.prod(len(a.values) for a in axes)
    if before is not None and count >= PLANNING_SHOWN:    # a large sweep is said (and asked) before it plans
        before(count, root)
    with planning(count, quiet) as on_point:
        base, axes, points = plan(scene_file, sets, on_point=on_point)
    if before is not None and count < PLANNING_SHOWN:     # a small one once every combination is valid
        before(count, root)
    swept = [a.key for a in axes if a.swept]

    folders = {p.name: root / p.name for p in points}   # each made by its run (none for runs never started)
    done = {p.name for p in points if is_finished(folders[p.name], p.scene_toml)}
    todo = [(p, folders[p.name]) for p in points if p.name not in done]

    outcomes: dict[str, Outcome] = {}
    result = SweepResult(rows=[], csv_path=root / RESULTS, swept=swept, skipped=len(done))
    from .progress import SweepProgress

    stopped = ""
    workers = min(jobs or os.cpu_count() or 1, len(todo))
    try:      # compiling: a stop ends it at once (raised), and no run starts
        if workers > 1 and scheduler is None:
            warm_up([p for p, _ in todo])
        if plots and todo:
            _check_figures_early(todo[0][0], plots, axes, root)
    except (KeyboardInterrupt, Stopped) as exc:
        stopped = exc.name if isinstance(exc, Stopped) else "SIGINT"
    # From here a stop signal only sets the flag, however many come: the runs in progress stop at their next
    # chunk, every worker exits, and the table is written, each row saying what its run did.
    with stop_signals() as flag, SweepProgress(len(points), quiet) as progress:
        if stopped:
            flag.set(stopped)
        progress.skipped(len(done), root)
        try:
            if todo and not flag.is_set():
                if scheduler is not None:
                    from .dask import run_dask

                    results = run_dask(todo, scheduler, flag.is_set)
                else:
                    results = run_local(todo, workers, flag.is_set)
                with closing(results):
                    for outcome in results:
                        outcomes[outcome[0].name] = outcome
                        progress.finished(*outcome)
        finally:
            result.interrupted, result.stopped_by = flag.is_set(), flag.signal
            result.rows = [_final_row(p, folders[p.name], outcomes.get(p.name)) for p in points]
            result.ran = sum(r["status"] != NOT_RUN for r in result.rows) - len(done)
            root.mkdir(parents=True, exist_ok=True)
            write_table(result.rows, swept, result.csv_path)
    if not result.interrupted:
        from .plot import plot_figure

        for figure in plots:
            result.plots.append(plot_figure(result.rows, axes, figure, root, title=base.name))
    return result


def warm_up(points: list[Point]) -> None:
    """Compile (or load from the cache) here, once, the kernels of each method that several points use, so that
    the workers load them from Numba's cache instead of compiling the same loop at the same time (methods used
    once compile in their workers, in parallel). A point whose scene fails here is left to its own run to
    report."""
    from ..kernels import warm_up as warm_scene
    from .points import scene_from_toml

    first: dict[str, object] = {}
    uses: dict[str, int] = {}
    for point in points:
        try:
            scene = scene_from_toml(point.scene_toml)
        except Exception:
            continue
        method = scene.integrator.method
        first.setdefault(method, scene)
        uses[method] = uses.get(method, 0) + 1
    for method, scene in first.items():
        if uses[method] > 1:
            try:
                warm_scene(scene)
            except Exception:
                pass


def _final_row(point: Point, folder: Path, outcome: Outcome | None) -> dict:
    """The row of a point: from the run just done, from its folder (a finished run kept on resume), or, for a
    run the sweep never started (it was stopped first), status not_run."""
    if outcome is not None:
        return make_row(*outcome)
    try:
        summary = json.loads((folder / SUMMARY).read_text(encoding="utf-8"))
        if not isinstance(summary, dict):
            raise ValueError
    except (OSError, ValueError, RecursionError):
        return {"run": point.name, **point.params, "status": NOT_RUN, "error": ""}
    return make_row(point, summary, "")


def _base_name(scene_file: str | Path, axes) -> str:
    """The scene's name with the sweep's single values applied (it names the default sweep folder)."""
    from ..scene.loader import SceneError, load_scene

    fixed = [f"{a.key}={toml_value(a.values[0])}" for a in axes if not a.swept]
    try:
        return load_scene(scene_file, fixed).name
    except SceneError as exc:
        raise SweepError(str(exc)) from None


def _check_figures_early(point: Point, plots: list[str], axes, root: Path) -> None:
    """Refuse an unknown --plot FIGURE before any run: the summary columns of a one-step run of the first
    combination (in memory, a fraction of a second once its kernel is compiled)."""
    from dataclasses import replace

    from ..run import INTERRUPTED, simulate
    from .points import scene_from_toml

    try:
        scene = scene_from_toml(point.scene_toml)
        probe = simulate(replace(scene, integrator=replace(scene.integrator, t_end=scene.integrator.dt)))
    except Exception:
        return    # the run itself will say what is wrong with it
    if probe.summary["status"] == INTERRUPTED:   # stopped while it compiled: the sweep stops too
        raise Stopped(probe.summary.get("stopped_by", "SIGINT"))
    row = make_row(point, probe.summary, "")
    from .plot import check_figure

    for figure in plots:
        check_figure([row], axes, figure, root)


def number(value: str) -> float:
    """A table cell as a float (NaN when empty or not a number)."""
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan
