"""The static solver's Schur complement in NumPy (ropesim/model/static_schur.py) and a free body's own rows at
rest in NumPy (StaticBodies.own_numpy), which an explicit method's static start uses instead of compiling
schur_factor, schur_solve and own_parts (which sdirk2 and galpha compile for their own loops).

Both are the same algebra as the compiled versions, so they are held to them at round-off: the same step of
the static solver's Newton system (the scene's differenced matrix, a free body's own rows and right-hand side)
on a 3-D spar on three chains and on a 2-D clump weight (a free point where three lines meet), to 1e-12 of
the step; the body's own mass matrix and loads to 1e-14 of each column's largest entry at turned and moved
poses. And such a static start compiles none of the kernels it replaces.
"""

from __future__ import annotations


import numpy as np
import pytest

import ropesim
from ropesim.model.banded import factor, solve, woodbury
from ropesim.model.body_groups import StaticBodies
from ropesim.model.build import build
from ropesim.model.jacobian import Jacobian, band_width
from ropesim.model.schur import lever, model_groups, schur_factor, schur_solve
from ropesim.model.static_matrix import DifferencedMatrix
from ropesim.model.static_schur import NumpySchur, levers
from ropesim.model.statics import _steady_time, forces_on_free_nodes
from ropesim.model.terms import accelerations, coupling_reach

from test_specialise import _probe


@pytest.mark.parametrize("dim,dof", [(2, 2), (2, 3), (3, 3), (3, 6)])
def test_levers_are_the_compiled_lever(dim, dof):
    """G_c of a point (the identity) and of a body (translation, then -[rho]x or (-rho_y, rho_x))."""
    arms = np.random.default_rng(dim * dof).normal(size=(3, 5))
    compiled = np.array([[[lever(arms, k, dim, dof, b, col) for col in range(dof)] for b in range(dim)]
                         for k in range(5)])
    assert np.array_equal(levers(arms, dim, dof), compiled)


def _system(name: str):
    """A built-in system's model at its initial shape, its differenced Newton matrix's pieces, its groups (arms
    placed), its bodies (NumPy own rows) and the net force."""
    model = build(ropesim.load_scene(name), solve=False)
    x = model.x0.copy()
    dim, n = x.shape
    w, cyclic = band_width(False, n, coupling_reach(model.scene))
    t = _steady_time(model.scene)
    free = np.ascontiguousarray(~model.held)
    acceleration = model.kernel(accelerations)
    matrix = DifferencedMatrix(model, acceleration, w, cyclic, free, model.mass,
                               np.where(model.held, 0.0, model.drag), t, model.velocity_dependent)
    jac = Jacobian(np.zeros(((w + 1) * dim, n * dim)), np.zeros((w * dim, w * dim)), np.zeros((dim, dim)), w)
    groups = model_groups(model, w, arms=False)
    bodies = StaticBodies(model, groups, t, compiled=False) if model.params.bodies is not None else None
    if bodies is not None:
        bodies.place(x, model.body_pose0)
    force = np.zeros(n * dim)
    forces_on_free_nodes(acceleration, x, np.zeros_like(x), np.zeros_like(x), model.params, t, model.mass, free,
                         force, model.params.junctions)
    if bodies is not None:
        bodies.evaluate(model.body_pose0, force)
    return model, x, w, matrix, jac, groups, bodies, force


@pytest.mark.parametrize("name", ["spread_mooring_free", "clump_weight"])
def test_numpy_schur_solves_as_the_compiled_one(name):
    """The step (every node's and every group's unknowns) of the static solver's Newton system, by the NumPy
    Schur complement and by the compiled one, at a short and a long pseudo-time step."""
    model, x, w, matrix, jac, groups, bodies, force = _system(name)
    dim, n = x.shape
    for tau in (1e-3, 1.0):
        matrix.fill(x, jac, tau)
        if bodies is not None:
            bodies.fill(tau)
        band = jac.band.copy()
        assert schur_factor(band, w, model.params.lines, groups)
        want = force * tau * tau
        schur_solve(band, w, model.params.lines, groups, want)
        want_du = groups.du.copy()
        schur = NumpySchur(groups, dim, model.kernel(factor), model.kernel(solve), jac.corner,
                           woodbury(n * dim, w * dim))
        band = jac.band.copy()
        assert schur.factor(band)
        got = force * tau * tau
        schur.solve(got)
        assert np.abs(got - want).max() <= 1e-12 * np.abs(want).max()
        assert np.abs(groups.du - want_du).max() <= 1e-12 * np.abs(want_du).max()
        assert np.abs(want).max() > 0.0


@pytest.mark.slow
def test_a_bodys_own_rows_at_rest_in_numpy_are_the_compiled_ones():
    """StaticBodies.own_numpy against own_parts (body_own_system at zero twist) for the spar in its current,
    moved and turned well away from its start."""
    model = build(ropesim.load_scene("spread_mooring_free"), solve=False)
    groups = model_groups(model, 1, arms=False)
    compiled, numpy = StaticBodies(model, groups, 1.0, True), StaticBodies(model, groups, 1.0, False)
    rng = np.random.default_rng(7)
    for _ in range(4):
        pose = model.body_pose0.copy()
        pose[:3] += 3.0 * rng.normal(size=pose[:3].shape)
        pose[3:7] += 0.2 * rng.normal(size=pose[3:7].shape)
        pose[3:7] /= np.linalg.norm(pose[3:7], axis=0)
        compiled.own(model.params, pose, compiled.still, compiled.t, compiled.work)
        numpy.own_numpy(pose)
        scale = np.abs(compiled.work).max(axis=(0, 1))
        assert np.all(np.abs(numpy.work - compiled.work) <= 1e-14 * scale)


@pytest.mark.slow
def test_a_free_bodys_explicit_static_start_compiles_no_schur_solver(tmp_path):
    """With an empty cache, spread_mooring_free's rk4 static start compiles none of the compiled Schur solver,
    the body's own rows or its arms' placement; the banded factor and solve are what it compiles instead."""
    code = """
        import ropesim
        from ropesim.model.build import build
        from ropesim.model.jit import template_name
        build(ropesim.load_scene("spread_mooring_free"))
        print(json.dumps(sorted({template_name(n.rsplit(".", 1)[1]) for n in compiled})))
    """
    names = _probe(code, tmp_path / "cache")
    assert "accelerations" in names and "factor" in names and "solve" in names   # the probe saw the compiles
    for kernel in ("schur_factor", "schur_solve", "own_parts", "set_body_arms", "newton_matrix"):
        assert kernel not in names, kernel
