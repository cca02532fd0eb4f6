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
    assert result.stdout.startswith(f"{path}: {traj.frames} frames of {traj.nodes} nodes, 1 file, ")
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
    assert result.stdout.startswith(f"{pvd}: {traj.frames} frames of {traj.nodes} nodes, {traj.frames + 1} files")
    sets = ET.parse(pvd).getroot().find("Collection").findall("DataSet")
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
    out.mkdir()
    (out / "stale.vtu").write_text("old")
    export(traj, "vtk", out)
    assert not (out / "stale.vtu").exists() and len(list(out.iterdir())) == traj.frames + 1
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
