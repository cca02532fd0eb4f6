"""`ropesim export`: a run folder's trajectory in the formats other tools read.

vtk     A VTK series for ParaView (and VisIt, or anything that reads VTK XML): one ``.vtu`` unstructured grid
        per saved frame, the nodes as points joined by line cells (the rope, closed for a loop), with point
        data ``velocity`` [m/s] and ``speed`` [m/s] and cell data ``tension`` [N] and ``strain`` [-] (segment j
        is cell j); the supports as a point set of their own (part 1 of each time step: one vertex per held
        node, point data ``support_force`` [N], the force the support exerts on its node, and its magnitude);
        and a ``.pvd`` collection listing each file with its time, which ParaView opens as one time-dependent
        dataset (SI units throughout, as ParaView expects). Written with meshio (the ``export`` extra): small,
        pure Python on numpy, and it writes VTK's XML formats with zlib-compressed binary arrays, which we
        would otherwise have to write (and get right) ourselves; pyvista would do it too, but pulls in all of
        VTK (well over 100 MB) to write a few small files.
csv     One CSV file in long format for spreadsheets: a header row naming each column with its unit, then a
        row per node per frame, ``t [s], node, x [m], y [m](, z [m]), vx [m/s], vy [m/s](, vz [m/s])``, every
        value written in full precision (it reads back bit for bit). Beside it two tables of the forces (in kN
        where they reach kilonewtons, the unit in each header): ``<stem>_tension_history.csv``, a row per
        frame with the end tensions and each support's force, and ``<stem>_tension_range.csv``, a row per
        segment with its position along the rope and its tension's min, max, mean and std over the run (or the
        window ``--from``/``--to``). Written with numpy alone.

NetCDF is not offered: through xarray it needs xarray, pandas, h5netcdf and h5py, about 120 MB installed (meshio
is 2 MB), to write the three arrays that ``trajectory.npz`` already holds, in a file no smaller (215 KB against
205 KB for the 3 s helicopter run; CSV 585 KB in 0.04 s, VTK 302 files, 718 KB in 0.15 s). numpy reads the npz
and xarray users wrap it in one call: ``xr.Dataset({"x": (("time", "node", "axis"), traj.x)}, coords={"time":
traj.t})``.

Every output is written beside its final name and moved into place only when complete.
"""

from __future__ import annotations

import os
import shutil
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .atomic import atomic_output
from .guard import PVD_MARK, output_file, output_folder

FORMATS = ("vtk", "csv")
EXTRAS = {"vtk": ("meshio", "export")}  # format: (module it needs, pip extra that installs it)
NOT_OFFERED = {"netcdf": "NetCDF would need xarray, pandas and h5py (about 120 MB) to hold the three arrays "
                         "trajectory.npz already holds (numpy reads it); use --to csv or --to vtk"}
AXES = "xyz"
FRAME_ROWS = 200_000  # CSV rows (node-frames) formatted at a time, so a long run is never loaded at once


class ExportError(ValueError):
    """An export that cannot be done as asked; ``str()`` is one line naming the option and what is allowed."""


@dataclass(frozen=True)
class Exported:
    """What :func:`export` wrote: the file to open, every file written, their total size and the time taken."""

    path: Path
    files: int
    bytes: int
    seconds: float
    frames: int = 0


def default_path(folder: Path, fmt: str) -> Path:
    """Where a format goes by default, inside the run folder."""
    return folder / {"vtk": "vtk", "csv": "trajectory.csv"}[fmt]


def require(fmt: str):
    """Import the library a format needs, or an ExportError naming the extra to install."""
    if fmt not in EXTRAS:
        return None
    module, extra = EXTRAS[fmt]
    try:
        return __import__(module)
    except ImportError:
        from ..install import install_hint

        raise ExportError(f"--to {fmt}: needs {module}, which is not installed; {install_hint(extra)}") from None


def export(traj, fmt: str, out: str | Path | None = None, start: float | None = None,
           stop: float | None = None) -> Exported:
    """Write ``traj`` (a :class:`ropesim.Trajectory`) as ``fmt`` ("vtk" or "csv") to ``out``.

    out: a folder for vtk (it gets ``<scene>.pvd`` and one ``.vtu`` per frame), a file for csv (and its two
    force tables beside it); by default inside the run folder (vtk/, trajectory.csv). ``start``/``stop`` [s]
    keep the frames in that window (``--from``/``--to``). Raises :class:`ExportError` (one line) for a bad
    request.
    """
    if fmt in NOT_OFFERED:
        raise ExportError(f"--to {fmt}: not offered: {NOT_OFFERED[fmt]}")
    if fmt not in FORMATS:
        raise ExportError(f"--to {fmt}: unknown format; use one of {', '.join(FORMATS)}")
    if out is None:
        if traj.folder is None:
            raise ExportError("--out: give an output path (this trajectory has no run folder)")
        out = default_path(Path(traj.folder), fmt)
    out = Path(out)
    library = require(fmt)
    from ..analysis.tension import frame_window

    try:
        frames = frame_window(traj.t, start, stop)
    except ValueError as exc:
        raise ExportError(str(exc)) from None
    began = time.perf_counter()
    if fmt == "vtk":
        path, files = _vtk(traj, output_folder(out, "vtk"), library, frames)
    else:
        real = output_file(out)
        tables = [] if traj.tension is None else [(output_file(history_path(real)), _history),
                                                   (output_file(range_path(real)), _range)]
        files = [real]
        with atomic_output(real) as tmp:
            _csv(traj, tmp, frames)
        for table, write in tables:
            with atomic_output(table) as tmp:
                write(traj, tmp, frames)
            files.append(table)
        path = out
    return Exported(path=path, files=len(files), bytes=sum(f.stat().st_size for f in files),
                    seconds=time.perf_counter() - began, frames=frames.stop - frames.start)


def history_path(out: Path) -> Path:
    """Where the CSV export's time history of the forces goes, beside ``out``."""
    return out.with_name(f"{out.stem}_tension_history.csv")


def range_path(out: Path) -> Path:
    """Where the CSV export's tension range along the rope goes, beside ``out``."""
    return out.with_name(f"{out.stem}_tension_range.csv")


def _columns(dim: int) -> list[str]:
    return ["t [s]", "node", *(f"{a} [m]" for a in AXES[:dim]), *(f"v{a} [m/s]" for a in AXES[:dim])]


def _csv(traj, path: Path, window: slice) -> None:
    _, nodes, dim = traj.x.shape
    fmt = ["%.17g", "%d"] + ["%.17g"] * (2 * dim)
    block = max(1, FRAME_ROWS // nodes)
    with open(path, "w", encoding="utf-8", newline="") as fh:
        fh.write(",".join(_columns(dim)) + "\n")
        for start in range(window.start, window.stop, block):
            stop = min(window.stop, start + block)
            t = np.repeat(np.asarray(traj.t[start:stop]), nodes)
            node = np.tile(np.arange(nodes), stop - start)
            xv = np.concatenate([np.asarray(traj.x[start:stop]), np.asarray(traj.v[start:stop])], axis=2)
            np.savetxt(fh, np.column_stack([t, node, xv.reshape(-1, 2 * dim)]), fmt=fmt, delimiter=",")


def _held_nodes(traj) -> np.ndarray:
    from ..model.build import build

    return build(traj.scene, solve=False).held_idx


def _history(traj, path: Path, window: slice) -> None:
    """A row per frame: t [s], the tension at both ends and each support's force components, in N or kN."""
    from ..analysis.tension import force_unit

    dim = traj.x.shape[2]
    held = _held_nodes(traj) if traj.support is not None else np.zeros(0, dtype=int)
    ends = np.asarray(traj.tension[window][:, [0, -1]])
    supports = np.asarray(traj.support[window]).reshape(len(ends), -1) if held.size else np.zeros((len(ends), 0))
    unit, scale = force_unit(max(float(np.abs(ends).max(initial=0.0)), float(np.abs(supports).max(initial=0.0))))
    last = traj.tension.shape[1] - 1
    columns = ["t [s]", f"tension segment 0 [{unit}]", f"tension segment {last} [{unit}]"]
    columns += [f"support node {i} F{a} [{unit}]" for i in held for a in AXES[:dim]]
    table = np.column_stack([np.asarray(traj.t[window]), ends / scale, supports / scale])
    with open(path, "w", encoding="utf-8", newline="") as fh:
        fh.write(",".join(columns) + "\n")
        np.savetxt(fh, table, fmt="%.17g", delimiter=",")


def _range(traj, path: Path, window: slice) -> None:
    """A row per segment: its index, its middle's distance along the rope at rest [m], and its tension's min,
    max, mean and std over the window, in N or kN."""
    from ..analysis.tension import force_unit, window_statistics

    stats = window_statistics(traj.tension, window)
    unit, scale = force_unit(float(np.abs(stats["max"]).max(initial=0.0)))
    segments = traj.tension.shape[1]
    along = (np.arange(segments) + 0.5) * traj.scene.rope.segment_length
    columns = ["segment", "s [m]", *(f"{name} tension [{unit}]" for name in ("min", "max", "mean", "std"))]
    table = np.column_stack([np.arange(segments), along, *(stats[k] / scale for k in ("min", "max", "mean", "std"))])
    with open(path, "w", encoding="utf-8", newline="") as fh:
        fh.write(",".join(columns) + "\n")
        np.savetxt(fh, table, fmt=["%d"] + ["%.17g"] * 5, delimiter=",")


def _vtk(traj, out: Path, meshio, window: slice) -> tuple[Path, list[Path]]:
    """One .vtu per frame and a .pvd listing them, built in a temporary folder and moved into place whole
    (``out``: missing, empty, or an earlier export, as :func:`ropesim.io.guard.output_folder` checked)."""
    from xml.sax.saxutils import quoteattr

    out = Path(os.path.abspath(out))     # "." and ".." by name, so the temporary folder goes beside it
    _, nodes, dim = traj.x.shape
    segments = np.column_stack([np.arange(nodes - 1), np.arange(1, nodes)])
    if traj.scene.rope.closed:
        segments = np.vstack([segments, [[nodes - 1, 0]]])
    name = traj.scene.name
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=out.parent))
    try:
        entries = []
        width = len(str(window.stop - 1))
        held = _held_nodes(traj) if traj.support is not None else np.zeros(0, dtype=int)
        for i in range(window.start, window.stop):
            x, v = (np.zeros((nodes, 3)) for _ in range(2))
            x[:, :dim], v[:, :dim] = traj.x[i], traj.v[i]
            file = f"{name}_{i:0{width}d}.vtu"
            cells = {} if traj.tension is None else {"tension": [np.asarray(traj.tension[i], dtype=float)],
                                                     "strain": [np.asarray(traj.strain[i], dtype=float)]}
            mesh = meshio.Mesh(x, [("line", segments)], cell_data=cells,
                               point_data={"velocity": v, "speed": np.linalg.norm(v, axis=1)})
            meshio.write(tmp / file, mesh, file_format="vtu")
            when = float(traj.t[i])
            entries.append(f'    <DataSet timestep="{when!r}" part="0" file={quoteattr(file)}/>')
            if held.size:
                force = np.zeros((held.size, 3))
                force[:, :dim] = traj.support[i]
                file = f"{name}_supports_{i:0{width}d}.vtu"
                points = meshio.Mesh(x[held], [("vertex", np.arange(held.size)[:, None])],
                                     point_data={"support_force": force,
                                                 "support_force_magnitude": np.linalg.norm(force, axis=1)})
                meshio.write(tmp / file, points, file_format="vtu")
                entries.append(f'    <DataSet timestep="{when!r}" part="1" file={quoteattr(file)}/>')
        (tmp / f"{name}.pvd").write_text(
            f'<?xml version="1.0"?>\n{PVD_MARK}\n<VTKFile type="Collection" version="0.1">\n  <Collection>\n'
            + "\n".join(entries) + "\n  </Collection>\n</VTKFile>\n", encoding="utf-8")
        os.chmod(tmp, 0o777 & ~_umask())
        _put_in_place(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return out / f"{name}.pvd", sorted(out.iterdir())


def _put_in_place(tmp: Path, out: Path) -> None:
    """Move the new series ``tmp`` to ``out``: renamed over an empty folder or none, swapped with an earlier
    export (which then goes); where a folder cannot be renamed (the current folder, a mount point) the earlier
    export's files are removed and the new ones moved in."""
    in_place = out.is_dir() and (out == Path.cwd() or os.path.ismount(out))   # a shell may stand in it
    if out.is_dir() and not in_place and not os.listdir(out):
        out.rmdir()
    if not out.exists():
        os.replace(tmp, out)
        return
    old = None if in_place else Path(tempfile.mkdtemp(prefix=f".{out.name}.old.", dir=out.parent))
    try:
        if old is None:
            raise OSError("in place")
        os.replace(out, old / out.name)
    except OSError:                      # every file there is ropesim's (the guard checked): replaced in place
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
        for entry in os.listdir(out):
            (out / entry).unlink()
        for entry in os.listdir(tmp):
            os.replace(tmp / entry, out / entry)
        shutil.rmtree(tmp, ignore_errors=True)
        return
    os.replace(tmp, out)
    shutil.rmtree(old, ignore_errors=True)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
