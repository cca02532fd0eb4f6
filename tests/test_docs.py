"""The documentation site keeps up with the code.

- Every key of every scene table (every initial shape too) is in the scene reference with its unit and its
  allowed range; every command and option of the CLI is in the CLI reference; every public name is on the
  API page. Checked on the generator's output for the real pages (the schema and the app walked here
  independently of the generator), and, when the docs extra is installed, on the built site.
- The scene reference's TOML examples load.
- The tutorials' command blocks are real: each block marked ``<!-- run -->`` runs, in page order, in a scratch
  folder (fast suite: scene end times capped; slow suite: everything exactly as written, ``<!-- run: slow -->``
  blocks included).
"""

from __future__ import annotations

import copy
import html
import importlib
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import textwrap
import tomllib
from dataclasses import fields
from pathlib import Path
from typing import Annotated

import pytest
import typer

from ropesim.scene import schema as S
from ropesim.scene.loader import SceneError, scene_from_dict as load

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
SCENE_PAGE = DOCS / "reference" / "scene.md"
CLI_PAGE = DOCS / "reference" / "cli.md"
API_PAGE = DOCS / "reference" / "api.md"
TUTORIAL_PAGES = [DOCS / "getting-started.md", *sorted((DOCS / "tutorials").glob("*.md"))]


def _hook():
    spec = importlib.util.spec_from_file_location("ropesim_docs_reference", DOCS / "hooks" / "reference.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


REF = _hook()


# ------------------------------------------------------------------------ the schema, walked independently


def schema_sections() -> dict[str, list[tuple[str, S.Spec]]]:
    """{section id: [(key, spec)]} for the top-level keys, every table and array of tables, and each initial
    shape, straight from the schema's own lists."""
    out = {"top-level": list(S.TOP_LEVEL_SCALARS.items())}
    for name, cls in {**S.TABLES, **S.ARRAYS_OF_TABLES, **S.NAMED_TABLES}.items():
        if name == "initial":
            for section, shapes in (("initial", S.INITIAL_SHAPES), ("initial-system", S.SYSTEM_INITIAL_SHAPES)):
                out[section] = [("shape", S.Spec("str", "", choices=tuple(shapes)))]
                for shape, shape_cls in shapes.items():
                    out[f"{section}-{shape}"] = [(f.name, f.metadata["spec"]) for f in fields(shape_cls)
                                                 if f.name != "shape"]
        else:
            assert cls is not None, f"[{name}] is a tagged union: teach this test and docs/hooks/reference.py"
            out[name] = [(f.name, f.metadata.get("spec")) for f in fields(cls)]
    for name, cls in S.SYSTEM_VARIANTS.items():   # [[bodies]] in a system: rigid bodies
        out[f"{name}-system"] = [(f.name, f.metadata.get("spec")) for f in fields(cls)]
    return out


def _number_shown(value) -> list[str]:
    """Ways a bound may be written: 0, 2, 1 000 000 (any digit grouping), 1e+06."""
    value = int(value) if float(value).is_integer() else value
    return [f"{value:g}", str(value), f"{value:,}".replace(",", "\u202f"), f"{value:,}".replace(",", " ")]


def _sections(markdown: str) -> dict[str, str]:
    """The Markdown by heading anchor: '## `[rope]` {#rope}' starts section 'rope', until the next heading."""
    parts = re.split(r"^#{2,3} .*\{#([A-Za-z0-9_.-]+)\}\s*$", markdown, flags=re.M)
    return {parts[i]: parts[i + 1] for i in range(1, len(parts), 2)}


def _row(section: str, key: str) -> str | None:
    match = re.search(rf"^\|[^|\n]*`{re.escape(key)}`[^|\n]*\|.*$", section, flags=re.M)
    return match.group(0) if match else None


def missing_scene_keys(markdown: str) -> list[str]:
    """Every schema key the scene reference Markdown lacks, or shows without its unit, range or choices."""
    sections = _sections(markdown)
    problems = []
    for name, keys in schema_sections().items():
        if name not in sections:
            problems.append(f"no section {{#{name}}}")
            continue
        for key, spec in keys:
            if spec is None:
                problems.append(f"{name}.{key}: a schema field without a Spec")
                continue
            row = _row(sections[name], key)
            if row is None:
                problems.append(f"{name}.{key}: no row")
                continue
            cells = [c.strip() for c in re.split(r"(?<!\\)\|", row.strip())[1:-1]]
            if len(cells) != 6:
                problems.append(f"{name}.{key}: expected key | type | unit | allowed | default | meaning")
                continue
            _, kind, unit, allowed, default, meaning = cells
            if unit.replace("²", "^2") != spec.unit:
                problems.append(f"{name}.{key}: unit {unit!r}, the schema says {spec.unit!r}")
            for choice in spec.choices:
                if str(choice) not in allowed:
                    problems.append(f"{name}.{key}: choice {choice!r} missing")
            for bound in (spec.low, spec.high):
                if bound is not None and not any(s in allowed for s in _number_shown(bound)):
                    problems.append(f"{name}.{key}: bound {bound} missing from {allowed!r}")
            if spec.low is not None and spec.open_low and ">" not in html.unescape(allowed):
                problems.append(f"{name}.{key}: the lower bound is strict, {allowed!r} does not say so")
            if not default or not meaning:
                problems.append(f"{name}.{key}: no default or no meaning")
    return problems


def _expanded(page: Path) -> str:
    return REF.expand(page.read_text(encoding="utf-8"), str(page))


def test_scene_reference_documents_every_key_with_unit_and_range():
    assert missing_scene_keys(_expanded(SCENE_PAGE)) == []


def test_scene_check_catches_a_missing_key_unit_or_table():
    """The check above is not vacuous: a row, a unit or a whole table taken out of the page is reported."""
    page = _expanded(SCENE_PAGE)
    no_row = re.sub(r"^\|[^|\n]*`segment_length`.*\n", "", page, flags=re.M)
    assert any("rope.segment_length: no row" in p for p in missing_scene_keys(no_row))
    wrong_unit = re.sub(r"(`stiffness` \| number \| )N/m", r"\1kg", page, count=1)
    assert any("unit" in p for p in missing_scene_keys(wrong_unit))
    no_table = page.replace("{#guides}", "{#somewhere-else}")
    assert "no section {#guides}" in missing_scene_keys(no_table)


def test_scene_reference_places_every_table_even_new_ones(monkeypatch):
    """A table added to the schema appears on the page through its 'rest' marker, keys and all."""
    from dataclasses import dataclass

    @dataclass(frozen=True)
    class Seabed:
        """A flat seabed the rope rests on."""

        depth: float = S.spec("float", "depth below y = 0", "m", low=0, open_low=True)
        friction: float = S.spec("float", "friction coefficient", default=0.5, low=0)

    monkeypatch.setitem(S.TABLES, "seabed", Seabed)
    page = _expanded(SCENE_PAGE)
    assert missing_scene_keys(page) == []
    assert "A flat seabed the rope rests on." in _sections(page)["seabed"]


def test_defaults_shown_for_absent_keys_name_real_keys():
    """docs/hooks/reference.py's WHEN_ABSENT (what leaving a key out means) names only keys that exist."""
    keys = {key for key in S.TOP_LEVEL_SCALARS}
    for name, entries in schema_sections().items():
        keys |= {f"{name.split('-')[0]}.{key}" for key, _ in entries}
    assert set(REF.WHEN_ABSENT) <= keys, set(REF.WHEN_ABSENT) - keys


def test_scene_reference_examples_are_valid_scenes():
    """Each ```toml block of the page is a complete scene, or a fragment that loads on top of a base one."""
    blocks = re.findall(r"```toml\n(.*?)```", SCENE_PAGE.read_text(encoding="utf-8"), flags=re.S)
    assert len(blocks) >= 10
    base = {"rope": {"nodes": 21, "segment_length": 1.0, "stiffness": 100.0, "mass": 1.0},
            "initial": {"shape": "line", "start": [0.0, 0.0], "end": [20.0, 0.0]},
            "integrator": {"dt": 0.001, "t_end": 0.01}}
    system = {"points": [{"id": "a", "position": [0.0, 0.0]}, {"id": "b", "position": [20.0, 0.0]}],
              "lines": [{"id": "l", "start": "a", "end": "b", "length": 21.0, "segments": 20, "EA": 1e6,
                         "mass_per_length": 1.0}],
              "integrator": {"dt": 0.001, "t_end": 0.01}}
    for block in blocks:
        fragment = tomllib.loads(block)
        complete = "integrator" in fragment and ("rope" in fragment or "lines" in fragment)
        start = system if fragment.keys() & {"lines", "points", "line_types"} else base
        raw = fragment if complete else {**copy.deepcopy(start), **fragment}
        try:
            load(raw, source="docs/reference/scene.md")
        except SceneError as exc:
            pytest.fail(f"example does not load: {exc}\n{block}")


# ----------------------------------------------------------------------------- the CLI, walked independently


def cli_options() -> dict[str, list[str]]:
    """{command: [every spelling of every option, and each argument's name in capitals]}, from the app."""
    import typer

    from ropesim.cli.app import app

    group = typer.main.get_command(app)
    ctx = typer.Context(group, info_name="ropesim", **(group.context_settings or {}))
    out = {"ropesim": [o for p in group.get_params(ctx) for o in p.opts + p.secondary_opts]}
    for name in group.list_commands(ctx):
        command = group.get_command(ctx, name)
        if command.hidden:
            continue
        cctx = typer.Context(command, info_name=name, parent=ctx)
        spellings = []
        for p in command.get_params(cctx):
            if getattr(p, "hidden", False):
                continue
            is_option = p.opts and p.opts[0].startswith("-")
            spellings += list(p.opts) + list(p.secondary_opts) if is_option else [p.name.upper()]
        out[name] = spellings
    return out


def missing_cli_options(markdown: str) -> list[str]:
    sections = _sections(markdown)
    problems = []
    for command, spellings in cli_options().items():
        if command not in sections:
            problems.append(f"no section for `ropesim {command}`" if command != "ropesim" else "no `ropesim` section")
            continue
        rows = [line for line in sections[command].splitlines() if line.startswith("|")]
        for spelling in spellings:
            if not any(re.search(rf"(?<![\w-]){re.escape(spelling)}(?![\w-])", row) for row in rows):
                problems.append(f"ropesim {command}: {spelling} missing")
    return problems


def test_cli_reference_documents_every_command_and_option():
    assert missing_cli_options(_expanded(CLI_PAGE)) == []


def test_cli_check_catches_a_missing_command_or_option():
    page = _expanded(CLI_PAGE)
    no_option = re.sub(r"^\|.*`--dts[^|]*\|.*\n", "", page, flags=re.M)
    assert "ropesim accuracy: --dts missing" in missing_cli_options(no_option)
    no_command = page.replace("{#frames}", "{#elsewhere}")
    assert "no section for `ropesim frames`" in missing_cli_options(no_command)


def test_cli_reference_places_new_commands(monkeypatch):
    """A command added to the app appears on the page through its 'rest' marker, options and all."""
    app_module = importlib.import_module("ropesim.cli.app")  # ropesim.cli.app is also the Typer object's name
    new_app = typer.Typer(name="ropesim", help="ropesim with one more command")
    for info in app_module.app.registered_commands:
        new_app.registered_commands.append(info)

    @new_app.command()
    def export(run_dir: Annotated[Path, typer.Argument(help="A run folder.")],
               fmt: Annotated[str, typer.Option("--format", "-f", help="csv or vtk.")] = "csv") -> None:
        """Export a run folder to another format."""

    monkeypatch.setattr(app_module, "app", new_app)
    page = _expanded(CLI_PAGE)
    assert missing_cli_options(page) == []
    assert "Export a run folder to another format." in _sections(page)["export"]


# -------------------------------------------------------------------------------------------- the built site


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    """The site built by `mkdocs build --strict` into a temporary folder (skipped without the docs extra)."""
    if importlib.util.find_spec("mkdocs") is None or importlib.util.find_spec("mkdocstrings") is None:
        pytest.skip('the docs extra is not installed (pip install -e ".[docs]")')
    out = tmp_path_factory.mktemp("site")
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    result = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(out)],
                            cwd=ROOT, capture_output=True, text=True, env=env, timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
    return out


def _html_sections(page: Path) -> dict[str, str]:
    text = page.read_text(encoding="utf-8")
    parts = re.split(r'<h[23] id="([^"]+)"', text)
    return {parts[i]: parts[i + 1] for i in range(1, len(parts), 2)}


def _html_rows(section: str) -> list[str]:
    return [html.unescape(re.sub(r"<[^>]+>", " ", row)) for row in re.findall(r"<tr>(.*?)</tr>", section, re.S)]


def test_built_scene_reference_has_every_key_with_its_unit(site):
    sections = _html_sections(site / "reference" / "scene" / "index.html")
    for name, keys in schema_sections().items():
        assert name in sections, f"built scene reference: no section #{name}"
        rows = _html_rows(sections[name])
        for key, spec in keys:
            unit = spec.unit.replace("^2", "²")
            assert any(re.search(rf"(?<!\w){key}(?!\w)", row) and unit in row for row in rows), \
                f"built scene reference #{name}: no row for {key} with unit {unit!r}"


def test_built_cli_reference_has_every_option(site):
    sections = _html_sections(site / "reference" / "cli" / "index.html")
    for command, spellings in cli_options().items():
        assert command in sections, f"built CLI reference: no section #{command}"
        rows = _html_rows(sections[command])
        for spelling in spellings:
            assert any(re.search(rf"(?<![\w-]){re.escape(spelling)}(?![\w-])", row) for row in rows), \
                f"built CLI reference, ropesim {command}: {spelling} missing"


def test_built_api_page_documents_every_public_name(site):
    import ropesim

    text = (site / "reference" / "api" / "index.html").read_text(encoding="utf-8")
    for name in ropesim.__all__:
        assert re.search(rf'<h2 id="[^"]*\.{name}"', text), f"API page: no entry for ropesim.{name}"


def test_built_site_has_every_page_and_image(site):
    for page in DOCS.rglob("*.md"):
        if "notebooks" in page.parts:
            continue
        rel = page.relative_to(DOCS).with_suffix("")
        built = site / ("index.html" if rel.name == "index" and rel.parent == Path(".") else
                        (rel.parent / "index.html" if rel.name == "index" else rel / "index.html"))
        assert built.is_file(), f"{page} was not built ({built})"
    for image in (DOCS / "images").rglob("*.*"):
        assert (site / image.relative_to(DOCS)).is_file()


# -------------------------------------------------------------------------------------- tutorials' commands

BLOCK = re.compile(r"^<!-- run(: slow)? -->\n+```(\w+)([^\n]*)\n(.*?)^```", re.M | re.S)

# The fast suite runs the tutorials' commands through this stand-in for `ropesim`, which caps every scene's
# end time (and asks `frames` for two frames instead of times the capped run does not reach). The slow suite
# runs the real command, exactly as the pages say.
T_END_CAP = 0.2
SHIM = """\
import sys

from ropesim.cli import main

CAP = {cap!r}


def capped(args):
    if args and args[0] in ("run", "check", "sweep", "accuracy", "stability"):
        done = False
        for i in range(len(args) - 1):
            if args[i] in ("--set", "-s") and args[i + 1].startswith("integrator.t_end="):
                args[i + 1], done = f"integrator.t_end={{CAP}}", True
        if not done:
            args += ["--set", f"integrator.t_end={{CAP}}"]
    if args and args[0] == "frames" and "--times" in args:
        i = args.index("--times")
        args[i:i + 2] = ["--count", "2"]  # a capped run has at least its first and last frames
    return args


if __name__ == "__main__":  # sweeps start worker processes, which import this file again
    sys.argv = ["ropesim", *capped(sys.argv[1:])]
    main()
"""


def runnable_blocks(page: Path) -> list[tuple[bool, str, str, str]]:
    """(slow, language, fence info, code) of every block marked <!-- run --> or <!-- run: slow -->."""
    return [(bool(m.group(1)), m.group(2), m.group(3), m.group(4))
            for m in BLOCK.finditer(page.read_text(encoding="utf-8"))]


def _workspace(tmp_path: Path, capped: bool) -> dict:
    """A scratch folder with scenarios/ and scripts/, and the environment to run a page's blocks in."""
    for name in ("scenarios", "scripts"):
        shutil.copytree(ROOT / name, tmp_path / name)
    bin_dir = Path(sys.executable).parent
    path = [str(bin_dir)]
    if capped:
        shim_dir = tmp_path / ".shim"
        shim_dir.mkdir()
        shim = shim_dir / "ropesim"
        shim.write_text(f"#!{sys.executable}\n" + SHIM.format(cap=T_END_CAP))
        shim.chmod(0o755)
        path.insert(0, str(shim_dir))
    env = {**os.environ, "PATH": os.pathsep.join(path + [os.environ.get("PATH", "")]), "MPLBACKEND": "Agg",
           "PYTHONUNBUFFERED": "1", "BROWSER": "true"}   # `ropesim view` opens its page with `true`: nothing
    return env


def run_page(page: Path, tmp_path: Path, slow: bool) -> None:
    blocks = runnable_blocks(page)
    env = _workspace(tmp_path, capped=not slow)
    for is_slow, language, info, code in blocks:
        if is_slow and not slow:
            continue
        title = re.search(r'title="([^"]+)"', info)
        if title:
            (tmp_path / title.group(1)).write_text(code, encoding="utf-8")
            continue
        if language == "bash":
            command = ["bash", "-euo", "pipefail", "-c", code]
        elif language == "python":
            command = [sys.executable, "-c", code]
        else:
            pytest.fail(f"{page.name}: a runnable ```{language} block must be bash, python or have a title=")
        proc = subprocess.Popen(command, cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                text=True, start_new_session=True)
        try:
            output, _ = proc.communicate(timeout=900)
        finally:
            if proc.poll() is None:
                os.killpg(proc.pid, 9)
        assert proc.returncode == 0, (f"{page.relative_to(ROOT)}: this block failed (exit {proc.returncode}):\n"
                                      f"{textwrap.indent(code, '    ')}\n{output[-4000:]}")


@pytest.mark.parametrize("page", TUTORIAL_PAGES, ids=lambda p: p.stem)
def test_tutorial_pages_have_runnable_commands(page):
    """Every tutorial (and getting started) marks its commands to run; an unmarked page would go untested."""
    blocks = runnable_blocks(page)
    if page.name == "index.md":
        return
    assert blocks, f"{page}: no <!-- run --> block"
    for _, language, info, _ in blocks:
        assert language in ("bash", "python") or 'title="' in info, f"{page}: a runnable ```{language} block"


# The fast suite runs the pages a newcomer reads first, capped; every page runs as written in the slow suite
# (each scene with other parts compiles its own kernels: a few seconds a page, too many for a quick loop).
QUICK_PAGES = ("getting-started.md",)


@pytest.mark.parametrize("page", [p for p in TUTORIAL_PAGES if p.name in QUICK_PAGES], ids=lambda p: p.stem)
def test_tutorial_commands_run(page, tmp_path):
    """The page's <!-- run --> blocks, in order, with every scene's end time capped."""
    run_page(page, tmp_path, slow=False)


@pytest.mark.slow
@pytest.mark.parametrize("page", [p for p in TUTORIAL_PAGES if p.name != "index.md"], ids=lambda p: p.stem)
def test_tutorial_commands_run_as_written(page, tmp_path):
    """Every marked block, slow ones too, exactly as written."""
    if page.name == "sweeps.md" and importlib.util.find_spec("distributed") is None:
        pytest.skip('the Dask tutorial needs the dask extra (pip install -e ".[dask]")')
    run_page(page, tmp_path, slow=True)
