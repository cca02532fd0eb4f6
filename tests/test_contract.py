"""The integrator contract (ropesim/integrate/base.py): every method's family keeps it.

- Exact restart (REBOUND's test): run to T, save the complete state, restore it into a fresh integrator and run
  to 2T; the result equals one straight run to 2T bit for bit, frames and ledger included. A family that
  forgets part of its state (carried forces, the plain stage's per-node work, Newton statistics) fails here.
- The METHODS table, the schema's choices and each method's family agree; run.py never names a family.
"""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

import ropesim
from ropesim.integrate.base import Integrator, Method
from ropesim.integrate.grid import TimeGrid
from ropesim.integrate.methods import METHODS, make_integrator
from ropesim.model.build import build
from ropesim.scene.schema import Integrator as IntegratorTable

ROOT = Path(__file__).resolve().parent.parent

SCENES = {   # scene, --set: a towed rope (plain stage), a driven 3-D rope with an end mass, the shooter (general)
    "helicopter_mass": ("helicopter_mass.toml", ["integrator.t_end=0.4", "output.interval=0.02"]),
    "helicopter_3d": ("helicopter_mass.toml", ["dimension=3", "initial.top=[0.0, 0.0, 0.0]",
                                               "initial.velocity=[8.0, 0.0, 1.0]", "driven.0.velocity=[8.0, 0.0, 1.0]",
                                               "integrator.t_end=0.4", "output.interval=0.02"]),
    "shooter_medium": ("shooter_medium.toml", ["integrator.t_end=0.4", "output.interval=0.02"]),
}


def _scene(scenarios, name, method):
    file, sets = SCENES[name]
    return ropesim.load_scene(scenarios / file, [*sets, f"integrator.method={method}"])


def _run(integrator, n):
    frames = integrator.new_frames(n)
    result = integrator.advance(n, frames)
    return result, frames


# galpha's loop for the shooter's terms is compiled by no other quick test (10 s of CPU, scripts/suite_profile.py):
# that pair restarts in the slow suite, galpha on the two helicopter scenes in both.
@pytest.mark.parametrize("name, method", [
    pytest.param(n, m, marks=pytest.mark.slow) if (n, m) == ("shooter_medium", "galpha") else (n, m)
    for n in SCENES for m in METHODS], ids=lambda v: v)
def test_exact_restart_from_a_saved_state(scenarios, name, method):
    scene = _scene(scenarios, name, method)
    model, grid = build(scene), TimeGrid.of(scene)
    half = grid.steps // 2 + 7          # not on a frame, nor on the blow-up check's cadence
    straight = make_integrator(model, grid)
    _, first = _run(straight, half)
    result, second = _run(straight, grid.steps - half)

    before = make_integrator(model, grid)
    _run(before, half)
    saved = before.state()
    again = make_integrator(model, grid)
    again.restore(saved)
    assert again.step == half
    resumed, frames = _run(again, grid.steps - half)

    assert resumed == result
    for a, b in zip(frames, second):
        assert np.array_equal(a, b)
    for key, value in straight.state().items():
        assert np.array_equal(value, again.state()[key]), key
    assert again.force_evaluations == straight.force_evaluations


def test_restore_refuses_a_state_of_another_shape(scenarios):
    scene = _scene(scenarios, "helicopter_mass", "verlet")
    other = ropesim.load_scene(scenarios / "helicopter_mass.toml", ["rope.nodes=11"])
    a = make_integrator(build(scene), TimeGrid.of(scene))
    b = make_integrator(build(other), TimeGrid.of(other))
    with pytest.raises(ValueError, match="saved state 'x' has shape"):
        a.restore(b.state())


def test_the_state_is_a_copy(scenarios):
    scene = _scene(scenarios, "shooter_medium", "pefrl")
    it = make_integrator(build(scene), TimeGrid.of(scene))
    saved = it.state()
    it.advance(10)
    assert not np.array_equal(saved["x"], it.x) and saved["step"] == 0


def test_methods_table_schema_and_families_agree():
    choices = IntegratorTable.__dataclass_fields__["method"].metadata["spec"].choices
    assert tuple(METHODS) == tuple(choices)
    for name, method in METHODS.items():
        assert isinstance(method, Method) and method.name == name
        assert issubclass(method.family, Integrator) and method.family is not Integrator
        assert method.order >= 1 and method.doc and method.evaluations >= 1


def test_run_module_knows_the_contract_not_the_families():
    tree = ast.parse((ROOT / "ropesim" / "run.py").read_text())
    imported = {node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) and node.module}
    families = {"integrate.splitting", "integrate.rk", "integrate.sdirk", "integrate.plain"}
    assert not imported & families
    assert "kind" not in {node.attr for node in ast.walk(tree) if isinstance(node, ast.Attribute)}
