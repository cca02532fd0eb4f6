"""Output files: the type chosen by the extension, written atomically (never a half-written file)."""

from __future__ import annotations

import os
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

from . import RenderError


def output_type(path: Path, allowed: tuple[str, ...], option: str = "--out") -> str:
    """The lower-case extension of ``path`` (e.g. ".gif") if it is one of ``allowed``; else a RenderError."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in allowed:
        kind = f"'{path.suffix}'" if path.suffix else "no extension"
        raise RenderError(f"{option} {path}: unknown file type ({kind}); use {' or '.join(allowed)}")
    if path.is_dir():
        raise RenderError(f"{option} {path}: is a folder; give a file name ending in {' or '.join(allowed)}")
    return suffix


@contextmanager
def atomic_output(path: Path) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` (same extension); move it into place only if the block succeeds.

    Any error or interrupt inside the block removes the temporary file, so ``path`` is either its old self
    or the complete new file.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=f".tmp{path.suffix}", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
