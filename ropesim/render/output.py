"""Output files: the type chosen by the extension, written atomically (never a half-written file)."""

from __future__ import annotations

from pathlib import Path

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


