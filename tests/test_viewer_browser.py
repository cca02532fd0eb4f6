"""`ropesim view`'s pages in a real browser: Debian's chromium, headless, driven by Playwright
(:mod:`ropesim.viewer.headless`; never a browser `playwright install` downloads).

Every built-in scene's page opens from file:// without a network request or a console error, draws a
picture, plays; the positions read back through the page's hook after moving its scrubber equal the run's
within the stated quantisation bound; orbit and zoom change the picture; an overlaid second run appears; a
content with several lines, bodies and a sea is drawn; a notebook's sandboxed iframe works.

Without chromium (or the playwright package) these tests are skipped, unless ROPESIM_REQUIRE_BROWSER=1 (CI sets
it): then they fail, so CI can never skip them silently.
"""

from __future__ import annotations

import io
import os

import numpy as np
import pytest

import ropesim
from ropesim.scene.builtin import builtin_names
from ropesim.viewer import headless
from ropesim.viewer.page import make_page, write_page

from test_viewer import general_content


@pytest.fixture(scope="module")
def browser():
    why = headless.missing()
    if why:
        if os.environ.get("ROPESIM_REQUIRE_BROWSER") == "1":
            pytest.fail(f"ROPESIM_REQUIRE_BROWSER=1 but {why}", pytrace=False)
        pytest.skip(why)
    with headless.browser() as b:
        yield b


def frames_of(name: str, count: int = 20) -> list[str]:
    """Overrides that keep a built-in scene's run to about ``count`` saved frames."""
    scene = ropesim.load_scene(name)
    return [f"integrator.t_end={min(scene.integrator.t_end, count * scene.output.interval):.6g}"]


@pytest.fixture(scope="module")
def builtin_runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("builtins")
    return {name: ropesim.simulate(ropesim.load_scene(name, frames_of(name)), root / name) for name in builtin_names()}


def picture(png: bytes) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)


def drawn_fraction(image: np.ndarray) -> float:
    """The fraction of pixels that differ from the background colour (the most common one)."""
    flat = image.reshape(-1, 3)
    colours, counts = np.unique(flat, axis=0, return_counts=True)
    background = colours[np.argmax(counts)]
    return float(np.mean(np.abs(flat - background).sum(axis=1) > 30))


def assert_clean(opened) -> None:
    assert opened.requests == [], f"the page asked the network for {opened.requests}"
    assert opened.errors == [], f"console errors: {opened.errors}"


@pytest.mark.slow
def test_every_built_in_scene_opens_offline_draws_and_plays(browser, builtin_runs):
    for name, traj in builtin_runs.items():
        page = write_page(traj.folder, traj.folder / "view.html")
        opened = browser.open(traj.folder / "view.html")
        assert_clean(opened)
        (info,) = opened.info()
        assert info["name"] == name and info["frames"] == traj.frames == page.frames[0]
        if traj.scene.is_system:   # every line by its id, every rigid body
            assert [(line["name"], line["nodes"]) for line in info["lines"]] == [
                (line.id, line.nodes) for line in traj.scene.lines]
            assert all(line["fields"] == ["tension", "strain", "speed"] for line in info["lines"])
            assert info["bodies"] == [body.id for body in traj.scene.rigid_bodies]
        else:
            assert info["lines"] == [{"name": "rope", "nodes": traj.nodes, "closed": traj.scene.rope.closed,
                                      "fields": ["tension", "strain", "speed"]}]
            assert info["bodies"] == (["thrower box"] if traj.scene.thrower else [])
        assert info["shapes"] == ["guide circle"] * len(traj.scene.guides)
        assert info["seabed"] == (traj.scene.seabed is not None)
        assert bool(info["water"]) == (traj.scene.sea is not None)    # the sea's scenes draw their surface
        assert drawn_fraction(picture(opened.canvas_png())) > 0.003, f"{name}: the canvas is blank"
        state = opened.state()
        assert state["frame"] == 0 and not state["playing"] and state["colorBy"] == "tension"
        opened.page.keyboard.press("Space")
        opened.wait_for("window.ropesim.state().frame > 0")
        opened.page.keyboard.press("Space")
        assert not opened.state()["playing"]
        assert_clean(opened)
        opened.page.close()


@pytest.mark.parametrize("name", ["helicopter_crosswind", "shooter_medium", "mooring_chain"])
def test_the_scrubber_shows_the_saved_positions_within_the_bound(browser, builtin_runs, name, tmp_path):
    traj = builtin_runs[name]
    write_page(traj.folder, tmp_path / "view.html")
    opened = browser.open(tmp_path / "view.html")
    (info,) = opened.info()
    x = np.asarray(traj.x)
    bound = info["bound"]
    assert bound == pytest.approx(max(1e-4, 1e-5 * float(np.max(x.max(axis=(0, 1)) - x.min(axis=(0, 1))))))
    for frame in (traj.frames - 1, traj.frames // 3, 0):
        opened.page.locator("#scrubber").fill(str(frame))      # as a user drags it: an input event
        assert opened.state()["frame"] == frame
        shown = np.array(opened.page.evaluate("window.ropesim.positions(0, 0)"), dtype=float)
        assert shown.shape == x[frame].shape
        assert np.abs(shown - x[frame]).max() <= bound * (1 + 1e-6)
    opened.page.locator("#canvas").click()
    opened.page.keyboard.press("ArrowRight")
    assert opened.state()["frame"] == 1
    opened.page.keyboard.press("Shift+ArrowRight")
    assert opened.state()["frame"] == 11
    opened.page.keyboard.press("End")
    assert opened.state()["frame"] == traj.frames - 1
    assert_clean(opened)


def test_orbit_and_zoom_change_the_picture(browser, builtin_runs, tmp_path):
    traj = builtin_runs["helicopter_crosswind"]
    write_page(traj.folder, tmp_path / "view.html")
    opened = browser.open(tmp_path / "view.html")
    box = opened.page.locator("#canvas").bounding_box()
    cx, cy = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    before, camera = picture(opened.canvas_png()), opened.state()["camera"]
    mouse = opened.page.mouse
    mouse.move(cx, cy)
    mouse.down()
    mouse.move(cx + 150, cy + 40, steps=8)
    mouse.up()
    turned, turned_camera = picture(opened.canvas_png()), opened.state()["camera"]
    assert np.linalg.norm(np.subtract(turned_camera[:3], camera[:3])) > 1e-3
    assert np.mean(np.abs(turned - before).sum(axis=2) > 30) > 0.005, "orbiting did not change the picture"
    mouse.move(cx, cy)
    mouse.wheel(0, -600)
    opened.page.wait_for_timeout(100)
    zoomed, zoomed_camera = picture(opened.canvas_png()), opened.state()["camera"]
    target = opened.page.evaluate("window.ropesim.viewer.controls.target.toArray()")
    distance = lambda c: np.linalg.norm(np.subtract(c[:3], target))
    assert distance(zoomed_camera) < 0.8 * distance(turned_camera)
    assert np.mean(np.abs(zoomed - turned).sum(axis=2) > 30) > 0.005, "zooming did not change the picture"
    opened.page.keyboard.press("r")                                   # back to the first view
    assert np.allclose(opened.state()["camera"], camera, rtol=1e-6)
    assert_clean(opened)


def colour_pixels(image: np.ndarray, hex_colour: str, tolerance: int = 40) -> int:
    rgb = np.array([int(hex_colour[i:i + 2], 16) for i in (1, 3, 5)])
    return int(np.sum(np.abs(image - rgb).sum(axis=2) < tolerance))


def test_an_overlaid_second_run_appears_in_its_own_colour(browser, builtin_runs, tmp_path):
    runs = [builtin_runs["shooter_medium"].folder, builtin_runs["shooter_vacuum"].folder]
    write_page(runs, tmp_path / "overlay.html")
    opened = browser.open(tmp_path / "overlay.html")
    assert [r["name"] for r in opened.info()] == ["shooter_medium", "shooter_vacuum"]
    assert opened.state()["colorBy"] == "run"
    legend = opened.page.locator("#legend .legend-row")
    assert legend.nth(0).inner_text() == "shooter_medium" and legend.nth(1).inner_text() == "shooter_vacuum"
    opened.page.locator("#scrubber").fill(str(opened.state()["frames"] - 1))
    second = "#2ca02c"                                        # the second run's colour
    shown = colour_pixels(picture(opened.canvas_png()), second)
    assert shown > 50, "the second run is not drawn"
    legend.nth(1).click()                                     # hides it
    assert colour_pixels(picture(opened.canvas_png()), second) < 0.05 * shown
    assert_clean(opened)


def test_lines_bodies_and_a_sea_are_drawn(browser, tmp_path):
    """The general content line systems and the sea will fill: two lines, a free point, a rolling vessel (a
    box with an orientation), waves and a seabed, drawn with no change to the page."""
    content = general_content()
    make_page(content).save(tmp_path / "system.html")
    opened = browser.open(tmp_path / "system.html")
    assert_clean(opened)
    (info,) = opened.info()
    assert [line["name"] for line in info["lines"]] == ["line 1", "line 2"]
    assert info["points"] == ["buoy", "fairlead"] and info["bodies"] == ["vessel"]
    assert info["water"] and info["seabed"] and info["shapes"] == ["pile"]
    bound = info["bound"]
    for frame in (0, 7, 19):
        opened.page.evaluate(f"window.ropesim.setFrame({frame})")
        for k in (0, 1):
            shown = np.array(opened.page.evaluate(f"window.ropesim.positions(0, {k})"))
            assert np.abs(shown - content.lines[k].positions[frame]).max() <= bound * (1 + 1e-6)
        pose = opened.page.evaluate("window.ropesim.bodyPose(0, 0)")
        assert np.allclose(pose["position"], content.bodies[0].position[frame], atol=1e-5)
        assert np.allclose(pose["quaternion"], content.bodies[0].orientation[frame], atol=1e-6)
    assert drawn_fraction(picture(opened.canvas_png())) > 0.01


@pytest.mark.slow
def test_a_notebook_iframe_runs_the_viewer(browser, builtin_runs, tmp_path):
    """Jupyter shows `_repr_html_` as it is: here, in a page of its own, the sandboxed iframe's viewer starts."""
    traj = builtin_runs["helicopter_mass"]
    (tmp_path / "notebook.html").write_text(f"<!DOCTYPE html><html><body>{traj._repr_html_()}</body></html>",
                                            encoding="utf-8")
    opened = browser.open(tmp_path / "notebook.html", wait=False)
    frame = opened.page.frames[1]
    opened.wait_for("window.ropesim && window.ropesim.firstFrameMs !== null", 30, frame=frame)
    assert frame.evaluate("window.ropesim.info()")[0]["name"] == "helicopter_mass"
    assert_clean(opened)


@pytest.mark.slow
@pytest.mark.parametrize("name", builtin_names())
def test_every_built_in_scene_at_its_full_length(browser, name, tmp_path):
    """The gallery's runs, whole: the page opens offline without an error, and the last frame's positions are
    the run's within the bound."""
    traj = ropesim.simulate(ropesim.load_scene(name), tmp_path / name)
    write_page(traj.folder, tmp_path / "view.html")
    opened = browser.open(tmp_path / "view.html")
    assert_clean(opened)
    (info,) = opened.info()
    assert info["frames"] == traj.frames
    opened.page.keyboard.press("End")
    for k, line in enumerate(traj.lines):   # a rope is its one line; a system's lines each have their nodes
        shown = np.array(opened.page.evaluate(f"window.ropesim.positions(0, {k})"), dtype=float)
        assert np.abs(shown - np.asarray(traj.line(line).positions[-1])).max() <= info["bound"] * (1 + 1e-6)
    assert drawn_fraction(picture(opened.canvas_png())) > 0.003
    opened.page.close()


def test_a_system_shows_each_line_and_its_bodies_box(browser, tmp_path):
    """A real system (the clump weight) and a made-up spar turning as it drifts: each line's positions and the
    body's box pose read back from the page as the run has them."""
    from conftest import ROOT
    from synthetic_system import turning_body_run

    systems = ROOT / "tests" / "data" / "systems"
    clump = ropesim.simulate(ropesim.load_scene(systems / "clump_weight.toml", ["integrator.t_end=0.5"]),
                             tmp_path / "clump")
    write_page(clump.folder, tmp_path / "clump.html")
    opened = browser.open(tmp_path / "clump.html")
    assert_clean(opened)
    (info,) = opened.info()
    assert [(line["name"], line["nodes"]) for line in info["lines"]] == [("left_wire", 11), ("right_wire", 11)]
    assert info["points"] == ["fixed point", "clump 200 kg"]
    for frame in (0, 30):
        opened.page.evaluate(f"window.ropesim.setFrame({frame})")
        for k, line in enumerate(("left_wire", "right_wire")):
            shown = np.array(opened.page.evaluate(f"window.ropesim.positions(0, {k})"))
            assert np.abs(shown - clump.line(line).positions[frame]).max() <= info["bound"] * (1 + 1e-6)
    spar = turning_body_run(ropesim.load_scene(systems / "oc3_hywind.toml"), frames=12)
    spar.view().save(tmp_path / "spar.html")
    opened = browser.open(tmp_path / "spar.html")
    assert_clean(opened)
    assert opened.info()[0]["bodies"] == ["spar"]
    body = spar.body("spar")
    centre = np.array([1.3, -35.0, 0.0])           # the middle of the box round (0, 0, 0) and the fairleads
    for frame in (0, 7):
        opened.page.evaluate(f"window.ropesim.setFrame({frame})")
        pose = opened.page.evaluate("window.ropesim.bodyPose(0, 0)")
        assert np.allclose(pose["position"], body.position[frame] + body.rotation[frame] @ centre, atol=1e-4)
        assert np.allclose(pose["quaternion"], body.quaternion[frame], atol=1e-6)
    assert drawn_fraction(picture(opened.canvas_png())) > 0.003
