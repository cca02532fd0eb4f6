"""Every command on a system of lines, end to end and by content: a run of the clump weight (two wires meeting at
a free 200 kg point) through `ropesim run`, then check, summary, plot, frames, animate, export, view and sweep;
what they draw, write and print is compared with the run's own arrays, line by line (each line's nodes as
the model lays them out). A plate swinging on two legs is a real run with a rigid body; a made-up turning spar
(tests/synthetic_system.py: its motion known in closed form) checks what is drawn and exported of a 3-D body."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import meshio
import numpy as np
import pytest
from PIL import Image
from typer.testing import CliRunner

import ropesim
from ropesim.analysis.tension import window_statistics
from ropesim.cli.app import app
from ropesim.model.build import build
from ropesim.model.layout import line_layouts

from conftest import ROOT
from synthetic_system import plate_scene, turning_body_run

SYSTEMS = ROOT / "tests" / "data" / "systems"
CLUMP = SYSTEMS / "clump_weight.toml"
runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args], env={"COLUMNS": "200"})


def words(text: str) -> str:
    """A table's text as its words, one space apart (its rules left out)."""
    return " ".join(text.replace("│", " ").split())


@pytest.fixture(scope="module")
def clump(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("system-runs") / "clump"
    result = invoke("run", CLUMP, "--set", "integrator.t_end=1", "--out", folder)
    assert result.exit_code == 0, result.output
    (folder / "run.txt").write_text(result.stdout)
    return folder


@pytest.fixture(scope="module")
def spar():
    """A made-up run of OC3-Hywind's spar turning at a steady rate while it drifts (tests/synthetic_system.py)."""
    return turning_body_run(ropesim.load_scene(SYSTEMS / "oc3_hywind.toml", ["initial.shape=lines"]), frames=9)


# ------------------------------------------------------------------------------------------ check, run, summary


def test_check_names_every_line_point_and_its_nodes():
    result = invoke("check", CLUMP)
    assert result.exit_code == 0, result.output
    out = words(result.stdout)
    assert "system 2 lines, 3 points, 2-D; 22 nodes" in out
    assert "line left_wire left -> clump, 22.5 m in 10 segments (nodes 0 .. 10); wire: 0.4 kg/m" in out
    assert "line right_wire clump -> right, 22.5 m in 10 segments (nodes 11 .. 21)" in out
    assert "point clump free, starting at (20, -10) m; 200 kg" in out and "point left fixed at (0, 0) m" in out
    data = json.loads(invoke("check", CLUMP, "--json").stdout)
    scene = ropesim.load_scene(CLUMP)
    layouts = line_layouts(scene)
    assert [(d["id"], d["first_node"], d["nodes"]) for d in data["lines"]] == [(line.id, line.first, line.nodes)
                                                                                for line in layouts]
    assert [p["kind"] for p in data["points"]] == ["fixed", "fixed", "free"] and data["nodes"] == 22


def test_run_prints_each_lines_tensions_as_the_summary_holds_them(clump):
    summary = json.loads((clump / "summary.json").read_text())
    out = words((clump / "run.txt").read_text())
    traj = ropesim.Trajectory.open(clump)
    for line in ("left_wire", "right_wire"):
        figures = summary["lines"][line]
        tension = traj.line(line).tension
        assert figures["start_N"] == pytest.approx(float(tension[-1, 0]))
        assert figures["end_N"] == pytest.approx(float(tension[-1, -1]))
        assert figures["max_N"] == pytest.approx(float(np.max(tension)))
        scale, unit = (1e3, "kN") if max(f["max_N"] for f in summary["lines"].values()) >= 1e3 else (1.0, "N")
        assert (f"tension, {line} {figures['start_N'] / scale:.4g} {unit} at its start, "
                f"{figures['end_N'] / scale:.4g} {unit} at its end") in out


def test_summary_gives_each_line_end_and_support_over_the_window(clump):
    result = invoke("summary", clump, "--from", "0.5", "--json")
    assert result.exit_code == 0, result.output
    figures = json.loads(result.stdout)
    traj = ropesim.Trajectory.open(clump)
    window = slice(int(np.searchsorted(traj.t, 0.5 - 1e-9)), traj.frames)
    for line in ("left_wire", "right_wire"):
        result_line = traj.line(line)
        for end, values in (("start", result_line.start_tension), ("end", result_line.end_tension)):
            expected = window_statistics(values[:, None], window)
            assert figures["lines"][line][end]["max"] == pytest.approx(float(expected["max"][0]))
            assert figures["lines"][line][end]["mean"] == pytest.approx(float(expected["mean"][0]))
    assert figures["support_labels"] == ["left (left_wire's start)", "right (right_wire's end)"]
    text = invoke("summary", clump).stdout
    assert "left_wire: start" in text and "right (right_wire's end): |F|" in text


# ------------------------------------------------------------------------------------------ pictures


def test_plot_draws_each_line_where_the_last_frame_has_it(clump, tmp_path):
    from ropesim.render.plots import run_figure

    traj = ropesim.Trajectory.open(clump)
    fig, panels = run_figure(traj)
    assert panels[0] == "shape" and "end tensions" in panels and "tension profile" in panels
    shape = fig.axes[0]
    x = np.asarray(traj.x[-1])
    for line in line_layouts(traj.scene):
        (artist,) = [a for a in shape.lines if a.get_label() == line.id]
        assert np.array_equal(artist.get_xdata(), x[line.first:line.end, 0])
        assert np.array_equal(artist.get_ydata(), x[line.first:line.end, 1])
    assert sorted(t.get_text() for t in shape.texts) == ["left_wire", "right_wire"]
    ends = fig.axes[panels.index("end tensions")]
    curves = {a.get_label(): a for a in ends.lines if not a.get_label().startswith("_")}
    assert list(curves) == ["left_wire start (left)", "left_wire end (clump)", "right_wire start (clump)",
                            "right_wire end (right)"]
    unit = 1e3 if "kN" in ends.get_ylabel() else 1.0
    assert np.allclose(curves["right_wire end (right)"].get_ydata() * unit, traj.line("right_wire").end_tension)
    result = invoke("plot", clump)
    assert result.exit_code == 0 and result.stdout.startswith(f"{clump / 'plots.png'}: shape, energy")


def test_frames_and_animate_draw_every_line_and_point(clump, tmp_path):
    from ropesim.render.scene_artist import RopeArtist
    from matplotlib.figure import Figure
    from ropesim.render.framing import projection

    traj = ropesim.Trajectory.open(clump)
    model = build(traj.scene, solve=False)
    artist = RopeArtist(Figure().add_subplot(), model, projection(None, 2))
    x = np.asarray(traj.x[37])
    artist.show(x)
    assert [a.get_label() for _, _, a in artist.lines] == ["left_wire", "right_wire"]
    for (part, _, line), layout in zip(artist.lines, line_layouts(traj.scene)):
        assert np.array_equal(line.get_xydata(), x[layout.first:layout.end])
    ((nodes, clump_mark),) = artist.special       # the clump: a heavy disc at left_wire's last node
    assert list(nodes) == [10] and np.array_equal(clump_mark.get_xydata(), x[[10]])
    for args, words in ((("frames", clump, "--count", "3"), "t = 0, 0.5, 1 s"),
                        (("animate", clump, "--fps", "10"), "frames at 10 fps")):
        result = invoke(*args)
        assert result.exit_code == 0 and words in result.stdout, result.output
    with Image.open(clump / "animation.gif") as gif:
        assert gif.n_frames == 11


def test_the_3d_view_draws_lines_and_body_axes_where_they_are(spar, tmp_path):
    from matplotlib.figure import Figure
    from scipy.spatial.transform import Rotation

    from ropesim.analysis.objects import body_glyphs
    from ropesim.render.view3d import State3D, axes_3d, plotted, run_box

    model = build(spar.scene, solve=False)
    ax = axes_3d(Figure(), [0, 0, 1, 1], run_box(spar.x, None, spar.body_x), False)
    state = State3D(ax, model)
    k = 6
    state.show(np.asarray(spar.x[k]), None, (np.asarray(spar.body_x[k]), np.asarray(spar.body_q[k])))
    for (_, _, artist), line in zip(state.lines, line_layouts(spar.scene)):
        assert np.allclose(np.array(artist.get_data_3d()).T, np.stack(plotted(spar.x[k][line.first:line.end]), -1))
    turn = Rotation.from_quat(np.asarray(spar.body_q[k, 0]), scalar_first=True).as_matrix()
    (glyph,) = body_glyphs(spar.scene)
    origin = np.asarray(spar.body_x[k, 0])
    for axis, artist in enumerate(state.axes):   # each drawn axis: from the reference point along R's column
        drawn = np.array(artist.get_data_3d()).T[:2]
        assert np.allclose(drawn, np.stack(plotted(np.stack([origin, origin + glyph.axis_length * turn[:, axis]])),
                                           -1))
    spokes = np.array(state.spokes.get_data_3d()).T.reshape(-1, 3, 3)[:, 1]   # (from, to, gap) per spoke
    fairleads = [spar.point(f"fairlead{i}").position[k] for i in (1, 2, 3)]
    assert np.allclose(spokes, np.stack(plotted(np.array(fairleads)), -1))
    from ropesim.render.animate import animate
    from ropesim.render.frames import frame_sheet

    movie = animate(spar, tmp_path / "spar.gif", fps=2)     # fewer saved frames than asked: every one
    assert movie.frames == spar.frames and movie.size == (640, 512)
    sheet = frame_sheet(spar, tmp_path / "spar.png", count=3)
    assert sheet.times == (0.0, 3.0, 6.0)


def test_a_2d_body_is_drawn_as_its_axes_and_spokes(tmp_path):
    from matplotlib.figure import Figure

    from ropesim.render.framing import projection
    from ropesim.render.scene_artist import RopeArtist

    plate = turning_body_run(plate_scene(), frames=7, rate=1.1)
    model = build(plate.scene, solve=False)
    artist = RopeArtist(Figure().add_subplot(), model, projection(None, 2))
    k = 4
    artist.show(np.asarray(plate.x[k]), None, (np.asarray(plate.body_x[k]), np.asarray(plate.body_q[k])))
    body = plate.body("plate")
    origin = np.asarray(body.position[k])
    for axis, line in enumerate(artist.bodies.axes):
        tip = line.get_xydata()[1]
        assert np.allclose((tip - origin) / np.linalg.norm(tip - origin), body.rotation[k][:, axis])
    tips = artist.bodies.spokes.get_xydata().reshape(-1, 3, 2)[:, 1]
    assert np.allclose(tips, [plate.point("left_eye").position[k], plate.point("right_eye").position[k]])
    from ropesim.render import RenderError
    from ropesim.render.animate import animate

    with pytest.raises(RenderError, match="the 3-D view is for 3-D scenes"):
        animate(plate, tmp_path / "p.gif", view="3d")


# ------------------------------------------------------------------------------------------ export, view, sweep


def test_vtk_holds_each_line_as_a_block_of_its_own_nodes(clump, tmp_path):
    result = invoke("export", clump, "--to", "vtk", "-o", tmp_path / "vtk")
    assert result.exit_code == 0, result.output
    traj = ropesim.Trajectory.open(clump)
    pvd = tmp_path / "vtk" / "clump_weight.pvd"
    sets = ET.parse(pvd).getroot().find("Collection").findall("DataSet")
    assert [(d.get("part"), d.get("name")) for d in sets[:3]] == [("0", "left_wire"), ("1", "right_wire"),
                                                                  ("2", "supports")]
    assert len(sets) == 3 * traj.frames
    for d in sets[3 * 7:3 * 7 + 2]:    # frame 7
        line = traj.line(d.get("name"))
        mesh = meshio.read(pvd.parent / d.get("file"))
        assert np.array_equal(mesh.points[:, :2], line.positions[7])
        assert np.array_equal(mesh.cell_data["tension"][0], line.tension[7])
        assert np.array_equal(mesh.cells_dict["line"], np.column_stack([np.arange(10), np.arange(1, 11)]))


def test_vtk_draws_a_body_as_its_axes_and_spokes(spar, tmp_path):
    from ropesim.analysis.objects import body_glyphs

    spar.export("vtk", tmp_path / "vtk")
    pvd = tmp_path / "vtk" / "oc3_hywind.pvd"
    sets = [d for d in ET.parse(pvd).getroot().find("Collection").findall("DataSet") if d.get("name") == "bodies"]
    assert len(sets) == spar.frames
    body = spar.body("spar")
    (glyph,) = body_glyphs(spar.scene)
    k = 5
    mesh = meshio.read(pvd.parent / sets[k].get("file"))
    origin = mesh.points[mesh.cells_dict["vertex"][0, 0]]
    assert np.allclose(origin, body.position[k])
    lines, part = mesh.cells_dict["line"], mesh.cell_data_dict["part"]["line"]
    for axis in range(3):
        (cell,) = lines[part == axis + 1]
        assert np.allclose(mesh.points[cell[1]] - origin, glyph.axis_length * body.rotation[k][:, axis])
    tips = mesh.points[lines[part == 4][:, 1]]
    assert np.allclose(tips, [spar.point(f"fairlead{i}").position[k] for i in (1, 2, 3)])
    assert np.allclose(mesh.point_data["line_force"][0], body.force[k])
    assert np.allclose(mesh.point_data["line_moment"][0], body.moment[k])
    assert np.allclose(mesh.point_data["orientation"][0], body.quaternion[k])


def test_csv_tables_read_back_per_line_and_per_body(clump, spar, tmp_path):
    result = invoke("export", clump, "--to", "csv", "-o", tmp_path / "clump.csv")
    assert result.exit_code == 0, result.output
    traj = ropesim.Trajectory.open(clump)
    text = (tmp_path / "clump.csv").read_text().splitlines()
    assert text[0] == "t [s],line,node,x [m],y [m],vx [m/s],vy [m/s]"
    rows = [row.split(",") for row in text[1:]]
    assert len(rows) == traj.frames * 22
    right = [r for r in rows[22 * 9:22 * 10] if r[1] == "right_wire"]      # frame 9
    assert [int(r[2]) for r in right] == list(range(11))
    assert np.array_equal(np.array([[float(v) for v in r[3:5]] for r in right]), traj.line("right_wire").positions[9])
    history = np.genfromtxt(tmp_path / "clump_tension_history.csv", delimiter=",", names=True)
    unit = 1e3 if "kN" in (tmp_path / "clump_tension_history.csv").read_text().split("\n")[0] else 1.0
    assert np.allclose(history[history.dtype.names[3]] * unit, traj.line("right_wire").start_tension, rtol=1e-12)
    spar.export("csv", tmp_path / "spar.csv")
    table = np.genfromtxt(tmp_path / "spar_bodies.csv", delimiter=",", skip_header=1, dtype=float)
    body = spar.body("spar")
    header = (tmp_path / "spar_bodies.csv").read_text().split("\n")[0].split(",")
    scale = 1e3 if "Fx [kN]" in header else 1.0
    assert np.allclose(table[:, 2:5], body.position) and np.allclose(table[:, 5:9], body.quaternion)
    assert np.allclose(table[:, 9:12], body.angles)
    assert np.allclose(table[:, header.index(f"Fx [{'kN' if scale > 1 else 'N'}]")] * scale, body.force[:, 0])


def test_view_content_has_each_line_and_the_bodies_box_turning_with_it(clump, spar):
    from ropesim.viewer.content import run_content

    content = run_content(clump)
    traj = ropesim.Trajectory.open(clump)
    assert [line.name for line in content.lines] == ["left_wire", "right_wire"]
    frames = np.array([0, 40, 100])
    for line in content.lines:
        assert np.array_equal(np.asarray(line.positions[frames]), traj.line(line.name).positions[frames])
        (tension,) = [f for f in line.fields if f.name == "tension"]
        assert np.array_equal(np.asarray(tension.values[frames]), traj.line(line.name).tension[frames])
    (heavy,) = [p for p in content.points if p.kind == "heavy"]
    assert np.array_equal(heavy.positions[frames][:, 0], traj.point("clump").position[frames])
    assert [s.name for s in content.series][:2] == ["tension at left_wire start (left)",
                                                    "tension at left_wire end (clump)"]
    spar_content = run_content(spar)
    (box,) = spar_content.bodies
    body = spar.body("spar")
    local = np.array([[0.0, 0.0, 0.0], [5.2, -70.0, 0.0], [-2.6, -70.0, -4.5], [-2.6, -70.0, 4.5]])
    centre = (local.min(axis=0) + local.max(axis=0)) / 2
    assert box.size == pytest.approx((7.8, 70.0, 9.0))
    k = np.arange(spar.frames)
    assert np.allclose(box.position[k], body.position + body.rotation @ centre)
    assert np.array_equal(np.asarray(box.orientation[k]), body.quaternion)
    result = invoke("view", clump, "--no-open")
    assert result.exit_code == 0 and "clump_weight (101 frames)" in result.stdout


def test_a_sweep_tabulates_each_lines_tensions(tmp_path):
    from ropesim.sweep.core import read_table

    result = invoke("sweep", CLUMP, "--set", "points.2.mass=100,300", "--set", "integrator.t_end=0.3", "--out",
                    tmp_path / "sweep", "-j", "1", "-q", "--yes")
    assert result.exit_code == 0, result.output
    rows = read_table(tmp_path / "sweep" / "results.csv")
    light, heavy = sorted(rows, key=lambda r: float(r["points.2.mass"]))
    assert float(heavy["lines.left_wire.max_N"]) > float(light["lines.left_wire.max_N"]) > 0


def test_plot_follows_each_body_and_draws_the_3d_shape(spar):
    from ropesim.render.plots import run_figure
    from ropesim.render.view3d import plotted

    fig, panels = run_figure(spar)
    assert panels[-2:] == ("body motion", "body rotation")
    assert fig.axes[0].name == "3d"                     # a 3-D system's shape panel
    shown = [a for a in fig.axes[0].lines if a.get_label() == "line2"]
    x = np.asarray(spar.x[-1])[21:42]
    assert len(shown) == 1 and np.allclose(np.array(shown[0].get_data_3d()).T, np.stack(plotted(x), -1))
    body = spar.body("spar")
    motion = {a.get_label(): a.get_ydata() for a in fig.axes[panels.index("body motion")].lines}
    assert np.allclose(motion["spar: Δz"], body.position[:, 2] - body.position[0, 2])
    turns = {a.get_label(): a.get_ydata() for a in fig.axes[panels.index("body rotation")].lines}
    assert np.allclose(turns["spar: about y"], body.angles[:, 1])


def test_a_3d_animation_frame_equals_the_whole_picture_drawn_afresh(spar):
    """The 3-D animation draws only what moves over the view it drew once; a frame so made is the picture a
    full drawing makes, pixel for pixel (the fixed points' markers over the lines, as a full drawing has them)."""
    from ropesim.render.animate import FrameRenderer3D

    renderer = FrameRenderer3D(spar, build(spar.scene, solve=False), None, 480)
    fast = [renderer.render(k) for k in (3, 8)]
    for artist in renderer.moving:
        artist.set_animated(False)
    renderer.canvas.draw()
    assert np.array_equal(fast[1], np.array(renderer.canvas.buffer_rgba()))
    assert not np.array_equal(fast[0], fast[1])


def test_every_command_on_a_run_with_a_rigid_body(tmp_path):
    """The plate on two legs, run by `ropesim run` (its body's state in the run folder, memory-mapped when read):
    every command exits 0, and what they write of the body is the run's."""
    from synthetic_system import BODY_2D

    scene = tmp_path / "plate.toml"
    scene.write_text(BODY_2D)
    folder = tmp_path / "plate"
    result = invoke("run", scene, "--set", "integrator.t_end=0.5", "--set", "integrator.method=verlet", "--out",
                    folder, "-q")
    assert result.exit_code == 0, result.output
    traj = ropesim.Trajectory.open(folder)
    assert traj.body_q.shape == (traj.frames, 1, 4) and np.allclose(np.linalg.norm(traj.body_q, axis=2), 1.0)
    for args in (("check", scene), ("summary", folder), ("plot", folder), ("frames", folder, "--count", "3"),
                 ("animate", folder, "--fps", "10"), ("export", folder, "--to", "vtk"),
                 ("export", folder, "--to", "csv"), ("view", folder, "--no-open")):
        result = invoke(*args)
        assert result.exit_code == 0, (args, result.output)
    assert "body plate free, reference point at (0, -5) m, turned (20) deg; 100 kg; points left_eye, right_eye" \
        in words(invoke("check", scene).stdout)
    table = np.genfromtxt(folder / "trajectory_bodies.csv", delimiter=",", skip_header=1)
    body = traj.body("plate")
    assert np.allclose(table[:, 2:4], body.position) and np.allclose(table[:, 8], body.angles[:, 0])
    sets = [d for d in ET.parse(folder / "vtk" / "plate_2d.pvd").getroot().find("Collection").findall("DataSet")
            if d.get("name") == "bodies"]
    mesh = meshio.read(folder / "vtk" / sets[-1].get("file"))
    assert np.allclose(mesh.points[0, :2], body.position[-1]) and np.allclose(mesh.points[0, 2], 0.0)
    assert np.allclose(mesh.point_data["line_moment"][0], [0.0, 0.0, body.moment[-1, 0]])
