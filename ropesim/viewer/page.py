"""The viewer's page: one HTML file holding the runs' data, three.js and the viewer's script, for any browser,
offline (a Content-Security-Policy in the page forbids every network request).

:func:`make_page` builds it in memory (a :class:`Page`, which a notebook shows as a sandboxed iframe);
:func:`write_page` writes it atomically, and never over a file ropesim did not write (a page says it is
ropesim's in its ``generator`` meta tag, near its start).
"""

from __future__ import annotations

import base64
import html
import re
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from pathlib import Path

from ..io.guard import HTML_MARK as GENERATOR   # the write guard knows ropesim's pages by it
from . import ViewError
from .content import RunContent, run_content
from .pack import PAGE_BUDGET, description_json, pack, select_frames

HEAD_BYTES = 1024           # the generator tag is within this many bytes of a page's start
NOTEBOOK_BUDGET = 20_000_000   # [bytes] a notebook keeps its outputs: its pages are thinned sooner
COLORMAP = "viridis"
COLORMAP_SPAN = (0.0, 0.92)    # viridis without its palest yellows, which vanish on the light background


@lru_cache(maxsize=None)
def asset(name: str) -> str:
    """The text of ``ropesim/viewer/assets/<name>``."""
    return resources.files("ropesim.viewer").joinpath("assets", name).read_text(encoding="utf-8")


@lru_cache(maxsize=1)
def colormap_bytes() -> bytes:
    """256 RGB triplets: the colours of a field from its low to its high end."""
    import numpy as np
    from matplotlib import colormaps

    rgb = colormaps[COLORMAP](np.linspace(*COLORMAP_SPAN, 256))[:, :3]
    return (np.rint(rgb * 255).astype(np.uint8)).tobytes()


@dataclass(frozen=True)
class Page:
    """A viewer page: its ``html``, the runs it shows, their frames in it (``every``: one saved frame in so many
    was kept), and ``note``, a remark on the thinning (or None)."""

    html: str
    runs: tuple[str, ...]
    frames: tuple[int, ...]
    every: int
    note: str | None = None

    @property
    def nbytes(self) -> int:
        return len(self.html.encode("utf-8"))

    def save(self, path: str | Path) -> Path:
        """Write the page to ``path`` (atomically; never over a file ropesim did not write) and return it."""
        return save_html(self.html, Path(path))

    def _repr_html_(self) -> str:
        return iframe(self)

    def __repr__(self) -> str:
        return (f"Page(runs={list(self.runs)}, frames={list(self.frames)}, every={self.every}, "
                f"{self.nbytes / 1e6:.1f} MB)")


def make_page(runs, *, every: int | None = None, start: float | None = None, end: float | None = None,
              budget: int = PAGE_BUDGET, three: str | None = None) -> Page:
    """A viewer page of ``runs`` (run folders, :class:`ropesim.Trajectory` objects or :class:`RunContent`;
    several are overlaid, each in its own colour): every saved frame from ``start`` to ``end`` [s] (default: the
    whole run), or every ``every``-th; without ``every``, thinned in time when the page would pass ``budget``
    bytes. ``three``: the URL of three.min.js to load instead of inlining it (the docs' pages share one copy).
    Raises :class:`ViewError` or RunFolderError with one line for what cannot be shown."""
    if not isinstance(runs, (list, tuple)):
        runs = [runs]
    if not runs:
        raise ViewError("no run to show")
    contents = [r if isinstance(r, RunContent) else run_content(r) for r in runs]
    dims = {c.dimension for c in contents}
    if len(dims) > 1:
        listed = ", ".join(f"{c.name} ({c.dimension}-D)" for c in contents)
        raise ViewError(f"runs of different dimensions cannot be overlaid in one view: {listed}")
    parts = _fixed_parts(three)
    overhead = sum(map(len, parts.values()))
    selection = select_frames(contents, every, start, end, budget=budget, overhead=overhead)
    while True:
        description, data = pack(contents, selection, colormap_bytes())
        text = _fill(parts, description_json(description), base64.b64encode(data).decode("ascii"))
        longest = max(len(f) for f in selection.frames)
        if every is not None or len(text) <= budget or selection.every >= longest - 1:
            break
        # the sample's estimate was low: the next k, measured again
        selection = select_frames(contents, None, start, end, budget=budget, overhead=overhead,
                                  at_least=selection.every + 1)
    return Page(html=text, runs=tuple(c.name for c in contents), frames=tuple(len(f) for f in selection.frames),
                every=selection.every, note=selection.note)


def view(runs, *, every: int | None = None, start: float | None = None, end: float | None = None,
         budget: int = NOTEBOOK_BUDGET) -> Page:
    """Runs in the browser viewer, as `ropesim view` shows them: ``runs`` are run folders or
    :class:`ropesim.Trajectory` objects (several are overlaid, each in its own colour). A notebook shows the
    returned :class:`Page` in a sandboxed iframe; ``page.save("runs.html")`` writes it as one offline file.

    Every saved frame from ``start`` to ``end`` [s] is kept, or every ``every``-th; without ``every`` a page
    that would pass ``budget`` bytes (20 MB: a notebook keeps its outputs) is thinned in time, and
    ``page.note`` says so. Positions are within max(0.1 mm, 1e-5 of the run's size) of the saved ones."""
    return make_page(runs, every=every, start=start, end=end, budget=budget)


def _fixed_parts(three: str | None) -> dict[str, str]:
    if three is None:
        script = f"<script>{asset('three.min.js')}</script>"
    else:
        script = f'<script src="{html.escape(three, quote=True)}"></script>'
    return {"css": asset("viewer.css"), "viewer": asset("viewer.js"), "three": script,
            "script_src": "" if three is None else " 'self'", "template": asset("page.html")}


FIELD = re.compile(r"\{(css|description|data|three|viewer|script_src)\}")


def _fill(parts: dict[str, str], description: str, data: str) -> str:
    """The template with its fields filled in one pass (so nothing inserted is read as a field)."""
    values = {**parts, "description": description, "data": data}
    return FIELD.sub(lambda m: values[m.group(1)], parts["template"])


def written_by_ropesim(path: Path) -> bool:
    """True if ``path`` is a page ropesim wrote (its generator tag near the start; the write guard's check,
    :func:`ropesim.io.guard.written_by_ropesim`)."""
    from ..io.guard import written_by_ropesim as ours

    return ours(path)


def check_target(path: Path, option: str | None = "--out") -> None:
    """Refuse (ViewError, one line naming ``option`` and the file) a target that is not an .html name, is a
    folder, or is a file ropesim did not write."""
    where = f"{option} {path}" if option else str(path)
    if path.suffix.lower() not in (".html", ".htm"):
        raise ViewError(f"{where}: a page is an .html file; give a name ending in .html")
    if path.is_dir():
        raise ViewError(f"{where}: is a folder; give a file name ending in .html")
    from ..io.guard import WriteRefused, output_file

    try:
        output_file(path, option=option or "")   # the one write guard: a link followed, a folder refused
    except WriteRefused:
        raise ViewError(f"{where}: exists and was not written by ropesim; it is left alone: remove it or "
                        f"choose another file{' with --out' if not option else ''}") from None


def save_html(text: str, path: Path, option: str | None = "--out") -> Path:
    """Write a page atomically to ``path`` after :func:`check_target`."""
    from ..io.atomic import atomic_output

    check_target(path, option)
    with atomic_output(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


def write_page(runs, out: str | Path, option: str | None = "--out", **options) -> Page:
    """Make the page of ``runs`` (see :func:`make_page`) and write it to ``out``; the target is checked first,
    so a refused one costs nothing (``option``: how to name it in a refusal)."""
    out = Path(out)
    check_target(out, option)
    page = make_page(runs, **options)
    save_html(page.html, out, option)
    return page


def iframe(page: Page, height: int = 560) -> str:
    """The page in a sandboxed iframe (scripts only: no access to the notebook, no network), for Jupyter."""
    note = (f"<div style='font-size:12px;color:#8a6d00'>ropesim: {html.escape(page.note)}</div>"
            if page.note else "")
    return (f"{note}<iframe sandbox=\"allow-scripts\" srcdoc=\"{html.escape(page.html, quote=True)}\" "
            f"style=\"width:100%;height:{height}px;border:1px solid #ddd\" "
            f"title=\"ropesim view of {html.escape(' + '.join(page.runs), quote=True)}\"></iframe>")
