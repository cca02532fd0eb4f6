"""`ropesim view` without a browser: what a run shows (the general content), the page's data decoded back
within its stated bound, thinning with its message, and bad input as one line with exit code 2.

The page in a real browser is tests/test_viewer_browser.py.
"""

from __future__ import annotations

import base64
import itertools
import json
import re
import zlib
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import ropesim
from ropesim.cli.app import app
from ropesim.viewer import ViewError
from ropesim.viewer.content import Body, Line, Points, RunContent, Series, Shape, Surface, run_content
from ropesim.viewer.pack import (FIELD_LEVELS, POSITION_FLOOR, Q16_NOT_FINITE, position_bound, select_frames)
from ropesim.viewer.page import GENERATOR, make_page, written_by_ropesim

runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args], env={"COLUMNS": "200"})


def one_line_error(result) -> str:
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    return lines[0]


# --------------------------------------------------------------------- decoding the page, in Python


def page_data(html: str) -> tuple[dict, bytes]:
    """The page's description and its inflated buffer, read as the browser reads them."""
    description = json.loads(re.search(r'<script type="application/json" id="ropesim-description">(.*?)</script>',
                                       html, re.S).group(1).replace("<\\/", "</"))
    data = re.search(r'<script type="application/octet-stream" id="ropesim-data">(.*?)</script>', html, re.S)
    return description, zlib.decompress(base64.b64decode(data.group(1)))


def decoded(buffer: bytes, ref: dict) -> np.ndarray:
    """An array of the page, its deltas added back (an independent copy of viewer.js's decode)."""
    dtype = {"u16": "<u2", "u8": "u1", "f32": "<f4", "f64": "<f8"}[ref["dtype"]]
    a = np.frombuffer(buffer, dtype=dtype, count=int(np.prod(ref["shape"])), offset=ref["offset"])
    a = a.reshape(ref["shape"]).astype(np.int64 if ref["dtype"] in ("u16", "u8") else float)
    bits = 16 if ref["dtype"] == "u16" else 8
    if ref["coding"] in ("delta-along", "delta-time-along"):
        a = np.cumsum(a, axis=-1) % 2 ** bits
    if ref["coding"] == "delta-time-along":
        a = np.cumsum(a, axis=0) % 2 ** bits
    return a


def positions(run: dict, buffer: bytes, ref: dict) -> np.ndarray:
    """Coordinates (F, K, D) [m] of a quantised positions array; NaN where not finite."""
    q = decoded(buffer, ref)                                     # (F, D, K)
    origin = np.asarray(run["quantisation"]["origin"])
    x = origin[None, :, None] + run["quantisation"]["step"] * q.astype(float)
    x[q == Q16_NOT_FINITE] = np.nan
    return x.transpose(0, 2, 1)


@pytest.fixture(scope="module")
def shooter(tmp_path_factory):
    scene = ropesim.load_scene("shooter_medium", ["integrator.t_end=0.3"])
    return ropesim.simulate(scene, tmp_path_factory.mktemp("view") / "shooter_medium")


@pytest.fixture(scope="module")
def sling(tmp_path_factory):
    scene = ropesim.load_scene("helicopter_crosswind", ["integrator.t_end=2"])
    return ropesim.simulate(scene, tmp_path_factory.mktemp("view") / "helicopter_crosswind")


def test_the_bound_is_a_tenth_of_a_millimetre_or_1e_5_of_the_size():
    assert position_bound(0.0) == position_bound(5.0) == POSITION_FLOOR == 1e-4
    assert position_bound(10.0) == pytest.approx(1e-4)
    assert position_bound(1200.0) == pytest.approx(0.012)


@pytest.mark.parametrize("fixture", ["shooter", "sling"])
def test_positions_and_fields_decode_within_their_stated_bounds(fixture, request):
    traj = request.getfixturevalue(fixture)
    page = make_page(traj.folder)
    description, buffer = page_data(page.html)
    run = description["runs"][0]
    x = np.asarray(traj.x)
    size = float(np.max(x.max(axis=(0, 1)) - x.min(axis=(0, 1))))
    bound = run["quantisation"]["bound"]
    assert bound == pytest.approx(max(1e-4, 1e-5 * size))
    line = run["lines"][0]
    shown = positions(run, buffer, line["positions"])
    assert shown.shape == x.shape
    error = np.abs(shown - x).max()
    assert error <= bound * (1 + 1e-9)
    assert error > 0.2 * bound          # it is quantised: the bound is the real size of the error, not loose
    assert np.allclose(decoded(buffer, run["time"]), traj.t, rtol=0, atol=0)
    fields = {f["name"]: f for f in line["fields"]}
    assert list(fields) == ["tension", "strain", "speed"]
    for name, truth, unit in (("tension", np.asarray(traj.tension), "N"), ("strain", 100 * np.asarray(traj.strain), "%"),
                              ("speed", np.linalg.norm(np.asarray(traj.v), axis=-1), "m/s")):
        f = fields[name]
        assert f["unit"] == unit and (f["low"], f["high"]) == pytest.approx((truth.min(), truth.max()))
        levels = decoded(buffer, f["values"])
        value = f["low"] + (f["high"] - f["low"]) * levels / FIELD_LEVELS
        assert np.abs(value - truth).max() <= (f["high"] - f["low"]) / FIELD_LEVELS / 2 * (1 + 1e-9)


def test_a_run_that_blew_up_keeps_its_finite_frames_and_marks_the_rest():
    t = np.arange(4.0)
    x = np.zeros((4, 3, 2))
    x[:, :, 0] = [0.0, 1.0, 2.0]
    x[2, 1] = [np.inf, 0.0]
    x[3] = np.nan
    content = RunContent("blown", 2, t, lines=[Line("rope", x)])
    description, buffer = page_data(make_page(content).html)
    shown = positions(description["runs"][0], buffer, description["runs"][0]["lines"][0]["positions"])
    assert np.allclose(shown[:2], x[:2], atol=1e-4)
    assert np.isnan(shown[2, 1, 0]) and np.isfinite(shown[2, 1, 1]) and np.isnan(shown[3]).all()


def test_what_a_run_shows_is_what_animate_marks(tmp_path):
    heli = run_content(ropesim.simulate(ropesim.load_scene("helicopter_mass", ["integrator.t_end=0.05"])))
    assert [line.name for line in heli.lines] == ["rope"] and not heli.lines[0].closed
    assert [(p.name, p.kind, p.nodes) for p in heli.points] == [("end mass 100 kg", "heavy", (20,)),
                                                               ("driven node (8 m/s)", "driven", (0,))]
    assert [s.name for s in heli.series] == ["tension at node 0 (segment 0)", "tension at node 20 (segment 19)"]
    assert heli.bodies == [] and heli.shapes == [] and heli.seabed is None and heli.water is None
    assert dict(heli.summary)["status"] == "completed" and dict(heli.summary)["stored"] == "in memory"

    shooter = run_content(ropesim.simulate(ropesim.load_scene("shooter_low_one_sided", ["integrator.t_end=0.05"])))
    assert shooter.lines[0].closed and shooter.lines[0].segments == 60
    (box,) = shooter.bodies
    assert box.fixed and box.size == (8.0, 2.6666666666666665, 0.0) and list(box.position) == [0.0, 0.0, 0.0]
    assert [(s.kind, s.radius, s.dashed) for s in shooter.shapes] == [("cylinder", 1.3333333333333333, False),
                                                                    ("cylinder", 1.3333333333333333, True)]
    assert [s.name for s in shooter.series] == ["loop inclination"]

    thrown = ropesim.load_scene("string_shooter_real", ["integrator.t_end=0.002"])
    angle = thrown.thrower.angle
    (box,) = run_content(ropesim.simulate(thrown)).bodies
    w, _, _, z = box.orientation       # turned about z by the launch angle
    assert np.degrees(2 * np.arctan2(z, w)) == pytest.approx(angle)

    chain = ropesim.load_scene("mooring_chain", ["integrator.t_end=0.01"])
    content = run_content(ropesim.simulate(chain))
    assert (content.seabed.height, content.seabed.slope_deg) == (-50.0, 0.0)
    assert [p.kind for p in content.points] == ["pinned", "driven"]


def test_several_lines_points_bodies_and_a_sea_fill_the_same_structure():
    """What line systems and the sea will write: more entries, packed by the same code (shown in a browser by
    test_viewer_browser.py::test_lines_bodies_and_a_sea_are_drawn)."""
    content = general_content()
    description, buffer = page_data(make_page(content).html)
    run = description["runs"][0]
    assert [line["name"] for line in run["lines"]] == ["line 1", "line 2"]
    assert [(p["name"], "positions" in p) for p in run["points"]] == [("buoy", True), ("fairlead", False)]
    assert [b["name"] for b in run["bodies"]] == ["vessel"]
    heights = decoded(buffer, run["water"]["heights"])
    assert heights.shape == (20, 9, 7) and np.allclose(heights, content.water.heights, atol=1e-6)
    assert run["seabed"] == {"height": -30.0, "slope_deg": 2.0}
    q = decoded(buffer, run["bodies"][0]["orientation"])
    assert np.allclose(q, content.bodies[0].orientation, atol=1e-7)
    shown = positions(run, buffer, run["points"][0]["positions"])
    assert np.abs(shown - content.points[0].positions).max() <= run["quantisation"]["bound"] * (1 + 1e-9)


def general_content(frames: int = 20, noise: float = 0.0) -> RunContent:
    """Two 3-D lines, a free point and a point on a line, a vessel rolling and heaving, waves, a sloped seabed;
    ``noise`` [m] shakes the lines' nodes (data that compresses as a rough run does)."""
    t = np.linspace(0.0, 0.5 * (frames - 1), frames)
    s = np.linspace(0.0, 1.0, 30)
    phase = 2 * np.pi * t / 10
    def line(x0, z0):
        x = np.empty((frames, 30, 3))
        x[..., 0] = x0 + 40 * s
        x[..., 1] = -30 + 30 * s ** 2 + np.sin(phase)[:, None] * s
        x[..., 2] = z0
        return x + noise * np.random.default_rng(1).standard_normal(x.shape)
    a, b = line(0.0, -5.0), line(0.0, 5.0)
    tension = 1e5 * (1 + s[None, :-1] + 0.1 * np.sin(phase)[:, None])
    buoy = np.stack([np.full(frames, 20.0), -10 + np.sin(phase), np.zeros(frames)], axis=1)[:, None, :]
    roll = 0.1 * np.sin(phase)
    grid_x, grid_z = np.linspace(-10, 60, 9), np.linspace(-20, 20, 7)
    waves = np.sin(phase[:, None, None] + grid_x[None, :, None] / 10) + 0 * grid_z[None, None, :]
    return RunContent(
        "system", 3, t,
        lines=[Line("line 1", a, fields=(ropesim_field("tension", tension),)),
               Line("line 2", b, fields=(ropesim_field("tension", 2 * tension),))],
        points=[Points("buoy", "heavy", "#262626", 8.0, positions=buoy),
                Points("fairlead", "driven", "#d62728", 12.0, line=0, nodes=(29,))],
        bodies=[Body("vessel", (20.0, 6.0, 8.0), np.stack([np.full(frames, 45.0), np.sin(phase), np.zeros(frames)], 1),
                     np.stack([np.cos(roll / 2), np.sin(roll / 2), np.zeros(frames), np.zeros(frames)], 1))],
        shapes=[Shape("pile", "cylinder", (10.0, -15.0, 0.0), 1.0, axis=(0.0, 1.0, 0.0))],
        water=Surface(x=grid_x, z=grid_z, heights=waves),
        seabed=Surface(height=-30.0, slope_deg=2.0),
        series=[Series("tension at the fairlead", "N", tension[:, -1])],
        summary=[("scene", "a made-up line system")])


def ropesim_field(name, values):
    from ropesim.viewer.content import Field

    return Field(name, "N", "segment", values)


# --------------------------------------------------------------------------------------- thinning


def test_a_page_over_budget_keeps_every_kth_frame_and_says_how_to_keep_more(sling):
    content = general_content(frames=400, noise=0.05)
    full = make_page(content)
    assert full.every == 1 and full.note is None and full.frames == (400,)
    data = len(re.search(r'id="ropesim-data">(.*?)</script>', full.html, re.S).group(1))
    budget = full.nbytes - data // 2             # room for about half the frames
    thinned = make_page(content, budget=budget)
    assert 2 <= thinned.every <= 4 and thinned.nbytes <= budget
    assert "--every 1 keeps every frame" in thinned.note and "--from/--to" in thinned.note
    assert re.search(rf"^400 frames would make a page of about \d\.\d MB: showing every {thinned.every}(nd|rd|th) "
                     rf"frame \({thinned.frames[0]} frames, a page of about \d\.\d MB\)", thinned.note), thinned.note
    description, buffer = page_data(thinned.html)
    t = decoded(buffer, description["runs"][0]["time"])
    assert t[0] == content.t[0] and t[-1] == content.t[-1]    # the first and the last frame stay
    assert np.allclose(t[:-1], content.t[::thinned.every][:len(t) - 1])
    chosen = make_page(sling.folder, every=3, start=0.5, end=1.5, budget=budget // 10)
    assert chosen.note is None and chosen.every == 3      # asked for: not thinned further
    description, buffer = page_data(chosen.html)
    assert np.allclose(decoded(buffer, description["runs"][0]["time"]), [0.5, 0.8, 1.1, 1.4, 1.5])


def test_frame_choices_that_cannot_be_met_are_one_line(sling):
    content = run_content(sling.folder)
    with pytest.raises(ViewError, match=r"--every 0: must be a whole number of frames, at least 1"):
        select_frames([content], every=0)
    with pytest.raises(ViewError, match=r"--to 1 is before --from 2"):
        select_frames([content], start=2.0, end=1.0)
    with pytest.raises(ViewError, match=r"no saved frame between 5 and 9 s \(the run: t = 0 \.\. 2 s\)"):
        select_frames([content], start=5.0, end=9.0)


# ----------------------------------------------------------------------------------- the command


def test_view_writes_the_page_into_the_run_folder(shooter, tmp_path):
    result = invoke("view", shooter.folder, "--no-open")
    assert result.exit_code == 0, result.output
    page = shooter.folder / "view.html"
    assert result.stdout.strip() == f"{page}: shooter_medium (31 frames), {page.stat().st_size / 1e6:.1f} MB"
    text = page.read_text(encoding="utf-8")
    assert text.startswith("<!DOCTYPE html>") and GENERATOR in text[:1024] and written_by_ropesim(page)
    assert "default-src 'none'" in text                         # no network at view time
    assert not re.search(r"<(script|link|img|iframe)\b[^>]*\s(src|href)=", text)   # everything inline
    assert "Copyright © 2010-2026 three.js authors" in text     # three.js's licence travels with it
    again = invoke("view", shooter.folder, "--no-open", "-q")    # its own page is replaced
    assert again.exit_code == 0 and again.output == ""
    assert sorted(p.name for p in shooter.folder.iterdir() if p.name.startswith(".")) == []   # no temporary left


def test_several_runs_overlay_into_the_first_folder(shooter, tmp_path):
    other = ropesim.simulate(ropesim.load_scene("shooter_high", ["integrator.t_end=0.2"]), tmp_path / "high")
    result = invoke("view", shooter.folder, other.folder, "--no-open")
    assert result.exit_code == 0, result.output
    description, _ = page_data((shooter.folder / "overlay.html").read_text())
    assert [(r["name"], r["frames"], r["color"]) for r in description["runs"]] == [
        ("shooter_medium", 31, "#1f77b4"), ("shooter_high", 21, "#2ca02c")]
    ranges = [[(f["name"], f["low"], f["high"]) for f in r["lines"][0]["fields"]] for r in description["runs"]]
    assert ranges[0] == ranges[1]                    # one colour scale for both runs: their colours compare
    tension = np.concatenate([np.ravel(shooter.tension), np.ravel(other.tension)])
    assert ranges[0][0][1:] == pytest.approx((tension.min(), tension.max()))


def test_an_interrupted_run_is_viewed_from_its_checkpoint(tmp_path):
    calls = itertools.count()
    scene = ropesim.load_scene("helicopter_mass", ["integrator.t_end=600"])
    ropesim.simulate(scene, tmp_path / "run", stop=lambda: next(calls) >= 2, checkpoint_seconds=0.0)
    folder = tmp_path / "run"
    assert (folder / "checkpoint" / "x.npy").is_file() and not (folder / "trajectory.npz").exists()
    result = invoke("view", folder, "--no-open")
    assert result.exit_code == 0, result.output
    traj = ropesim.Trajectory.open(folder)
    description, buffer = page_data((folder / "view.html").read_text())
    run = description["runs"][0]
    assert dict(run["summary"])["status"] == "interrupted" and 1 < run["frames"] == traj.frames < 60001
    shown = positions(run, buffer, run["lines"][0]["positions"])
    assert np.abs(shown - np.asarray(traj.x)).max() <= run["quantisation"]["bound"] * (1 + 1e-9)


@pytest.mark.parametrize("args,message", [
    (["{tmp}"], "{tmp}: not a run folder: scene.toml is missing"),
    (["{tmp}/nowhere"], "{tmp}/nowhere: no such run folder (make one with `ropesim run SCENE.toml`)"),
    (["shooter_low"], "shooter_low: is a built-in scene, not a run folder; run it first: `ropesim run "
                      "shooter_low` writes runs/shooter_low, then `ropesim view runs/shooter_low`"),
    (["{shooter}", "{sling}"], "runs of different dimensions cannot be overlaid in one view: shooter_medium "
                               "(2-D), helicopter_crosswind (3-D)"),
    (["{shooter}", "-o", "{tmp}/mine.html"], "--out {tmp}/mine.html: exists and was not written by ropesim; it "
                                             "is left alone: remove it or choose another file"),
    (["{shooter}", "-o", "{tmp}/page.png"], "--out {tmp}/page.png: a page is an .html file; give a name ending "
                                            "in .html"),
    (["{shooter}", "-o", "{tmp}/folder.html"], "--out {tmp}/folder.html: is a folder; give a file name ending "
                                               "in .html"),
    (["{shooter}", "--every", "0"], "--every 0: must be a number of saved frames from 1 to 1000000000"),
    (["{shooter}", "--from", "0.2", "--to", "0.1"], "--to 0.1 is before --from 0.2"),
    (["{shooter}", "--from", "7"], "--from/--to: no saved frame between 7 and 0.3 s (the run: t = 0 .. 0.3 s)"),
])
def test_bad_input_is_one_line_and_exit_2(args, message, shooter, sling, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "mine.html").write_text("<html>my own notes</html>")
    (tmp_path / "folder.html").mkdir()
    names = {"tmp": tmp_path, "shooter": shooter.folder, "sling": sling.folder}
    line = one_line_error(invoke("view", *[a.format(**names) for a in args], "--no-open"))
    assert line == "ropesim: " + message.format(**names)
    assert (tmp_path / "mine.html").read_text() == "<html>my own notes</html>"


def test_a_file_in_the_default_place_that_is_not_ropesims_is_left_alone(shooter):
    mine = shooter.folder / "view.html"
    mine.write_text("my notes")
    try:
        line = one_line_error(invoke("view", shooter.folder, "--no-open"))
        assert line == (f"ropesim: {mine}: exists and was not written by ropesim; it is left alone: remove it or "
                        f"choose another file with --out")
        assert mine.read_text() == "my notes"
    finally:
        mine.unlink()


def test_no_browser_is_opened_where_there_is_no_display(shooter, monkeypatch):
    import webbrowser

    opened = []
    monkeypatch.setattr(webbrowser, "open", lambda url: opened.append(url) or True)
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    result = invoke("view", shooter.folder)
    assert result.exit_code == 0 and opened == []
    assert "no display here to open a browser on" in result.stderr
    monkeypatch.setenv("DISPLAY", ":0")
    result = invoke("view", shooter.folder)
    assert result.exit_code == 0 and opened == [(shooter.folder / "view.html").resolve().as_uri()]
    assert result.stderr == ""


def test_a_notebook_shows_the_viewer_in_a_sandboxed_iframe(shooter):
    html = shooter._repr_html_()
    assert "<b>ropesim.Trajectory</b>" in html                     # the short table first
    frame = re.search(r'<iframe sandbox="allow-scripts" srcdoc="([^"]*)"', html)
    assert frame and "allow-same-origin" not in html
    assert "id=&quot;ropesim-data&quot;" in frame.group(1)
    page = shooter.view(every=2)
    assert page.every == 2 and page.frames == (16,) and repr(page).startswith("Page(runs=['shooter_medium']")
    saved = page.save(Path(shooter.folder) / "mine.html")
    assert written_by_ropesim(saved)
