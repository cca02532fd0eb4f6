"""The command line fits a shell and a script: completion, commands grouped in help panels, `--to` as a fixed
choice, and `--json` on `check` and `equilibrium` (each a test that failed before issue 24)."""

from __future__ import annotations

import json

import numpy as np
import typer
from typer.testing import CliRunner

from ropesim.cli.app import PICTURES, RUNNING, SCENES, STUDIES, _formats, app
from ropesim.integrate.methods import METHODS

runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args], env={"COLUMNS": "120"})


def test_shell_completion_is_offered():
    result = invoke("--help")
    assert "--install-completion" in result.stdout and "--show-completion" in result.stdout


def test_every_command_sits_in_one_help_panel():
    group = typer.main.get_command(app)
    ctx = typer.Context(group, info_name="ropesim")
    panels = {name: group.get_command(ctx, name).rich_help_panel for name in group.list_commands(ctx)}
    assert set(panels.values()) == {RUNNING, SCENES, STUDIES, PICTURES}, panels
    assert len(panels) == 16      # view (issue 25) joined the pictures panel, import (issue 21) the scenes panel
    text = invoke("--help").stdout
    assert all(panel in text for panel in (RUNNING, SCENES, STUDIES, PICTURES))
    assert text.index(f"─ {RUNNING} ") < text.index("│ run ") < text.index(f"─ {PICTURES} ") < text.index("│ export ")


def test_export_to_is_a_fixed_choice_in_help_and_completion():
    assert "[vtk|csv]" in invoke("export", "--help").stdout
    assert _formats("") == ["vtk", "csv"] and _formats("v") == ["vtk"] and _formats("x") == []


def test_check_json_is_one_object_with_the_bounds():
    result = invoke("check", "helicopter_mass", "--json")
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert data["scene"] == "helicopter_mass" and data["valid"] and data["nodes"] == 21
    assert set(data["stable_dt_s"]) == set(METHODS)
    assert data["stable_dt_s"]["sdirk2"] is None and 0 < data["stable_dt_s"]["verlet"] < 1
    assert data["output"]["frames"] == data["frames"] and isinstance(data["output"]["kernel_cached"], bool)
    assert "springs" in data["force_terms"]


def test_check_says_that_with_a_tolerance_dt_is_the_reporting_grid():
    """galpha with integrator.tolerance chooses its own steps: `ropesim check` calls dt the grid x and v are
    reported on, in its table and in its JSON ("dt_is")."""
    sets = ("--set", "integrator.method=galpha", "--set", "integrator.tolerance=1e-3")
    table = invoke("check", "helicopter_mass", *sets)
    assert table.exit_code == 0, table.output
    text = " ".join(table.output.split())
    assert "adaptive steps to a tolerance of 0.001 m; dt = 0.001 s is the reporting grid" in text, text
    data = json.loads(invoke("check", "helicopter_mass", "--json", *sets).stdout)
    assert data["dt_is"] == "grid"
    assert json.loads(invoke("check", "helicopter_mass", "--json").stdout)["dt_is"] == "step"


def test_equilibrium_json_has_the_supports_and_tensions(tmp_path):
    result = invoke("equilibrium", "mooring_chain", "--json", "-o", tmp_path / "static.toml")
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)                     # stdout is the JSON alone; the note goes to stderr
    assert data["converged"] and data["residual_N"] <= 1e-10 * data["force_scale_N"]
    anchor, fairlead = data["supports"]
    assert anchor["kind"] == "pinned" and fairlead["kind"] == "driven"
    assert np.isclose(fairlead["magnitude_N"], np.hypot(*fairlead["force_N"]))
    assert len(data["tension_N"]) == 82 and len(data["positions_m"]) == 83
    assert data["seabed"]["touchdown_node"] is not None
    assert (tmp_path / "static.toml").exists() and "written:" in result.stderr
