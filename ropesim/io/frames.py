"""Reading a run folder's arrays without its scene: the frames, the ledger and the summary.

A finished run's frames come from ``trajectory.npz`` (memory-mapped), an unfinished one's from its last
checkpoint, as ``manifest.json`` says (:mod:`ropesim.io.runfolder`); every array's CRC-32 is checked first
unless ``verify`` is off. :meth:`ropesim.Trajectory.open` adds the scene and its checks; a scene's
``initial.shape = "from_run"`` start reads its frame from here.
"""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np

from ..integrate.health import LEDGER_COLUMNS
from .runfolder import (CHECKPOINT, FINISHED, INCOMPLETE, INTERRUPTED, LEDGER, SCENE, SUMMARY, TRAJECTORY,
                        RunFolderError, holder, memmap_npz, open_stream_array, read_manifest)


class Moved(Exception):
    """A checkpoint file vanished while reading: the run moved on; read its manifest again."""


def _summary_file(folder: Path) -> dict:
    try:
        return json.loads((folder / SUMMARY).read_text(encoding="utf-8"))
    except (ValueError, OSError):
        return {}


def read_frames(folder: Path, manifest: dict | None, verify: bool = True):
    """(named arrays, ledger (F, C) or None, summary) of a run folder, as its manifest says."""
    if manifest is None or manifest["status"] in FINISHED:
        if not (folder / TRAJECTORY).is_file():
            raise RunFolderError(f"{folder}: not a run folder: {TRAJECTORY} is missing")
        try:
            arrays = memmap_npz(folder / TRAJECTORY, verify=verify)
        except RunFolderError:
            raise
        except (zipfile.BadZipFile, ValueError, OSError, EOFError) as exc:
            raise RunFolderError(f"{folder / TRAJECTORY}: corrupt or unreadable ({exc})") from None
        return arrays, _read_ledger(folder), _summary_file(folder)
    cp = manifest.get("checkpoint")
    running = holder(folder)
    if not cp or not cp.get("frames"):
        what = f"is still starting (pid {running})" if running else "was stopped before its first checkpoint"
        raise RunFolderError(f"{folder}: {what}: no frames yet")
    arrays = {}
    for name, spec in manifest["arrays"].items():
        path = folder / CHECKPOINT / f"{name}.npy"
        if not path.is_file():
            raise Moved()
        arrays[name] = open_stream_array(path, tuple(spec["per_frame"]), np.dtype(spec["dtype"]), cp["frames"],
                                         cp["crc32"].get(name), verify=verify)
    ledger = arrays.pop("ledger", None)
    summary = _summary_file(folder) if manifest["status"] == INTERRUPTED else {}
    if summary.get("status") != manifest["status"]:
        state = (f"still running ({running})" if running else
                 "never finished (killed, or stopped by a full disk)")
        summary = {"scene": manifest.get("scene", folder.name), "status": INCOMPLETE,
                   "message": f"{state}; the last checkpoint is at t = {cp['t']:.6g} s ({cp['frames']} frames); "
                              f"`ropesim run --resume {folder}` continues it",
                   "t_end": cp["t"], "frames": cp["frames"], "steps": cp["step"]}
    return arrays, ledger, summary


def _read_ledger(folder: Path) -> np.ndarray | None:
    try:
        flows = read_flows(folder)
    except (OSError, ValueError, KeyError, zipfile.BadZipFile, EOFError) as exc:
        raise RunFolderError(f"{folder / LEDGER}: corrupt or unreadable ({exc})") from None
    return None if flows is None else flows[0]


def read_flows(folder: Path) -> tuple[np.ndarray, float] | None:
    """(flows (F, C), energy0) from a run folder's ``ledger.npz``, or None when it has none; a column an older
    ropesim did not book is zero."""
    path = Path(folder) / LEDGER
    if not path.is_file():
        return None
    with np.load(path) as npz:
        frames = len(npz["t"])
        return (np.stack([npz[name] if name in npz.files else np.zeros(frames) for name in LEDGER_COLUMNS], axis=1),
                float(npz["energy0"]))


def check_run_folder(folder: Path) -> None:
    """Raise :class:`RunFolderError` with one line unless ``folder`` is a folder holding a run's scene.toml."""
    if not folder.is_dir():
        raise RunFolderError(f"{folder}: no such run folder (make one with `ropesim run SCENE.toml`)")
    if not (folder / SCENE).is_file():
        raise RunFolderError(f"{folder}: not a run folder: {SCENE} is missing")


def read_run(folder: Path, verify: bool = True):
    """(named arrays, ledger (F, C) or None, summary) of a run folder, finished or not; a run that commits a
    checkpoint while it is read is read again from its new manifest."""
    check_run_folder(folder)
    for attempt in range(3):
        try:
            return read_frames(folder, read_manifest(folder), verify)
        except Moved:
            if attempt == 2:
                raise RunFolderError(f"{folder}: changes too fast to read (a run is finishing there)") from None
