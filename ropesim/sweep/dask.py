"""``ropesim sweep --scheduler ADDRESS``: the same runs on a Dask distributed cluster.

Each worker resolves the scene from its TOML text and runs it with :func:`ropesim.sweep.run_point` in a
temporary folder of its own, then sends back the run's arrays, scene and summary; this process writes them
into the sweep's run folder with the usual atomic writes. So workers need ropesim installed but no file
system shared with this machine, and the runs (deterministic, like every ropesim run) give the same arrays
bit for bit as a local sweep. Needs the ``dask`` extra (:func:`ropesim.install.install_hint` says how to install it).
"""

from __future__ import annotations

import tempfile
import time
import uuid
from pathlib import Path
from typing import Callable, Iterator

import numpy as np

from .plan import Point, SweepError
from .points import POLL_SECONDS, Outcome, _outcome, run_point_safely
from ..io.atomic import write_json_atomic, write_text_atomic
from ..io.runfolder import SCENE, SUMMARY, TRAJECTORY, write_npz_atomic

CONNECT_TIMEOUT = "20s"


def run_remote(scene_toml: str) -> dict:
    """On a worker: run the scene in a scratch folder and return its files' contents (or the error)."""
    with tempfile.TemporaryDirectory(prefix="ropesim-sweep-") as tmp:
        summary, error = run_point_safely(scene_toml, tmp)
        if summary is None:
            return {"error": error}
        with np.load(Path(tmp) / TRAJECTORY) as npz:
            arrays = {name: npz[name] for name in npz.files}
        return {"arrays": arrays, "scene": (Path(tmp) / SCENE).read_text(encoding="utf-8"), "summary": summary}


def store(result: dict, folder: Path) -> tuple[dict | None, str]:
    """Write a worker's run into ``folder`` (summary last: its presence marks the run finished)."""
    if "error" in result:
        return None, result["error"]
    folder.mkdir(parents=True, exist_ok=True)
    write_npz_atomic(folder / TRAJECTORY, result["arrays"])
    write_text_atomic(folder / SCENE, result["scene"])
    write_json_atomic(folder / SUMMARY, result["summary"])
    return result["summary"], ""


def run_dask(todo: list[tuple[Point, Path]], address: str,
             stopping: Callable[[], bool] = lambda: False) -> Iterator[Outcome]:
    """Submit every point to the scheduler at ``address``; yields each outcome as it comes back, until
    ``stopping()`` (asked every POLL_SECONDS) says the sweep was stopped: then the runs not back yet are
    cancelled."""
    try:
        from dask.distributed import Client, as_completed
    except ImportError:
        from ..install import install_hint

        raise SweepError(f"--scheduler needs dask.distributed, which is not installed: {install_hint('dask')}") from None
    try:
        client = Client(address, timeout=CONNECT_TIMEOUT, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise SweepError(f"--scheduler {address}: cannot connect to a Dask scheduler there "
                         f"({' '.join(str(exc).split())})") from None
    with client:
        folders = {p.name: folder for p, folder in todo}
        token = uuid.uuid4().hex[:8]
        futures = {client.submit(run_remote, p.scene_toml, key=f"ropesim-{p.name}-{token}"): p for p, _ in todo}
        arrived = as_completed(futures, loop=client.loop)
        try:
            while not arrived.is_empty() and not stopping():
                if not arrived.has_ready():
                    time.sleep(POLL_SECONDS)
                    continue
                for future in arrived.next_batch(block=False):
                    point = futures[future]
                    yield _outcome(point, lambda: store(future.result(), folders[point.name]))
        finally:
            client.cancel([f for f in futures if not f.done()])
