"""What a command shows on the terminal while it starts and while Numba compiles.

``ropesim run`` shows a spinner from its first moment, before numpy and Numba are imported: what it is doing,
then, while Numba compiles, which kernel compiles, that this happens once, and where the compiled kernel is
cached, with the seconds so far; the run's progress bar takes its place when it appears. ``ropesim compile``,
``accuracy``, ``stability`` and ``sweep`` show it while something compiles. Nothing is shown when stderr is not
a terminal, or with ``--quiet``: batch scripts that pipe the output see clean lines.

What compiles is observed, not guessed: Numba broadcasts a ``numba:compile`` event whenever a dispatcher
compiles (a cache miss) and none when it loads a kernel from its cache, and :class:`Startup` listens to it.
This module imports nothing heavy at import time (rich when the spinner first shows, Numba in
:meth:`Startup.watch`), so the spinner appears within a few tenths of a second of the command starting.
"""

from __future__ import annotations

import os
import sys
import threading
import time

FAMILY_MODULES = {   # the module of a family's compiled loop: how to name what compiles when its loop compiles
    "ropesim.model.terms": "the force terms",
    "ropesim.model.statics": "the static solver",
}


def cache_dir() -> str:
    """Where Numba caches the compiled kernels (``~`` for the home folder), as a person reads it."""
    folder = os.environ.get("NUMBA_CACHE_DIR", "")
    if not folder:
        return "Numba's cache beside the sources"
    home = os.path.expanduser("~")
    if home not in ("", "~", "/") and (folder == home or folder.startswith(home + os.sep)):
        folder = "~" + folder[len(home):]
    return folder


def describe(module: str, name: str) -> str:
    """How to name a compile whose outermost function is ``module.name``: an integrator's loop by its methods
    ("the rk4 kernel"), the force terms or the static solver by what they are, anything else by its name."""
    from ..integrate.methods import METHODS

    methods = [m.name for m in METHODS.values() if m.family.__module__ == module]
    if methods:
        listed = methods[0] if len(methods) == 1 else ", ".join(methods[:-1]) + " and " + methods[-1]
        return f"the {listed} kernel"
    return FAMILY_MODULES.get(module, f"ropesim's {name}")


class _View:
    """The spinner's line: a rich renderable asked afresh at every refresh (so the seconds count up)."""

    def __init__(self, owner: "Startup"):
        from rich.spinner import Spinner

        self.owner = owner
        self.spinner = Spinner("dots")

    def __rich_console__(self, console, options):
        self.spinner.text = self.owner.line()
        yield self.spinner.render(console.get_time())


class _Guard:
    """sys.stdout or sys.stderr while the spinner shows: a write first takes the spinner away, then goes to the
    stream; the spinner comes back on the next line a moment after the last write."""

    def __init__(self, stream, owner: "Startup"):
        self._stream, self._owner = stream, owner

    def write(self, text: str) -> int:
        if not isinstance(text, str):
            raise TypeError(f"write() argument must be str, not {type(text).__name__}")
        owner = self._owner
        with owner._lock:
            owner._interrupted()
            n = self._stream.write(text)
            self._stream.flush()
            owner._resume_soon()
        return n

    def __getattr__(self, name):
        return getattr(self._stream, name)


class Startup:
    """A transient spinner on stderr, only when stderr is a terminal and ``enabled``.

    ``text`` is shown from :meth:`__enter__` on (None: nothing until something compiles, and nothing once it
    has). While Numba compiles (after :meth:`watch`) the line says what compiles: ``kernel`` ("the sdirk2
    kernel") or, if None, what :func:`describe` calls the outermost function compiling. :meth:`stop` hides it for
    good (a progress bar takes over). ``compiles`` counts the outermost compiles seen, ``functions`` every
    function of ropesim compiled under them.
    """

    def __init__(self, enabled: bool, text: str | None = None, kernel: str | None = None):
        self.enabled, self.text, self.kernel = enabled, text, kernel
        self.compiles = 0
        self.functions = 0
        self._live = None
        self._closed = False
        self._stack: list[str] = []            # ropesim's functions compiling now, outermost first
        self._depth = 0
        self._compiling: str | None = None     # what compiles (see describe), while something does
        self._since: float | None = None       # when the first compile began (monotonic s)
        self._listener = None
        self._lock = threading.RLock()
        self._streams = (sys.stdout, sys.stderr)
        self._pending = False    # taken away by another write; shown again after it
        self._timer: threading.Timer | None = None

    # -- showing ----------------------------------------------------------------------------------------

    def __enter__(self) -> "Startup":
        if self.text is not None:
            self._show()
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def line(self):
        """The text after the spinner, now."""
        from rich.text import Text

        what, stack, since = self._compiling, self._stack, self._since
        if what is None or since is None:
            return Text(self.text or "")
        function = next((name for name in reversed(stack) if name), "")
        return Text.assemble(("Compiling " + what, "bold"), f": once, then cached in {cache_dir()}",
                             (f"  {function} {time.monotonic() - since:.0f} s", "dim"))

    def _show(self) -> None:
        with self._lock:
            if not self.enabled or self._closed or self._live is not None:
                return
            from rich.console import Console
            from rich.live import Live

            streams = (sys.stdout, sys.stderr)
            console = Console(file=streams[1])
            if not console.is_terminal or console.is_dumb_terminal:   # TERM=dumb cannot redraw a line
                self.enabled = False
                return
            # rich's own redirection of stdout and stderr misses what Typer and click print (click keeps its own
            # stream objects), so the guards below take the spinner away before anything else is written.
            self._live = Live(_View(self), console=console, transient=True, refresh_per_second=12.5,
                              redirect_stdout=False, redirect_stderr=False)
            self._live.start(refresh=True)
            self._streams = streams
            sys.stdout, sys.stderr = _Guard(streams[0], self), _Guard(streams[1], self)

    def _hide(self) -> None:
        with self._lock:
            if self._live is not None:
                sys.stdout, sys.stderr = self._streams
                self._live.stop()
                self._live = None

    def _interrupted(self) -> None:
        """Something else writes to the terminal: take the spinner away first (it comes back at the next line)."""
        self._hide()
        self._pending = True

    RESUME_AFTER = 0.25   # seconds without writes before a spinner taken away by a write comes back

    def _resume_soon(self) -> None:
        with self._lock:
            if self._timer is not None:
                self._timer.cancel()
            self._timer = threading.Timer(self.RESUME_AFTER, self._resume)
            self._timer.daemon = True
            self._timer.start()

    def _resume(self) -> None:
        with self._lock:
            self._timer = None
            if self._pending and (self.text is not None or self._compiling is not None):
                self._pending = False
                self._show()

    def update(self, text: str | None = None, kernel: str | None = None) -> None:
        """Change the idle text or the name of what compiles."""
        if text is not None:
            self.text = text
        if kernel is not None and kernel != self.kernel:
            self.kernel = kernel
            self._since = None    # the seconds shown count from this kernel's first compile

    def stop(self) -> None:
        """Hide the spinner for good (the command's own progress display takes over)."""
        with self._lock:
            self._closed = True
            if self._timer is not None:
                self._timer.cancel()
                self._timer = None
            self._hide()

    def close(self) -> None:
        """Hide the spinner and stop listening to Numba."""
        self.stop()
        if self._listener is not None:
            from numba.core import event

            event.unregister("numba:compile", self._listener)
            self._listener = None

    # -- listening to Numba ------------------------------------------------------------------------------

    def watch(self) -> "Startup":
        """Listen to Numba's compile events from now on (this imports Numba). Nothing to do when disabled."""
        if not self.enabled or self._closed or self._listener is not None:
            return self
        from numba.core import event

        owner = self

        class Listener(event.Listener):
            def on_start(self, ev):
                owner._started(ev.data["dispatcher"].py_func)

            def on_end(self, ev):
                owner._ended()

        self._listener = Listener()
        event.register("numba:compile", self._listener)
        return self

    def _started(self, func) -> None:
        from ..model.jit import template_name

        # Numba compiles under one global lock, so the events of every thread nest properly.
        module, name = getattr(func, "__module__", "") or "", template_name(getattr(func, "__qualname__", "?"))
        ours = module.startswith("ropesim")
        self._stack.append(name if ours else "")
        self._depth += 1
        self.functions += ours
        if self._depth == 1:
            self.compiles += 1
            if self._since is None:
                self._since = time.monotonic()
            self._compiling = self.kernel or describe(module, name)
            if self.text is None and threading.current_thread() is threading.main_thread():
                self._show()

    def _ended(self) -> None:
        self._depth -= 1
        if self._stack:
            self._stack.pop()
        if self._depth == 0:
            self._compiling = None
            if self.text is None and threading.current_thread() is threading.main_thread():
                self._hide()


# ---------------------------------------------------------------------------------- before Typer parses

_early: Startup | None = None
QUIET_OR_HELP = {"-q", "--quiet", "-h", "--help"}


def start_early(args: list[str]) -> None:
    """For ``ropesim run`` on a terminal, show the spinner before Typer parses the command line (parsing
    imports pydantic, about 0.15 s); :func:`take_early` hands it to the command. A wrong guess costs nothing:
    the command closes it if it turns out quiet, and :func:`close_early` when the command never took it."""
    global _early
    if args[:1] == ["run"] and not QUIET_OR_HELP & set(args[1:]) and sys.stderr.isatty():
        _early = Startup(True, "Starting ropesim run").__enter__()


def take_early() -> Startup | None:
    """The spinner :func:`start_early` showed, now the caller's to close; None if it showed none."""
    global _early
    early, _early = _early, None
    return early


def close_early() -> None:
    early = take_early()
    if early is not None:
        early.close()
