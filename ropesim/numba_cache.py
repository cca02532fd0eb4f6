"""Where Numba keeps ropesim's compiled kernels, so a second run loads them instead of compiling again.

Numba caches a ``cache=True`` function in the ``__pycache__`` folder beside its source file, and when that
folder cannot be written (a package installed into a read-only location) it tries the user-wide
``~/.cache/numba``; when neither can be written it refuses to define the function at all, so importing
ropesim would fail. :func:`ensure_writable_cache` runs before any kernel is defined and, only when the package
folder is not writable and the user has not set ``NUMBA_CACHE_DIR``, points ``NUMBA_CACHE_DIR`` at the first
writable of the user cache folder (``$XDG_CACHE_HOME/ropesim/numba`` or ``~/.cache/ropesim/numba``; the
platform's equivalent on macOS and Windows) and a per-user folder in the temporary directory. It never
imports numba, so it costs the command line nothing measurable.
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parent


def writable(folder: Path) -> bool:
    """True when ``folder`` exists or can be made, and a file can be created in it (what Numba checks)."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError:
        return False
    return True


def user_cache_dir() -> Path | None:
    """This platform's per-user cache folder for ropesim's kernels, or None without a home folder."""
    try:
        home = Path.home()
    except (RuntimeError, KeyError):
        home = None
    if sys.platform == "win32":
        base = os.environ.get("LOCALAPPDATA") or (home / "AppData" / "Local" if home else None)
    elif sys.platform == "darwin":
        base = home / "Library" / "Caches" if home else None
    else:
        base = os.environ.get("XDG_CACHE_HOME") or (home / ".cache" if home else None)
    return Path(base) / "ropesim" / "numba" if base else None


def temp_cache_dir() -> Path:
    """A per-user folder for the kernels in the temporary directory (last resort)."""
    user = os.getuid() if hasattr(os, "getuid") else os.environ.get("USERNAME", "user")
    return Path(tempfile.gettempdir()) / f"ropesim-kernels-{user}"


def choose_cache_dir(package_dir: Path = PACKAGE_DIR, environ=os.environ) -> str | None:
    """The folder to give Numba as ``NUMBA_CACHE_DIR``, or None to leave Numba's own choice alone.

    None when the user set ``NUMBA_CACHE_DIR`` or the package's ``__pycache__`` is writable (an editable or
    user-owned install); otherwise the first writable of :func:`user_cache_dir` and :func:`temp_cache_dir`.
    """
    if environ.get("NUMBA_CACHE_DIR"):
        return None
    if writable(package_dir / "__pycache__") and writable(package_dir / "forces" / "__pycache__"):
        return None
    for candidate in (user_cache_dir(), temp_cache_dir()):
        if candidate is not None and writable(candidate):
            return str(candidate)
    return None


def ensure_writable_cache() -> str | None:
    """Set ``NUMBA_CACHE_DIR`` when ropesim's own folder cannot hold the cache; returns the folder chosen."""
    chosen = choose_cache_dir()
    if chosen is None:
        return None
    os.environ["NUMBA_CACHE_DIR"] = chosen
    config = sys.modules.get("numba.core.config")
    if config is not None:   # numba read its environment already: tell it directly
        config.CACHE_DIR = chosen
    return chosen
