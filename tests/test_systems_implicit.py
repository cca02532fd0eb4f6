"""Systems of lines with the static solver and sdirk2 (each line banded, the free points' unknowns by a Schur
complement, ropesim/model/schur.py), against independent references.

- Statics: a free point hanging from n identical elastic catenaries in closed form (tests/references/
  line_systems.py), the 2-D clump weight on two wires and a 3-D three-line spread, converging to it at second
  order in the segment length as the lumped-mass discretisation must; and the same lumped system solved by
  scipy to round-off.
- Dynamics: sdirk2 on a clump weight converges at second order in dt to a fine reference and agrees with
  verlet; a free point's line ends stay together to the last bit; a system started in its static shape stays
  there.
"""

from __future__ import annotations

import json
import math
import textwrap
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from references.line_systems import catenary_shape, lumped_statics, point_on_catenaries
from ropesim.analysis.statics import equilibrium
from ropesim.integrate.grid import TimeGrid
from ropesim.integrate.methods import make_integrator
from ropesim.model.build import build
from ropesim.model.layout import point_ends
from ropesim.scene.loader import load_scene, scene_from_toml

DATA = Path(__file__).parent / "data" / "systems"
G = 9.81


def hub_scene(dim: int, anchors: list[tuple], hub: tuple, length: float, segments: int, hub_mass: float,
              mass_per_length: float = 0.4, EA: float = 5e6, method: str = "sdirk2", dt: float = 1e-3,
              t_end: float = 1.0, extra: str = "", compression: bool = False) -> str:
    """TOML of a free point ``hub`` on lines to fixed ``anchors``: line i runs from its anchor to the hub when i is
    even, from the hub to its anchor when odd (both ends of a line on the hub's side get exercised)."""
    out = [f'name = "hub"\ndimension = {dim}\n',
           f"[line_types.wire]\ndiameter = 0.01\nmass_per_length = {mass_per_length}\nEA = {EA}\n"
           f"compression = {'true' if compression else 'false'}\n"]
    for i, a in enumerate(anchors):
        out.append(f'[[points]]\nid = "a{i}"\nposition = {list(a)}\n')
    out.append(f'[[points]]\nid = "hub"\nkind = "free"\nposition = {list(hub)}\nmass = {hub_mass}\n')
    for i in range(len(anchors)):
        start, end = (f"a{i}", "hub") if i % 2 == 0 else ("hub", f"a{i}")
        out.append(f'[[lines]]\nid = "l{i}"\ntype = "wire"\nstart = "{start}"\nend = "{end}"\nlength = {length}\n'
                   f"segments = {segments}\n")
    out.append(f"[gravity]\ng = {G}\n[integrator]\nmethod = \"{method}\"\ndt = {dt}\nt_end = {t_end}\n{extra}")
    return "\n".join(out)


def spread(n: int, radius: float) -> list[tuple]:
    """n anchors at height 0, evenly round the vertical (y) axis at ``radius``."""
    return [(radius * math.cos(2 * math.pi * i / n), 0.0, radius * math.sin(2 * math.pi * i / n)) for i in range(n)]


def hub_position(shape) -> np.ndarray:
    return next(p.position for p in shape.points if p.id == "hub")


# ----------------------------------------------------------------------------------------------------- statics


def test_clump_weight_hangs_where_the_elastic_catenaries_put_it():
    """tests/data/systems/clump_weight.toml: the 200 kg clump on two 22.5 m wires (0.4 kg/m, EA 5 MN) from
    anchors 40 m apart. Its depth and the anchors' pull against the continuous elastic catenary: the lumped-mass
    lines approach it at second order in the segment length (10 -> 40 segments: the depth's error falls 16-fold,
    asserted > 10-fold; measured 2.5e-6 and 1.5e-7 of the depth, the pull's 9e-7 and 6e-8). The point stays on
    the symmetry axis; the two supports carry the whole weight."""
    exact = point_on_catenaries(2, 20.0, 22.5, 5e6, 0.4 * G, 200.0 * G)
    base = load_scene(DATA / "clump_weight.toml")
    errors = []
    for segments in (10, 40):
        scene = replace(base, lines=tuple(replace(line, segments=segments) for line in base.lines),
                        gravity=replace(base.gravity, g=G))
        shape = equilibrium(scene)
        assert shape.converged
        x, y = hub_or_clump(shape)
        assert abs(x - 20.0) < 1e-9
        errors.append(abs(-y - exact.depth))
        supports = [p.force for p in shape.points if p.force is not None]
        assert len(supports) == 2
        total = sum(supports)
        assert total[1] == pytest.approx((200.0 + 2 * 0.4 * 22.5) * G, rel=1e-10)   # the whole weight
        assert abs(total[0]) < 1e-8 * total[1]
        assert np.linalg.norm(supports[0]) == pytest.approx(exact.anchor_tension, rel=4e-6 / (segments / 10) ** 2)
        first_segment = next(line.start_tension for line in shape.lines if line.id == "left_wire")
        assert exact.point_tension < first_segment < exact.anchor_tension   # half a segment below the anchor
    assert errors[1] < errors[0] / 10
    assert errors[1] < 5e-7 * exact.depth


def hub_or_clump(shape) -> np.ndarray:
    return next(p.position for p in shape.points if p.kind == "free")


def test_clump_weight_static_shape_is_the_lumped_systems_own_balance():
    """The same lumped system (ropesim's node masses, its springs k = EA / l, tension-only) solved for its balance
    by scipy from the continuum's guess: every node where ropesim puts it, to 1e-9 m (the solvers' tolerances,
    forces balanced to 1e-10 of the largest force: positions to about 1e-10 of the 22 m lines)."""
    scene = load_scene(DATA / "clump_weight.toml")
    shape = equilibrium(scene)
    assert shape.converged
    model = shape.model
    # the lumped system, written out from the scene: one node per line node, the clump's two ends merged into one
    ends = point_ends(scene, model.lines)["clump"]
    keep = [i for i in range(model.nodes) if i not in ends[1:]]
    index = {i: keep.index(i) for i in keep} | {i: keep.index(ends[0]) for i in ends[1:]}
    mass = np.zeros(len(keep))
    for i in range(model.nodes):
        mass[index[i]] += model.mass[i]
    springs = [(index[i], index[i + 1], line.stiffness, line.segment_length, line.slack)
               for line in model.lines for i in range(line.first, line.end - 1)]
    held = np.zeros(len(keep), dtype=bool)
    held[[index[i] for i in model.held_idx]] = True
    exact = point_on_catenaries(2, 20.0, 22.5, 5e6, 0.4 * scene.gravity.g, 200.0 * scene.gravity.g)
    arc = np.linspace(22.5, 0.0, model.lines[0].nodes)          # the left wire, anchor to clump
    across, up = catenary_shape(exact, arc, 5e6, 0.4 * scene.gravity.g)
    left = np.stack([20.0 - across, up - exact.depth], axis=1)
    right = np.stack([40.0 - left[::-1, 0], left[::-1, 1]], axis=1)
    guess = np.concatenate([left, right])[keep]
    expected = lumped_statics(guess, springs, mass, held, scene.gravity.g)
    assert np.abs(shape.x[keep] - expected).max() < 1e-9


def test_three_lines_spread_round_a_free_point_in_3d():
    """A 500 kg point on three 36 m lines (2 kg/m, EA 10 MN) from anchors 120 degrees apart at 30 m from its axis:
    its depth and the anchors' pull against the continuous elastic catenary at second order in the segment
    length (8 -> 32 segments: measured 5.8e-5 -> 3.6e-6 of the depth, the pull 4.9e-6 -> 3.1e-7), the three
    pulls equal by symmetry, the point on the axis."""
    anchors = spread(3, 30.0)
    exact = point_on_catenaries(3, 30.0, 36.0, 1e7, 2.0 * G, 500.0 * G)
    errors = []
    for segments in (8, 32):
        scene = scene_from_toml(hub_scene(3, anchors, (0.0, -15.0, 0.0), 36.0, segments, 500.0, 2.0, 1e7))
        shape = equilibrium(scene)
        assert shape.converged
        position = hub_position(shape)
        assert np.abs(position[[0, 2]]).max() < 1e-9
        errors.append(abs(-position[1] - exact.depth))
        forces = np.array([p.force for p in shape.points if p.force is not None])
        magnitude = np.linalg.norm(forces, axis=1)
        assert np.ptp(magnitude) < 1e-9 * magnitude.max()
        assert forces.sum(axis=0)[1] == pytest.approx((500.0 + 3 * 2.0 * 36.0) * G, rel=1e-10)
        assert magnitude[0] == pytest.approx(exact.anchor_tension, rel=2e-5 / (segments / 8) ** 2)
    assert errors[1] < errors[0] / 10
    assert errors[1] < 1e-5 * exact.depth


def test_equilibrium_prints_points_and_lines(tmp_path):
    """`ropesim equilibrium` on a system: every point (supports with their force, the free point where it
    rests) and every line's tensions, as a table and as JSON; --out, which writes a rope's 'points' start, is
    refused in one line (exit 2)."""
    from typer.testing import CliRunner

    from ropesim.cli.app import app

    runner = CliRunner()
    scene = str(DATA / "clump_weight.toml")
    result = runner.invoke(app, ["equilibrium", scene])
    assert result.exit_code == 0, result.output
    for text in ("point left", "point right", "point clump", "free at (20, -10.3", "line left_wire",
                 "line right_wire", "tension at its start"):
        assert text in result.output
    data = json.loads(runner.invoke(app, ["equilibrium", scene, "--json"]).output)
    assert {p["id"]: p["kind"] for p in data["points"]} == {"left": "fixed", "right": "fixed", "clump": "free"}
    assert [line["id"] for line in data["lines"]] == ["left_wire", "right_wire"]
    left = next(p for p in data["points"] if p["id"] == "left")
    assert left["magnitude_N"] == pytest.approx(data["lines"][0]["start_tension_N"], rel=2e-3)
    refused = runner.invoke(app, ["equilibrium", scene, "--out", str(tmp_path / "x.toml")])
    assert refused.exit_code == 2
    assert "equilibrium" in refused.output and "Traceback" not in refused.output
    assert not (tmp_path / "x.toml").exists()


# ---------------------------------------------------------------------------------------------------- dynamics


def advance(scene, method: str, dt: float, t_end: float, watch=None):
    """Run ``scene`` with ``method`` at ``dt`` to ``t_end``; returns the integrator (and calls ``watch(it)``
    after every step when given)."""
    scene = replace(scene, integrator=replace(scene.integrator, method=method, dt=dt, t_end=t_end))
    model, grid = build(scene), TimeGrid.of(scene)
    it = make_integrator(model, grid)
    for _ in range(grid.steps if watch else 1):
        result = it.advance(1 if watch else grid.steps)
        assert result.status == 0, result
        if watch:
            watch(it)
    return it


def test_sdirk2_on_the_clump_weight_converges_at_second_order():
    """The clump dropping onto its two wires (they bounce it at about 3 Hz and ring axially near 500 Hz), to
    0.5 s. The wires take compression here: a tension-only segment switching on and off is not smooth, and an
    order needs a smooth problem. sdirk2 at dt = 1, 0.5, 0.25 ms against rk4 at 10 us (whose own error, by
    verlet at 10 us, is 1e-7 m, below the finest sdirk2 error of 5e-5 m): fitted order 2 +- 0.1; and at
    0.125 ms sdirk2 agrees with verlet at 10 us within its own error (measured 1.2e-5 m)."""
    base = load_scene(DATA / "clump_weight.toml")
    scene = replace(base, lines=tuple(replace(line, compression=True) for line in base.lines))
    reference = advance(scene, "rk4", 1e-5, 0.5).x
    steps = (1e-3, 5e-4, 2.5e-4)
    errors = [np.abs(advance(scene, "sdirk2", dt, 0.5).x - reference).max() for dt in steps]
    order = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert order == pytest.approx(2.0, abs=0.1), errors
    verlet = advance(scene, "verlet", 1e-5, 0.5).x
    assert np.abs(advance(scene, "sdirk2", 1.25e-4, 0.5).x - verlet).max() < 2.5e-5


# slow: a 3-D sdirk2 loop of a free point with every fluid term that no other quick test compiles (12 s of a cold
# run); sdirk2 on a system stays quick with the clump weight above.
@pytest.mark.slow
def test_three_line_spread_in_water_sdirk2_against_rk4_and_the_point_holds_together():
    """The 3-D three-line spread (lines starting and ending on the point, so both factorisation directions of
    the lines run) under water: buoyancy, Morison drag and added mass on the lines and on the point (its own
    volume, Ca and CdA), the lines taking compression (a smooth problem). Dropped from 1 m above its balance,
    over 1 s: sdirk2 against rk4 at 20 us (whose own error is 1e-6 m) converges at second order (0.8 -> 0.1 ms:
    2.6e-4, 6.9e-5, 1.9e-5, 4.1e-6 m measured); at 0.2 ms asserted within 6e-5 m. The point's three line ends
    move as one throughout, their positions and velocities equal to round-off (they start where the lines'
    layout puts them, equal here, a few ulps apart for some positions, and never drift further)."""
    water = textwrap.dedent("""
        [fluid]
        density = 1025.0
        [buoyancy]
        [fluid_drag]
        cd_normal = 1.2
        cd_tangential = 0.1
        [added_mass]
        ca_normal = 1.0
        ca_tangential = 0.2
        """)
    text = hub_scene(3, spread(3, 30.0), (0.0, -18.85, 0.0), 36.0, 12, 500.0, 2.0, 1e7, extra=water,
                     compression=True)
    text = text.replace("mass = 500.0", "mass = 500.0\nvolume = 0.2\nca = 1.0\ncd_area = 0.3")
    scene = scene_from_toml(text)
    ends = point_ends(scene)["hub"]
    worst = [0.0, 0.0]

    def together(it):
        worst[0] = max(worst[0], np.ptp(it.x[:, ends], axis=1).max())
        worst[1] = max(worst[1], np.ptp(it.v[:, ends], axis=1).max())

    implicit = advance(scene, "sdirk2", 2e-4, 1.0, together)
    assert worst[0] < 1e-14 * 40.0 and worst[1] < 1e-12
    explicit = advance(scene, "rk4", 2e-5, 1.0)
    assert np.abs(implicit.x - explicit.x).max() < 6e-5
    assert np.abs(explicit.x[1, ends[0]] - (-18.85)) > 0.1   # it did move


@pytest.mark.parametrize("method", ["sdirk2", "verlet"])
def test_a_system_started_in_its_static_shape_stays_there(method):
    """initial.shape = "equilibrium" for the clump weight: its runs start in the static balance, so nothing
    moves: over 1 s no node strays 1e-8 m (what the static solve's residual force, 1e-10 of the largest, could
    move it on the wires' stiffness is below 1e-10 m)."""
    text = (DATA / "clump_weight.toml").read_text() + '\n[initial]\nshape = "equilibrium"\n'
    scene = scene_from_toml(text)
    it = advance(scene, method, 1e-3 if method == "sdirk2" else 1e-4, 1.0)
    assert np.abs(it.x - it.model.x0).max() < 1e-8
    clump = point_ends(scene)["clump"][0]
    assert it.model.x0[1, clump] == pytest.approx(-10.3272, abs=1e-4)
