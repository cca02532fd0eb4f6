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
        window ``--from``/``--to``). Written with numpy alone. With a ``[sea]`` the positions table has a
        ``submerged`` column (each node's fraction below the surface) and ``<stem>_sea.csv`` a row per frame
        with each line's submerged fraction and the surface's elevation at each probe (VTK: point data
        ``submerged``).

NetCDF is not offered: through xarray it needs xarray, pandas, h5netcdf and h5py, about 120 MB installed (meshio
is 2 MB), to write the three arrays that ``trajectory.npz`` already holds, in a file no smaller (215 KB against
205 KB for the 3 s helicopter run; CSV 585 KB in 0.04 s, VTK 302 files, 718 KB in 0.15 s). numpy reads the npz
and xarray users wrap it in one call: ``xr.Dataset({"x": (("time", "node", "axis"), traj.x)}, coords={"time":
traj.t})``.

A system of lines: in VTK each line is a block of its own (a part of each time step, named by its id in the
``.pvd``: ParaView shows the lines as a multiblock dataset), then the supports, then the rigid bodies as glyphs
(one part: per body a vertex at its reference point, a line cell along each of its axes and a spoke to each of its
points; cell data ``body`` (its index) and ``part`` (0 the reference point, 1-3 the x, y, z axes, 4 a spoke);
point data, the same on every point of a body's glyph: ``orientation`` (w, x, y, z), ``body_velocity`` [m/s],
``body_angular_velocity`` [rad/s], and the force ``line_force`` [N] and moment ``line_moment`` [N m] about its
reference point that its lines put on it). In CSV the positions table has a ``line`` column and each node's
index along its line; the force history has each line's start and end tension and the supports' forces, named
by their points; the tension range a row per segment of each line; and ``<stem>_bodies.csv`` a row per body per
frame: its position, orientation (quaternion and the scene's angles), velocities and its lines' force and moment.

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
        if traj.scene.rigid_bodies and traj.body_x is not None:
            tables.append((output_file(bodies_path(real)), _bodies))
        if traj.line_submerged is not None:
            tables.append((output_file(sea_path(real)), _sea))
        files = [real]
        with atomic_output(real) as tmp:
            (_csv_lines if traj.scene.is_system else _csv)(traj, tmp, frames)
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


def bodies_path(out: Path) -> Path:
    """Where the CSV export's table of a system's rigid bodies goes, beside ``out``."""
    return out.with_name(f"{out.stem}_bodies.csv")


def _columns(dim: int) -> list[str]:
    return ["t [s]", "node", *(f"{a} [m]" for a in AXES[:dim]), *(f"v{a} [m/s]" for a in AXES[:dim])]


def _node_values(traj, start: int, stop: int) -> np.ndarray:
    """Frames start:stop's positions, velocities and (with a sea) submerged fractions, (k, N, columns)."""
    parts = [np.asarray(traj.x[start:stop]), np.asarray(traj.v[start:stop])]
    if traj.submerged is not None:
        parts.append(np.asarray(traj.submerged[start:stop])[..., None])
    return np.concatenate(parts, axis=2)


def _value_columns(traj) -> list[str]:
    dim = traj.x.shape[2]
    return _columns(dim)[2:] + (["submerged [-]"] if traj.submerged is not None else [])


def _csv(traj, path: Path, window: slice) -> None:
    _, nodes, dim = traj.x.shape
    columns = _value_columns(traj)
    fmt = ["%.17g", "%d"] + ["%.17g"] * len(columns)
    block = max(1, FRAME_ROWS // nodes)
    with open(path, "w", encoding="utf-8", newline="") as fh:
        fh.write(",".join(["t [s]", "node", *columns]) + "\n")
        for start in range(window.start, window.stop, block):
            stop = min(window.stop, start + block)
            t = np.repeat(np.asarray(traj.t[start:stop]), nodes)
            node = np.tile(np.arange(nodes), stop - start)
            values = _node_values(traj, start, stop)
            np.savetxt(fh, np.column_stack([t, node, values.reshape(-1, len(columns))]), fmt=fmt, delimiter=",")


def _csv_lines(traj, path: Path, window: slice) -> None:
    """A system's positions table: a row per node per frame, its line's id and its index along the line."""
    from ..model.layout import line_layouts

    _, nodes, dim = traj.x.shape
    lines = line_layouts(traj.scene)
    ids = np.array([_csv_text(line.id) for line in lines for _ in range(line.nodes)], dtype=object)
    along = np.concatenate([np.arange(line.nodes) for line in lines])
    columns = _value_columns(traj)
    fmt = ["%.17g", "%s", "%d"] + ["%.17g"] * len(columns)
    block = max(1, FRAME_ROWS // nodes)
    with open(path, "w", encoding="utf-8", newline="") as fh:
        fh.write(",".join(["t [s]", "line", "node", *columns]) + "\n")
        for start in range(window.start, window.stop, block):
            stop = min(window.stop, start + block)
            table = np.empty((stop - start, nodes, 3 + len(columns)), dtype=object)
            table[:, :, 0] = np.asarray(traj.t[start:stop])[:, None]
            table[:, :, 1] = ids
            table[:, :, 2] = along
            table[:, :, 3:] = _node_values(traj, start, stop)
            np.savetxt(fh, table.reshape(-1, table.shape[-1]), fmt=fmt, delimiter=",")


def sea_path(out: Path) -> Path:
    """Where the CSV export's table of the sea (submerged fractions, probes) goes, beside ``out``."""
    return out.with_name(f"{out.stem}_sea.csv")


def _sea(traj, path: Path, window: slice) -> None:
    """A row per frame: t [s], each line's submerged fraction of its length and, with probes, the surface's
    elevation above the mean level at each [m]."""
    from ..model.layout import line_layouts

    ids = [line.id for line in line_layouts(traj.scene)] if traj.scene.is_system else ["rope"]
    columns = ["t [s]"] + [_csv_text(f"submerged {i} [-]") for i in ids]
    parts = [np.asarray(traj.t[window])[:, None], np.asarray(traj.line_submerged[window])]
    if traj.probe_elevation is not None:
        axes = "x" if traj.scene.dimension == 2 else ("x y" if traj.frame.turned else "x z")
        columns += [_csv_text(f"eta at {axes} = {' '.join(f'{c:g}' for c in p)} [m]") for p in traj.scene.sea.probes]
        parts.append(np.asarray(traj.probe_elevation[window]))
    with open(path, "w", encoding="utf-8", newline="") as fh:
        fh.write(",".join(columns) + "\n")
        np.savetxt(fh, np.column_stack(parts), fmt="%.17g", delimiter=",")


def _csv_text(text: str) -> str:
    """``text`` as one CSV field: quoted where it holds a comma, a quote or a line break."""
    if any(c in text for c in ',"\n\r'):
        return '"' + text.replace('"', '""') + '"'
    return text


def _held_nodes(traj) -> np.ndarray:
    from ..model.build import build

    return build(traj.scene, solve=False).held_idx


def _history(traj, path: Path, window: slice) -> None:
    """A row per frame: t [s], the tension at both ends (of every line) and each support's force components, in
    N or kN."""
    from ..analysis.tension import force_unit, support_labels

    dim = traj.x.shape[2]
    held = _held_nodes(traj) if traj.support is not None else np.zeros(0, dtype=int)
    system = traj.scene.is_system
    if system:
        first = np.cumsum([0] + [line.segments for line in _layouts(traj)])
        ends = np.asarray(traj.tension[window][:, [k for a, b in zip(first[:-1], first[1:]) for k in (a, b - 1)]])
    else:
        ends = np.asarray(traj.tension[window][:, [0, -1]])
    supports = np.asarray(traj.support[window]).reshape(len(ends), -1) if held.size else np.zeros((len(ends), 0))
    unit, scale = force_unit(max(float(np.abs(ends).max(initial=0.0)), float(np.abs(supports).max(initial=0.0))))
    if system:
        columns = ["t [s]"] + [_csv_text(f"tension {line.id} {which} [{unit}]") for line in traj.scene.lines
                               for which in ("start", "end")]
        columns += [_csv_text(f"support {label} F{a} [{unit}]") for label in support_labels(traj.scene, held)
                    for a in AXES[:dim]]
    else:
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
    lines = _layouts(traj)
    index = np.concatenate([np.arange(line.segments) for line in lines])
    along = np.concatenate([(np.arange(line.segments) + 0.5) * line.segment_length for line in lines])
    columns = ["segment", "s [m]", *(f"{name} tension [{unit}]" for name in ("min", "max", "mean", "std"))]
    table = np.column_stack([index, along, *(stats[k] / scale for k in ("min", "max", "mean", "std"))])
    fmt = ["%d"] + ["%.17g"] * 5
    if traj.scene.is_system:    # each row named by its line; segments numbered from the line's start
        columns = ["line"] + columns
        table = np.column_stack([np.array([_csv_text(line.id) for line in lines for _ in range(line.segments)],
                                          dtype=object), table.astype(object)])
        fmt = ["%s"] + fmt
    with open(path, "w", encoding="utf-8", newline="") as fh:
        fh.write(",".join(columns) + "\n")
        np.savetxt(fh, table, fmt=fmt, delimiter=",")


def _bodies(traj, path: Path, window: slice) -> None:
    """A row per rigid body per frame: t [s], its id, its reference point [m], orientation (quaternion w, x, y, z
    and the scene's angles [deg]), velocity [m/s], angular velocity [rad/s], and the force and moment its lines
    put on it (about its reference point), in N and N m or kN and kN m."""
    from ..analysis.tension import force_unit

    dim = traj.x.shape[2]
    turns = AXES if dim == 3 else "z"
    bodies = [traj.body(b.id) for b in traj.scene.rigid_bodies]
    columns = {
        "position": [np.asarray(b.position[window]) for b in bodies],
        "quaternion": [np.asarray(b.quaternion[window]) for b in bodies],
        "angles": [b.angles[window] for b in bodies],
        "velocity": [np.asarray(b.velocity[window]) for b in bodies],
        "angular_velocity": [np.asarray(b.angular_velocity[window]) for b in bodies],
        "force": [b.force[window] for b in bodies],
        "moment": [b.moment[window] for b in bodies],
    }
    largest = max([float(np.abs(a).max(initial=0.0)) for a in columns["force"] + columns["moment"]])
    unit, scale = force_unit(largest)
    header = ["t [s]", "body", *(f"{a} [m]" for a in AXES[:dim]), "qw", "qx", "qy", "qz",
              *(f"angle {a} [deg]" for a in turns), *(f"v{a} [m/s]" for a in AXES[:dim]),
              *(f"w{a} [rad/s]" for a in turns), *(f"F{a} [{unit}]" for a in AXES[:dim]),
              *(f"M{a} [{unit} m]" for a in turns)]
    t = np.asarray(traj.t[window])
    rows = []
    for k, body in enumerate(bodies):
        numbers = np.column_stack([t, *(columns[name][k] for name in ("position", "quaternion", "angles",
                                                                     "velocity", "angular_velocity")),
                                   columns["force"][k] / scale, columns["moment"][k] / scale]).astype(object)
        rows.append(np.insert(numbers, 1, _csv_text(body.id), axis=1))
    table = np.stack(rows, axis=1).reshape(-1, len(header))   # frame after frame, the bodies in order
    with open(path, "w", encoding="utf-8", newline="") as fh:
        fh.write(",".join(header) + "\n")
        np.savetxt(fh, table, fmt=["%.17g", "%s"] + ["%.17g"] * (len(header) - 2), delimiter=",")


def _layouts(traj):
    from ..model.layout import line_layouts

    return line_layouts(traj.scene)


def _vtk(traj, out: Path, meshio, window: slice) -> tuple[Path, list[Path]]:
    """One .vtu per frame and part (the rope, or each line; the supports; the rigid bodies) and a .pvd listing
    them, built in a temporary folder and moved into place whole (``out``: missing, empty, or an earlier export,
    as :func:`ropesim.io.guard.output_folder` checked)."""
    from xml.sax.saxutils import quoteattr

    out = Path(os.path.abspath(out))     # "." and ".." by name, so the temporary folder goes beside it
    name = traj.scene.name
    parts = _vtk_parts(traj, meshio)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=out.parent))
    try:
        entries = []
        width = len(str(window.stop - 1))
        for i in range(window.start, window.stop):
            when = float(traj.t[i])
            for k, (label, stem, mesh_of) in enumerate(parts):
                file = f"{stem}_{i:0{width}d}.vtu"
                meshio.write(tmp / file, mesh_of(i), file_format="vtu")
                named = f" name={quoteattr(label)}" if traj.scene.is_system else ""
                entries.append(f'    <DataSet timestep="{when!r}" part="{k}"{named} file={quoteattr(file)}/>')
        (tmp / f"{name}.pvd").write_text(
            f'<?xml version="1.0"?>\n{PVD_MARK}\n<VTKFile type="Collection" version="0.1">\n  <Collection>\n'
            + "\n".join(entries) + "\n  </Collection>\n</VTKFile>\n", encoding="utf-8")
        os.chmod(tmp, 0o777 & ~_umask())
        _put_in_place(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return out / f"{name}.pvd", sorted(out.iterdir())


def _vtk_parts(traj, meshio) -> list[tuple[str, str, object]]:
    """(label, file stem, frame index -> meshio.Mesh) of each part of a time step: the rope (or each line of a
    system), the supports if any node is held, a system's rigid bodies if the run holds their states."""
    name = traj.scene.name
    dim = traj.x.shape[2]
    lines = _layouts(traj)
    segment0 = np.cumsum([0] + [line.segments for line in lines])

    def padded(a) -> np.ndarray:
        a = np.asarray(a, dtype=float)
        out = np.zeros(a.shape[:-1] + (3,))
        out[..., :dim] = a
        return out

    def line_mesh(k: int):
        line = lines[k]
        cells = np.column_stack([np.arange(line.nodes - 1), np.arange(1, line.nodes)])
        if line.closed:
            cells = np.vstack([cells, [[line.nodes - 1, 0]]])
        nodes, segments = slice(line.first, line.end), slice(segment0[k], segment0[k + 1])

        def mesh(i: int):
            x, v = padded(traj.x[i][nodes]), padded(traj.v[i][nodes])
            data = {} if traj.tension is None else {"tension": [np.asarray(traj.tension[i][segments], dtype=float)],
                                                    "strain": [np.asarray(traj.strain[i][segments], dtype=float)]}
            point = {"velocity": v, "speed": np.linalg.norm(v, axis=1)}
            if traj.submerged is not None:
                point["submerged"] = np.asarray(traj.submerged[i][nodes], dtype=float)
            return meshio.Mesh(x, [("line", cells)], cell_data=data, point_data=point)
        return mesh

    if traj.scene.is_system:
        stems = _file_stems(name, [line.id for line in lines])
        parts = [(line.id, stem, line_mesh(k)) for k, (line, stem) in enumerate(zip(lines, stems))]
    else:
        parts = [("rope", name, line_mesh(0))]
    held = _held_nodes(traj) if traj.support is not None else np.zeros(0, dtype=int)
    if held.size:
        def supports(i: int):
            force = padded(traj.support[i])
            return meshio.Mesh(padded(traj.x[i][held]), [("vertex", np.arange(held.size)[:, None])],
                               point_data={"support_force": force,
                                           "support_force_magnitude": np.linalg.norm(force, axis=1)})
        parts.append(("supports", f"{name}_supports", supports))
    if traj.scene.rigid_bodies and traj.body_x is not None:
        parts.append(("bodies", f"{name}_bodies", _body_glyphs(traj, meshio, padded)))
    return parts


def _file_stems(name: str, ids: list[str]) -> list[str]:
    """A file name stem per line: the scene's name and the line's id, made safe for a file name (the line's
    index instead where two ids would give the same name)."""
    import re

    safe = [re.sub(r"[^A-Za-z0-9_.-]", "_", key) for key in ids]
    if len(set(safe)) < len(safe):
        safe = [f"line{k}" for k in range(len(ids))]
    return [f"{name}_{key}" for key in safe]


def _body_glyphs(traj, meshio, padded):
    """Frame index -> the rigid bodies' glyphs as one meshio.Mesh (see the module)."""
    from ..analysis.objects import body_glyphs
    from ..analysis.rotation import rotation_matrix

    dim = traj.x.shape[2]
    glyphs = body_glyphs(traj.scene)
    bodies = [traj.body(b.id) for b in traj.scene.rigid_bodies]

    def mesh(i: int):
        points, vertices, lines, line_body, line_part, data = [], [], [], [], [], {}
        body_of_point = []
        rotation = rotation_matrix(np.asarray(traj.body_q[i]), dim)
        for b, (glyph, turn) in enumerate(zip(glyphs, rotation)):
            origin = np.asarray(traj.body_x[i][b], dtype=float)
            spokes, axes = glyph.segments(origin, turn)
            first = len(points)
            points.append(origin)
            vertices.append(first)
            for k, tip in enumerate([end for _, end in axes] + [end for _, end in spokes]):
                points.append(tip)
                lines.append((first, len(points) - 1))
                line_body.append(b)
                line_part.append(k + 1 if k < dim else 4)
            body_of_point += [b] * (len(points) - first)
        where = np.array(body_of_point)

        def per_point(values) -> np.ndarray:
            return np.stack([np.asarray(values[b], dtype=float) for b in where])

        data["orientation"] = per_point([np.asarray(body.quaternion[i]) for body in bodies])
        data["body_velocity"] = padded(per_point([np.asarray(body.velocity[i]) for body in bodies]))
        data["body_angular_velocity"] = per_point([np.asarray(traj.body_w[i][b]) for b in range(len(bodies))])
        data["line_force"] = padded(per_point([body.force[i] for body in bodies]))
        moment = per_point([body.moment[i] for body in bodies])
        data["line_moment"] = moment if dim == 3 else np.column_stack([np.zeros((len(where), 2)), moment])
        cells = [("vertex", np.array(vertices)[:, None]), ("line", np.array(lines, dtype=int).reshape(-1, 2))]
        cell_data = {"body": [np.arange(len(bodies)), np.array(line_body)],
                     "part": [np.zeros(len(bodies), dtype=int), np.array(line_part)]}
        return meshio.Mesh(padded(np.array(points)), cells, cell_data=cell_data, point_data=data)
    return mesh


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
