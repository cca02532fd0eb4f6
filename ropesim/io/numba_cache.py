"""Where Numba keeps ropesim's compiled kernels, so a second run loads them instead of compiling again.

Numba caches a ``cache=True`` function beside its source file (in ``__pycache__``) and checks only that one
file's time stamp when it loads it. A kernel inlines helpers from other modules, so after an edit to a helper
alone (``forces/thrower.py``, say) Numba would go on loading the kernel compiled with the old helper: stale
physics, silently. And when the package folder cannot be written (an install into a read-only place) it
tries ``~/.cache/numba``, and when that cannot be written either it refuses to define the function, so
importing ropesim would fail.

So, unless the user has set ``NUMBA_CACHE_DIR``, :func:`ensure_writable_cache` (run before any kernel is
defined) points it at a folder named by a fingerprint of every source file of the package (path, size and
modification time): any edit anywhere in ropesim starts a fresh folder, and every kernel compiles anew.
The folder lies under the first writable of the package's ``__pycache__/kernels``, the user cache folder
(``$XDG_CACHE_HOME/ropesim/numba`` or ``~/.cache/ropesim/numba``; the platform's equivalent on macOS and
Windows) and a per-user folder in the temporary directory; the most recently used few are kept, older
ones deleted. It never imports numba, and the fingerprint (a stat per source file) costs well under a
millisecond.

Numba's cache index files are pickles, loaded as the user who runs ropesim: whoever can write the cache folder
can run code as that user. So, as OpenSSH checks the folders of its keys: the kernel folder and the folder
above it are made with mode 0700, and one that exists is used only when it is a real folder (not a link),
owned by this user and not writable by group or others; else the next place is tried. The temporary
directory's name is predictable (another user may have made it first): when it fails the check a private
folder made by ``mkdtemp`` (removed at exit) serves this process, and one line on stderr says why.
"""

from __future__ import annotations

import atexit
import hashlib
import os
import shutil
import stat
import sys
import tempfile
from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parent.parent   # the ropesim package
KEEP = 3   # kernel folders kept per cache location (the current one and the two used before it)


def writable(folder: Path) -> bool:
    """True when ``folder`` exists or can be made, and a file can be created in it (what Numba checks)."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError:
        return False
    return True


def untrusted(folder: Path) -> str:
    """Why ``folder`` must not hold compiled kernels (pickles loaded as this user), or "" when it may: it must be
    a real folder (not a link), owned by this user, and not writable by group or others."""
    if not hasattr(os, "getuid"):   # Windows: a user's folders are private by their access lists
        return ""
    st = os.lstat(folder)
    if stat.S_ISLNK(st.st_mode):
        return "it is a symbolic link"
    if not stat.S_ISDIR(st.st_mode):
        return "it is not a folder"
    if st.st_uid != os.getuid():
        return f"it belongs to another user (uid {st.st_uid})"
    if st.st_mode & 0o022:
        return f"others can write to it (mode {stat.S_IMODE(st.st_mode):o}; chmod go-w {folder})"
    return ""


def private_folder(base: Path, name: str) -> tuple[Path | None, str]:
    """(``base/name``, "") once both are made (mode 0700) or checked (:func:`untrusted`) and a file can be
    created in it; (None, why) when one fails the check; (None, "") when it cannot be written."""
    try:
        base.parent.mkdir(parents=True, exist_ok=True)
        for folder in (base, base / name):
            try:
                os.mkdir(folder, 0o700)
            except FileExistsError:
                pass
            why = untrusted(folder)
            if why:
                return None, f"{folder}: {why}"
        tempfile.TemporaryFile(dir=base / name).close()
    except OSError:
        return None, ""
    return base / name, ""


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


def source_fingerprint(package_dir: Path = PACKAGE_DIR) -> str:
    """12 hex digits that change whenever any ``.py`` file of the package is added, removed or modified."""
    digest = hashlib.sha1()
    for path in sorted(package_dir.rglob("*.py")):
        stat = path.stat()
        digest.update(f"{path.relative_to(package_dir).as_posix()}:{stat.st_size}:{stat.st_mtime_ns}\n".encode())
    return digest.hexdigest()[:12]


def prune(base: Path, keep: Path, count: int = KEEP) -> None:
    """Delete the kernel folders in ``base`` beyond the ``count`` most recently used (``keep`` among them)."""
    try:
        os.utime(keep)   # marks it used now
        others = sorted((p for p in base.iterdir() if p.is_dir() and p != keep),
                        key=lambda p: p.stat().st_mtime, reverse=True)
    except OSError:
        return
    for old in others[count - 1:]:
        shutil.rmtree(old, ignore_errors=True)


def choose_cache_dir(package_dir: Path = PACKAGE_DIR, environ=os.environ) -> str | None:
    """The folder to give Numba as ``NUMBA_CACHE_DIR``, or None to leave the user's own setting alone.

    The fingerprint's folder (see the module doc) under the first writable of the package's
    ``__pycache__/kernels``, :func:`user_cache_dir` and :func:`temp_cache_dir`.
    """
    if environ.get("NUMBA_CACHE_DIR"):
        return None
    fingerprint = source_fingerprint(package_dir)
    refused = ""
    for base in (package_dir / "__pycache__" / "kernels", user_cache_dir(), temp_cache_dir()):
        if base is None:
            continue
        folder, why = private_folder(base, fingerprint)
        if folder is not None:
            prune(base, folder)
            return str(folder)
        refused = why or refused
    if refused:   # the predictable temporary folder (or another) was not safe: a private one for this process
        try:
            folder = Path(tempfile.mkdtemp(prefix="ropesim-kernels-"))
        except OSError:
            return None
        atexit.register(shutil.rmtree, folder, ignore_errors=True)
        sys.stderr.write(f"ropesim: warning: not using the compile cache {refused}; kernels compile into "
                         f"{folder} for this run only\n")
        return str(folder)
    return None


def ensure_writable_cache() -> str | None:
    """Set ``NUMBA_CACHE_DIR`` to :func:`choose_cache_dir`'s folder (unless the user set it); returns it."""
    chosen = choose_cache_dir()
    if chosen is None:
        return None
    os.environ["NUMBA_CACHE_DIR"] = chosen
    config = sys.modules.get("numba.core.config")
    if config is not None:   # numba read its environment already: tell it directly
        config.CACHE_DIR = chosen
    return chosen
