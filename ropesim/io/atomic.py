"""Atomic, durable output files: written beside their final name, flushed, moved into place only when complete.

The sequence is SQLite's and every careful database's: write a temporary file in the same folder, ``fsync`` it,
``rename`` it over the final name (atomic on POSIX), then ``fsync`` the folder so that the rename itself
survives a power cut. A reader sees the old file or the new one, never half of either.
"""

from __future__ import annotations

import errno
import json
import os
import re
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


FILE_MODE = 0o666 & ~_umask()  # what open() would give a new file (mkstemp's own 0600 would hide results)
TEMPORARY_NAME = re.compile(r"^\.(.+)\.[a-z0-9_]{8}\.tmp(\.[^.]*)?$")   # atomic_output's .STEM.XXXXXXXX.tmp.EXT


def fsync_path(path: str | Path) -> None:
    """``fsync`` a file or a folder by name (a folder's entries: renames and new files in it)."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0) if Path(path).is_dir() else os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError as exc:  # some file systems cannot fsync a folder; that is their durability, not an error
        if exc.errno not in (errno.EINVAL, errno.ENOTSUP, errno.EBADF):
            raise
    finally:
        os.close(fd)


class WriteFailed(OSError):
    """Writing an output file failed (a full disk, a read-only folder); ``str()`` is one line naming the file
    that was asked for, never the temporary file beside it. ``errno`` is the failure's (ENOSPC, EACCES, ...)."""

    def __init__(self, path: str | Path, exc: OSError):
        super().__init__(exc.errno, exc.strerror or str(exc), str(path))
        self.path = Path(path)

    def __str__(self) -> str:
        return f"{self.path}: cannot write it ({self.strerror})"


@contextmanager
def atomic_output(path: str | Path, durable: bool = True) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` (same extension); move it into place only if the block succeeds.

    Any error or interrupt inside the block removes the temporary file, so ``path`` is either its old self
    or the complete new file, with the permissions a newly created file gets. With ``durable`` the file is
    flushed to disk before the rename and the folder after it. An OSError on the way (making the folder or the
    temporary file, writing, renaming) comes out as :class:`WriteFailed`, naming ``path``.
    """
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=f".tmp{path.suffix}", dir=path.parent)
        os.close(fd)
    except OSError as exc:
        raise WriteFailed(path, exc) from None
    try:
        yield Path(tmp)
        os.chmod(tmp, FILE_MODE)
        if durable:
            fsync_path(tmp)
        os.replace(tmp, path)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        if isinstance(exc, WriteFailed):
            raise
        raise WriteFailed(path, exc) from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    if durable:
        fsync_path(path.parent)


def write_text_atomic(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` via a temporary file in the same folder, fsync and an atomic rename."""
    with atomic_output(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def write_json_atomic(path: Path, data: dict) -> None:
    """Write ``data`` as indented JSON to ``path``, atomically (see :func:`write_text_atomic`)."""
    write_text_atomic(path, json.dumps(data, indent=2, sort_keys=False) + "\n")
