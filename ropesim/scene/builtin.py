"""The built-in scenes, shipped inside the package (``ropesim/scenarios/*.toml``), and finding a scene by name.

A command's SCENE argument is a scene file, or the name of a built-in scene: an argument that is not an
existing file and names a built-in (``helicopter_mass`` or ``helicopter_mass.toml``) means that built-in,
so ``ropesim run helicopter_mass`` works from any folder and after ``pip install pyropesim`` from a wheel.
A path that exists always wins over a name. Anything else is refused in one line that lists the built-ins
and suggests the closest name.
"""

from __future__ import annotations

import difflib
import re
import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from .errors import SceneError

SUFFIX = ".toml"


def builtin_folder() -> Path:
    """The folder holding the built-in scene files (inside the installed package)."""
    return Path(str(resources.files("ropesim") / "scenarios"))


def builtin_names() -> list[str]:
    """Names of the built-in scenes, sorted."""
    return sorted(p.stem for p in builtin_folder().glob(f"*{SUFFIX}"))


def builtin_path(name: str) -> Path | None:
    """The file of built-in scene ``name`` (with or without ``.toml``), or None if there is no such built-in."""
    stem = name.removesuffix(SUFFIX)
    return builtin_folder() / f"{stem}{SUFFIX}" if stem in builtin_names() else None


def describe(path: Path) -> str:
    """A scene file's ``description`` (empty if it has none or cannot be read)."""
    try:
        return str(tomllib.loads(path.read_text(encoding="utf-8")).get("description", ""))
    except (OSError, ValueError):
        return ""


@dataclass(frozen=True)
class SceneSource:
    """Where a SCENE argument points: the file, and how to name it in messages."""

    path: Path
    builtin: bool = False

    @property
    def label(self) -> str:
        return f"built-in scene {self.path.stem}" if self.builtin else str(self.path)


def looks_like_a_name(text: str) -> bool:
    """Whether a command-line argument could be a built-in's name (no folder in it)."""
    return "/" not in text and "\\" not in text


def not_found(text: str) -> SceneError:
    """The one-line refusal for a SCENE argument that is neither a file nor a built-in's name."""
    names = builtin_names()
    close = difflib.get_close_matches(Path(text).name.removesuffix(SUFFIX), names, n=1, cutoff=0.6)
    hint = f"did you mean {close[0]}? " if close else ""
    return SceneError(text, "", f"no such scene file or built-in scene; {hint}built-in scenes: {', '.join(names)} "
                                f"(`ropesim scenarios` describes them)")


def resolve(arg: str | Path) -> SceneSource:
    """The scene a SCENE argument means: an existing path as it is, else the built-in it names.

    Raises :class:`SceneError` (one line naming the argument, the built-ins and the closest one) if neither.
    """
    text = str(arg)
    path = Path(arg)
    if path.exists():
        return SceneSource(path)
    if looks_like_a_name(text):
        found = builtin_path(text)
        if found is not None:
            return SceneSource(found, builtin=True)
    raise not_found(text)



# ------------------------------------------------------------------------ `ropesim new`: an annotated copy

_KEY = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\s*=")
_HEADER = re.compile(r"^\[(\[?)\s*([A-Za-z_][A-Za-z0-9_]*)(?:\.[A-Za-z0-9_-]+)?\s*\]\]?\s*(#.*)?$")
NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")
_OUR_HEADER = re.compile(r"^# \S+: a scene to edit, copied from .* by `ropesim new`")
HEADER_LINES = 5  # the header annotated_copy writes, with the blank line after it


def _keys(table: str | None, raw: dict) -> dict:
    """{key: (Spec, default)} of the keys ``table`` may hold (the top level when None); MISSING if required."""
    from dataclasses import MISSING, fields

    from . import schema as S

    if table is None:
        return {k: (spec, MISSING) for k, spec in S.TOP_LEVEL_SCALARS.items()}
    system = "lines" in raw
    cls = ((S.SYSTEM_VARIANTS.get(table) if system else None) or S.TABLES.get(table)
           or S.ARRAYS_OF_TABLES.get(table) or S.NAMED_TABLES.get(table))
    if table == "initial":
        cls = _initial_shapes(raw).get(raw.get("initial", {}).get("shape", "lines" if system else ""))
    if cls is None:
        return {}
    return {f.name: (f.metadata["spec"], f.default) for f in fields(cls) if "spec" in f.metadata}


def _initial_shapes(raw: dict) -> dict:
    """The ``initial.shape`` choices of the scene ``raw``: a system's or one rope's."""
    from . import schema as S

    return S.SYSTEM_INITIAL_SHAPES if "lines" in raw else S.INITIAL_SHAPES


def _doc(spec) -> str:
    text = spec.doc + (f" [{spec.unit}]" if spec.unit else "")
    if spec.choices:
        text += f"; one of {', '.join(map(str, spec.choices))}"
    return text


def annotated_copy(source: Path, name: str, label: str | None = None) -> str:
    """The text of scene file ``source`` as a new scene ``name``, to edit: a header saying where it came from,
    its own comments kept, a comment line above every key from the schema (meaning, unit, choices), and the
    optional keys it leaves out listed, commented out, at their defaults."""
    from dataclasses import MISSING

    import tomli_w

    from .. import __version__
    from . import schema as S

    text = source.read_text(encoding="utf-8")
    raw = tomllib.loads(text)
    lines = text.splitlines()
    if lines and _OUR_HEADER.match(lines[0]):   # a copy of a copy: its old header goes, its notes stay
        lines = lines[HEADER_LINES:]
    present = set(lines)
    out = [f"# {name}: a scene to edit, copied from {label or source} by `ropesim new` (ropesim {__version__}).",
           f"# Check it with `ropesim check {name}.toml`, run it with `ropesim run {name}.toml`. Units are SI; x is",
           "# horizontal, y points up. Each key has its meaning above it; optional keys left out are shown",
           "# commented out at their defaults. The original file's comments follow.",
           ""]
    table, seen, last_key = None, set(), None

    def close_table() -> None:
        """Commented-out lines for the optional keys the table just closed leaves out."""
        if last_key is None:
            return
        missing = [(k, spec, default) for k, (spec, default) in _keys(table, raw).items()
                   if k not in seen and k != "shape" and default is not MISSING and default is not None]
        shown = [f"# {k} = {tomli_w.dumps({k: list(d) if isinstance(d, tuple) else d}).split('= ', 1)[1].strip()}"
                 f"   # {_doc(spec)}" for k, spec, default in missing for d in [default]]
        out[last_key + 1:last_key + 1] = [line for line in shown if line not in present]

    named = False
    for line in lines:
        header = _HEADER.match(line)
        key = _KEY.match(line)
        if header:
            close_table()
            table, seen, last_key = header.group(2), set(), None
        elif key:
            k = key.group(1)
            spec = _keys(table, raw).get(k, (None,))[0]
            if table is None and k == "name":
                line, named = f'name = "{name}"', True
            if table == "initial" and k == "shape":
                spec = S.Spec("str", "initial shape", choices=tuple(_initial_shapes(raw)))
            if spec is not None and out[-1] != f"# {_doc(spec)}":
                out.append(f"# {_doc(spec)}")
            seen.add(k)
            out.append(line)
            last_key = len(out) - 1
            continue
        out.append(line)
    close_table()
    if not named:
        out.insert(HEADER_LINES, f'name = "{name}"')
    return "\n".join(out) + "\n"
