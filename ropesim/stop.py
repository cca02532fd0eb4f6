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
