"""MkDocs hook: the scene-file and command-line references, generated from the code at every build.

A page asks for a generated part with an HTML comment on a line of its own:

    <!-- ropesim:scene rope -->     the [rope] table: heading, the dataclass's docstring, one row per key
    <!-- ropesim:scene rest -->     every table not placed earlier on the page, in the schema's order
    <!-- ropesim:cli run -->        the `ropesim run` command: summary, usage, arguments, options
    <!-- ropesim:cli commands -->   a table of every command in its help panel, with its one-line summary
    <!-- ropesim:cli rest -->       every command not placed earlier on the page, in the app's order

So a key, a table or a command added to the code appears in the docs without anyone editing a page, and a
marker naming something the code no longer has is a warning (an error under ``mkdocs build --strict``).
The scene reference reads ``ropesim.scene.schema`` (each field's ``metadata["spec"]``: kind, unit, range,
choices, doc; the field's default; the table's docstring); the CLI reference reads the Typer app through
``typer.main.get_command`` and the click parameters' own help records. ``tests/test_docs.py`` tests both
generators against the schema and the app, and the built pages.
"""

from __future__ import annotations

import inspect
import logging
import re
from dataclasses import MISSING, fields

log = logging.getLogger("mkdocs.hooks.ropesim")

MARKER = re.compile(r"^<!-- ropesim:(scene|cli|api) ([A-Za-z0-9_.-]+) -->[ \t]*$", re.M)

# ------------------------------------------------------------------------------------------ scene file

KINDS = {
    "int": "integer",
    "float": "number",
    "bool": "boolean",
    "str": "string",
    "vector": "vector",
    "int_list": "node indices",
    "points": "list of vectors",
    "rows": "table",
    "angles": "angles",
    "dofs": "per degree of freedom",
    "dof_rows": "table",
    "inertia": "inertia",
    "wave_rows": "table",
    "horizontal": "list of positions",
}

# What a key left out means when the schema's default is None ("work it out from the rest of the scene").
# Keyed by dotted path (table.key; the initial shapes share "initial."). tests/test_docs.py checks that
# every entry still names a key of the schema, so this list cannot outlive the keys it describes.
WHEN_ABSENT = {
    "name": "the file's stem",
    "description": '`""`',
    "dimension": "`2`",
    "up": '`"y"`',
    "initial.top": "the origin",
    "initial.top_center": "the thrower's `center`",
    "initial.velocity": "zero",
    "overrides.mass": "the rope's `mass`",
    "overrides.drag": "the `[drag]` table's `b` (0 without one)",
    "initial.velocities": "`velocity` for every node",
    "initial.time": "the run's last saved frame",
    "rope.nodes": "`segments` + 1 (a loop: `segments`) in the physical form",
    "rope.segment_length": "`length` / `segments` in the physical form",
    "rope.stiffness": "`EA` / l in the physical form",
    "rope.mass": "`mass_per_length` × l in the physical form",
    "rope.mass_per_length": "`density` × π d² / 4 when both are given",
    "rope.compression": "`true` per node, `false` in the physical form",
    "rope.axial_damping": "zero, or ζ l √(EA m′) with `axial_damping_ratio` ζ",
    "rope.axial_damping_ratio": "none: `axial_damping` gives BA",
    "seabed.friction_axial": "`friction`",
    "seabed.contact_width": "the rope's `diameter`",
    "driven.velocity": "zero (only the sinusoid or the path moves the node)",
    "driven.phase": "zero on every axis",
    "thrower.omega0": "4π |v_max| / L",
    "sea.depth": "`level` − `seabed.height` with a `[seabed]`, else deep water",
    "sea.wind": "still air",
    "waves.height": "**required** for `regular`",
    "waves.period": "**required** for `regular`",
    "waves.significant_height": "**required** for `jonswap` and `pierson_moskowitz`",
    "waves.peak_period": "**required** for `jonswap` and `pierson_moskowitz`",
    "waves.gamma": "DNV-RP-C205's: 5 for Tp/√Hs ≤ 3.6, exp(5.75 − 1.15 Tp/√Hs) up to 5, then 1",
    "waves.components": "`100` for a spectrum",
    "waves.frequency_range": "0.5 and 3 times the peak frequency 2π/Tp",
    "waves.table": "`table_file`'s rows (**required** one way or the other for `table`)",
    "waves.table_file": "none: the rows are inline in `table`",
    "guides.omega0": "the thrower's ω0 (required without a `[thrower]`)",
    # systems: a line type, a line (its type's value, else ...), a point, a rigid body
    "line_types.mass_per_length": "`density` × π d² / 4 when both are given",
    "line_types.compression": "`false`",
    "line_types.cd_normal": "`[fluid_drag]`'s",
    "line_types.cd_tangential": "`[fluid_drag]`'s",
    "line_types.ca_normal": "`[added_mass]`'s",
    "line_types.ca_tangential": "`[added_mass]`'s",
    "lines.type": "none: the line gives its material itself",
    "lines.diameter": "its type's (none without one)",
    "lines.mass_per_length": "its type's, else `density` × π d² / 4 (**required** one way or another)",
    "lines.density": "its type's (none without one)",
    "lines.EA": "its type's (**required** in one or the other)",
    "lines.axial_damping": "its type's, else zero; ζ l √(EA m′) with `axial_damping_ratio` ζ (the line's own key "
                           "wins over its type's)",
    "lines.axial_damping_ratio": "its type's (none without one)",
    "lines.EI": "its type's, else no bending stiffness",
    "lines.compression": "its type's, else `false`",
    "lines.cd_normal": "its type's, else `[fluid_drag]`'s",
    "lines.cd_tangential": "its type's, else `[fluid_drag]`'s",
    "lines.ca_normal": "its type's, else `[added_mass]`'s",
    "lines.ca_tangential": "its type's, else `[added_mass]`'s",
    "points.kind": '`"body"` when `body` is given, else `"fixed"`',
    "points.mass": "0 on a free point (other kinds take none)",
    "points.volume": "0 on a free point (other kinds take none)",
    "points.cd_area": "0 on a free point (other kinds take none)",
    "points.ca": "0 on a free point (other kinds take none)",
    "points.velocity": "zero on a driven point",
    "points.period": "**required** with `amplitude`",
    "points.phase": "zero with `amplitude`",
    "points.ramp_time": "0 on a driven point",
    "bodies.orientation": "zero: the body's axes along the scene's",
    "bodies.center_of_gravity": "the body's reference point",
    "bodies.inertia": "none (**required** for a free body)",
    "bodies.center_of_buoyancy": "the body's reference point",
    "bodies.height": "none (**required** for a free body under a `[sea]`, unless `fraction = \"moordyn\"`)",
    "bodies.cd_area": "zero",
    "bodies.cd_rotation": "zero",
    "bodies.added_mass": "zero",
    "bodies.added_inertia": "zero",
    "bodies.velocity": "zero on a driven body",
    "bodies.angular_velocity": "zero on a driven body",
    "bodies.period": "**required** with `amplitude`",
    "bodies.phase": "zero with `amplitude`",
    "bodies.ramp_time": "0 on a driven body",
}


def _schema():
    from ropesim.scene import schema

    return schema


def _number(value) -> str:
    if isinstance(value, float) and value.is_integer() and abs(value) < 1e15:
        value = int(value)
    if isinstance(value, int) and abs(value) >= 10_000:
        return f"{value:,}".replace(",", "\u202f")  # narrow no-break space: 1 000 000
    return f"{value:g}" if isinstance(value, float) else str(value)


def _toml(value) -> str:
    """A default as it is written in a scene file."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, (tuple, list)):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    return str(value)


def allowed(spec) -> str:
    """The values a key accepts, as shown in the reference's 'allowed' column."""
    if spec.choices:
        return "one of " + ", ".join(f"`{_toml(c)}`" for c in spec.choices)
    if spec.low is not None and spec.high is not None:
        return f"{_number(spec.low)} to {_number(spec.high)}" if not spec.open_low else \
            f"> {_number(spec.low)}, ≤ {_number(spec.high)}"
    if spec.low is not None:
        return f"{'>' if spec.open_low else '≥'} {_number(spec.low)}"
    if spec.high is not None:
        return f"≤ {_number(spec.high)}"
    return {
        "bool": "`true` or `false`",
        "vector": "`dimension` numbers",
        "int_list": "a list of indices, or one; −N to N−1",
        "points": "N vectors",
        "rows": "rows of t and `dimension` numbers, t increasing",
        "wave_rows": "rows of 4 numbers: amplitude > 0, angular frequency > 0, phase, direction",
        "horizontal": "2-D: x each; 3-D: 2 numbers each (x, z; z up: x, y); over water",
        "angles": "3 numbers in 3-D (about x, y, z), 1 in 2-D (about z)",
        "dofs": "6 numbers in 3-D (x, y, z, then about x, y, z), 3 in 2-D (x, y, about z)",
        "dof_rows": "rows of t and one number per degree of freedom (6 in 3-D, 3 in 2-D), t increasing",
        "inertia": "3-D: 3 moments > 0, or a positive definite tensor's 6 entries; 2-D: 1 moment > 0",
        "str": "any",
        "int": "any integer",
        "float": "any number",
    }.get(spec.kind, "any")


def _text(doc: str) -> str:
    """A docstring or spec doc as Markdown: reST ``code`` becomes `code`; a table cell's | is escaped."""
    return re.sub(r"``([^`]+)``", r"`\1`", doc)


def _cell(text: str) -> str:
    return _escape_html(text).replace("|", "\\|").replace("\n", " ")


def _escape_html(text: str) -> str:
    """Escape < and > outside `code` spans, so that e.g. runs/<scene name>/ is not taken for an HTML tag."""
    parts = re.split(r"(`[^`]*`)", text)
    return "".join(p if p.startswith("`") else p.replace("<", "&lt;").replace(">", "&gt;") for p in parts)


def _docstring(cls) -> str:
    return _text(inspect.cleandoc(cls.__doc__ or ""))


def spec_fields(cls) -> list:
    """The keys of one table: its dataclass fields that carry a Spec (an initial shape's `shape` tag does not)."""
    return [f for f in fields(cls) if "spec" in f.metadata]


def default_of(path: str, f) -> str:
    """The 'default' column: **required**, the TOML literal, or what leaving it out means."""
    spec = f.metadata["spec"]
    if f.default is MISSING and f.default_factory is MISSING:
        return "**required**"
    if f.default is not None:
        return f"`{_toml(f.default)}`"
    return WHEN_ABSENT.get(path, "none" if not spec.required else "**required**")


def key_table(rows: list[tuple[str, str, object, str]]) -> str:
    """rows: (anchor id, key, spec, default column)."""
    out = ["| key | type | unit | allowed | default | meaning |", "|---|---|---|---|---|---|"]
    for anchor, key, spec, default in rows:
        kind = KINDS.get(spec.kind, spec.kind)
        unit = spec.unit.replace("^2", "²") if spec.unit else ""
        out.append(f"| <a id=\"{anchor}\"></a>`{key}` | {kind} | {unit} | {_cell(allowed(spec))} | "
                   f"{_cell(default)} | {_cell(_text(spec.doc))} |")
    return "\n".join(out)


def _table_rows(prefix: str, cls, table: str = "") -> list:
    """One row per key of ``cls``: anchors ``prefix.KEY``; WHEN_ABSENT is looked up as ``table.KEY`` (default
    ``prefix``)."""
    return [(f"{prefix}.{f.name}", f.name, f.metadata["spec"], default_of(f"{table or prefix}.{f.name}", f))
            for f in spec_fields(cls)]


def scene_tables() -> list[str]:
    """Every part of a scene file the reference documents, in the order a resolved scene.toml lists them."""
    schema = _schema()
    return ["top-level", *schema.TABLES, *getattr(schema, "NAMED_TABLES", {}), *schema.ARRAYS_OF_TABLES]


def scene_section(name: str) -> str:
    """The generated Markdown for one part of a scene file (see :func:`scene_tables`)."""
    schema = _schema()
    required = set(getattr(schema, "REQUIRED_TABLES", ()))
    if name == "top-level":
        rows = [(key, key, spec, WHEN_ABSENT.get(key, "**required**" if spec.required else "none"))
                for key, spec in schema.TOP_LEVEL_SCALARS.items()]
        return "## Top-level keys {#top-level}\n\nKeys before the first table.\n\n" + key_table(rows)
    if name in schema.ARRAYS_OF_TABLES:
        cls = schema.ARRAYS_OF_TABLES[name]
        out = (f"## `[[{name}]]` {{#{name}}}\n\n{_docstring(cls)}\n\n"
               f"An array of tables: write one `[[{name}]]` header per entry. `--set` addresses entry i as "
               f"`{name}.i.KEY`, counting from 0.\n\n" + key_table(_table_rows(name, cls)))
        variant = getattr(schema, "SYSTEM_VARIANTS", {}).get(name)
        if variant is not None:   # the same array's entries in a system: another class, other keys
            out += (f"\n\n### `[[{name}]]` in a system {{#{name}-system}}\n\nIn a system (a scene with "
                    f"`[[lines]]`), each `[[{name}]]` entry has these keys instead. {_docstring(variant)}\n\n"
                    + key_table(_table_rows(f"{name}-system", variant, name)))
        return out
    if name in getattr(schema, "NAMED_TABLES", {}):
        cls = schema.NAMED_TABLES[name]
        return (f"## `[{name}.NAME]` {{#{name}}}\n\n{_docstring(cls)}\n\n"
                f"A table of named tables: write one `[{name}.NAME]` header per entry, NAME a plain name without "
                f"dots. `--set` addresses a key as `{name}.NAME.KEY`.\n\n" + key_table(_table_rows(name, cls)))
    if name not in schema.TABLES:
        raise KeyError(name)
    cls = schema.TABLES[name]
    status = "**Required.**" if name in required else \
        "Optional: a scene without this table does without this part of the model."
    if cls is None:
        return _union_section(name, status)
    return f"## `[{name}]` {{#{name}}}\n\n{status} {_docstring(cls)}\n\n" + key_table(_table_rows(name, cls))


def union_shapes(name: str, system: bool = False) -> dict:
    """A tagged-union table (TABLES[name] is None): its tag's values and their dataclasses (``system``: in a
    system of lines)."""
    schema = _schema()
    if name == "initial":
        return dict(getattr(schema, "SYSTEM_INITIAL_SHAPES", {}) if system else schema.INITIAL_SHAPES)
    raise ValueError(f"scene table [{name}] is a tagged union that docs/hooks/reference.py does not know; "
                     f"teach union_shapes() where its variants are listed")


def _union_section(name: str, status: str) -> str:
    from ropesim.scene.schema import Spec

    shapes = union_shapes(name)
    tag = Spec("str", "which layout; each has its own keys below, and a key of another one is refused",
               choices=tuple(shapes))
    out = [f"## `[{name}]` {{#{name}}}\n\n{status} The key `shape` chooses one of {len(shapes)} layouts, each "
           f"with its own keys.\n\n" + key_table([(f"{name}.shape", "shape", tag, "**required**")])]
    out += _shape_sections(name, name, shapes)
    systems = union_shapes(name, system=True)
    if systems:
        tag = Spec("str", "how a system starts", choices=tuple(systems))
        default = f'`"{next(iter(systems))}"`'
        out.append(f"### In a system {{#{name}-system}}\n\nA system's `[{name}]` is optional, and so is its "
                   f"`shape`: it starts as `{next(iter(systems))}` without them. The shapes above start one rope; a "
                   f"system takes one of these.\n\n" + key_table([(f"{name}-system.shape", "shape", tag, default)]))
        out += _shape_sections(name, f"{name}-system", systems)
    return "\n\n".join(out)


def _shape_sections(name: str, prefix: str, shapes: dict) -> list[str]:
    out = []
    for shape, cls in shapes.items():
        rows = [(f"{prefix}-{shape}.{f.name}", f.name, f.metadata["spec"], default_of(f"{name}.{f.name}", f))
                for f in spec_fields(cls)]
        out.append(f"### `shape = \"{shape}\"` {{#{prefix}-{shape}}}\n\n{_docstring(cls)}\n\n"
                   + (key_table(rows) if rows else "No other keys."))
    return out


# ---------------------------------------------------------------------------------------- command line


def cli_root():
    """The Typer app as a click-style group, and its context (help option names and all)."""
    import typer

    from ropesim.cli.app import app

    group = typer.main.get_command(app)
    ctx = typer.Context(group, info_name="ropesim", **(group.context_settings or {}))
    return group, ctx


def cli_commands() -> list[str]:
    group, ctx = cli_root()
    return [name for name in group.list_commands(ctx) if not group.get_command(ctx, name).hidden]


def _command(name: str):
    import typer

    group, ctx = cli_root()
    command = group.get_command(ctx, name)
    if command is None:
        raise KeyError(name)
    return command, typer.Context(command, info_name=name, parent=ctx)


def _params(command, ctx) -> tuple[list, list]:
    params = [p for p in command.get_params(ctx) if not getattr(p, "hidden", False)]
    arguments = [p for p in params if not p.opts or not p.opts[0].startswith("-")]
    options = [p for p in params if p not in arguments]
    return arguments, options


def param_names(param) -> list[str]:
    """Every spelling of an option (--out, -o), or an argument's name in capitals."""
    names = list(param.opts) + list(getattr(param, "secondary_opts", []))
    if names and names[0].startswith("-"):
        return names
    return [param.name.upper()]


def _split_record(help_text: str) -> tuple[str, str]:
    """click puts '[default: 25.0; x>=1]' and '[required]' at the end of a help record: split them off."""
    extras = []
    while True:
        match = re.search(r"\s*\[([^\[\]]*)\]\s*$", help_text)
        if not match or not re.match(r"(default|required|env var|x[<>]|\d)", match.group(1)):
            break
        extras.insert(0, match.group(1))
        help_text = help_text[: match.start()]
    return help_text.strip(), "; ".join(extras)


def _usage(name: str, command, ctx) -> str:
    arguments, _ = _params(command, ctx)
    words = ["ropesim", name, "[OPTIONS]"] + [
        f"{p.name.upper()}{'...' if getattr(p, 'nargs', 1) == -1 else ''}" if p.required else f"[{p.name.upper()}]"
        for p in arguments]
    return " ".join(words)


def _options_table(options, ctx) -> str:
    out = ["| option | meaning | default |", "|---|---|---|"]
    for p in options:
        names, help_text = p.get_help_record(ctx)
        help_text, extra = _split_record(help_text or "")
        if getattr(p, "multiple", False) and "repeatable" not in help_text:
            help_text += " Repeatable."
        anchor = max(p.opts, key=len).lstrip("-") if p.opts else p.name
        default, notes = "", []
        for part in filter(None, (x.strip() for x in extra.split(";"))):
            if part.startswith("default:"):
                default = f"`{part[len('default:'):].strip()}`"
            else:
                notes.append(part)
        if notes:
            help_text += f" ({'; '.join(notes)})"
        out.append(f"| <a id=\"{ctx.info_name}-{anchor}\"></a>`{names}` | {_cell(help_text)} | {_cell(default)} |")
    return "\n".join(out)


def _paragraphs(text: str) -> str:
    """A command's help as Markdown: paragraphs as they are, an indented paragraph as a code block."""
    out = []
    for para in inspect.cleandoc(text or "").split("\n\n"):
        lines = para.split("\n")
        if all(line.startswith("  ") for line in lines):
            out.append("```text\n" + "\n".join(line[2:] for line in lines) + "\n```")
        else:
            out.append(_escape_html(para))
    return "\n\n".join(out)


def cli_section(name: str) -> str:
    """The generated Markdown for one command: summary, usage, arguments and options."""
    if name == "ropesim":
        group, ctx = cli_root()
        _, options = _params(group, ctx)
        return (f"## `ropesim` {{#ropesim}}\n\n{_paragraphs(group.help)}\n\n```text\nropesim [OPTIONS] COMMAND "
                f"[ARGS]...\n```\n\n" + _options_table(options, ctx))
    command, ctx = _command(name)
    arguments, options = _params(command, ctx)
    out = [f"## `ropesim {name}` {{#{name}}}", _paragraphs(command.help), f"```text\n{_usage(name, command, ctx)}\n```"]
    if arguments:
        rows = ["| argument | meaning |", "|---|---|"]
        for p in arguments:
            help_text, _ = _split_record((p.get_help_record(ctx) or ("", ""))[1] or getattr(p, "help", "") or "")
            rows.append(f"| `{param_names(p)[0]}` | {_cell(help_text)} |")
        out.append("\n".join(rows))
    out.append(_options_table(options, ctx))
    return "\n\n".join(out)


def cli_summary_table() -> str:
    """One row per command, grouped by its help panel (as `ropesim --help` shows them): the panel, its name
    (linked to its section) and the first line of its help."""
    rows = ["| group | command | what it does |", "|---|---|---|"]
    commands = [(_command(name)[0], name) for name in cli_commands()]
    panels = list(dict.fromkeys(command.rich_help_panel or "" for command, _ in commands))
    for command, name in sorted(commands, key=lambda c: panels.index(c[0].rich_help_panel or "")):
        first = inspect.cleandoc(command.help or "").split("\n\n")[0].replace("\n", " ")
        rows.append(f"| {command.rich_help_panel or ''} | [`ropesim {name}`](#{name}) | {_cell(first)} |")
    return "\n".join(rows)


# ------------------------------------------------------------------------------------------ Python API


def api_names() -> list[str]:
    """The public API: ``ropesim.__all__``."""
    import ropesim

    return list(ropesim.__all__)


def api_path(name: str) -> str:
    """Where a public name is defined, for mkdocstrings: ``ropesim.run.simulate`` for ``simulate``.

    ``ropesim`` exports its names lazily (``__getattr__``), which static analysis cannot follow, so each is
    documented where it lives; looked up at every build, the page follows the code when a module moves."""
    import ropesim

    if name not in ropesim.__all__:
        raise KeyError(name)
    obj = getattr(ropesim, name)
    module = getattr(obj, "__module__", None) if isinstance(obj, type) or callable(obj) else None
    if module is None:
        module = f"ropesim.{ropesim._LAZY[name]}"
    return f"{module}.{name}"


def api_section(name: str) -> str:
    return f"::: {api_path(name)}\n    options:\n      heading: \"ropesim.{name}\"\n      toc_label: \"{name}\""


# ---------------------------------------------------------------------------------------------- hook


def expand(markdown: str, where: str = "page") -> str:
    """Replace every ropesim marker of a page by its generated Markdown."""
    placed = {"scene": set(), "cli": set(), "api": set()}
    for kind, name in MARKER.findall(markdown):
        if (kind, name) != ("cli", "commands"):
            placed[kind].add(name)

    def generate(match: re.Match) -> str:
        kind, name = match.group(1), match.group(2)
        if name == "rest":
            names = {"scene": scene_tables, "cli": cli_commands, "api": api_names}[kind]()
            return "\n\n".join(generate_one(kind, n) for n in names if n not in placed[kind])
        if kind == "cli" and name == "commands":
            return cli_summary_table()
        return generate_one(kind, name)

    def generate_one(kind: str, name: str) -> str:
        try:
            return {"scene": scene_section, "cli": cli_section, "api": api_section}[kind](name)
        except KeyError:
            what = {"scene": "scene table", "cli": "command", "api": "public name in ropesim.__all__"}[kind]
            log.warning("%s: <!-- ropesim:%s %s -->: no such %s in the code", where, kind, name, what)
            return ""
        except ValueError as exc:
            log.warning("%s: <!-- ropesim:%s %s -->: %s", where, kind, name, exc)
            return ""

    return MARKER.sub(generate, markdown)


def on_page_markdown(markdown: str, page, config, files, **kwargs) -> str:
    if "<!-- ropesim:" not in markdown:
        return markdown
    return expand(markdown, page.file.src_uri)
