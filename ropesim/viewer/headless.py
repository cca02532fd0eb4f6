"""A viewer page in a headless Chromium, driven by Playwright: for the browser tests, the benchmark
(``scripts/bench_viewer.py``) and the docs' screenshots (``scripts/make_viewer_pages.py``).

The browser is Debian's ``chromium`` (``apt-get install chromium``; ROPESIM_CHROMIUM names another binary),
never one ``playwright install`` downloads: the ``playwright`` package (the test extra) only drives it. Each
session starts it with a fresh profile in a temporary folder and no background traffic of its own (no
component updates, no sync), software WebGL, and every request that is not the page's own file refused and
recorded, so a page that reaches for the network fails its test.
"""

from __future__ import annotations

import os
import shutil
import tempfile
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterator

CHROMIUM = "/usr/bin/chromium"
ARGS = ("--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update",
        "--no-first-run", "--disable-sync")      # headless, software WebGL, no traffic of its own
READY_TIMEOUT = 30.0    # [s]
READY = "window.ropesim && (window.ropesim.firstFrameMs !== null || window.ropesim.error)"


def wait_for(page_or_frame, expression: str, timeout: float = 10.0):
    """Poll ``expression`` in a page or frame until it is truthy, and return its value."""
    deadline = time.monotonic() + timeout
    while True:
        value = page_or_frame.evaluate(expression)
        if value:
            return value
        if time.monotonic() > deadline:
            raise TimeoutError(f"{expression!r} still false after {timeout:g} s")
        time.sleep(0.02)


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

    def wait_for(self, expression: str, timeout: float = 10.0, frame=None):
        """Poll ``expression`` until it is truthy (Playwright's own wait_for_function evaluates a string, which
        the page's Content-Security-Policy forbids); TimeoutError after ``timeout`` seconds."""
        return wait_for(frame or self.page, expression, timeout)

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

    def open(self, path: str | Path, viewport: tuple[int, int] = (1000, 700), wait: bool = True,
             allow: tuple[Path, ...] = ()) -> Opened:
        """Load the page at ``path``; with ``wait``, until its first frame is drawn (or it reported an error).
        ``allow``: local files the page may load besides itself (the docs' pages share one three.min.js)."""
        path = Path(path).resolve()
        page = self.context.new_page()
        page.set_viewport_size({"width": viewport[0], "height": viewport[1]})
        opened = Opened(page)
        own = {path.as_uri(), *(Path(a).resolve().as_uri() for a in allow)}

        def route(r):
            url = r.request.url
            if url in own or url.startswith(("data:", "blob:")):
                r.continue_()
            else:
                opened.requests.append(url)
                r.abort()

        page.route("**/*", route)
        page.on("console", lambda m: opened.errors.append(m.text) if m.type == "error" else None)
        page.on("pageerror", lambda e: opened.errors.append(str(e)))
        page.goto(path.as_uri())
        if not wait:
            return opened
        opened.wait_for(READY, READY_TIMEOUT)
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
