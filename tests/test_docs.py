"""The documentation site keeps up with the code.

- Every key of every scene table (every initial shape too) is in the scene reference with its unit and its
  allowed range; every command and option of the CLI is in the CLI reference; every public name is on the
  API page. Checked on the generator's output for the real pages (the schema and the app walked here
  independently of the generator), and, when the docs extra is installed, on the built site.
- The scene reference's TOML examples load.
- The tutorials' command blocks are real: each block marked ``<!-- run -->`` runs, in page order, in a scratch
  folder (fast suite: scene end times capped; slow suite: everything exactly as written, ``<!-- run: slow -->``
  blocks included), and the page shows every picture they draw.
- The built site as a reader sees it at 1280 px (headless Chromium): no code block wider than the column, no
  picture shown far smaller than its file without a click to zoom, every equation typeset, no request leaving
  the site.
"""

from __future__ import annotations

import copy
import html
import importlib
import importlib.util
import os
import re
import subprocess
import sys
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


def _load(path: Path, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _hook():
    return _load(DOCS / "hooks" / "reference.py", "ropesim_docs_reference")


REF = _hook()
BLOCKS = _load(ROOT / "scripts" / "tutorial_blocks.py", "ropesim_tutorial_blocks")


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

# Building the site executes the notebooks and renders every page in Chromium: a minute or more of CPU, in the
# slow suite (which CI runs, so CI still builds the site once); the quick loop checks the pages' sources above.
BUILT_SITE = pytest.mark.slow


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    """The site built by `mkdocs build --strict` into a temporary folder: CI's build of the site (`.ci/run` sets
    ROPESIM_REQUIRE_DOCS=1, which turns the skip without the docs extra into a failure, and builds it nowhere else)."""
    if importlib.util.find_spec("mkdocs") is None or importlib.util.find_spec("mkdocstrings") is None:
        if os.environ.get("ROPESIM_REQUIRE_DOCS") == "1":
            pytest.fail("ROPESIM_REQUIRE_DOCS=1 but the docs extra is not installed", pytrace=False)
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


@BUILT_SITE
def test_built_scene_reference_has_every_key_with_its_unit(site):
    sections = _html_sections(site / "reference" / "scene" / "index.html")
    for name, keys in schema_sections().items():
        assert name in sections, f"built scene reference: no section #{name}"
        rows = _html_rows(sections[name])
        for key, spec in keys:
            unit = spec.unit.replace("^2", "²")
            assert any(re.search(rf"(?<!\w){key}(?!\w)", row) and unit in row for row in rows), \
                f"built scene reference #{name}: no row for {key} with unit {unit!r}"


@BUILT_SITE
def test_built_cli_reference_has_every_option(site):
    sections = _html_sections(site / "reference" / "cli" / "index.html")
    for command, spellings in cli_options().items():
        assert command in sections, f"built CLI reference: no section #{command}"
        rows = _html_rows(sections[command])
        for spelling in spellings:
            assert any(re.search(rf"(?<![\w-]){re.escape(spelling)}(?![\w-])", row) for row in rows), \
                f"built CLI reference, ropesim {command}: {spelling} missing"


@BUILT_SITE
def test_built_api_page_documents_every_public_name(site):
    import ropesim

    text = (site / "reference" / "api" / "index.html").read_text(encoding="utf-8")
    for name in ropesim.__all__:
        assert re.search(rf'<h2 id="[^"]*\.{name}"', text), f"API page: no entry for ropesim.{name}"


@BUILT_SITE
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


@BUILT_SITE
def test_the_notebooks_are_pages_with_their_outputs(site):
    """mkdocs-jupyter executed docs/notebooks/*.ipynb at the build: their pages show what the cells printed and
    drew (the stored notebooks have no outputs; tests/test_notebook.py runs them too)."""
    quickstart = (site / "notebooks" / "quickstart" / "index.html").read_text(encoding="utf-8")
    assert "ropesim.Trajectory" in quickstart and "&lt;video" not in quickstart and "<video" in quickstart
    plots = r'<img[^>]* src="data:image/png;base64,'                 # matplotlib's figures
    assert len(re.findall(plots, quickstart)) == 1 and "the rope trails" in quickstart
    moorings = (site / "notebooks" / "moorings" / "index.html").read_text(encoding="utf-8")
    assert len(re.findall(plots, moorings)) == 3
    assert "fairlead load 360 to 1782 kN after the ramp" in moorings
    for page in (quickstart, moorings):                           # no error, nothing on stderr (a warning)
        assert not re.search(r'<div[^>]* data-mime-type="application/vnd.jupyter.stderr"', page)
        assert "Traceback" not in page


# ------------------------------------------------------------------ the built site in a browser, at 1280 px

VIEWPORT = (1280, 900)      # a laptop's screen: both sidebars shown, a 748-px column on most pages
READABLE_PX = 200           # a picture shown smaller than its file is still at least this wide (or its own width)
REPOSITORY_FACTS = "https://api.github.com/repos/pyropesim/ropesim"   # Material's star count: optional, may fail
PROBE = "_probe"            # a page made wrong on purpose, to show that each check below catches what it checks
PROBE_CONTENT = (
    "<pre><code>" + "x" * 200 + "</code></pre>"
    '<img src="../images/accuracy_helicopter.png" style="width: 300px">'          # 1210 px wide, no zoom
    '<a class="glightbox" href="../images/accuracy_helicopter.png">'
    '<img src="../images/accuracy_helicopter.png" style="width: 150px"></a>'      # zoom, but too small
    '<span class="arithmatex">\\(\\frac{1}{\\)</span>'                           # a TeX mistake
    '<link rel="preload" href="https://example.org/font.woff2" as="font" crossorigin>')

# What each page shows, measured in the page: every code block's overflow (the block scrolls sideways by this
# many pixels), every picture's shown and natural width and whether a click opens it full size, every equation.
MEASURE = """async () => {
  for (const d of document.querySelectorAll('article details')) d.open = true;
  for (const img of document.querySelectorAll('article img')) img.loading = 'eager';
  await Promise.all([...document.querySelectorAll('article img')].map(i => i.decode().catch(() => null)));
  await document.fonts.ready;
  const code = [...document.querySelectorAll('article pre')].map(pre => {
    const boxes = [pre, ...pre.querySelectorAll(':scope > code')];
    return {overflow: Math.max(...boxes.map(b => b.scrollWidth - b.clientWidth)),
            line: pre.textContent.split('\\n').reduce((a, b) => b.length > a.length ? b : a, '').slice(0, 70)};
  });
  const pictures = [...document.querySelectorAll('article img')].map(img => {
    const link = img.closest('a');
    const src = img.currentSrc || img.src;
    return {src: src.startsWith('data:') ? src.slice(0, 40) : src, shown: img.getBoundingClientRect().width,
            natural: img.naturalWidth,
            zoom: !!link && (link.classList.contains('glightbox') || link.href === src)};
  });
  const equations = [...document.querySelectorAll('article .arithmatex')].map(e => ({
    tex: e.querySelector('annotation') ? e.querySelector('annotation').textContent : e.textContent,
    typeset: !!e.querySelector('.katex') && !e.querySelector('.katex-error')}));
  return {code, pictures, equations, column: document.querySelector('article').clientWidth};
}"""


def _serve_only(base: str, left: list[str], route) -> None:
    """Let a page load what the site serves; record every request that would leave it, and refuse it (Material's
    request for the repository's star count gets a made-up answer, as if the host had been reached)."""
    url = route.request.url
    if url.startswith((base, "data:", "blob:")):
        route.continue_()
        return
    left.append(url)
    if url.startswith(REPOSITORY_FACTS):
        route.fulfill(status=200, content_type="application/json",
                      body='{"stargazers_count": 0, "forks_count": 0, "tag_name": "v0.1.0"}')
    else:
        route.abort()


@pytest.fixture(scope="module")
def rendered(site) -> dict[str, dict]:
    """Every page of the built site as Chromium shows it at 1280 px, served from 127.0.0.1 (as a web host would):
    {page: what MEASURE returns, plus the requests that left the site and the console's errors}. Skipped
    without a browser, unless ROPESIM_REQUIRE_BROWSER=1 (CI)."""
    import functools
    import http.server
    import threading

    from ropesim.viewer import headless

    why = headless.missing()
    if why:
        if os.environ.get("ROPESIM_REQUIRE_BROWSER") == "1":
            pytest.fail(f"ROPESIM_REQUIRE_BROWSER=1 but {why}", pytrace=False)
        pytest.skip(why)

    class Quiet(http.server.SimpleHTTPRequestHandler):
        def log_message(self, *args):
            pass

    page = (site / "getting-started" / "index.html").read_text(encoding="utf-8")
    article = re.search(r'<article class="md-content__inner md-typeset">', page).end()
    (site / PROBE).mkdir(exist_ok=True)
    (site / PROBE / "index.html").write_text(page[:article] + PROBE_CONTENT + page[article:], encoding="utf-8")
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(Quiet, directory=str(site)))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    base = f"http://127.0.0.1:{server.server_address[1]}/"
    folders = [p.parent.relative_to(site) for p in site.rglob("index.html")]
    pages = sorted("" if f == Path(".") else f.as_posix() for f in folders)
    out = {}
    try:
        with headless.browser() as browser:
            for name in pages:
                tab = browser.context.new_page()
                tab.set_viewport_size({"width": VIEWPORT[0], "height": VIEWPORT[1]})
                left, errors = [], []
                tab.route("**/*", functools.partial(_serve_only, base, left))
                tab.on("console", lambda m, errors=errors: errors.append(m.text) if m.type == "error" else None)
                tab.on("pageerror", lambda e, errors=errors: errors.append(str(e)))
                tab.goto(base + name + ("/" if name else ""), wait_until="load")
                out[name or "home"] = {**tab.evaluate(MEASURE), "left": left, "errors": errors}
                tab.close()
    finally:
        server.shutdown()
    return out


def wide_blocks(shown: dict) -> list[str]:
    return [f"{block['overflow']} px too wide: {block['line']!r}" for block in shown["code"] if block["overflow"] > 1]


def small_pictures(shown: dict) -> list[str]:
    problems = []
    for picture in shown["pictures"]:
        if picture["natural"] == 0:
            problems.append(f"{picture['src']} did not load")
        elif picture["shown"] < 0.5 * picture["natural"] and not picture["zoom"]:
            problems.append(f"{picture['src']} shown {picture['shown']:.0f} px of its {picture['natural']}, and "
                            f"no click opens it full size")
        elif picture["shown"] < min(READABLE_PX, picture["natural"]) - 1:
            problems.append(f"{picture['src']} shown only {picture['shown']:.0f} px wide")
    return problems


def untypeset(shown: dict) -> list[str]:
    return [eq["tex"] for eq in shown["equations"] if not eq["typeset"]]


def left_the_site(shown: dict) -> list[str]:
    return [url for url in shown["left"] if not url.startswith(REPOSITORY_FACTS)]


def _each_page(rendered: dict, check) -> dict[str, list[str]]:
    found = {page: check(shown) for page, shown in rendered.items() if page != PROBE}
    return {page: problems for page, problems in found.items() if problems}


@BUILT_SITE
def test_code_blocks_fit_the_column_at_1280_px(rendered):
    """No code block scrolls sideways on a 1280-px screen: commands and outputs are reflowed to the column."""
    assert _each_page(rendered, wide_blocks) == {}
    assert sum(len(shown["code"]) for shown in rendered.values()) > 100      # the blocks were found
    assert len(wide_blocks(rendered[PROBE])) == 1                            # and a wide one is caught


@BUILT_SITE
def test_pictures_are_shown_readably_with_click_to_zoom(rendered):
    """A picture is shown at least half its file's width, or a click opens it full size; never narrower than
    READABLE_PX (or its own width); and every picture loaded."""
    assert _each_page(rendered, small_pictures) == {}
    assert sum(p["zoom"] for shown in rendered.values() for p in shown["pictures"]) > 50
    caught = small_pictures(rendered[PROBE])                                 # the probe's two shrunken pictures
    assert len(caught) == 2 and "no click" in caught[0] and "only" in caught[1], caught


@BUILT_SITE
def test_equations_are_typeset_by_the_sites_own_katex(rendered):
    assert _each_page(rendered, untypeset) == {}
    for page in ("background/physics", "background/accuracy", "background/validation"):
        assert rendered[page]["equations"], f"{page}: no equations"
    assert untypeset(rendered[PROBE]) == [r"\frac{1}{"]


@BUILT_SITE
def test_pages_need_no_network_and_log_no_error(rendered):
    """Fonts, KaTeX, the lightbox and the notebooks' outputs all come from the site; Material's star count of
    the repository is the one request that may leave it (the page works without it)."""
    assert _each_page(rendered, left_the_site) == {}
    assert left_the_site(rendered[PROBE]) == ["https://example.org/font.woff2"]
    assert _each_page(rendered, lambda shown: shown["errors"]) == {}


# -------------------------------------------------------------------------------------- tutorials' commands

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


def _workspace(tmp_path: Path, capped: bool) -> dict:
    """A scratch folder with scenarios/ and scripts/, and the environment to run a page's blocks in."""
    BLOCKS.workspace(tmp_path)
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


def run_page(page: Path, tmp_path: Path, slow: bool) -> set[str]:
    """Run the page's blocks in order (slow ones too with ``slow``); the pictures they drew."""
    env = _workspace(tmp_path, capped=not slow)
    for is_slow, language, info, code in BLOCKS.runnable_blocks(page):
        if is_slow and not slow:
            continue
        try:
            BLOCKS.run_block(page, language, info, code, tmp_path, env)
        except AssertionError as exc:
            pytest.fail(str(exc).replace(page.name, str(page.relative_to(ROOT)), 1))
    return BLOCKS.pictures_in(tmp_path)


@pytest.mark.parametrize("page", TUTORIAL_PAGES, ids=lambda p: p.stem)
def test_tutorial_pages_have_runnable_commands(page):
    """Every tutorial (and getting started) marks its commands to run; an unmarked page would go untested."""
    blocks = BLOCKS.runnable_blocks(page)
    if page.name == "index.md":
        return
    assert blocks, f"{page}: no <!-- run --> block"
    for _, language, info, _ in blocks:
        assert language in ("bash", "python") or 'title="' in info, f"{page}: a runnable ```{language} block"


# The fast suite runs the pages a newcomer reads first, capped; every page runs as written in the slow suite
# (each scene with other parts compiles its own kernels: a few seconds a page, too many for a quick loop).
QUICK_PAGES = ("getting-started.md",)


def assert_pictures_shown(page: Path, drawn: set[str]) -> None:
    """Every picture the page's commands drew is on the page, naming the drawn file in its title
    (scripts/make_tutorial_images.py keeps them), and every such picture's file exists."""
    shown = BLOCKS.shown_pictures(page)
    assert drawn <= set(shown), f"{page.name} does not show what its commands drew: {sorted(drawn - set(shown))}"
    for title, src in shown.items():
        assert (page.parent / src).is_file(), f"{page.name}: {src} (of {title}) is missing"


@pytest.mark.parametrize("page", [p for p in TUTORIAL_PAGES if p.name in QUICK_PAGES], ids=lambda p: p.stem)
def test_tutorial_commands_run_and_their_pictures_are_shown(page, tmp_path):
    """The page's <!-- run --> blocks, in order, with every scene's end time capped; the page shows what they
    drew."""
    assert_pictures_shown(page, run_page(page, tmp_path, slow=False))


def test_a_picture_the_commands_drew_and_the_page_does_not_show_is_caught(tmp_path):
    page = tmp_path / "page.md"
    page.write_text('![a](pic.png "runs/a/frames.png")\n', encoding="utf-8")
    (tmp_path / "pic.png").write_bytes(b"")
    assert_pictures_shown(page, {"runs/a/frames.png"})
    with pytest.raises(AssertionError, match="runs/b/plots.png"):
        assert_pictures_shown(page, {"runs/a/frames.png", "runs/b/plots.png"})


@pytest.mark.slow
@pytest.mark.parametrize("page", [p for p in TUTORIAL_PAGES if p.name != "index.md"], ids=lambda p: p.stem)
def test_tutorial_commands_run_as_written(page, tmp_path):
    """Every marked block, slow ones too, exactly as written; the page shows every picture they drew."""
    if page.name == "sweeps.md" and importlib.util.find_spec("distributed") is None:
        pytest.skip('the Dask tutorial needs the dask extra (pip install -e ".[dask]")')
    assert_pictures_shown(page, run_page(page, tmp_path, slow=True))
