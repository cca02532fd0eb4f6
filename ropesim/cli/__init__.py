"""The command line (Typer) and what it prints (rich)."""

import signal as _signal
import sys as _sys
import threading as _threading


def _interrupted_while_loading(_signum, _frame):
    """Ctrl-C while the command line's modules load (a few tenths of a second): one line, exit 130, instead of a
    traceback through whatever module was loading."""
    _sys.stderr.write("ropesim: interrupted\n")
    raise SystemExit(130)


_main_thread = _threading.current_thread() is _threading.main_thread()
_previous = _signal.signal(_signal.SIGINT, _interrupted_while_loading) if _main_thread else None
try:
    from .app import app, main
finally:
    if _main_thread:
        _signal.signal(_signal.SIGINT, _previous)

__all__ = ["app", "main"]
