"""The run folder on disk: ``trajectory.npz``, ``scene.toml`` and ``summary.json``.

``trajectory.npz`` holds ``t`` (F,) [s], ``x`` (F, N, D) [m] and ``v`` (F, N, D) [m/s], every saved frame from
t = 0. It is an ordinary uncompressed ``.npz`` (``numpy.load`` reads it), written so that each array can also be
memory-mapped: :meth:`Trajectory.open` reads frames lazily, so a trajectory of any size can be analysed.

Frames stream to memory-mapped ``.npy`` files in a hidden folder while the run goes on; the ``.npz`` is then
assembled beside its final name and moved into place, so a reader never sees half a file.
"""

from __future__ import annotations

import json
import shutil
import tempfile
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .atomic import atomic_output

TRAJECTORY, SCENE, SUMMARY = "trajectory.npz", "scene.toml", "summary.json"
ARRAYS = ("t", "x", "v")
DERIVED = ("tension", "strain", "support")   # per frame, derived from t, x and v as they are stored


class RunFolderError(ValueError):
    """A run folder that cannot be read; ``str()`` is one line for the user."""


def write_text_atomic(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` via a temporary file in the same folder and an atomic rename."""
    with atomic_output(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def write_json_atomic(path: Path, data: dict) -> None:
    write_text_atomic(path, json.dumps(data, indent=2, sort_keys=False) + "\n")


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
    """Write an uncompressed, memory-mappable ``.npz`` atomically, streaming each array in chunks."""
    with atomic_output(path) as tmp:
        with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_STORED, allowZip64=True) as zf:
            for name, arr in arrays.items():
                with zf.open(f"{name}.npy", "w", force_zip64=True) as fh:
                    _write_npy(fh, arr)


def _memmap_npz(path: Path) -> dict[str, np.ndarray]:
    """Memory-map every array of an uncompressed ``.npz`` (as ``write_npz_atomic`` makes them)."""
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
            fh.seek(info.header_offset + 30 + name_len + extra_len)
            version = np.lib.format.read_magic(fh)
            if version == (1, 0):
                shape, fortran, dtype = np.lib.format.read_array_header_1_0(fh)
            else:
                shape, fortran, dtype = np.lib.format.read_array_header_2_0(fh)
            offset = fh.tell()
            if np.prod(shape) == 0:
                out[name] = np.zeros(shape, dtype=dtype)
            else:
                out[name] = np.memmap(path, dtype=dtype, mode="r", offset=offset, shape=shape,
                                      order="F" if fortran else "C")
    return out


class FrameStore:
    """Where a run's saved frames go: memory for :func:`ropesim.simulate`, disk for a run folder.

    With ``derive`` (a function of the frames' t (k,), x and v (k, N, D) returning named (k, ...) arrays, and
    ``shapes`` their per-frame shapes) each appended chunk also stores what it derives: the segments' tension
    and strain, the supports' forces (:mod:`ropesim.model.tension`).
    """

    def __init__(self, n_frames: int, nodes: int, dim: int, folder: Path | None = None, derive=None,
                 shapes: dict[str, tuple] | None = None):
        self.count = 0
        self.folder = folder
        self.derive = derive
        self.names = ARRAYS + tuple(shapes or {})
        shape = {"t": (n_frames,), "x": (n_frames, nodes, dim), "v": (n_frames, nodes, dim),
                 **{name: (n_frames, *s) for name, s in (shapes or {}).items()}}
        if folder is None:
            self._tmp = None
            for name in self.names:
                setattr(self, name, np.zeros(shape[name]))
        else:
            folder.mkdir(parents=True, exist_ok=True)
            self._tmp = Path(tempfile.mkdtemp(prefix=".frames-", dir=folder))
            open_mm = np.lib.format.open_memmap
            for name in self.names:
                setattr(self, name, open_mm(self._tmp / f"{name}.npy", mode="w+", dtype=np.float64,
                                            shape=shape[name]))

    def append(self, t: np.ndarray, x_dn: np.ndarray, v_dn: np.ndarray) -> None:
        """Append frames given in kernel layout (F, D, N)."""
        k = len(t)
        if k == 0:
            return
        end = self.count + k
        self.t[self.count:end] = t
        self.x[self.count:end] = np.swapaxes(x_dn, 1, 2)
        self.v[self.count:end] = np.swapaxes(v_dn, 1, 2)
        if self.derive is not None:
            for name, values in self.derive(self.t[self.count:end], self.x[self.count:end],
                                            self.v[self.count:end]).items():
                getattr(self, name)[self.count:end] = values
        self.count = end

    def arrays(self) -> dict[str, np.ndarray]:
        return {name: getattr(self, name)[:self.count] for name in self.names}

    def finish(self) -> None:
        """Write ``trajectory.npz`` (frames so far) atomically and drop the streaming files."""
        if self.folder is None:
            return
        try:
            write_npz_atomic(self.folder / TRAJECTORY, self.arrays())
        finally:
            self.discard()

    def discard(self) -> None:
        if self._tmp is not None:
            for name in self.names:
                arr = getattr(self, name)
                if isinstance(arr, np.memmap):
                    arr._mmap.close()
            shutil.rmtree(self._tmp, ignore_errors=True)
            self._tmp = None


@dataclass
class Trajectory:
    """Saved frames of one run: ``t`` (F,) [s], ``x`` and ``v`` (F, N, D) [m, m/s], each segment's ``tension``
    [N] and ``strain`` (F, S), the force each support exerts on its held node, ``support`` (F, H, D) [N] (None
    without held nodes), with its scene and summary (the derived arrays are None for a run folder written
    before ropesim stored them).

    From :func:`ropesim.simulate` the arrays are in memory; from :meth:`open` they are memory-mapped.
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    scene: object
    summary: dict = field(default_factory=dict)
    folder: Path | None = None
    tension: np.ndarray | None = None
    strain: np.ndarray | None = None
    support: np.ndarray | None = None

    @property
    def frames(self) -> int:
        return len(self.t)

    @property
    def nodes(self) -> int:
        return self.x.shape[1]

    @classmethod
    def open(cls, folder: str | Path) -> "Trajectory":
        """Read a run folder lazily; raises :class:`RunFolderError` with one clear line if it is unusable."""
        from ..scene.loader import SceneError, load_scene

        folder = Path(folder)
        if not folder.is_dir():
            raise RunFolderError(f"{folder}: no such run folder (make one with `ropesim run SCENE.toml`)")
        for name in (TRAJECTORY, SCENE):
            if not (folder / name).is_file():
                raise RunFolderError(f"{folder}: not a run folder: {name} is missing")
        try:
            scene = load_scene(folder / SCENE)
        except SceneError as exc:
            raise RunFolderError(f"{folder}: its scene.toml is not valid: {exc}") from None
        try:
            arrays = _memmap_npz(folder / TRAJECTORY)
        except (zipfile.BadZipFile, ValueError, OSError, EOFError) as exc:
            raise RunFolderError(f"{folder / TRAJECTORY}: corrupt or unreadable ({exc})") from None
        missing = [a for a in ARRAYS if a not in arrays]
        if missing:
            raise RunFolderError(f"{folder / TRAJECTORY}: missing arrays {', '.join(missing)}")
        t, x, v = arrays["t"], arrays["x"], arrays["v"]
        n, d = scene.rope.nodes, scene.dimension
        if t.ndim != 1 or x.shape != (len(t), n, d) or v.shape != x.shape or len(t) == 0:
            raise RunFolderError(f"{folder / TRAJECTORY}: arrays do not match the scene: t {t.shape}, "
                                 f"x {x.shape}, v {v.shape}, expected (F,), (F, {n}, {d})")
        derived = {name: arrays.get(name) for name in DERIVED}
        for name, values in derived.items():
            if values is not None and (values.ndim < 2 or values.shape[0] != len(t)):
                raise RunFolderError(f"{folder / TRAJECTORY}: {name} has shape {values.shape}, not one row per "
                                     f"frame ({len(t)})")
        summary = {}
        if (folder / SUMMARY).is_file():
            try:
                summary = json.loads((folder / SUMMARY).read_text(encoding="utf-8"))
            except (ValueError, OSError):
                summary = {}
        return cls(t=t, x=x, v=v, scene=scene, summary=summary, folder=folder, **derived)

    # Other tools and notebooks (ropesim.io.export, ropesim.render.notebook).
    def export(self, to: str, out: str | Path | None = None):
        """Write this run for other tools: ``to`` "vtk" (a ParaView series) or "csv" (see ropesim.io.export)."""
        from .export import export
        return export(self, to, out)

    def animate(self, **options):
        """An animation that plays inline in Jupyter (an MP4 in a <video>); options as `ropesim animate`'s."""
        from ..render.notebook import inline_animation
        return inline_animation(self, **options)

    def _repr_html_(self) -> str:
        from ..render.notebook import summary_html
        return summary_html(self)

    def __repr__(self) -> str:
        return (f"Trajectory(scene={self.scene.name!r}, {self.summary.get('status', 'completed')}, "
                f"{self.frames} frames, t = {float(self.t[0]):.6g} .. {float(self.t[-1]):.6g} s, "
                f"{self.nodes} nodes, {self.x.shape[2]}-D, {'in memory' if self.folder is None else self.folder})")
