"""How to install ropesim and its extras, as ropesim itself tells a user (one place for every install hint).

The distribution is called ``pyropesim`` on the package index (the name ``ropesim`` there belongs to an
unrelated project, whose code installing by that name would bring); the import name and the command
stay ``ropesim``. A hint names what installs the missing part into the installation that is running: from
its checkout when ropesim was installed editable from one (``pip install -e '/path/to/checkout[export]'``),
else by the distribution's name (``pip install 'pyropesim[export]'``).
"""

from __future__ import annotations

from pathlib import Path

DISTRIBUTION = "pyropesim"


def checkout() -> Path | None:
    """The source tree ropesim runs from (installed editable from it, or not installed at all), or None when it
    runs from an installed wheel: the package's parent folder holds the project's pyproject.toml."""
    root = Path(__file__).resolve().parent.parent
    try:
        text = (root / "pyproject.toml").read_text(encoding="utf-8")
    except OSError:
        return None
    return root if f'name = "{DISTRIBUTION}"' in text else None


def install_hint(extra: str | None = None) -> str:
    """The pip command that installs ropesim with ``extra`` (a name from pyproject.toml's
    optional-dependencies) into the running installation."""
    suffix = f"[{extra}]" if extra else ""
    tree = checkout()
    if tree is not None:
        where = "." if tree == Path.cwd().resolve() else str(tree)
        return f"pip install -e '{where}{suffix}'"
    return f"pip install '{DISTRIBUTION}{suffix}'"
