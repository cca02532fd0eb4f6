"""The command line (Typer) and what it prints (rich)."""

from ..stop import quiet_interrupts_while_loading, started_as_the_command_line

if started_as_the_command_line():
    quiet_interrupts_while_loading()   # (ropesim/__init__ did too) a traceback through an import is no message
try:
    from .app import app, main
finally:
    if started_as_the_command_line():
        quiet_interrupts_while_loading(False)   # from here on main() and the commands handle Ctrl-C

__all__ = ["app", "main"]
