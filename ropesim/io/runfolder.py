"""The run folder as a transaction: one writer (a lock), frames streamed in durable checkpoints, a manifest
written last that says what the folder holds.

Layout while a run goes on, and after it was interrupted, killed or stopped by a full disk::

    RUN/.lock                 advisory lock (flock) of the one process writing here; its pid and command
    RUN/manifest.json         written last at every commit: status, time grid, arrays, the last checkpoint
    RUN/scene.toml            the resolved scene
    RUN/checkpoint/NAME.npy   one append-only .npy file per named per-frame array (t, x, v, tension, ...,
                              ledger); the manifest says how many frames are committed and their CRC-32
    RUN/checkpoint/state-STEP.npz   the integrator's complete state at the last checkpoint
    RUN/summary.json          (interrupted runs) what happened up to the stop

and once the run has finished (completed or blew up)::

    RUN/trajectory.npz, RUN/ledger.npz, RUN/summary.json, RUN/state.npz, RUN/manifest.json, RUN/scene.toml

A commit (:meth:`RunWriter.checkpoint`) appends nothing new: the frames were already written with ordinary
``write()`` calls as the chunks came (so a full disk is an exception, never a SIGBUS from a memory map). It
rewrites each stream file's .npy header to the committed frame count, ``fsync``s every stream file, writes the
state file (temporary name, fsync, rename), and then the manifest the same way: the manifest's rename is the
commit point, as the journal's deletion is SQLite's. Frames past the manifest's count (a torn last chunk) are
ignored by readers and cut off by ``--resume``, as REBOUND's SimulationArchive ignores a torn last blob.

A new run into an existing run folder builds the new folder beside it and swaps the two in one
``renameat2(RENAME_EXCHANGE)``, so a reader sees the old run or the new one, never a mix; stale pictures go
with the old run.
"""

from __future__ import annotations

import ctypes
import errno
import fcntl
import hashlib
import json
import os
import shutil
import struct
import sys
import tempfile
import time
import zipfile
import zlib
from pathlib import Path

import numpy as np

from .atomic import FILE_MODE, TEMPORARY_NAME, _umask, atomic_output, fsync_path, write_json_atomic

from .layout import (BLEW_UP, CHECKPOINT, COMPLETED, FINISHED, FORMAT, INCOMPLETE, INTERRUPTED, LEDGER, LOCK,
                     MANIFEST, RUN_MARKERS, SCENE, STATE, SUMMARY, TRAJECTORY)
HEADER_BYTES = 256          # a stream file's .npy header, padded so that it can be rewritten in place
VERIFY_BLOCK = 16 * 2 ** 20


class RunFolderError(ValueError):
    """A run folder that cannot be read or written as asked; ``str()`` is one line for the user."""


class RunFolderBusy(RunFolderError):
    """Another process holds the run folder's lock."""


class DiskFull(RunFolderError):
    """The disk filled up; ``str()`` says how much was needed and free, and what was kept."""


# ----------------------------------------------------------------------------------------------- helpers


def scene_hash(scene_toml: str) -> str:
    return hashlib.sha256(scene_toml.encode("utf-8")).hexdigest()


def free_bytes(path: Path) -> int:
    """Free bytes for an unprivileged writer on the file system holding ``path`` (or its nearest parent)."""
    path = Path(path).absolute()
    while not path.exists() and path != path.parent:
        path = path.parent
    st = os.statvfs(path)
    return st.f_bavail * st.f_frsize


def human(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB", "PB"):
        if abs(n) < 1000 or unit == "PB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.3g} {unit}"
        n /= 1000
    return f"{n:.3g} PB"  # pragma: no cover


def write_json_durable(path: Path, data: dict) -> None:
    with atomic_output(path) as tmp:
        tmp.write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")


def read_manifest(folder: Path) -> dict | None:
    """The folder's manifest, or None when it has none (a folder written before ropesim had one)."""
    path = Path(folder) / MANIFEST
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise RunFolderError(f"{path}: cannot read ({exc.strerror or exc})") from None
    try:
        manifest = json.loads(text)
        if not isinstance(manifest, dict) or "status" not in manifest:
            raise ValueError("no status")
    except ValueError:
        raise RunFolderError(f"{path}: corrupt (not the JSON manifest ropesim writes)") from None
    return manifest


def _write_all(fd: int, data) -> None:
    view = memoryview(data).cast("B")
    while len(view):
        n = os.write(fd, view)
        view = view[n:]


# ------------------------------------------------------------------------------------------------- lock


class FolderLock:
    """An advisory ``flock`` on ``RUN/.lock``, held for the life of a run; the OS drops it when the process
    dies, however it dies (kill -9 included), so a stale lock never blocks the next run.

    A writer holds the lock exclusively (``LOCK_EX``); a reader asking who writes (:func:`holder`) takes it
    shared for an instant. A ``.lock`` file nobody holds is stale (a writer killed before it removed the file):
    it is taken over like a missing one."""

    def __init__(self, fd: int, path: Path):
        self.fd, self.path = fd, path

    @classmethod
    def acquire(cls, folder: Path, what: str = "") -> "FolderLock":
        path = Path(folder) / LOCK
        for _ in range(5):
            fd = os.open(path, os.O_RDWR | os.O_CREAT, FILE_MODE)
            if not _lock_exclusive(fd):
                holder = _describe_holder(fd)
                os.close(fd)
                raise RunFolderBusy(f"{folder}: another ropesim is writing this run folder ({holder}); wait for "
                                    f"it, stop it, or choose another --out") from None
            try:  # the lock file must still be the one at that path (a replacement may have swapped folders)
                same = os.fstat(fd).st_ino == os.stat(path).st_ino
            except FileNotFoundError:
                same = False
            if same:
                lock = cls(fd, path)
                lock.record(what)
                return lock
            os.close(fd)
        raise RunFolderBusy(f"{folder}: its lock keeps changing hands; another ropesim is replacing it")

    def record(self, what: str = "") -> None:
        info = {"pid": os.getpid(), "command": what or " ".join([Path(sys.argv[0]).name, *sys.argv[1:]])[:300],
                "since": time.strftime("%Y-%m-%d %H:%M:%S")}
        data = (json.dumps(info) + "\n").encode()
        try:
            os.ftruncate(self.fd, 0)
            os.pwrite(self.fd, data, 0)
        except OSError:
            pass  # the record is informational; a full disk must not stop the run here

    def release(self, remove: bool = False) -> None:
        """Unlock; with ``remove`` the lock file goes first (safe: a waiting process re-checks the path)."""
        if remove:
            try:
                if os.fstat(self.fd).st_ino == os.stat(self.path).st_ino:
                    os.unlink(self.path)
            except OSError:
                pass
        if self.fd is not None:
            try:
                fcntl.flock(self.fd, fcntl.LOCK_UN)
            finally:
                os.close(self.fd)
                self.fd = None


READERS_WAIT = 2.0   # seconds a writer waits out readers' momentary shared locks (never another writer)


def _lock_exclusive(fd: int) -> bool:
    """Take ``fd``'s ``flock`` exclusively without waiting for a writer: False when another writer holds it.

    A reader's probe (:func:`holder`) holds the lock shared for an instant; a plain ``LOCK_EX | LOCK_NB`` would
    take that for a writer and refuse the run, naming whoever the lock file last recorded (a finished or
    killed run). So a refused exclusive lock is tried shared: that succeeds only when no writer holds it
    (readers alone), and the exclusive lock is tried again once they are done."""
    deadline = time.monotonic() + READERS_WAIT
    while True:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return True
        except BlockingIOError:
            pass
        try:
            fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:
            return False                  # held exclusively: a writer
        fcntl.flock(fd, fcntl.LOCK_UN)
        if time.monotonic() > deadline:
            return False
        time.sleep(0.001)


def _describe_holder(fd: int) -> str:
    try:
        info = json.loads(os.pread(fd, 4096, 0).decode() or "{}")
    except (OSError, ValueError):
        info = {}
    if not info.get("pid"):
        return "its process did not record itself"
    return f"pid {info['pid']}, `{info.get('command', '?')}`, since {info.get('since', '?')}"


def holder(folder: Path) -> str | None:
    """Who holds the folder's lock ("pid 123, `ropesim run ...`"), or None when nobody does."""
    path = Path(folder) / LOCK
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return None
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except BlockingIOError:
        return _describe_holder(fd)
    finally:
        os.close(fd)
    return None


# ------------------------------------------------------------------------------------------- the stream


def npy_header(shape: tuple, dtype) -> bytes:
    """A version 1.0 .npy header of exactly HEADER_BYTES bytes (so it can be rewritten in place)."""
    text = repr({"descr": np.lib.format.dtype_to_descr(np.dtype(dtype)), "fortran_order": False,
                 "shape": tuple(int(s) for s in shape)}).encode("latin1")
    pad = HEADER_BYTES - 10 - len(text) - 1
    if pad < 0:  # pragma: no cover - a shape with more digits than any machine holds
        raise ValueError(f"shape {shape} too long for a stream header")
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", HEADER_BYTES - 10) + text + b" " * pad + b"\n"


class Stream:
    """One append-only ``.npy`` file of a named per-frame array, written with ``write()`` (no memory map)."""

    def __init__(self, path: Path, per_frame: tuple, dtype=np.float64, count: int = 0, crc: int = 0,
                 create: bool = True):
        self.path, self.per_frame, self.dtype = path, tuple(per_frame), np.dtype(dtype)
        self.row_bytes = int(np.prod(self.per_frame, dtype=np.int64)) * self.dtype.itemsize
        self.count, self.crc = count, crc
        if create:
            self.fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_TRUNC, FILE_MODE)
            _write_all(self.fd, npy_header((0, *self.per_frame), self.dtype))
        else:
            self.fd = os.open(path, os.O_RDWR)
            os.ftruncate(self.fd, HEADER_BYTES + count * self.row_bytes)   # a torn tail past the commit goes
            os.lseek(self.fd, 0, os.SEEK_END)
        self.synced, self.synced_crc = count, crc

    def append(self, rows: np.ndarray) -> None:
        rows = np.ascontiguousarray(rows, dtype=self.dtype)
        if rows.shape[1:] != self.per_frame:
            raise ValueError(f"{self.path.name}: rows of shape {rows.shape[1:]}, expected {self.per_frame}")
        if len(rows) == 0:
            return
        _write_all(self.fd, rows.data)
        self.crc = zlib.crc32(rows.data, self.crc)
        self.count += len(rows)

    def sync(self) -> None:
        os.pwrite(self.fd, npy_header((self.count, *self.per_frame), self.dtype), 0)
        os.fsync(self.fd)
        self.synced, self.synced_crc = self.count, self.crc

    def close(self) -> None:
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None


def open_stream_array(path: Path, per_frame: tuple, dtype, count: int, crc: int | None = None,
                      verify: bool = True) -> np.ndarray:
    """The first ``count`` frames of a stream file, memory-mapped read-only; its CRC-32 checked against ``crc``."""
    dtype = np.dtype(dtype)
    shape = (count, *per_frame)
    nbytes = int(np.prod(shape, dtype=np.int64)) * dtype.itemsize
    try:
        size = path.stat().st_size
    except FileNotFoundError:
        raise RunFolderError(f"{path}: missing") from None
    if size < HEADER_BYTES + nbytes:
        raise RunFolderError(f"{path}: truncated ({size} bytes; the manifest commits {count} frames, "
                             f"{HEADER_BYTES + nbytes} bytes)")
    if verify and crc is not None:
        got = _crc_of(path, HEADER_BYTES, nbytes)
        if got != crc:
            raise RunFolderError(f"{path}: damaged (its CRC-32 does not match the manifest's); the frames are "
                                 f"not used")
    if nbytes == 0:
        return np.zeros(shape, dtype=dtype)
    return np.memmap(path, dtype=dtype, mode="r", offset=HEADER_BYTES, shape=shape)


def _crc_of(path: Path, offset: int, nbytes: int) -> int:
    crc = 0
    with open(path, "rb") as fh:
        fh.seek(offset)
        left = nbytes
        while left > 0:
            block = fh.read(min(VERIFY_BLOCK, left))
            if not block:
                break
            crc = zlib.crc32(block, crc)
            left -= len(block)
    return crc


# ---------------------------------------------------------------------------------------- npz writing


WRITE_BLOCK_BYTES = 16 * 2 ** 20  # an array is written this many bytes at a time, never copied whole


def _write_npy(fh, arr) -> None:
    """Write ``arr`` in .npy format to ``fh``, a block of leading rows at a time (a memory map is read lazily)."""
    arr = np.asarray(arr)
    if not arr.flags.c_contiguous:
        arr = np.ascontiguousarray(arr)
    np.lib.format.write_array_header_1_0(fh, np.lib.format.header_data_from_array_1_0(arr))
    if arr.ndim == 0 or arr.size == 0:
        fh.write(arr.tobytes())
        return
    rows = max(1, WRITE_BLOCK_BYTES // max(1, arr[0].nbytes))
    for start in range(0, len(arr), rows):
        fh.write(np.ascontiguousarray(arr[start:start + rows]).data)


def write_npz_atomic(path: Path, arrays: dict[str, np.ndarray]) -> None:
    """Write an uncompressed, memory-mappable ``.npz`` atomically and durably, streaming each array in blocks."""
    with atomic_output(path) as tmp:
        with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_STORED, allowZip64=True) as zf:
            for name, arr in arrays.items():
                with zf.open(f"{name}.npy", "w", force_zip64=True) as fh:
                    _write_npy(fh, arr)


def memmap_npz(path: Path, verify: bool = True) -> dict[str, np.ndarray]:
    """Memory-map every array of an uncompressed ``.npz``; with ``verify`` each member's CRC-32 is checked
    first (the check ``numpy.load`` makes when it reads a member whole), so damaged frames are refused."""
    out = {}
    with zipfile.ZipFile(path) as zf, open(path, "rb") as fh:
        for info in zf.infolist():
            name = info.filename.removesuffix(".npy")
            if info.compress_type != zipfile.ZIP_STORED:
                out[name] = np.load(zf.open(info.filename), allow_pickle=False)
                continue
            fh.seek(info.header_offset)
            local = fh.read(30)
            if local[:4] != b"PK\x03\x04":
                raise RunFolderError(f"{path}: corrupt zip entry {info.filename}")
            name_len = int.from_bytes(local[26:28], "little")
            extra_len = int.from_bytes(local[28:30], "little")
            start = info.header_offset + 30 + name_len + extra_len
            if verify and _crc_of(path, start, info.compress_size) != info.CRC:
                raise RunFolderError(f"{path}: damaged: {info.filename} fails its CRC-32 check (the file was "
                                     f"changed or corrupted on disk); its frames are not used")
            fh.seek(start)
            version = np.lib.format.read_magic(fh)
            if version == (1, 0):
                shape, fortran, dtype = np.lib.format.read_array_header_1_0(fh)
            else:
                shape, fortran, dtype = np.lib.format.read_array_header_2_0(fh)
            offset = fh.tell()
            if int(np.prod(shape)) * dtype.itemsize > info.compress_size:
                raise RunFolderError(f"{path}: {info.filename} is shorter than its header says")
            if np.prod(shape) == 0:
                out[name] = np.zeros(shape, dtype=dtype)
            else:
                out[name] = np.memmap(path, dtype=dtype, mode="r", offset=offset, shape=shape,
                                      order="F" if fortran else "C")
    return out


# ----------------------------------------------------------------------------------------- the writer


def _exchange(a: Path, b: Path) -> None:
    """Swap two paths atomically (Linux renameat2 RENAME_EXCHANGE); OSError where it is not available."""
    try:
        fn = ctypes.CDLL(None, use_errno=True).renameat2
    except (AttributeError, OSError):
        raise OSError(errno.ENOSYS, "renameat2 is not available") from None
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    if fn(-100, os.fsencode(str(a)), -100, os.fsencode(str(b)), 2) != 0:
        e = ctypes.get_errno()
        raise OSError(e, os.strerror(e), str(a))


def _remove_own_temporaries(folder: Path) -> None:
    """Remove the temporary files of a run's own files (a writer killed during its final write leaves
    ``.trajectory.XXXXXXXX.tmp.npz``, up to the trajectory's size); called with the folder's lock held."""
    own = {Path(name).stem for name in (TRAJECTORY, LEDGER, STATE, SUMMARY, MANIFEST, SCENE)}
    for entry in os.listdir(folder):
        match = TEMPORARY_NAME.match(entry)
        if match and match.group(1) in own:
            (folder / entry).unlink(missing_ok=True)


def _can_exchange(beside: Path) -> bool:
    """True when this file system swaps two folders atomically (tried on two empty ones beside ``beside``)."""
    a = b = None
    try:
        a = Path(tempfile.mkdtemp(prefix=f"{beside.name}.x-", dir=beside.parent))
        b = Path(tempfile.mkdtemp(prefix=f"{beside.name}.y-", dir=beside.parent))
        _exchange(a, b)
        return True
    except OSError:
        return False
    finally:
        for path in (a, b):
            if path is not None:
                _remove_tree(path)


def _remove_tree(path: Path) -> None:
    shutil.rmtree(path, ignore_errors=True)


def _clean_leftovers(folder: Path) -> None:
    """Remove hidden siblings left by replacements that were killed (unless another process is using one)."""
    try:
        siblings = list(folder.parent.glob(f".{folder.name}.new-*"))
    except OSError:
        return
    for sibling in siblings:
        if sibling.is_dir() and holder(sibling) is None:
            _remove_tree(sibling)


class RunWriter:
    """The one writer of a run folder: streams named per-frame arrays, commits checkpoints, finishes the run.

    ``specs`` maps each per-frame array's name to its per-frame shape (``t`` is ``()``, ``x`` is ``(N, D)``);
    every array is float64. Make one with :meth:`create` (a new run; replaces an earlier run in the folder) or
    :meth:`reopen` (continue from the last checkpoint).
    """

    def __init__(self, folder: Path, lock: FolderLock, manifest: dict, streams: dict[str, Stream]):
        self.folder, self.lock, self.manifest, self.streams = folder, lock, manifest, streams
        self.state_file: str | None = (manifest.get("checkpoint") or {}).get("state")

    # -- making one -------------------------------------------------------------------------------------

    @classmethod
    def create(cls, folder: Path, scene_toml: str, specs: dict[str, tuple], grid: dict,
               command: str = "") -> "RunWriter":
        """A new run in ``folder`` (``grid``: what the manifest records about it: scene name, time grid).

        ``folder`` must be missing, empty or a run folder holding nothing but ropesim's files
        (:func:`ropesim.io.guard.output_folder`; a link is followed). An earlier run there stays whole until
        the new one commits its first checkpoint past t = 0 (:meth:`checkpoint`): the new run is built beside
        it and swapped in then, so a rerun killed or stopped before that leaves the earlier run as it was.
        """
        from .guard import WriteRefused, is_run_folder, output_folder

        try:
            folder = output_folder(folder, "run")
        except WriteRefused as exc:
            raise RunFolderError(str(exc)) from None
        old_lock = None
        if folder.is_dir():
            old_lock = FolderLock.acquire(folder, command)
        try:
            _clean_leftovers(folder)
            folder.parent.mkdir(parents=True, exist_ok=True)
            if old_lock is None or _same_device(folder, folder.parent):   # else a mount point: in place below
                staging = None
                try:
                    staging = Path(tempfile.mkdtemp(prefix=f".{folder.name}.new-", dir=folder.parent))
                    os.chmod(staging, 0o777 & ~_umask())
                    lock = FolderLock.acquire(staging, command)
                except OSError:
                    if staging is not None:
                        _remove_tree(staging)
                    staging = None
                if staging is not None and old_lock is not None and not _can_exchange(staging):
                    lock.release()
                    _remove_tree(staging)
                    staging = None
                if staging is not None:
                    try:
                        writer = cls._build(staging, staging, lock, scene_toml, specs, grid)
                    except BaseException:
                        lock.release()
                        _remove_tree(staging)
                        raise
                    writer.target, writer.earlier = folder, old_lock
                    if old_lock is None or not is_run_folder(folder):
                        writer.swap()        # nothing there to keep (a new or empty folder): in place at once
                    old_lock = None
                    return writer
            # In place: the old folder's own lock is held; clear it, the manifest first so that it stops
            # claiming to be a run, then build the new run inside.
            if old_lock is None:
                folder.mkdir(parents=True, exist_ok=True)
                old_lock = FolderLock.acquire(folder, command)
            _clear(folder)
            writer = cls._build(folder, folder, old_lock, scene_toml, specs, grid)
            old_lock = None
            return writer
        finally:
            if old_lock is not None:
                old_lock.release(remove=True)

    target: Path | None = None        # where the run goes once swapped in (None: it is there already)
    earlier: FolderLock | None = None  # the lock of the earlier run kept there until the swap

    @property
    def pending(self) -> bool:
        """True while the run is still built beside its folder (an earlier run there is kept until the swap)."""
        return self.target is not None

    def swap(self) -> None:
        """Move the run from beside its folder into it: renamed in (a new or empty folder), or exchanged with the
        earlier run in one atomic ``renameat2``, which then goes. The streams' open files move with it."""
        if self.target is None:
            return
        staging, folder = self.folder, self.target
        if self.earlier is None and folder.is_dir() and not os.listdir(folder):
            folder.rmdir()
        if self.earlier is None and not folder.exists():
            os.rename(staging, folder)
        else:
            _exchange(staging, folder)
        self.folder, self.target = folder, None
        for stream in self.streams.values():
            stream.path = folder / CHECKPOINT / stream.path.name
        self.lock.path = folder / LOCK
        fsync_path(folder.parent)
        if self.earlier is not None:
            self.earlier.release()
            self.earlier = None
            _remove_tree(staging)           # the earlier run, swapped out

    def discard(self) -> Path:
        """Drop a run that was never swapped in (stopped before its first checkpoint past t = 0): the earlier
        run stays as it was. Returns the folder that holds it."""
        folder = self.target
        self.close_streams()
        if self.lock is not None:
            self.lock.release()
            self.lock = None
        _remove_tree(self.folder)
        if self.earlier is not None:
            self.earlier.release(remove=True)
            self.earlier = None
        self.folder, self.target = folder, None
        return folder

    @classmethod
    def _build(cls, where: Path, folder: Path, lock: FolderLock, scene_toml: str, specs: dict, grid: dict):
        from .. import __version__

        with atomic_output(where / SCENE) as tmp:
            tmp.write_text(scene_toml, encoding="utf-8")
        (where / CHECKPOINT).mkdir(exist_ok=True)
        streams = {name: Stream(where / CHECKPOINT / f"{name}.npy", shape) for name, shape in specs.items()}
        for s in streams.values():
            s.sync()
        manifest = {
            "format": FORMAT,
            "status": INCOMPLETE,
            "message": "",
            "ropesim_version": __version__,
            "scene_sha256": scene_hash(scene_toml),
            **grid,
            "arrays": {name: {"per_frame": list(shape), "dtype": "<f8"} for name, shape in specs.items()},
            "checkpoint": None,
            "files": {},
            "writer": {"pid": os.getpid(), "started": time.strftime("%Y-%m-%d %H:%M:%S")},
        }
        write_json_durable(where / MANIFEST, manifest)
        fsync_path(where / CHECKPOINT)
        return cls(folder, lock, manifest, streams)

    @classmethod
    def reopen(cls, folder: Path, command: str = "") -> "RunWriter":
        """Lock ``folder`` and open its run to continue from the last checkpoint (see :func:`resume_plan`)."""
        from .guard import WriteRefused, follow

        shown = Path(folder)
        try:
            folder = follow(shown, "--resume")
        except WriteRefused as exc:
            raise RunFolderError(str(exc)) from None
        if not folder.is_dir():
            raise RunFolderError(f"{shown}: no such run folder")
        if read_manifest(folder) is None:    # before the lock: a folder that is no run is left as it was
            raise RunFolderError(f"{shown}: has no manifest.json (not a run folder, or written by an older "
                                 f"ropesim), so it cannot be resumed; run the scene again")
        lock = FolderLock.acquire(folder, command)
        try:
            manifest = read_manifest(folder)
            if manifest is None:
                raise RunFolderError(f"{shown}: has no manifest.json, so it cannot be resumed; run the scene again")
            _remove_own_temporaries(folder)
            if manifest["status"] in FINISHED:   # streams left by a writer killed after its final commit
                _remove_tree(folder / CHECKPOINT)
            return cls(folder, lock, manifest, {})
        except BaseException:
            lock.release(remove=True)
            raise

    # -- continuing -------------------------------------------------------------------------------------

    def load_checkpoint(self, specs: dict[str, tuple]) -> tuple[dict[str, np.ndarray], dict]:
        """Open the streams at the last checkpoint (a torn tail cut off) and return (integrator state, its
        record in the manifest). A finished run's frames are copied back into streams first (an extension)."""
        m = self.manifest
        mine = {name: tuple(a["per_frame"]) for name, a in m["arrays"].items()}
        if mine != {n: tuple(s) for n, s in specs.items()}:
            raise RunFolderError(f"{self.folder}: its frames hold arrays {sorted(mine)} of other shapes than this "
                                 f"ropesim writes ({sorted(specs)}); run the scene again")
        if m["status"] in FINISHED:
            return self._reopen_finished(specs)
        cp = m.get("checkpoint")
        if not cp:
            raise RunFolderError(f"{self.folder}: was stopped before its first checkpoint; nothing to resume, "
                                 f"run the scene again")
        for name, shape in specs.items():
            path = self.folder / CHECKPOINT / f"{name}.npy"
            open_stream_array(path, shape, np.float64, cp["frames"], cp["crc32"][name])   # verifies
            self.streams[name] = Stream(path, shape, count=cp["frames"], crc=cp["crc32"][name], create=False)
        state = self._read_state(self.folder / cp["state"])
        for stray in (self.folder / CHECKPOINT).glob("state-*.npz"):   # a state written after the last commit
            if stray.name != Path(cp["state"]).name:
                stray.unlink(missing_ok=True)
        for stray in (self.folder / CHECKPOINT).glob(".*"):
            stray.unlink(missing_ok=True)
        self.state_file = cp["state"]
        return state, cp

    def _read_state(self, path: Path) -> dict:
        try:
            with np.load(path, allow_pickle=False) as npz:
                return {name: npz[name] for name in npz.files}
        except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
            raise RunFolderError(f"{path}: the checkpoint's integrator state is unreadable ({exc}); "
                                 f"run the scene again") from None

    def _reopen_finished(self, specs: dict[str, tuple]) -> tuple[dict, dict]:
        """A completed run to extend: its frames go back into streams, its final state is the checkpoint."""
        folder = self.folder
        state = self._read_state(folder / STATE)
        arrays = memmap_npz(folder / TRAJECTORY)
        with np.load(folder / LEDGER) as npz:
            from ..integrate.health import LEDGER_COLUMNS

            frames = len(npz["t"])
            ledger = np.stack([npz[c] if c in npz.files else np.zeros(frames) for c in LEDGER_COLUMNS], axis=1)
        arrays["ledger"] = ledger
        cp_dir = folder / CHECKPOINT
        _remove_tree(cp_dir)
        cp_dir.mkdir()
        for name, shape in specs.items():
            s = Stream(cp_dir / f"{name}.npy", shape)
            a = arrays[name]
            for start in range(0, len(a), 4096):
                s.append(np.asarray(a[start:start + 4096]))
            self.streams[name] = s
        counts = {s.count for s in self.streams.values()}
        if len(counts) != 1:
            raise RunFolderError(f"{folder}: its arrays hold different numbers of frames; run the scene again")
        step = int(state["step"])
        old = self.manifest.get("checkpoint") or {}
        (folder / SUMMARY).unlink(missing_ok=True)       # it must never say completed beside an unfinished run
        self.checkpoint(state, step=step, t=float(arrays["t"][-1]),
                        extra={k: old[k] for k in ("wall_time_s", "compile_time_s") if k in old})
        for name in (TRAJECTORY, LEDGER, STATE):
            (folder / name).unlink(missing_ok=True)
        return state, self.manifest["checkpoint"]

    def drop_last_frames(self, keep: int) -> None:
        """Cut every stream back to ``keep`` frames (an extension drops the old run's off-grid last frame)."""
        for name, s in self.streams.items():
            if s.count > keep:
                s.close()
                a = open_stream_array(s.path, s.per_frame, s.dtype, keep, verify=False)
                crc = _crc_of(s.path, HEADER_BYTES, keep * s.row_bytes)
                del a
                self.streams[name] = Stream(s.path, s.per_frame, count=keep, crc=crc, create=False)

    # -- writing ----------------------------------------------------------------------------------------

    @property
    def count(self) -> int:
        return min(s.count for s in self.streams.values()) if self.streams else 0

    def append(self, arrays: dict[str, np.ndarray]) -> None:
        """Write frames (no fsync: the next checkpoint makes them durable)."""
        try:
            for name, s in self.streams.items():
                s.append(arrays[name])
        except OSError as exc:
            if exc.errno in (errno.ENOSPC, errno.EDQUOT):
                for s in self.streams.values():     # give back the space of the torn chunk: the commit stands
                    try:
                        os.ftruncate(s.fd, HEADER_BYTES + s.synced * s.row_bytes)
                        os.lseek(s.fd, 0, os.SEEK_END)
                        s.count, s.crc = s.synced, s.synced_crc
                    except OSError:
                        pass
                raise self.disk_full(self.bytes_to_go()) from None
            raise

    expected_frames = 0    # the frames the whole run saves (set by ropesim.run), for "how much is needed"

    def bytes_to_go(self) -> int:
        """Bytes still to write: the frames to come in the streams, then every frame once more in the npz."""
        row = sum(s.row_bytes for s in self.streams.values())
        frames = max(self.expected_frames, self.count)
        return (frames - self.count) * row + frames * row

    def disk_full(self, needed: int, what: str = "the rest of the run") -> DiskFull:
        cp = self.manifest.get("checkpoint")
        if self.pending:
            return DiskFull(f"{self.target}: the disk is full: writing {what} needs about {human(needed)} and "
                            f"{human(free_bytes(self.folder))} is free; the new run is dropped and the earlier run "
                            f"in {self.target} is kept as it was")
        kept = (f"every frame up to the last checkpoint (t = {cp['t']:.6g} s, {cp['frames']} frames) is kept in "
                f"{self.folder}; free some space and `ropesim run --resume {self.folder}` continues it"
                if cp else f"nothing was checkpointed yet in {self.folder}")
        return DiskFull(f"{self.folder}: the disk is full: writing {what} needs about {human(needed)} and "
                        f"{human(free_bytes(self.folder))} is free; {kept}")

    def checkpoint(self, state: dict[str, np.ndarray], step: int, t: float, extra: dict | None = None,
                   status: str = INCOMPLETE, message: str = "") -> None:
        """Commit: the frames written so far and ``state`` become durable, then the manifest names them."""
        try:
            for s in self.streams.values():
                s.sync()
            name = f"{CHECKPOINT}/state-{step:012d}.npz"
            with atomic_output(self.folder / name) as tmp:
                with open(tmp, "wb") as fh:
                    np.savez(fh, **state)
            m = self.manifest
            m["status"], m["message"] = status, message
            m["checkpoint"] = {"step": int(step), "t": float(t), "frames": self.count, "state": name,
                               "crc32": {n: s.crc for n, s in self.streams.items()}, **(extra or {}),
                               "written": time.strftime("%Y-%m-%d %H:%M:%S")}
            write_json_durable(self.folder / MANIFEST, m)
        except OSError as exc:
            if exc.errno in (errno.ENOSPC, errno.EDQUOT):
                raise self.disk_full(sum(a.nbytes for a in state.values()) + 4096, "a checkpoint") from None
            raise
        old, self.state_file = self.state_file, name
        if old and old != name:
            (self.folder / old).unlink(missing_ok=True)
        if self.pending and t > 0:
            self.swap()      # the new run has frames of its own now: it takes the earlier run's place

    def arrays(self) -> dict[str, np.ndarray]:
        """Every frame written so far, memory-mapped read-only (for the summary)."""
        for s in self.streams.values():
            os.pwrite(s.fd, npy_header((s.count, *s.per_frame), s.dtype), 0)
        return {name: open_stream_array(s.path, s.per_frame, s.dtype, s.count, verify=False)
                for name, s in self.streams.items()}

    def finish(self, status: str, state: dict, files: dict[str, dict[str, np.ndarray]], summary: dict,
               message: str = "") -> None:
        """A finished run: write ``files`` (name -> arrays, as npz), the final state and the summary, then commit
        the manifest with ``status``; the checkpoint streams go, and the lock with them.

        Nothing can run after a ``kill -9``: one that lands between the commit and the lock's removal (a few
        milliseconds) leaves the finished run whole beside a stale ``.lock`` and perhaps the streams. Readers
        ignore both, nobody holds that lock, and the next writer of the folder removes them (:meth:`reopen`)."""
        self.swap()
        try:
            for name, arrays in files.items():
                write_npz_atomic(self.folder / name, arrays)
            with atomic_output(self.folder / STATE) as tmp:
                with open(tmp, "wb") as fh:
                    np.savez(fh, **state)
            write_json_atomic(self.folder / SUMMARY, summary)
        except OSError as exc:
            if exc.errno in (errno.ENOSPC, errno.EDQUOT):
                needed = sum(int(np.asarray(a).nbytes) for arrays in files.values() for a in arrays.values())
                raise self.disk_full(needed, "trajectory.npz and ledger.npz") from None
            raise
        m = self.manifest
        m["status"], m["message"] = status, message
        m["files"] = {name: (self.folder / name).stat().st_size for name in (*files, STATE, SUMMARY, SCENE)}
        write_json_durable(self.folder / MANIFEST, m)
        self.close_streams()
        _remove_tree(self.folder / CHECKPOINT)
        self.lock.release(remove=True)     # at once: the folder is whole; the fsync below makes both durable
        self.lock = None
        fsync_path(self.folder)

    def mark(self, status: str, message: str, summary: dict | None = None) -> None:
        """Record how an unfinished run stopped (interrupted) beside its last checkpoint; the summary first. A
        run stopped before it replaced an earlier run is dropped instead (:meth:`discard`)."""
        if self.pending:
            self.discard()
            return
        if summary is not None:
            write_json_atomic(self.folder / SUMMARY, summary)
        self.manifest["status"], self.manifest["message"] = status, message
        write_json_durable(self.folder / MANIFEST, self.manifest)

    def close_streams(self) -> None:
        for s in self.streams.values():
            s.close()

    def close(self) -> None:
        if self.pending:      # failed before it replaced the earlier run (a full disk, say): that one stays
            self.discard()
            return
        self.close_streams()
        if self.lock is not None:
            self.lock.release(remove=True)
            self.lock = None


def _same_device(a: Path, b: Path) -> bool:
    try:
        return os.stat(a).st_dev == os.stat(b).st_dev
    except OSError:
        return True


def _clear(folder: Path) -> None:
    """Empty a run folder in place (its lock file stays): the manifest and summary first, the scene next."""
    for name in (MANIFEST, SUMMARY, SCENE):
        (folder / name).unlink(missing_ok=True)
    for entry in os.listdir(folder):
        if entry == LOCK:
            continue
        path = folder / entry
        if path.is_dir() and not path.is_symlink():
            _remove_tree(path)
        else:
            path.unlink(missing_ok=True)
    fsync_path(folder)
