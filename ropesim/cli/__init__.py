"""The command line (Typer) and what it prints (rich)."""

from .app import app, main

__all__ = ["app", "main"]
