"""The splitting loop's plain stage (ropesim.integrate.plain) against the general stage it stands in for.

Both step the same physics with the same floating-point operations per node, so trajectories must agree bit
for bit. Their energy ledgers book the same exact integrals summed in different orders (per kick over the
nodes, or per node over time with the kinetic part telescoped), so they agree to round-off: a relative
1e-9 of the energy that flowed is many orders above the ~1e-13 that thousands of float64 sums lose.
"""

import numpy as np
import pytest

import ropesim
from ropesim.integrate import plain
from ropesim.integrate.grid import TimeGrid
from ropesim.integrate.health import DRAG, HELD
from ropesim.integrate.methods import METHODS, make_integrator
from ropesim.integrate.splitting import Splitting
from ropesim.model.build import build

SPLITTING = [name for name, m in METHODS.items() if m.kind == "splitting"]

LOOP = """
name = "closed loop"
dimension = 2
[rope]
nodes = 24
mass = 0.01
segment_length = 0.05
stiffness = 400.0
closed = true
[initial]
shape = "square_loop"
top_center = [0.0, 0.0]
velocity = [0.5, 0.0]
[gravity]
g = 9.81
[drag]
b = 0.02
[[overrides]]
index = 5
mass = 0.03
[[overrides]]
index = 11
drag = 0.2
[[driven]]
nodes = [0]
velocity = [0.5, 0.0]
[integrator]
dt = 0.0005
t_end = 2.0
[output]
interval = 0.05
"""


def _both(scene, method, steps=None):
    """(plain, general) integrators after running ``steps`` (default all) steps, with their frames."""
    grid = TimeGrid.of(scene)
    model = build(scene)
    out = []
    for specialise in (True, False):
        stepper = Splitting(model, grid, METHODS[method], specialise=specialise)
        frames = stepper.new_frames(steps or grid.steps)
        result = stepper.advance(steps or grid.steps, frames)
        out.append((stepper, frames, result))
    return out


def _scene(tmp_path, text, sets=()):
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return ropesim.load_scene(path, list(sets))


def _assert_same(fast, general):
    (a, fa, ra), (b, fb, rb) = fast, general
    assert a.on_plain_stage and not b.on_plain_stage
    assert ra == rb
    assert np.array_equal(a.x, b.x) and np.array_equal(a.v, b.v)
    for i in range(3):   # saved times, positions, velocities
        assert np.array_equal(fa[i], fb[i])
    flows = abs(b.ledger[HELD]) + b.ledger[DRAG]
    np.testing.assert_allclose(fa[3], fb[3], rtol=0, atol=1e-9 * flows)
    np.testing.assert_allclose(a.ledger, b.ledger, rtol=0, atol=1e-9 * flows)


@pytest.mark.parametrize("method", SPLITTING)
@pytest.mark.parametrize("name", ["helicopter_uniform", "helicopter_mass", "helicopter_parachute"])
def test_towed_ropes_match_the_general_loop(scenarios, name, method):
    """The end mass and the parachute are nodes with their own mass or drag: exceptions to the bulk."""
    scene = ropesim.load_scene(scenarios / f"{name}.toml", [f"integrator.method={method}", "integrator.t_end=1.5"])
    _assert_same(*_both(scene, method))


@pytest.mark.parametrize("method", SPLITTING)
def test_a_closed_loop_with_overrides_matches_the_general_loop(tmp_path, method):
    _assert_same(*_both(_scene(tmp_path, LOOP, [f"integrator.method={method}"]), method))


def test_in_a_vacuum_drag_books_exactly_nothing(tmp_path):
    text = LOOP.replace("[drag]\nb = 0.02\n", "").replace("drag = 0.2", "mass = 0.02")
    (fast, frames, _), general = _both(_scene(tmp_path, text), "verlet")
    assert not fast.plain.has_drag
    assert fast.ledger[DRAG] == 0.0 and np.all(frames[3][:, DRAG] == 0.0)
    _assert_same((fast, frames, _), general)


def test_the_ledger_is_identical_however_the_run_is_chunked(scenarios):
    scene = ropesim.load_scene(scenarios / "helicopter_mass.toml", ["integrator.method=pefrl"])
    model, grid = build(scene), TimeGrid.of(scene)
    whole = make_integrator(model, grid, "pefrl")
    whole.advance(700)
    pieces = make_integrator(model, grid, "pefrl")
    for n in (1, 63, 64, 72, 500):   # pieces ending on, before and after the blow-up checks' cadence
        pieces.advance(n)
    assert whole.on_plain_stage
    assert np.array_equal(whole.ledger, pieces.ledger) and np.array_equal(whole.x, pieces.x)


def test_the_bulk_is_the_commonest_free_node_and_the_rest_are_exceptions(scenarios):
    scene = ropesim.load_scene(scenarios / "helicopter_mass.toml")
    stepper = make_integrator(build(scene), TimeGrid.of(scene), "verlet")
    model, state = stepper.model, stepper.plain
    last = model.nodes - 1
    assert state.exceptions.tolist() == [last]   # the heavy end mass; the held node 0 is not an exception
    assert state.bulk[0] == 1.0 / model.mass[1] != 1.0 / model.mass[last]


@pytest.mark.parametrize("name, extra, sets, fast", [
    ("helicopter_uniform", "", [], True),
    ("helicopter_mass", "", ["integrator.method=pefrl"], True),
    ("shooter_low", "", [], False),                                      # a thrower and guide circles
    ("helicopter_uniform", "\n[bending]\nstiffness = 10.0\n", [], False),   # bending springs
    ("helicopter_uniform", "\n[thrower]\ncenter = [0.0, -50.0]\nlength = 1.0\nwidth = 1.0\nv_max = 1.0\n"
                           "b_thrower = 1.0\n", [], False),                  # a thrower, even far away
])
def test_only_a_plain_spring_rope_takes_the_plain_stage(scenarios, tmp_path, name, extra, sets, fast):
    scene = _scene(tmp_path, (scenarios / f"{name}.toml").read_text() + extra, sets)
    assert plain.applies(build(scene), METHODS[scene.integrator.method]) == fast
    assert make_integrator(build(scene), TimeGrid.of(scene)).on_plain_stage == fast


def test_a_blow_up_on_the_plain_stage_is_caught_and_named(scenarios):
    """Far past the stable step: stopped early, at the same step and with the same verdict as the general loop."""
    scene = ropesim.load_scene(scenarios / "helicopter_uniform.toml", ["integrator.dt=0.04", "integrator.t_end=100"])
    (fast, _, (done_a, _, status_a, node_a)), (general, _, (done_b, _, status_b, node_b)) = _both(scene, "verlet")
    assert status_a != 0 and (done_a, status_a, node_a) == (done_b, status_b, node_b)
    assert done_a < TimeGrid.of(scene).steps / 10


@pytest.mark.parametrize("closed", [False, True])
def test_the_plain_check_measures_what_the_general_one_does(tmp_path, closed):
    """Energy to round-off, and the same worst spring, as ropesim.model.terms.mechanical_energy; NaN stays NaN."""
    from ropesim.model.terms import mechanical_energy

    text = LOOP if closed else LOOP.replace("closed = true", "closed = false").replace(
        'shape = "square_loop"\ntop_center = [0.0, 0.0]', 'shape = "line"\nstart = [0.0, 0.0]\nend = [1.1, -0.3]')
    model = build(_scene(tmp_path, text))
    rng = np.random.default_rng(7)
    x = model.x0 + rng.normal(scale=0.01, size=model.x0.shape)
    v = rng.normal(size=model.x0.shape)
    lengths, terms = np.zeros(model.nodes), np.zeros(model.nodes)
    spring, g = model.params.spring, model.params.gravity[0]
    fast = plain.chain_energy(x, v, model.mass, spring[0, 0], spring[0, 1], closed, g, lengths, terms)
    general = model.kernel(mechanical_energy)(x, v, model.mass, model.params)
    assert fast[0] == pytest.approx(general[0], rel=1e-12)
    assert fast[1:] == general[1:]
    x[1, 3] = np.nan
    assert not np.isfinite(plain.chain_energy(x, v, model.mass, spring[0, 0], spring[0, 1], closed, g, lengths, terms)[0])
