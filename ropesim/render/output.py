"""Output files: the type chosen by the extension, checked by the one write guard, written atomically and tagged
as ropesim's (so a later run may replace them, and nothing else; see :mod:`ropesim.io.guard`)."""

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


def output_path(path: str | Path, allowed: tuple[str, ...], option: str = "--out") -> tuple[Path, str]:
    """(the file to write for ``path``, its type): the type checked by :func:`output_type`, the place by
    :func:`ropesim.io.guard.output_file` (a link followed; a file ropesim did not write is refused)."""
    from ..io.guard import output_file

    kind = output_type(path, allowed, option)
    return output_file(path, option=option), kind


def save_png(fig, path: str | Path, dpi: float) -> None:
    """Write a matplotlib figure to the PNG ``path`` atomically, tagged as ropesim's (its Software field)."""
    from .. import __version__
    from ..io.atomic import atomic_output
    from ..io.guard import SOFTWARE

    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png", dpi=dpi, metadata={"Software": f"{SOFTWARE} {__version__}"})
