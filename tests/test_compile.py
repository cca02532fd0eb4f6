"""`ropesim compile`: every kernel into Numba's cache ahead of time, after which no run compiles anything.

Whether a run compiled is observed, not inferred from its timing: Numba broadcasts a ``numba:compile`` event
whenever a function compiles (a cache miss) and none when it loads one from its cache, and the probe below
counts them while it runs every built-in scene, every method on helicopter_mass and on a mooring line of the
user's that starts in its static shape (named to `ropesim compile`, since a scene compiles only its own parts),
and the static solver of `ropesim equilibrium` on each, through the command line.

Two tests share the work. On the test run's own cache (one per run, tests/conftest.py), which the other tests
have partly filled, `ropesim compile` prepares every built-in scene and the mooring line and the probe finds
nothing left to compile (the slow suite: it compiles what no other test needs). On an empty cache, for
helicopter_mass alone, it compiles each family's loop once: the symplectic family's other methods share it.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from typer.testing import CliRunner

from ropesim.cli.app import app
from ropesim.integrate.methods import METHODS
from ropesim.scene.builtin import builtin_names

ROOT = Path(__file__).resolve().parent.parent

# A scene no built-in one is yet: a line that starts in its static shape (the static solver before the run) on a
# seabed, in water, its fairlead driven on a sinusoid.
MOORING = """
name = "mooring"
[rope]
length = 30.0
segments = 12
mass_per_length = 50.0
diameter = 0.1
EA = 1.0e6
[initial]
shape = "equilibrium"
start = [0.0, 0.0]
end = [24.0, 12.0]
[pinned]
nodes = [0]
[[driven]]
nodes = [-1]
amplitude = [2.0, 1.0]
period = [8.0, 8.0]
[gravity]
g = 9.81
[fluid]
density = 1025.0
[buoyancy]
[seabed]
height = 0.0
friction = 0.5
[integrator]
method = "sdirk2"
dt = 0.0005
t_end = 1.0
"""

PROBE = textwrap.dedent("""
    import json, sys, tempfile
    from numba.core import event

    compiled = []

    class Listener(event.Listener):
        def on_start(self, ev):
            f = ev.data["dispatcher"].py_func
            compiled.append(f"{f.__module__}.{f.__qualname__}")

        def on_end(self, ev):
            pass

    event.register("numba:compile", Listener())
    from typer.testing import CliRunner
    from ropesim.cli.app import app
    from ropesim.integrate.methods import METHODS

    mooring, scenes = sys.argv[1], sys.argv[2:]   # mooring: "" for none
    cases = [(name, []) for name in scenes]
    cases += [("helicopter_mass", [f"integrator.method={m}"]) for m in METHODS]
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        cases += [(mooring, [f"integrator.method={m}"]) for m in METHODS if mooring]
        cases += [(name, ["integrator.method=galpha"]) for name in scenes if name == "spread_mooring_free"]
        for name, sets in cases:
            before = len(compiled)
            args = ["run", name, "--out", f"{tmp}/run", "--quiet", "--force", "--set", "integrator.t_end=0.02"]
            for item in sets:
                args += ["--set", item]
            result = CliRunner().invoke(app, args)
            summary = json.load(open(f"{tmp}/run/summary.json"))
            case = " ".join(["mooring" if name == mooring else name, *sets])
            out[case] = [result.exit_code, compiled[before:], summary["compile_time_s"]]
        for name in [*scenes, mooring] if mooring else scenes:
            before = len(compiled)
            result = CliRunner().invoke(app, ["equilibrium", name])
            case = "equilibrium " + ("mooring" if name == mooring else name)
            solved = result.exception is None or isinstance(result.exception, SystemExit)   # exit 1: no static shape
            out[case] = [0 if solved else repr(result.exception), compiled[before:], 0.0]
    print(json.dumps(out))
""")


def _run(args: list[str], cache: str | None) -> subprocess.CompletedProcess:
    """``python ARGS`` with Numba's cache at ``cache`` (None: the test run's cache, which the environment names)."""
    env = {**os.environ, "NUMBA_CACHE_DIR": cache} if cache else dict(os.environ)
    assert env.get("NUMBA_CACHE_DIR")   # set by ropesim's import in this process, or by tests/conftest.py
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, cwd=ROOT, timeout=900, env=env)


def _compile_then_probe(cache: str | None, folder: Path, scenes: list[str], mooring: bool) -> tuple[str, dict]:
    """`ropesim compile SCENES` (every built-in scene if none; its table), then, with ``mooring``, `ropesim compile`
    of the mooring scene written in ``folder``, then the probe's runs of them all."""
    path = folder / "mooring.toml"
    path.write_text(MOORING)
    done = _run(["-m", "ropesim", "compile", *scenes], cache)
    assert done.returncode == 0 and done.stderr == "", done.stderr
    if mooring:
        own = _run(["-m", "ropesim", "compile", str(path), "--quiet"], cache)
        assert own.returncode == 0 and own.stdout == own.stderr == "", own.stderr
    probe = _run(["-c", PROBE, str(path) if mooring else "", *(scenes or builtin_names())], cache)
    assert probe.returncode == 0, probe.stderr
    return done.stdout, json.loads(probe.stdout)


def _check_nothing_compiles(runs: dict, scenes: list[str], mooring: bool) -> None:
    # the runs of the scenes, helicopter_mass and the mooring line with every method, galpha on the free spar (a
    # free rigid body), then the static solves
    free = "spread_mooring_free" in scenes
    assert len(runs) == len(scenes) + (1 + mooring) * len(METHODS) + free + len(scenes) + mooring
    for case, (code, compiled, compile_time) in runs.items():
        assert code == 0, case
        assert compiled == [], f"{case} compiled {compiled}"
        # What the summary calls "compile or cache load": loading a kernel from the cache takes 0.03 to 0.3 s here
        # (the first load imports Numba's type registry), compiling one 8 s or more, so 1 s tells them apart
        # with room for a loaded machine.
        assert compile_time < 1.0, case


def _rows(table: str) -> dict[str, str]:
    """The table's rows by their first word (a method's name, "static" for the static solver)."""
    for name in [*METHODS, "static solver"]:
        assert any(line.split()[:1] == [name.split()[0]] for line in table.splitlines()), (name, table)
    return {line.split()[0]: line for line in table.splitlines() if line.split()[:1]}


@pytest.mark.slow
def test_ropesim_compile_prepares_every_built_in_scene_so_that_no_run_compiles(tmp_path):
    """Every built-in scene, and a user's mooring line named to `ropesim compile`, on the test run's cache: what
    the other tests compiled is loaded, the rest compiled, and then nothing compiles."""
    table, runs = _compile_then_probe(None, tmp_path, [], mooring=True)
    _rows(table)
    assert f"made ready for {len(builtin_names())} built-in scenes:" in " ".join(table.split())
    _check_nothing_compiles(runs, builtin_names(), mooring=True)


@pytest.mark.slow
def test_ropesim_compile_from_an_empty_cache_compiles_each_family_once(tmp_path):
    """helicopter_mass from an empty cache: one loop per family, shared by the family's methods, after which none
    of its runs (every method) nor its static solve compiles."""
    table, runs = _compile_then_probe(str(tmp_path / "cache"), tmp_path, ["helicopter_mass"], mooring=False)
    lines = _rows(table)
    for name in ("symplectic_euler", "rk4", "sdirk2", "galpha", "static"):
        assert "compiled" in lines[name], table
    for name in ("verlet", "yoshida4", "pefrl"):
        assert "shares the loop of symplectic_euler" in lines[name], table
    assert "made ready for 1 scene:" in " ".join(table.split())
    _check_nothing_compiles(runs, ["helicopter_mass"], mooring=False)


@pytest.mark.parametrize("args, message", [
    (["--method", "nope"], "ropesim: --method nope: unknown integrator nope; allowed " + ", ".join(METHODS)),
    (["--method", "rk4,nope"], "ropesim: --method rk4,nope: unknown integrator nope; allowed "
                               + ", ".join(METHODS)),
    (["--method", ","], "ropesim: --method ,: unknown integrator (none); allowed " + ", ".join(METHODS)),
])
def test_compile_refuses_an_unknown_method_in_one_line(args, message):
    result = CliRunner().invoke(app, ["compile", *args])
    assert result.exit_code == 2
    assert result.output.splitlines() == [message]


def test_compile_restricted_to_methods_prints_their_rows_only():
    result = CliRunner().invoke(app, ["compile", "helicopter_mass", "--method", "verlet", "--method", "rk4,verlet"])
    assert result.exit_code == 0, result.output
    rows = [line.split()[0] for line in result.output.splitlines()
            if line.split()[:1] and line.split()[0] in [*METHODS, "static"]]
    assert rows == ["verlet", "rk4"]
    assert "made ready for 1 scene:" in " ".join(result.output.split())
    quiet = CliRunner().invoke(app, ["compile", "helicopter_mass", "--method", "rk4", "--quiet"])
    assert quiet.exit_code == 0 and quiet.output == ""
