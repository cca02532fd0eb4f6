"""Regenerate the docs' viewer pages (docs/viewer/NAME.html, embedded in the gallery) and their screenshots
(docs/images/viewer/NAME.png) for every built-in scene, with ropesim's own viewer and a headless Chromium.

    python scripts/make_viewer_pages.py            # about two minutes on two cores (runs every built-in scene)

Each scene runs as the gallery's pictures do (the towed ropes for 60 s, the rest their default length). The
pages share one three.min.js (docs/viewer/three.min.js, the vendored bundle) instead of inlining it, so the site
carries three.js once; everything else is in each page. The screenshots need Debian's chromium and the
playwright package (the test extra); --no-screenshots writes the pages alone.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LONGER = {"helicopter_uniform": ["integrator.t_end=60", "output.interval=0.05"],
          "helicopter_mass": ["integrator.t_end=60", "output.interval=0.05"],
          "helicopter_parachute": ["integrator.t_end=60", "output.interval=0.05"]}
SHOT_AT = {"mooring_chain": 0.7, "buoy_tether": 0.3, "cantilever_beam": 0.1, "string_shooter_real": 0.3}  # of the run
VIEWPORT = (900, 560)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-screenshots", action="store_true", help="write the pages only")
    parser.add_argument("scenes", nargs="*", help="built-in scenes (default: all)")
    args = parser.parse_args()
    sys.path.insert(0, str(ROOT))
    import ropesim
    from ropesim.scene.builtin import builtin_names
    from ropesim.viewer.page import asset, make_page

    pages, shots = ROOT / "docs" / "viewer", ROOT / "docs" / "images" / "viewer"
    pages.mkdir(parents=True, exist_ok=True)
    (pages / "three.min.js").write_text(asset("three.min.js"), encoding="utf-8")
    names = args.scenes or builtin_names()
    with tempfile.TemporaryDirectory(prefix="ropesim-viewer-pages-") as tmp:
        os.chdir(tmp)                # the pages name their run folders runs/NAME, as `ropesim run NAME` writes them
        for name in names:
            traj = ropesim.simulate(ropesim.load_scene(name, LONGER.get(name, [])), Path("runs") / name)
            page = make_page(traj, three="three.min.js")
            page.save(pages / f"{name}.html")
            print(f"docs/viewer/{name}.html: {page.frames[0]} frames, {page.nbytes / 1e3:.0f} kB"
                  + (f" ({page.note})" if page.note else ""))
        if not args.no_screenshots:
            screenshots(names, pages, shots)
    return 0


def screenshots(names: list[str], pages: Path, shots: Path) -> None:
    from ropesim.viewer import headless

    shots.mkdir(parents=True, exist_ok=True)
    with headless.browser() as browser:
        for name in names:
            opened = browser.open(pages / f"{name}.html", viewport=VIEWPORT, allow=(pages / "three.min.js",))
            if opened.errors or opened.requests:
                raise SystemExit(f"{name}: the page failed in the browser: {opened.errors or opened.requests}")
            frames = opened.state()["frames"]
            opened.page.evaluate(f"window.ropesim.setFrame({round(SHOT_AT.get(name, 1.0) * (frames - 1))})")
            opened.page.wait_for_timeout(200)
            opened.page.screenshot(path=str(shots / f"{name}.png"))
            opened.page.close()
            print(f"docs/images/viewer/{name}.png")


if __name__ == "__main__":
    sys.exit(main())
