"""Pictures of a run (ropesim.render): which frames are shown, where the view looks, that what is drawn is
where the trajectory says, and the files written (GIF, MP4, PNG): frame counts, sizes, determinism, and no
half-written file when something fails."""

from __future__ import annotations

import math
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings, example
from hypothesis import strategies as st
from PIL import Image

import ropesim
from ropesim.model.energy import energy_terms
from ropesim.analysis.summary import largest_stretch
from ropesim.model.build import build
from ropesim.render import RenderError, framing
from ropesim.render.animate import FrameRenderer, animate
from ropesim.render.encode import gif_fps, gif_palette
from ropesim.render.frames import HEADER_ROOM, frame_sheet
from ropesim.render.framing import (Band, Box, Circle, fit_box, followed_nodes, outline, projection,
                                    single_view, view_box)
from ropesim.render.plots import largest_stretch_series, per_frame, plot_run
from ropesim.render.scene_artist import ROPE_COLOR
from ropesim.render.timeline import animation_plan, chosen_frames, parse_times
from ropesim.io.trajectory import Trajectory

from conftest import SCENARIOS

TOWED_3D = """
name = "towed_3d"
dimension = 3
[rope]
nodes = 11
segment_length = 0.5
stiffness = 5000.0
mass = 5.0
[initial]
shape = "hanging"
top = [0.0, 0.0, 0.0]
velocity = [8.0, 0.0, 3.0]
[[driven]]
nodes = [0]
velocity = [8.0, 0.0, 3.0]
[gravity]
g = 9.81
[drag]
b = 5.0
[integrator]
dt = 0.001
t_end = 0.3
"""

RED = (214, 39, 40)      # the driven node's marker
DARK = (38, 38, 38)      # the end mass's marker


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> dict[str, Trajectory]:
    """Short runs written to run folders and read back lazily, as the commands read them."""
    base = tmp_path_factory.mktemp("render-runs")
    scenes = {
        "heli": ropesim.load_scene(SCENARIOS / "helicopter_mass.toml", ["integrator.t_end=0.5"]),
        "para": ropesim.load_scene(SCENARIOS / "helicopter_parachute.toml", ["integrator.t_end=0.3"]),
        "shooter": ropesim.load_scene(SCENARIOS / "shooter_medium.toml", ["integrator.t_end=0.3"]),
        "towed3d": ropesim.scene_from_toml(TOWED_3D),
    }
    out = {}
    for name, scene in scenes.items():
        ropesim.simulate(scene, base / name)
        out[name] = Trajectory.open(base / name)
    return out


# ------------------------------------------------------------------------------------ frame choice


@settings(max_examples=200, deadline=None)
@given(frames=st.integers(2, 400), interval=st.floats(0.001, 0.1), fps=st.floats(1, 120), speed=st.floats(0.1, 4),
       a=st.floats(0, 1), b=st.floats(0, 1))
@example(frames=15, interval=0.09375, fps=2.0, speed=0.125, a=7.939257801542888e-10, b=1.0)  # start within slack
def test_animation_plan_takes_the_nearest_frames_at_the_requested_rate(frames, interval, fps, speed, a, b):
    t = np.arange(frames) * interval
    start, end = sorted((a * t[-1], b * t[-1]))
    plan = animation_plan(t, fps, speed, start, end)
    step = speed / fps
    assert np.all(np.diff(plan.indices) > 0)
    if interval <= step:
        assert plan.note is None and plan.fps == fps
        targets = start + step * np.arange(len(plan.indices))
        assert len(plan.indices) == math.floor((end - start) / step + 1e-9) + 1
        assert np.all(np.abs(t[plan.indices] - targets) <= interval / 2 + 1e-12)
    elif interval > step * (1 + 1e-6):
        # too few saved frames: every saved frame in the range, once, at the rate the run supports
        assert plan.note is not None and "too few" in plan.note
        assert plan.fps == pytest.approx(speed / interval)
        slack = 1e-9 * max(1.0, t[-1])  # the plan's documented slack: 1e-9 of the run (timeline.RELATIVE_SLACK)
        inside = np.flatnonzero((t >= start - slack) & (t <= end + slack))
        assert np.array_equal(plan.indices, inside)


@pytest.mark.parametrize("kwargs, fragment", [
    ({"fps": 0}, "--fps 0"), ({"fps": -2}, "--fps -2"), ({"fps": math.nan}, "--fps nan"),
    ({"speed": 0}, "--speed 0"), ({"start": -1}, "--start -1: outside the run"),
    ({"end": 2}, "--end 2: outside the run (t = 0 .. 1 s)"), ({"start": 0.6, "end": 0.4}, "before --start"),
])
def test_animation_plan_rejects_impossible_requests(kwargs, fragment):
    t = np.linspace(0, 1, 101)
    with pytest.raises(RenderError) as err:
        animation_plan(t, **{"fps": 25, **kwargs})
    assert fragment in str(err.value) and "\n" not in str(err.value)


def test_chosen_frames_are_the_nearest_saved_ones():
    t = np.linspace(0, 3, 301)
    assert list(chosen_frames(t, times=[0, 0.504, 1.006, 3])) == [0, 50, 101, 300]
    assert list(chosen_frames(t, count=4)) == [0, 100, 200, 300]
    assert list(chosen_frames(t)) == [0, 60, 120, 180, 240, 300]  # default: six evenly spaced
    assert list(chosen_frames(t[:4])) == [0, 1, 2, 3]                # fewer saved frames: all of them
    assert list(chosen_frames(t, count=302)) == list(range(301))
    assert parse_times(" 0, 0.5,2 ") == [0, 0.5, 2]
    for kwargs, fragment in [({"times": [0, 3.5]}, "--times 3.5: outside the run"),
                             ({"times": [1], "count": 2}, "one or the other"),
                             ({"count": 0}, "--count 0")]:
        with pytest.raises(RenderError) as err:
            chosen_frames(t, **kwargs)
        assert fragment in str(err.value)
    for text in ("0,x", "1,,2", "nan"):
        with pytest.raises(RenderError, match="--times"):
            parse_times(text)


# ---------------------------------------------------------------------------------------- framing


def test_projection_names_the_axes_across_and_up():
    assert projection(None, 2).axes == (0, 1)
    assert projection("yx", 2).axes == (1, 0)
    assert projection("XZ", 3).axes == (0, 2)
    assert projection("zy", 3).axes == (2, 1)
    for view, dim in [("xz", 2), ("xx", 3), ("xyz", 3), ("ab", 3)]:
        with pytest.raises(RenderError, match=f"--view {view.lower()}"):
            projection(view, dim)


def test_outline_projects_the_thrower_box_and_guide_cylinders(runs):
    scene = runs["shooter"].scene
    flat = outline(build(scene), projection("xy", 2))
    assert flat[0] == Box((0.0, 0.0), (4.0, 4 / 3))
    assert flat[1:] == [Circle((-4.0, 0.0), 4 / 3), Circle((4.0, 0.0), 4 / 3)]
    # the same shooter in 3-D: the box is W wide in z too; a guide is a cylinder along z, seen side-on a band
    scene3 = replace(scene, dimension=3, thrower=replace(scene.thrower, center=(0.0, 0.0, 1.0)),
                     guides=tuple(replace(g, center=(*g.center, 0.0)) for g in scene.guides))
    model3 = SimpleNamespace(scene=scene3)
    assert outline(model3, projection("xz", 3)) == [Box((0.0, 1.0), (4.0, 4 / 3)), Band(0, -4.0, 4 / 3),
                                                    Band(0, 4.0, 4 / 3)]
    assert outline(model3, projection("zy", 3)) == [Box((1.0, 0.0), (4 / 3, 4 / 3)), Band(1, 0.0, 4 / 3),
                                                    Band(1, 0.0, 4 / 3)]
    assert outline(model3, projection("xy", 3))[1:] == flat[1:]


def test_a_seabed_is_drawn_edge_on_and_a_swaying_drive_quotes_no_speed(tmp_path):
    """The mooring chain's picture: the seabed is the ground line y = height (+ tan(slope) x) with the ground
    below it, in the side view only; it does not widen the view. Its fairlead surges and heaves, so the legend
    says "driven node" without the constant velocity a tow would quote (the sinusoid's would be 0 m/s)."""
    from ropesim.render.framing import Ground, outline_extent
    from ropesim.render.scene_artist import special_nodes

    scene = ropesim.load_scene(SCENARIOS / "mooring_chain.toml", ["integrator.t_end=0.2", "output.interval=0.1"])
    model = SimpleNamespace(scene=scene)
    assert outline(model, projection("xy", 2)) == [Ground(-50.0, 0.0)]
    sloped = replace(scene, seabed=replace(scene.seabed, slope=10.0))
    assert outline(SimpleNamespace(scene=sloped), projection("xy", 2)) == [Ground(-50.0, math.tan(math.radians(10)))]
    scene3 = replace(scene, dimension=3)
    assert outline(SimpleNamespace(scene=scene3), projection("zy", 3)) == [Ground(-50.0, 0.0)]
    assert outline(SimpleNamespace(scene=scene3), projection("xz", 3)) == []
    assert outline(SimpleNamespace(scene=replace(sloped, dimension=3)), projection("zy", 3)) == []
    lo, hi = outline_extent([Ground(-50.0, 0.0)])
    assert np.all(np.isinf(lo)) and np.all(np.isinf(hi))
    assert [label for label, _, _ in special_nodes(build(scene))] == ["driven node"]
    heli = ropesim.load_scene(SCENARIOS / "helicopter_mass.toml")
    assert "driven node (8 m/s)" in [label for label, _, _ in special_nodes(build(heli))]
    # drawn: below the seabed's line the picture is the ground's grey, above it the water's white
    ropesim.simulate(scene, tmp_path / "chain")
    frame_sheet(Trajectory.open(tmp_path / "chain"), tmp_path / "chain.png", count=1, width=480)
    image = np.asarray(Image.open(tmp_path / "chain.png").convert("RGB")).astype(int)
    grey = np.all(np.abs(image - 230) <= 2, axis=2)        # GEOMETRY's facecolor 0.9
    rows = np.flatnonzero(grey.mean(axis=1) > 0.5)
    assert len(rows) > 10 and image.shape[0] * 0.3 < rows.min() < image.shape[0] * 0.8


@pytest.mark.parametrize("name, follow", [("shooter", False), ("heli", False), ("heli", True), ("towed3d", True)])
def test_view_box_holds_every_node_of_the_whole_run_read_in_blocks(runs, monkeypatch, name, follow):
    traj = runs[name]
    model = build(traj.scene)
    proj = projection(None, traj.scene.dimension)
    nodes = followed_nodes(model, follow)
    whole = view_box(model, traj.x, proj, nodes)
    monkeypatch.setattr(framing, "FRAME_BLOCK", 7)  # blocks that do not divide the frame count
    assert np.array_equal(view_box(model, traj.x, proj, nodes), whole)
    x = np.asarray(traj.x)
    if follow:
        x = x - x[:, nodes].mean(axis=1, keepdims=True)
        assert np.all(np.abs(x[:, nodes]) < 1e-9)  # the followed node sits at the origin
    p = x[:, :, list(proj.axes)].reshape(-1, 2)
    assert np.all(p >= whole[:, 0]) and np.all(p <= whole[:, 1])
    if not follow:
        lo, hi = framing.outline_extent(outline(model, proj))
        assert np.all(np.fmin(lo, whole[:, 0]) == whole[:, 0]) and np.all(np.fmax(hi, whole[:, 1]) == whole[:, 1])


@settings(max_examples=200, deadline=None)
@given(w=st.floats(0.01, 1e4), h=st.floats(0.01, 1e4), cx=st.floats(-1e3, 1e3), size=st.integers(128, 2000),
       legend=st.booleans())
def test_single_view_has_equal_axes_and_codec_friendly_size(w, h, cx, size, legend):
    box = np.array([[cx - w / 2, cx + w / 2], [-h, 0.0]])
    layout = single_view(box, size, legend)
    assert layout.width % 16 == 0 and layout.height % 16 == 0
    assert min(layout.width, layout.height) >= framing.MIN_SIDE
    assert max(layout.width, layout.height) <= max(size, framing.MIN_SIDE) + 16
    left, bottom, aw, ah = layout.axes
    assert left + aw <= layout.width and bottom + ah <= layout.height
    span = layout.box[:, 1] - layout.box[:, 0]
    assert span[0] / aw == pytest.approx(span[1] / ah, rel=1e-9)  # one metre is as many pixels across as up
    assert np.all(layout.box[:, 0] <= box[:, 0] + 1e-9 * w) and np.all(layout.box[:, 1] >= box[:, 1] - 1e-9 * h)
    assert np.allclose(fit_box(box, aw, ah), layout.box)


# ----------------------------------------------------------------------------- what is drawn where


def _centroid(image: np.ndarray, colour: tuple[int, int, int], renderer: FrameRenderer, tolerance: int = 30,
              around: np.ndarray | None = None) -> np.ndarray:
    """(column, row) [px] centre of the pixels inside the view (and within 20 px of ``around``, if given)
    within ``tolerance`` of ``colour``."""
    near = np.all(np.abs(image[..., :3].astype(int) - colour) <= tolerance, axis=-1)
    left, bottom, width, height = renderer.layout.axes
    inside = np.zeros_like(near)
    top = renderer.layout.height - bottom - height
    inside[top + 2:top + height - 2, left + 2:left + width - 2] = True  # not the legend, not the frame
    near &= inside
    if around is not None:
        rows, cols = np.indices(near.shape)
        near &= (np.abs(cols - around[0]) < 20) & (np.abs(rows - around[1]) < 20)  # not the time stamp
    assert near.sum() > 5, f"no {colour} pixels drawn"
    rows, cols = np.nonzero(near)
    return np.array([cols.mean(), rows.mean()])


def _pixel(renderer: FrameRenderer, point: np.ndarray) -> np.ndarray:
    """(column, row) [px] of a projected point [m] in the lab frame, from the layout alone."""
    layout = renderer.layout
    left, bottom, aw, ah = layout.axes
    box = layout.box
    col = left + (point[0] - box[0, 0]) / (box[0, 1] - box[0, 0]) * aw
    row = layout.height - (bottom + (point[1] - box[1, 0]) / (box[1, 1] - box[1, 0]) * ah)
    return np.array([col, row])


def test_lab_frame_draws_the_driven_node_and_end_mass_where_they_are(runs):
    traj = runs["heli"]
    model = build(traj.scene)
    renderer = FrameRenderer(traj, model, projection(None, 2), None, 480)
    for i in (0, traj.frames - 1):
        image = renderer.render(i)
        assert image.shape == (renderer.size[1], renderer.size[0], 4)
        x = np.asarray(traj.x[i])
        # the end mass, a filled circle, is centred on the last node
        end = _pixel(renderer, x[-1])
        assert np.allclose(_centroid(image, DARK, renderer, 12, around=end), end, atol=1.0)
        # the driven node's triangle is within its own size of node 0
        assert np.allclose(_centroid(image, RED, renderer), _pixel(renderer, x[0]), atol=3.0)
    # over the run the driven node moves at V = (8, 0) m/s: that many metres, as many pixels as the scale says
    first, last = (_centroid(renderer.render(i), RED, renderer) for i in (0, traj.frames - 1))
    metres_per_px = (renderer.layout.box[0, 1] - renderer.layout.box[0, 0]) / renderer.layout.axes[2]
    assert last - first == pytest.approx([8.0 * traj.t[-1] / metres_per_px, 0.0], abs=0.5)


@pytest.mark.parametrize("name, view", [("heli", None), ("towed3d", "xz"), ("towed3d", "zy")])
def test_follow_keeps_the_driven_node_still_while_the_lab_moves(runs, name, view):
    traj = runs[name]
    model = build(traj.scene)
    proj = projection(view, traj.scene.dimension)
    follow = FrameRenderer(traj, model, proj, followed_nodes(model, True), 480)
    spots = [_centroid(follow.render(i), RED, follow) for i in range(0, traj.frames, 7)]
    assert np.allclose(spots, spots[0], atol=0.5)
    lab = FrameRenderer(traj, model, proj, None, 480)
    moved = _centroid(lab.render(traj.frames - 1), RED, lab) - _centroid(lab.render(0), RED, lab)
    velocity = np.asarray(traj.scene.driven[0].velocity)[list(proj.axes)]
    metres_per_px = (lab.layout.box[0, 1] - lab.layout.box[0, 0]) / lab.layout.axes[2]
    # rows count down the picture, so "up" is minus a row
    expected = velocity * traj.t[-1] / metres_per_px * np.array([1, -1])
    assert moved == pytest.approx(expected, abs=0.5)


# ------------------------------------------------------------------------------------------ files


def test_gif_has_the_expected_frames_size_timing_and_exact_colours(runs, tmp_path):
    traj = runs["heli"]
    result = animate(traj, tmp_path / "a.gif", fps=25, size=400)
    expected = math.floor(float(traj.t[-1]) * 25 + 1e-9) + 1
    assert result.frames == expected == 13
    with Image.open(tmp_path / "a.gif") as gif:
        assert gif.n_frames == expected
        assert gif.size == result.size
        assert gif.info["duration"] == 40 and gif.info["loop"] == 0
        gif.seek(expected - 1)
        last = np.asarray(gif.convert("RGB"))
    assert tuple(last[2, -2]) == (255, 255, 255)  # the background stays exactly white
    assert np.any(np.all(last == tuple(int(ROPE_COLOR[i:i + 2], 16) for i in (1, 3, 5)), axis=-1))
    again = animate(traj, tmp_path / "b.gif", fps=25, size=400)
    assert again == replace(result, path=tmp_path / "b.gif")
    assert (tmp_path / "a.gif").read_bytes() == (tmp_path / "b.gif").read_bytes()


def test_mp4_decodes_with_the_expected_frame_count_and_is_deterministic(runs, tmp_path):
    import imageio_ffmpeg

    traj = runs["heli"]
    result = animate(traj, tmp_path / "a.mp4", fps=30)
    expected = math.floor(float(traj.t[-1]) * 30 + 1e-9) + 1
    assert result.frames == expected
    reader = imageio_ffmpeg.read_frames(str(tmp_path / "a.mp4"))
    meta = next(reader)
    assert tuple(meta["size"]) == result.size
    assert sum(1 for _ in reader) == expected
    assert imageio_ffmpeg.count_frames_and_secs(str(tmp_path / "a.mp4"))[0] == expected
    animate(traj, tmp_path / "b.mp4", fps=30)
    assert (tmp_path / "a.mp4").read_bytes() == (tmp_path / "b.mp4").read_bytes()


def test_gif_rate_is_a_whole_number_of_hundredths(runs, tmp_path):
    assert [gif_fps(f) for f in (25, 30, 20, 49, 200)] == [25, 100 / 3, 20, 50, 50]
    notes = []
    result = animate(runs["para"], tmp_path / "fast.gif", fps=80, note=notes.append)
    assert result.fps == 50 and len(notes) == 1 and "at most 50 fps" in notes[0]


def test_too_few_saved_frames_uses_every_saved_frame_and_says_so(runs, tmp_path):
    traj = runs["para"]
    notes = []
    result = animate(traj, tmp_path / "slow.mp4", fps=250, note=notes.append)
    assert result.frames == traj.frames and result.fps == pytest.approx(100)
    assert len(notes) == 1 and "too few for 250 fps" in notes[0]


def test_gif_palette_keeps_the_most_frequent_colours_exactly():
    rng = np.random.default_rng(1)
    image = np.zeros((60, 60, 4), dtype=np.uint8)
    image[..., :3] = rng.integers(0, 256, (60, 60, 3))   # 3600 colours, each rare
    image[:30] = (255, 255, 255, 255)
    image[30:40] = (31, 119, 180, 255)
    palette = np.asarray(gif_palette([image]).getpalette()[:768]).reshape(256, 3)
    assert [tuple(c) for c in palette[:2]] == [(255, 255, 255), (31, 119, 180)]


def test_failure_while_encoding_leaves_no_file_behind(runs, tmp_path, monkeypatch):
    out = tmp_path / "keep.gif"
    animate(runs["heli"], out, fps=25, end=0.1)     # the previous animation (ropesim's, so it may be replaced)
    previous = out.read_bytes()
    calls = {"n": 0}
    real = FrameRenderer.render

    def failing(self, i):
        calls["n"] += 1
        if calls["n"] > 8:
            raise KeyboardInterrupt
        return real(self, i)

    monkeypatch.setattr(FrameRenderer, "render", failing)
    for target in (out, tmp_path / "new.mp4"):
        calls["n"] = 0
        with pytest.raises(KeyboardInterrupt):
            animate(runs["heli"], target, fps=25)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.gif"]
    assert out.read_bytes() == previous


def test_frame_sheet_png_size_times_and_determinism(runs, tmp_path):
    traj = runs["shooter"]
    sheet = frame_sheet(traj, tmp_path / "a.png", times=[0, 0.1, 0.3], width=600)
    assert sheet.times == (0.0, pytest.approx(0.1), pytest.approx(0.3))
    with Image.open(tmp_path / "a.png") as png:
        assert png.size == sheet.size and png.size[0] == 600
    frame_sheet(traj, tmp_path / "b.png", times=[0, 0.1, 0.3], width=600)
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()
    # two rows of the same panels are about twice as tall as one
    one = frame_sheet(traj, tmp_path / "c.png", count=2, columns=2, width=600).size
    two = frame_sheet(traj, tmp_path / "d.png", count=4, columns=2, width=600).size
    assert two[1] - HEADER_ROOM == pytest.approx(2 * (one[1] - HEADER_ROOM), abs=2)
    over = frame_sheet(runs["towed3d"], tmp_path / "e.png", overlay=True, follow=True, view="xz")
    with Image.open(tmp_path / "e.png") as png:
        assert png.size == over.size


# ------------------------------------------------------------------------------------------ plots


def test_plots_choose_panels_by_scene_and_match_the_analyses(runs, tmp_path, monkeypatch):
    heli, shooter = runs["heli"], runs["shooter"]
    every = {"energy", "stretch"}  # and whatever else every run gets
    towed = plot_run(heli, tmp_path / "h.png").panels
    assert every <= set(towed) and "towed" in towed and "shooter" not in towed
    plot = plot_run(shooter, tmp_path / "s.png")
    assert every <= set(plot.panels) and "shooter" in plot.panels and "towed" not in plot.panels
    with Image.open(tmp_path / "s.png") as png:
        assert png.size == plot.size
    model = build(heli.scene)
    monkeypatch.setattr(framing, "FRAME_BLOCK", 7)
    series = largest_stretch_series(heli, model)
    best, at = largest_stretch(model, heli.x)
    assert series.max() == best and int(np.argmax(series)) == at
    blocked = per_frame(heli, lambda x, v: energy_terms(model, x, v))
    direct = energy_terms(model, np.asarray(heli.x), np.asarray(heli.v))
    assert blocked.keys() == direct.keys()
    for key in direct:
        assert np.allclose(blocked[key], direct[key], rtol=1e-12, atol=1e-9)
