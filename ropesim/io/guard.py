"""May ropesim write here? The one check every command makes before it writes a file or a folder.

Nothing outside ropesim's own files is ever touched. So before a command writes:

- a **file** (a picture, a CSV, a scene file): a symbolic link is followed (the data goes where it points; a
  link to nowhere is refused); a folder at that name is refused; an existing file is replaced only when
  ropesim wrote it (:func:`written_by_ropesim`), or with ``--force`` where a command offers it (``new``,
  ``equilibrium``);
- a **folder** it replaces or fills (a run folder, a VTK series, a sweep folder): a link is followed; a file at
  that name is refused; an existing folder is used only when everything in it is ropesim's
  (:func:`foreign_entries`), else the refusal names what is not.

How ropesim knows its own files: a PNG, GIF or MP4 carries ``ropesim`` as its software or comment tag (every
picture ropesim writes is tagged); a CSV starts with one of the headers ropesim writes; a VTK series' .pvd
says so in a comment; a page of ``ropesim view`` carries its generator tag; inside a run folder (one with a manifest, scene or trajectory) the names ropesim gives
its files are its own (the run's files, and the pictures and exports written there by default). Refusals are
:class:`WriteRefused` (one line; the command line exits 2).
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from .atomic import TEMPORARY_NAME
from .layout import LOCK, RUN_MARKERS, STATE

SOFTWARE = "ropesim"    # the tag ropesim puts in the pictures it writes (PNG Software, GIF and MP4 comment)
PVD_MARK = "<!-- written by ropesim export -->"
HTML_MARK = '<meta name="generator" content="ropesim view">'   # ropesim.viewer.page.GENERATOR

# A run folder's own entries (see ropesim.io.runfolder) and what commands write into it by default.
RUN_FILES = frozenset({*RUN_MARKERS, STATE, LOCK})
DEFAULT_OUTPUTS = frozenset({"plots.png", "frames.png", "animation.gif", "animation.mp4", "trajectory.csv", "vtk",
                             "trajectory_tension_history.csv", "trajectory_tension_range.csv",
                             "trajectory_bodies.csv", "trajectory_sea.csv"})
CSV_HEADERS = ("t [s],node,",                         # ropesim export --to csv
               "t [s],line,node,",                    # ... of a system of lines
               "t [s],tension segment 0 [",           # ... its time history of the forces
               "t [s],tension ",                      # ... a system's, by line
               "segment,s [m],min tension [",         # ... its tension range along the rope
               "line,segment,s [m],min tension [",    # ... along each line of a system
               "t [s],body,",                         # ... a system's rigid bodies
               "t [s],submerged ",                    # ... the sea: submerged fractions, probes
               "method,dt,steps,status,",             # ropesim accuracy: accuracy.csv
               "stiffness,method,dt,dt_over_ref",     # ropesim stability: stability.csv
               "stiffness,method,ref_dt,")            # ropesim stability: bounds.csv
TEMPORARY = re.compile(TEMPORARY_NAME.pattern + r"|^\.frames-[a-z0-9_]+$")   # and an older ropesim's frames


class WriteRefused(ValueError):
    """A command pointed at a file or folder that is not ropesim's to replace; ``str()`` is one line."""


# ------------------------------------------------------------------------------------------ checks


def follow(path: str | Path, option: str = "--out") -> Path:
    """``path`` with a symbolic link (at its end or on the way) followed to where it points; a link whose
    target's folder does not exist is refused."""
    path = Path(path)
    if not path.is_symlink():
        return path
    target = Path(os.path.realpath(path))
    if not target.exists() and not target.parent.is_dir():
        raise WriteRefused(f"{option} {path}: is a link to {os.readlink(path)}, which does not exist")
    return target


def output_file(path: str | Path, *, replace: bool = False, option: str = "--out", force_hint: bool = False) -> Path:
    """The path to write a file at ``path`` (a link followed); refused: a folder there, or an existing file that
    ropesim did not write (unless ``replace``: a command's --force)."""
    shown = Path(path)
    real = follow(shown, option)
    if real.is_dir():
        raise WriteRefused(f"{option} {shown}: is a folder; give a file name")
    if real.exists() and not replace and (force_hint or not owned_file(real)):
        if force_hint:
            raise WriteRefused(f"{option} {shown}: exists; add --force to replace it, or choose another name")
        raise WriteRefused(f"{option} {shown}: exists and was not written by ropesim; choose another --out, or "
                           f"move it away first")
    blocked = next((p for p in real.parents if p.exists() and not p.is_dir()), None)
    if blocked is not None:
        raise WriteRefused(f"{option} {shown}: cannot write it: {blocked} is a file, not a folder")
    return real


def output_folder(path: str | Path, kind: str, option: str = "--out") -> Path:
    """The folder to write a ``kind`` ("run", "vtk" or "sweep") at ``path`` (a link followed); refused: a file
    there, or a folder holding anything that is not ropesim's (named in the refusal)."""
    shown = Path(path)
    real = follow(shown, option)
    if real.exists() and not real.is_dir():
        raise WriteRefused(f"{option} {shown}: exists and is not a folder")
    blocked = next((p for p in real.parents if p.exists() and not p.is_dir()), None)
    if blocked is not None:
        what = {"run": "the run folder", "vtk": "the series", "sweep": "the sweep folder"}[kind]
        raise WriteRefused(f"{option} {shown}: cannot write {what}: {blocked} is a file, not a folder")
    if real.is_dir():
        foreign = foreign_entries(real, kind)
        if foreign:
            raise WriteRefused(_refusal(shown, real, kind, foreign, option))
    return real


def _refusal(shown: Path, real: Path, kind: str, foreign: list[str], option: str) -> str:
    names = ", ".join(foreign[:4]) + (f" and {len(foreign) - 4} more" if len(foreign) > 4 else "")
    if kind == "run":
        if not is_run_folder(real):
            return (f"{shown}: exists and is not a run folder (it holds {names}); a run replaces its folder "
                    f"whole, so choose another --out or empty it")
        return (f"{shown}: holds what ropesim did not write ({names}); a new run replaces the folder whole: move "
                f"{'it' if len(foreign) == 1 else 'them'} out of it, or choose another --out")
    what = {"vtk": "a VTK series that ropesim exported", "sweep": "a sweep folder"}[kind]
    return (f"{option} {shown}: exists and is not {what} (it holds {names}); choose another {option} or an "
            f"empty folder")


# ----------------------------------------------------------------------------------------- ownership


def is_run_folder(folder: Path) -> bool:
    """True when ``folder`` holds any of a run's own files (a run, or what is left of one)."""
    try:
        return any((folder / name).exists() for name in RUN_MARKERS)
    except OSError:
        return False


def foreign_entries(folder: Path, kind: str) -> list[str]:
    """The entries of ``folder`` (sorted, relative to it) that ropesim did not write, for a folder of ``kind``."""
    try:
        entries = sorted(os.listdir(folder))
    except OSError:
        return []
    foreign = []
    signed = kind == "vtk" and (folder.name == "vtk" and is_run_folder(folder.parent) or any(
        PVD_MARK.encode() in _head(p, 200) for p in folder.glob("*.pvd") if p.is_file()))
    for name in entries:
        path = folder / name
        if TEMPORARY.match(name):
            continue
        if kind == "run":
            ok = _run_entry(folder, name)
        elif kind == "vtk":
            ok = signed and name.endswith((".vtu", ".pvd")) and path.is_file() and not path.is_symlink()
        elif kind == "sweep":
            ok = (name == "results.csv" and _sweep_table(path)) or owned_picture(path) or (
                path.is_dir() and not path.is_symlink() and not foreign_entries(path, "run"))
        else:
            raise ValueError(kind)
        if not ok:
            foreign.append(name + ("/" if path.is_dir() and not path.is_symlink() else ""))
    if kind == "run":
        foreign += [f"checkpoint/{n}" for n in _foreign_checkpoint(folder / "checkpoint")]
        if (folder / "vtk").is_dir():
            foreign += [f"vtk/{n}" for n in foreign_entries(folder / "vtk", "vtk")]
    return foreign


def _run_entry(folder: Path, name: str) -> bool:
    path = folder / name
    if path.is_symlink():
        return False
    if name in RUN_FILES:
        return True
    if name in DEFAULT_OUTPUTS and is_run_folder(folder):
        return True
    return path.is_file() and owned_file(path)


def _foreign_checkpoint(folder: Path) -> list[str]:
    if not folder.is_dir() or folder.is_symlink():
        return []
    return [n for n in sorted(os.listdir(folder))
            if not (re.fullmatch(r"[a-z_]+\.npy|state-\d+\.npz", n) or TEMPORARY.match(n))]


def owned_file(path: Path) -> bool:
    """True when the file at ``path`` was written by ropesim (by its tag or header; see the module doc), or is
    one of a run folder's own files."""
    path = Path(path)
    if path.parent.is_dir() and path.name in RUN_FILES | DEFAULT_OUTPUTS and is_run_folder(path.parent):
        return True
    return written_by_ropesim(path)


def owned_picture(path: Path) -> bool:
    return path.suffix.lower() in (".png", ".gif", ".mp4") and path.is_file() and written_by_ropesim(path)


def written_by_ropesim(path: Path) -> bool:
    """True when the file's own bytes say ropesim wrote it: a PNG's Software, a GIF's or MP4's comment, a CSV's
    header, a .pvd's comment. Reads at most the file's first few kB (an MP4: its index box)."""
    path = Path(path)
    suffix = path.suffix.lower()
    try:
        if suffix == ".png":
            return _png_software(path).startswith(SOFTWARE)
        if suffix == ".gif":
            return _gif_comment(path).startswith(SOFTWARE)
        if suffix == ".mp4":
            return SOFTWARE.encode() in _mp4_moov(path)
        if suffix == ".csv":
            line = _head(path, 4096).split(b"\n", 1)[0].decode("utf-8", "replace")
            return line.startswith(CSV_HEADERS) or (path.name == "results.csv" and _sweep_header(line))
        if suffix == ".pvd":
            return PVD_MARK.encode() in _head(path, 200)
        if suffix in (".html", ".htm"):
            return HTML_MARK.encode() in _head(path, 1024)      # ropesim view's page
    except OSError:
        return False
    return False


def _sweep_header(line: str) -> bool:
    return line.startswith("run,") and ",status,error" in line


def _sweep_table(path: Path) -> bool:
    try:
        return path.is_file() and _sweep_header(_head(path, 65536).split(b"\n", 1)[0].decode("utf-8", "replace"))
    except OSError:
        return False


def _head(path: Path, n: int) -> bytes:
    with open(path, "rb") as fh:
        return fh.read(n)


def _png_software(path: Path) -> str:
    """The PNG's tEXt "Software" value ("" if none), from the chunks before the image data."""
    with open(path, "rb") as fh:
        if fh.read(8) != b"\x89PNG\r\n\x1a\n":
            return ""
        for _ in range(64):
            head = fh.read(8)
            if len(head) < 8:
                return ""
            size, kind = int.from_bytes(head[:4], "big"), head[4:]
            if kind in (b"IDAT", b"IEND") or size > 1 << 20:
                return ""
            data = fh.read(size)
            fh.seek(4, os.SEEK_CUR)   # the CRC
            if kind == b"tEXt" and data.startswith(b"Software\x00"):
                return data[9:].decode("latin-1")
    return ""


def _gif_comment(path: Path) -> str:
    """The text of the GIF's first comment extension ("" if none) before its first image."""
    with open(path, "rb") as fh:
        data = fh.read(1 << 16)
    if data[:3] != b"GIF" or len(data) < 13:
        return ""
    i = 13 + (3 << ((data[10] & 7) + 1) if data[10] & 0x80 else 0)
    while i + 2 <= len(data) and data[i] == 0x21:       # extensions, until the first image (0x2C)
        label, i = data[i + 1], i + 2
        text = b""
        while i < len(data) and data[i]:
            text += data[i + 1:i + 1 + data[i]]
            i += 1 + data[i]
        i += 1
        if label == 0xFE:
            return text.decode("latin-1")
    return ""


def _mp4_moov(path: Path) -> bytes:
    """The MP4's top-level 'moov' box (its index and metadata), at most 64 MB; b"" if none."""
    size_all = path.stat().st_size
    with open(path, "rb") as fh:
        offset = 0
        while offset + 8 <= size_all:
            fh.seek(offset)
            head = fh.read(16)
            size, kind = int.from_bytes(head[:4], "big"), head[4:8]
            if size == 1:
                size = int.from_bytes(head[8:16], "big")
            elif size == 0:
                size = size_all - offset
            if size < 8:
                return b""
            if kind == b"moov":
                fh.seek(offset)
                return fh.read(min(size, 64 << 20))
            offset += size
    return b""
