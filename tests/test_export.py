"""`ropesim export`: each format read back with its own reader (meshio for VTK, numpy for CSV) equals the run
folder's trajectory; outputs are atomic; a missing extra or an unknown format is one line with exit code 2."""

from __future__ import annotations

import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import meshio
import numpy as np
import pytest
from typer.testing import CliRunner

import ropesim
from ropesim.cli.app import app
from ropesim.io.export import ExportError, export
from ropesim.install import install_hint

from conftest import SCENARIOS

runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args], env={"COLUMNS": "200"})


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> dict[str, Path]:
    base = tmp_path_factory.mktemp("export-runs")
    out = {}
    for name, sets in (("helicopter_parachute", ["integrator.t_end=0.2"]),
                       ("shooter_low", ["integrator.t_end=0.1"]),
                       ("helicopter_uniform", ["integrator.t_end=0.1", "dimension=3", "initial.top=[0.0,0.0,0.0]",
                                               "initial.velocity=[8.0,0.0,1.0]", "driven.0.velocity=[8.0,0.0,1.0]"])):
        scene = ropesim.load_scene(SCENARIOS / f"{name}.toml", sets)
        ropesim.simulate(scene, base / name)
        out[name] = base / name
    return out


@pytest.mark.parametrize("name", ["helicopter_parachute", "shooter_low", "helicopter_uniform"])
def test_csv_reads_back_exactly_with_numpy(runs, name):
    traj = ropesim.Trajectory.open(runs[name])
    result = invoke("export", runs[name], "--to", "csv")
    assert result.exit_code == 0, result.output
    path = runs[name] / "trajectory.csv"
    assert result.stdout.startswith(f"{path}: {traj.frames} frames of {traj.nodes} nodes, 3 files, ")
    dim = traj.x.shape[2]
    header = path.read_text().splitlines()[0]
    assert header == ",".join(["t [s]", "node", *(f"{a} [m]" for a in "xyz"[:dim]),
                               *(f"v{a} [m/s]" for a in "xyz"[:dim])])
    table = np.loadtxt(path, delimiter=",", skiprows=1)
    assert table.shape == (traj.frames * traj.nodes, 2 + 2 * dim)
    rows = table.reshape(traj.frames, traj.nodes, -1)
    assert np.array_equal(rows[:, 0, 0], traj.t) and np.array_equal(rows[:, :, 1], np.tile(np.arange(traj.nodes),
                                                                                           (traj.frames, 1)))
    assert np.array_equal(rows[:, :, 2:2 + dim], traj.x)      # bit for bit
    assert np.array_equal(rows[:, :, 2 + dim:], traj.v)


@pytest.mark.parametrize("name", ["helicopter_parachute", "shooter_low", "helicopter_uniform"])
def test_vtk_series_reads_back_with_meshio_and_lists_every_time(runs, name, tmp_path):
    traj = ropesim.Trajectory.open(runs[name])
    result = invoke("export", runs[name], "--to", "vtk", "-o", tmp_path / "vtk")
    assert result.exit_code == 0, result.output
    pvd = tmp_path / "vtk" / f"{traj.scene.name}.pvd"
    held = traj.support is not None
    files = traj.frames * (2 if held else 1) + 1
    assert result.stdout.startswith(f"{pvd}: {traj.frames} frames of {traj.nodes} nodes, {files} files")
    sets = [d for d in ET.parse(pvd).getroot().find("Collection").findall("DataSet") if d.get("part") == "0"]
    assert [float(d.get("timestep")) for d in sets] == list(traj.t)
    dim = traj.x.shape[2]
    closed = traj.scene.rope.closed
    for i, d in enumerate(sets):
        mesh = meshio.read(pvd.parent / d.get("file"))
        assert np.array_equal(mesh.points[:, :dim], traj.x[i])
        assert np.array_equal(mesh.point_data["velocity"][:, :dim], traj.v[i])
        assert np.allclose(mesh.point_data["speed"], np.linalg.norm(traj.v[i], axis=1))
        lines = mesh.cells_dict["line"]
        assert len(lines) == traj.nodes - (0 if closed else 1)
        assert list(lines[0]) == [0, 1] and (list(lines[-1]) == [traj.nodes - 1, 0]) == closed


def test_vtk_replaces_an_old_export_whole_and_leaves_nothing_behind(runs, tmp_path):
    traj = ropesim.Trajectory.open(runs["shooter_low"])
    out = tmp_path / "series"
    export(traj, "vtk", out)
    (out / "stale.vtu").write_text("old")           # a frame of an earlier, longer export
    export(traj, "vtk", out)
    assert not (out / "stale.vtu").exists() and len(list(out.iterdir())) == traj.frames * (
        2 if traj.support is not None else 1) + 1
    assert [p.name for p in tmp_path.iterdir()] == ["series"]   # no temporary folder left


def test_default_outputs_go_into_the_run_folder(runs):
    traj = ropesim.Trajectory.open(runs["helicopter_parachute"])
    assert export(traj, "vtk").path == runs["helicopter_parachute"] / "vtk" / "helicopter_parachute.pvd"
    assert export(traj, "csv").path == runs["helicopter_parachute"] / "trajectory.csv"


@pytest.mark.parametrize("args,fragment", [
    (["--to", "netcdf"], "--to netcdf: not offered: NetCDF would need xarray"),
    (["--to", "xlsx"], "--to xlsx: unknown format; use one of vtk, csv"),
    (["--to", "csv", "-o", "{run}"], "is a folder; give a file name"),
])
def test_bad_requests_are_one_line(runs, args, fragment):
    run = runs["shooter_low"]
    result = invoke("export", run, *[a.format(run=run) for a in args])
    assert result.exit_code == 2 and result.stdout == ""
    assert result.stderr.splitlines() == [result.stderr.strip()] and fragment in result.stderr


def test_a_missing_extra_names_it(runs, monkeypatch):
    monkeypatch.setitem(sys.modules, "meshio", None)   # as if not installed: importing it raises ImportError
    result = invoke("export", runs["shooter_low"], "--to", "vtk", "-o", runs["shooter_low"] / "v2")
    assert result.exit_code == 2
    assert result.stderr == ("ropesim: --to vtk: needs meshio, which is not installed; "
                             f"{install_hint('export')}\n")   # pip install -e '<checkout>[export]' here
    assert not (runs["shooter_low"] / "v2").exists()
    with pytest.raises(ExportError, match="\\[export\\]"):
        export(ropesim.Trajectory.open(runs["shooter_low"]), "vtk")


def test_export_of_a_scene_says_to_run_it_first(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = invoke("export", "shooter_low", "--to", "csv")
    assert result.exit_code == 2 and "is a built-in scene, not a run folder; run it first" in result.stderr


# ------------------------------------------------------------------------------- tension in every export

@pytest.fixture(scope="module")
def mooring(tmp_path_factory) -> Path:
    """buoy_tether for 30 s: a pinned anchor, forces past a kilonewton, the current ramping in."""
    folder = tmp_path_factory.mktemp("export-mooring") / "buoy"
    ropesim.simulate(ropesim.load_scene(SCENARIOS / "buoy_tether.toml", ["integrator.t_end=30"]), folder)
    return folder


@pytest.mark.parametrize("name", ["mooring", "shooter_low", "helicopter_uniform"])
def test_vtk_carries_tension_strain_and_the_supports_forces_as_in_the_npz(runs, mooring, name, tmp_path):
    folder = mooring if name == "mooring" else runs[name]
    traj = ropesim.Trajectory.open(folder)
    stored = np.load(folder / "trajectory.npz")
    pvd = export(traj, "vtk", tmp_path / "vtk").path
    sets = ET.parse(pvd).getroot().find("Collection").findall("DataSet")
    rope = [d for d in sets if d.get("part") == "0"]
    supports = [d for d in sets if d.get("part") == "1"]
    held = stored["support"].shape[1] if "support" in stored.files else 0
    assert len(supports) == (len(rope) if held else 0)
    for i, d in enumerate(rope):
        mesh = meshio.read(pvd.parent / d.get("file"))
        assert np.array_equal(mesh.cell_data["tension"][0], stored["tension"][i])      # [N], bit for bit
        assert np.array_equal(mesh.cell_data["strain"][0], stored["strain"][i])
    dim = traj.x.shape[2]
    for i, d in enumerate(supports):
        points = meshio.read(pvd.parent / d.get("file"))
        assert float(d.get("timestep")) == traj.t[i]
        assert np.array_equal(points.point_data["support_force"][:, :dim], stored["support"][i])
        assert np.array_equal(points.cells_dict["vertex"][:, 0], np.arange(held))
        assert np.allclose(points.point_data["support_force_magnitude"], np.linalg.norm(stored["support"][i], axis=1))


def test_csv_force_tables_match_the_npz_in_kilonewtons(mooring, tmp_path):
    traj = ropesim.Trajectory.open(mooring)
    stored = np.load(mooring / "trajectory.npz")
    out = tmp_path / "buoy.csv"
    export(traj, "csv", out)
    history = tmp_path / "buoy_tension_history.csv"
    header = history.read_text().splitlines()[0].split(",")
    last = stored["tension"].shape[1] - 1
    assert header == ["t [s]", "tension segment 0 [kN]", f"tension segment {last} [kN]",
                      "support node 0 Fx [kN]", "support node 0 Fy [kN]"]      # the float's pull passes 1 kN
    table = np.loadtxt(history, delimiter=",", skiprows=1)
    assert np.array_equal(table[:, 0], stored["t"])
    assert np.allclose(table[:, 1], stored["tension"][:, 0] / 1e3, rtol=1e-15, atol=0)
    assert np.allclose(table[:, 2], stored["tension"][:, -1] / 1e3, rtol=1e-15, atol=0)
    assert np.allclose(table[:, 3:], stored["support"][:, 0, :] / 1e3, rtol=1e-15, atol=0)
    ranges = np.loadtxt(tmp_path / "buoy_tension_range.csv", delimiter=",", skiprows=1)
    tension = stored["tension"]
    assert np.array_equal(ranges[:, 0], np.arange(tension.shape[1]))
    assert np.allclose(ranges[:, 1], (np.arange(tension.shape[1]) + 0.5) * 2.0)       # 2 m segments
    for column, expected in zip(range(2, 6), (tension.min(0), tension.max(0), tension.mean(0), tension.std(0))):
        assert np.allclose(ranges[:, column] * 1e3, expected, rtol=1e-12, atol=1e-9)


def test_a_window_leaves_the_ramp_in_out_of_every_table(mooring, tmp_path):
    traj = ropesim.Trajectory.open(mooring)
    stored = np.load(mooring / "trajectory.npz")
    result = invoke("export", mooring, "--to", "csv", "-o", tmp_path / "late.csv", "--from", "20", "--until", "25")
    assert result.exit_code == 0, result.output
    keep = (stored["t"] >= 20) & (stored["t"] <= 25)
    assert f": {keep.sum()} frames of" in result.stdout
    rows = np.loadtxt(tmp_path / "late.csv", delimiter=",", skiprows=1).reshape(keep.sum(), traj.nodes, -1)
    assert np.array_equal(rows[:, 0, 0], stored["t"][keep]) and np.array_equal(rows[:, :, 2:4], stored["x"][keep])
    ranges = np.loadtxt(tmp_path / "late_tension_range.csv", delimiter=",", skiprows=1)
    assert np.allclose(ranges[:, 2] * 1e3, stored["tension"][keep].min(0), rtol=1e-12)
    assert np.allclose(ranges[:, 5] * 1e3, stored["tension"][keep].std(0), rtol=1e-9, atol=1e-9)
    empty = invoke("export", mooring, "--to", "csv", "--from", "40")
    assert empty.exit_code == 2 and "no saved frame in that window" in empty.stderr


def test_summary_and_plot_take_a_window(mooring, tmp_path):
    import json

    stored = np.load(mooring / "trajectory.npz")
    keep = stored["t"] >= 15
    result = invoke("summary", mooring, "--from", "15", "--json")
    assert result.exit_code == 0, result.output
    figures = json.loads(result.stdout)
    assert figures["from_s"] == 15 and figures["frames"] == keep.sum() and figures["unit"] == "kN"
    tension = stored["tension"][keep]
    assert np.isclose(figures["start"]["min"], tension[:, 0].min()) and np.isclose(figures["end"]["std"],
                                                                                    tension[:, -1].std())
    assert np.allclose(figures["segments"]["mean"], tension.mean(0))
    magnitude = np.linalg.norm(stored["support"][keep][:, 0], axis=1)
    assert np.isclose(figures["supports"][0]["max"], magnitude.max())
    assert figures["max_N"] == tension.max()
    table = invoke("summary", mooring, "--from", "15")
    assert "[kN]" in table.stdout and f"t = 15 .. {stored['t'][-1]:g} s" in table.stdout
    plot = invoke("plot", mooring, "-o", tmp_path / "late.png", "--from", "15", "--to", "25")
    assert plot.exit_code == 0, plot.output
    bad = invoke("plot", mooring, "-o", tmp_path / "none.png", "--from", "25", "--to", "15")
    assert bad.exit_code == 2 and "no saved frame in that window" in bad.stderr
