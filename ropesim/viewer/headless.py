"""A viewer page in a headless Chromium, driven by Playwright: for the browser tests, the benchmark
(``scripts/bench_viewer.py``) and the docs' screenshots (``scripts/make_viewer_pages.py``).

The browser is Debian's ``chromium`` (``apt-get install chromium``; ROPESIM_CHROMIUM names another binary),
never one ``playwright install`` downloads: the ``playwright`` package (the test extra) only drives it. Each
session starts it with a fresh profile in a temporary folder and no background traffic of its own (no
component updates, sync or field trials), software WebGL, and every request that is not the page's own file
refused and recorded, so a page that reaches for the network fails its test.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterator

CHROMIUM = "/usr/bin/chromium"
ARGS = ("--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update",
        "--no-first-run", "--disable-sync", "--disable-default-apps", "--disable-domain-reliability",
        "--disable-features=OptimizationHints,MediaRouter,Translate", "--metrics-recording-only",
        "--enable-unsafe-swiftshader")
READY_TIMEOUT_MS = 30_000


def chromium() -> str | None:
    """The Chromium binary to drive (ROPESIM_CHROMIUM, else Debian's /usr/bin/chromium), or None if absent."""
    path = os.environ.get("ROPESIM_CHROMIUM", CHROMIUM)
    return path if Path(path).is_file() and os.access(path, os.X_OK) else None


def missing() -> str | None:
    """Why a browser session cannot start here (no playwright, no chromium), or None if it can."""
    try:
        import playwright  # noqa: F401
    except ImportError:
        return 'the playwright package is not installed (pip install -e ".[test]")'
    if chromium() is None:
        return f"no chromium at {os.environ.get('ROPESIM_CHROMIUM', CHROMIUM)} (apt-get install chromium)"
    return None


@dataclass
class Opened:
    """A page open in the browser, with what it did wrong: requests beyond its own file, console errors."""

    page: object
    requests: list[str] = field(default_factory=list)
    errors: list[str] = field(default_factory=list)

    def state(self) -> dict:
        return self.page.evaluate("window.ropesim.state()")

    def info(self) -> list[dict]:
        return self.page.evaluate("window.ropesim.info()")

    def canvas_png(self) -> bytes:
        return self.page.locator("#canvas").screenshot()


class Browser:
    """One headless Chromium with a fresh profile; :meth:`open` loads a page and waits for its first frame."""

    def __init__(self, context):
        self.context = context

    def open(self, path: str | Path, viewport: tuple[int, int] = (1000, 700)) -> Opened:
        path = Path(path).resolve()
        page = self.context.new_page()
        page.set_viewport_size({"width": viewport[0], "height": viewport[1]})
        opened = Opened(page)
        own = path.as_uri()

        def route(r):
            url = r.request.url
            if url == own or url.startswith(("data:", "blob:")):
                r.continue_()
            else:
                opened.requests.append(url)
                r.abort()

        page.route("**/*", route)
        page.on("console", lambda m: opened.errors.append(m.text) if m.type == "error" else None)
        page.on("pageerror", lambda e: opened.errors.append(str(e)))
        page.goto(own)
        page.wait_for_function("window.ropesim && (window.ropesim.firstFrameMs !== null || window.ropesim.error)",
                               timeout=READY_TIMEOUT_MS)
        error = page.evaluate("window.ropesim.error")
        if error:
            opened.errors.append(error)
        return opened


@contextmanager
def browser() -> Iterator[Browser]:
    """A headless Chromium for the length of the block (see the module); raises RuntimeError if none can
    start here (:func:`missing` says why)."""
    why = missing()
    if why:
        raise RuntimeError(why)
    from playwright.sync_api import sync_playwright

    profile = tempfile.mkdtemp(prefix="ropesim-chromium-")
    try:
        with sync_playwright() as p:
            context = p.chromium.launch_persistent_context(profile, executable_path=chromium(), headless=True,
                                                           args=list(ARGS))
            try:
                yield Browser(context)
            finally:
                context.close()
    finally:
        shutil.rmtree(profile, ignore_errors=True)
