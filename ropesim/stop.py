"""Stopping cleanly: SIGTERM and SIGHUP (a batch scheduler, `timeout`, a closed terminal) end a command as
Ctrl-C does. Inside a run they only set a flag (:func:`ropesim.run.stop_signals`); elsewhere the command-line
entry point turns them into :class:`Stopped`."""

from __future__ import annotations


class Stopped(BaseException):
    """SIGTERM or SIGHUP outside a run's own clean stop; ``name`` is the signal's. A BaseException, like
    KeyboardInterrupt, so that no ``except Exception`` swallows it."""

    def __init__(self, name: str):
        super().__init__(name)
        self.name = name


def _interrupted_while_loading(_signum, _frame):
    """Nothing is written yet while modules load: say so and end at once (an exception raised here could land
    in any library's import, which may swallow or wrap it)."""
    import os
    import sys

    sys.stderr.write("ropesim: interrupted\n")
    sys.stderr.flush()
    os._exit(130)


def quiet_interrupts_while_loading(on: bool = True) -> None:
    """While the command line's modules load (a few tenths of a second, more on a busy machine), Ctrl-C is one
    line and exit 130 instead of a traceback through whatever module was loading; ``on=False`` gives Ctrl-C
    back to Python (KeyboardInterrupt), which the command line then handles. Only in the main thread."""
    import signal
    import threading

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, _interrupted_while_loading if on else signal.default_int_handler)


def started_as_the_command_line() -> bool:
    """True in a process started as `ropesim ...` or `python -m ropesim ...` (not when a program imports it)."""
    import os
    import sys

    argv = getattr(sys, "orig_argv", [])
    return (bool(sys.argv) and os.path.basename(sys.argv[0]) == "ropesim") or argv[1:3] == ["-m", "ropesim"]
