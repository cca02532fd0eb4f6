"""The pictures each tutorial shows are the ones its own commands draw: run every marked block of the page as
written (docs/getting-started.md, docs/tutorials/*.md; scripts/tutorial_blocks.py), in a scratch folder, and keep
each picture it drew as docs/images/tutorials/<page>/<path, runs/ left out, / as _>.

A page names the drawn file in each picture's title (``![...](... "runs/heli300/frames.png")``); a picture the
page shows from elsewhere (a figure another script in scripts/ makes with the same command) is not copied. The
test suite (tests/test_docs.py) runs the pages' quick blocks and fails when a page does not show a picture
they drew.

    python scripts/make_tutorial_images.py                 # every page, slow blocks too: about 3 minutes
    python scripts/make_tutorial_images.py moorings --fast # one page, its quick blocks only
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

from tutorial_blocks import ROOT, pictures_in, run_block, runnable_blocks, shown_pictures, workspace

DOCS = ROOT / "docs"
PAGES = [DOCS / "getting-started.md", *sorted(p for p in (DOCS / "tutorials").glob("*.md") if p.name != "index.md")]


def target(page: Path, drawn: str) -> Path:
    name = drawn.removeprefix("runs/").replace("/", "_")
    return DOCS / "images" / "tutorials" / page.stem / name


def make(page: Path, fast: bool) -> None:
    started = time.monotonic()
    with tempfile.TemporaryDirectory(prefix=f"tutorial-{page.stem}-") as scratch:
        folder = Path(scratch)
        workspace(folder)
        env = {**os.environ, "MPLBACKEND": "Agg", "BROWSER": "true", "COLUMNS": "86",
               "PATH": os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")])}
        for slow, language, info, code in runnable_blocks(page):
            if slow and fast:
                continue
            if "dask " in code and importlib.util.find_spec("distributed") is None:
                print(f"  {page.name}: skipped a block that needs the dask extra", file=sys.stderr)
                continue
            run_block(page, language, info, code, folder, env, timeout=3600)
        shown = shown_pictures(page)
        for drawn in sorted(pictures_in(folder)):
            where = target(page, drawn)
            if drawn in shown and (page.parent / shown[drawn]).resolve() != where.resolve():
                print(f"  {drawn}: shown as {shown[drawn]} (made by another script)")
                continue
            where.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(folder / drawn, where)
            note = "" if drawn in shown else "   <- NOT SHOWN on the page yet"
            print(f"  {drawn} -> {where.relative_to(ROOT)} ({where.stat().st_size / 1e3:.0f} kB){note}")
    print(f"{page.relative_to(ROOT)}: {time.monotonic() - started:.0f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("pages", nargs="*", help="page names (getting-started, moorings, ...); default: all")
    parser.add_argument("--fast", action="store_true", help="leave out the blocks marked <!-- run: slow -->")
    args = parser.parse_args()
    pages = [p for p in PAGES if not args.pages or p.stem in args.pages]
    if not pages:
        parser.error(f"no such page; the pages: {', '.join(p.stem for p in PAGES)}")
    for page in pages:
        make(page, args.fast)


if __name__ == "__main__":
    main()
