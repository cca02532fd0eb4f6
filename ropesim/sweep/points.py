"""Running a sweep's points: each one resolved scene into its own run folder, as ``ropesim run`` does, in a
pool of fresh local processes (the Dask alternative is :mod:`ropesim.sweep.dask`)."""

from __future__ import annotations

import json
import multiprocessing
import os
import signal
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from pathlib import Path
from typing import Callable, Iterator

from ..io.runfolder import SCENE, SUMMARY, TRAJECTORY
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


NOT_STARTED = "not run (the sweep was stopped first)"
_STOP = None          # in a worker: the sweep's stop event (set by the parent on Ctrl-C or SIGTERM)
_PARENT = None        # in a worker: the parent's pid (a worker whose parent died stops too)


def _stopping() -> bool:
    return (_STOP is not None and _STOP.is_set()) or (_PARENT is not None and os.getppid() != _PARENT)


def run_point(scene_toml: str, folder: str) -> dict:
    """Run one resolved scene into ``folder``, exactly as ``ropesim run`` does; returns its summary.

    A folder holding an unfinished run of this very scene (interrupted, killed) continues from its last
    checkpoint, bit for bit as if it had never stopped; anything else there is replaced.
    """
    from ..run import resume, simulate

    if _stopping():
        return {"status": "not_started"}
    if _resumable(Path(folder), scene_toml):
        return resume(folder, stop=_stopping).summary
    scene = scene_from_toml(scene_toml, source=str(Path(folder) / SCENE))
    return simulate(scene, folder, stop=_stopping).summary


def _resumable(folder: Path, scene_toml: str) -> bool:
    from ..io.runfolder import FINISHED, read_manifest, scene_hash

    try:
        manifest = read_manifest(folder)
    except ValueError:
        return False
    return (manifest is not None and manifest["status"] not in FINISHED and bool(manifest.get("checkpoint"))
            and manifest.get("scene_sha256") == scene_hash(scene_toml))


def run_point_safely(scene_toml: str, folder: str) -> tuple[dict | None, str]:
    """:func:`run_point` in a worker: (summary, "") or (None, the error in one line).

    The error travels as text because not every exception survives pickling back from a worker process.
    """
    try:
        summary = run_point(scene_toml, folder)
    except Exception as exc:  # a run's own failure is recorded in the table; the sweep goes on
        return None, describe(exc)
    if summary.get("status") == "not_started":
        return None, NOT_STARTED
    return summary, ""


def describe(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {' '.join(str(exc).split())}"


def _worker_start(stop, parent: int) -> None:
    """Worker start-up: Ctrl-C reaches a worker only while it integrates, where the run stops cleanly; the
    sweep's stop event and the parent's pid tell it to start nothing new and stop the run in progress."""
    global _STOP, _PARENT
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _STOP, _PARENT = stop, parent


Outcome = tuple[Point, dict | None, str]  # the point, its summary (None if it raised), the error text


POLL_SECONDS = 0.1   # how often a sweep's loop asks whether it was stopped


def run_local(todo: list[tuple[Point, Path]], jobs: int,
              stopping: Callable[[], bool] = lambda: False) -> Iterator[Outcome]:
    """Run points in a pool of ``jobs`` fresh processes; yields each outcome as it finishes.

    ``stopping()`` is asked every POLL_SECONDS (the sweep's stop signals set it; they raise nothing here, so
    no exception ever lands inside the pool's own code). Once it is true, or the generator is closed early, the
    workers' stop event is set: no run starts after it, and those in progress stop at their next chunk, keeping
    their frames for a rerun to resume; every worker has exited before the outcomes of the runs that stopped
    meanwhile are yielded (unless the generator was closed: then their folders say how they ended).
    """
    context = multiprocessing.get_context("spawn")
    stop = context.Event()
    pool = ProcessPoolExecutor(max_workers=jobs, mp_context=context, initializer=_worker_start,
                               initargs=(stop, os.getpid()))
    futures: dict = {}

    def started(done) -> Iterator[Outcome]:
        for future in done:
            outcome = _outcome(futures.pop(future), future.result)
            if outcome[2] != NOT_STARTED:
                yield outcome

    try:
        for p, folder in todo:
            if stopping():
                break
            futures[pool.submit(run_point_safely, p.scene_toml, str(folder))] = p
        pending = set(futures)
        while pending and not stopping():
            done, pending = wait(pending, timeout=POLL_SECONDS, return_when=FIRST_COMPLETED)
            yield from started(done)
    finally:
        stop.set()
        pool.shutdown(wait=True, cancel_futures=True)
    yield from started([f for f in futures if f.done() and not f.cancelled()])   # stopped at their next chunk


def _outcome(point: Point, result: Callable[[], tuple[dict | None, str]]) -> Outcome:
    """The outcome of a finished future; a worker that died (killed, out of memory) counts as an error too."""
    try:
        summary, error = result()
    except Exception as exc:
        summary, error = None, describe(exc)
    return point, summary, error



