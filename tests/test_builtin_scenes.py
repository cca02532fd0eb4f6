"""Built-in scenes travel with the package: found by name from any folder, listed by `ropesim scenarios`, copied
to edit by `ropesim new`; the top-level scenarios/ path (the README's first command) still works."""

from __future__ import annotations

import tomllib
from dataclasses import replace
from pathlib import Path

import pytest
from typer.testing import CliRunner

from ropesim.cli.app import app
from ropesim.scene.builtin import builtin_folder, builtin_names, resolve
from ropesim.scene.loader import SceneError, load_scene

from conftest import ROOT

runner = CliRunner()
SHORT = "integrator.t_end=0.05"


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args], env={"COLUMNS": "200"})


def one_line_error(result) -> str:
    assert result.exit_code == 2, result.output
    assert result.stdout == "" and "Traceback" not in result.stderr
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    return lines[0]


def test_the_scenes_live_in_the_package_and_scenarios_points_there():
    assert builtin_folder() == ROOT / "ropesim" / "scenarios"
    seed = {"helicopter_uniform", "helicopter_mass", "helicopter_parachute", "shooter_vacuum", "shooter_low",
            "shooter_low_one_sided", "shooter_medium", "shooter_high"}   # the write-up's scenes, and more since
    assert seed < set(builtin_names())
    assert (ROOT / "scenarios").resolve() == builtin_folder().resolve()
    assert (ROOT / "scenarios" / "helicopter_mass.toml").is_file()


def test_scenarios_lists_every_built_in_on_one_line_with_its_description():
    result = invoke("scenarios")
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert [line.split()[0] for line in lines] == builtin_names()
    for line, name in zip(lines, builtin_names()):
        description = tomllib.loads((builtin_folder() / f"{name}.toml").read_text())["description"]
        assert line.endswith(description), line


def test_a_name_runs_the_built_in_from_any_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = invoke("run", "helicopter_mass", "--set", SHORT, "-q")
    assert result.exit_code == 0, result.output
    assert (tmp_path / "runs" / "helicopter_mass" / "trajectory.npz").is_file()
    assert invoke("check", "shooter_low.toml").exit_code == 0   # the name with its extension works too


def test_an_existing_file_wins_over_a_built_in_name(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    text = (builtin_folder() / "helicopter_mass.toml").read_text().replace('name = "helicopter_mass"',
                                                                           'name = "mine"')
    Path("helicopter_mass.toml").write_text(text)
    assert resolve("helicopter_mass.toml").path == Path("helicopter_mass.toml")
    result = invoke("check", "helicopter_mass.toml")
    assert result.exit_code == 0 and "valid scene 'mine'" in result.stdout
    assert resolve("helicopter_mass").builtin   # the bare name is no file here: the built-in


LISTED = "built-in scenes: " + ", ".join(builtin_names())   # every one, in order


@pytest.mark.parametrize("arg,hint", [("helicopter_mas", "did you mean helicopter_mass?"),
                                      ("shooter_lwo.toml", "did you mean shooter_low?"),
                                      ("nowhere/helicopter_mass.toml", LISTED),
                                      ("zzz", LISTED)])
def test_an_unknown_scene_is_one_line_listing_the_built_ins(arg, hint):
    line = one_line_error(invoke("run", arg))
    assert line.startswith(f"ropesim: {arg}: no such scene file or built-in scene"), line
    assert hint in line and "shooter_vacuum" in line
    if arg == "zzz":
        assert "did you mean" not in line


def test_a_bad_built_in_run_names_the_built_in_and_the_key():
    line = one_line_error(invoke("run", "shooter_low", "--set", "rope.mass=0"))
    assert line.startswith("ropesim: built-in scene shooter_low (with --set rope.mass=0): rope.mass: must be"), line


@pytest.mark.parametrize("source", builtin_names())
def test_new_writes_an_annotated_copy_that_loads_as_the_same_scene(tmp_path, monkeypatch, source):
    monkeypatch.chdir(tmp_path)
    result = invoke("new", "my_scene", "--from", source)
    assert result.exit_code == 0, result.output
    written = tmp_path / "my_scene.toml"
    assert result.stdout.startswith("my_scene.toml: a copy of built-in scene")
    assert replace(load_scene(written), name=source) == load_scene(builtin_folder() / f"{source}.toml")
    assert load_scene(written).name == "my_scene"
    text = written.read_text()
    assert text.startswith(f"# my_scene: a scene to edit, copied from built-in scene {source} by `ropesim new`")
    original = (builtin_folder() / f"{source}.toml").read_text()
    for line in original.splitlines():   # every comment of the original is kept
        if line.lstrip().startswith("#"):
            assert line in text, line
    if load_scene(written).is_system:   # a line type's keys, a rigid body's (not a rope's point body's)
        assert "# axial stiffness EA [N]\nEA = " in text
        if "[[bodies]]" in original:
            assert "# the body's name, which points name to sit on it\nid = " in text
            assert "its added-mass coefficient" not in text   # a point body's ca, no rigid body's key
        assert "# initial shape; one of lines, equilibrium" in text or "[initial]" not in original
    elif load_scene(written).rope.physical:   # meaning and unit above each key
        assert "# axial stiffness EA (physical form) [N]\nEA = " in text
    else:
        assert "# spring constant k between neighbours [N/m]\nstiffness = 5000.0" in text
    assert "# integration method; one of symplectic_euler, verlet," in text
    if source.startswith("helicopter") and not load_scene(written).is_system:   # the optional keys left out, at their defaults, commented out
        assert "# closed = false   # true for a closed loop" in text


def test_new_refuses_to_overwrite_or_a_bad_name(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert invoke("new", "a").exit_code == 0
    assert "helicopter_mass" in Path("a.toml").read_text()   # the default source
    line = one_line_error(invoke("new", "a", "--from", "shooter_low"))
    assert line == "ropesim: NAME a.toml: exists; add --force to replace it, or choose another name"
    assert invoke("new", "a", "--from", "shooter_low", "--force").exit_code == 0
    assert load_scene("a.toml").thrower is not None
    assert "NAME my scene: use letters" in one_line_error(invoke("new", "my scene"))
    assert "did you mean shooter_low?" in one_line_error(invoke("new", "b", "--from", "shooter_lo"))
    assert not Path("b.toml").exists()
    Path("sub").mkdir()
    assert invoke("new", "sub/c.toml", "--from", "a.toml").exit_code == 0 and load_scene("sub/c.toml").name == "c"
    copy = Path("sub/c.toml").read_text()
    assert copy.startswith("# c: a scene to edit, copied from a.toml by")
    first = Path("a.toml").read_text().splitlines()[5:]   # a copy of a copy: a new header, nothing else added
    assert copy.splitlines()[5:] == [line.replace('name = "a"', 'name = "c"') for line in first]


def test_resolve_raises_a_scene_error():
    with pytest.raises(SceneError, match="no such scene file or built-in scene"):
        resolve("no_such_scene")
