"""The command line (Typer) and what it prints (rich)."""

from ..stop import quiet_interrupts_while_loading, started_as_the_command_line

if started_as_the_command_line():
    quiet_interrupts_while_loading()   # (ropesim/__init__ did too) a traceback through an import is no message
from .app import app, main   # main() hands Ctrl-C back to Python inside its own try, where it is one line too

__all__ = ["app", "main"]
