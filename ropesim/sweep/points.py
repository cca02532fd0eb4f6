"""Running a sweep's points: each one resolved scene into its own run folder, as ``ropesim run`` does, in a
pool of fresh local processes (the Dask alternative is :mod:`ropesim.sweep.dask`)."""

from __future__ import annotations

import json
import multiprocessing
import signal
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Callable, Iterator

from ..io.trajectory import SCENE, SUMMARY, TRAJECTORY
from ..scene.loader import scene_from_toml
from .plan import Point


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



