"""The static solver's Newton matrix by coloured finite differences (ropesim/model/static_matrix.py), which an
explicit method's static start uses instead of compiling the analytic one (ropesim/model/terms.py's
newton_matrix, which sdirk2 and galpha compile for their own loops).

Checked against the analytic matrix where that is the exact derivative (every spring taut, so no compressive
geometric stiffness is left out; no flow, so no drag tangent stiffness): the two agree to the differences'
error, about sqrt(eps) |x| / l of a segment's stiffness (here 1e-7 of the matrix's largest entry, held to
1e-6). The static shapes either matrix leads to agree to the solver's tolerance, in about as many iterations,
on a mooring line on a seabed and on a line blown over by a current (the matrix's non-symmetric part, solved by
the Krylov step). And an explicit static start compiles none of the analytic matrix's kernels.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import tomli_w

import ropesim
from ropesim.model.build import build
from ropesim.model.jacobian import Jacobian, band_width
from ropesim.model.static_matrix import DifferencedMatrix, colours
from ropesim.model.statics import Equilibrium, _steady_time, solve_equilibrium
from ropesim.model.terms import accelerations, coupling_reach, newton_matrix

from test_specialise import _probe


def scene_of(raw: dict, method: str = "rk4") -> ropesim.Scene:
    raw = {**raw, "integrator": {"method": method, "dt": 0.001, "t_end": 0.1}}
    return ropesim.scene_from_toml(tomli_w.dumps(raw), source="test", default_name="test")


# A 60 m line of 12 segments on a seabed, in water, from an anchor to a fairlead: every velocity-dependent term
# (drag, axial damping, the seabed's friction) and added mass in the matrix.
MOORING = {
    "rope": {"length": 60.0, "segments": 12, "mass_per_length": 50.0, "diameter": 0.1, "EA": 1.0e7,
             "axial_damping": 1.0e5},
    "initial": {"shape": "equilibrium", "start": [0.0, -20.0], "end": [50.0, 0.0]},
    "pinned": {"nodes": [0, -1]}, "gravity": {"g": 9.81}, "fluid": {"density": 1025.0}, "buoyancy": {},
    "fluid_drag": {"cd_normal": 1.2, "cd_tangential": 0.3}, "added_mass": {"ca_normal": 1.0},
    "seabed": {"height": -20.0, "friction": 0.5},
}
# A 3-D line with second-neighbour (bending) springs: a band two nodes wide.
BENT = {
    "dimension": 3,
    "rope": {"nodes": 11, "segment_length": 0.5, "stiffness": 4.0e4, "mass": 0.3},
    "initial": {"shape": "line", "start": [0.0, 0.0, 0.0], "end": [5.0, -1.0, 0.5]},
    "pinned": {"nodes": [0]}, "gravity": {"g": 9.81}, "bending": {"stiffness": 300.0},
}
# A closed loop of 17 nodes (not a multiple of the three colours) with one node pinned: the wrap-around corner.
LOOP = {
    "rope": {"nodes": 17, "segment_length": 0.4, "stiffness": 800.0, "mass": 0.2, "closed": True},
    "initial": {"shape": "points", "points": [[1.2 * float(np.cos(2 * np.pi * i / 17)),
                                               1.2 * float(np.sin(2 * np.pi * i / 17))] for i in range(17)]},
    "pinned": {"nodes": [3]}, "gravity": {"g": 9.81},
}


@pytest.mark.parametrize("n,w,cyclic", [(10, 1, False), (10, 1, True), (11, 2, True), (17, 1, True),
                                        (4, 1, True), (23, 2, False), (7, 3, True)])
def test_no_two_nodes_of_a_colour_share_a_row(n, w, cyclic):
    groups = colours(n, w, cyclic)
    assert sorted(np.concatenate(groups).tolist()) == list(range(n))
    for group in groups:
        for a in group:
            for b in group:
                apart = abs(int(a) - int(b))
                if cyclic:
                    apart = min(apart, n - apart)
                assert a == b or apart > 2 * w, (group, a, b)
    assert len(groups) <= 2 * w + 1 + (2 * w if cyclic else 0)


def _taut(model, stretch: float = 1.02) -> np.ndarray:
    """The initial shape stretched about its first node (every spring taut) and bent a little (the blocks all
    different)."""
    x = model.x0[:, :1] + stretch * (model.x0 - model.x0[:, :1])
    return x + np.random.default_rng(3).normal(scale=1e-3, size=x.shape)


@pytest.mark.parametrize("raw", [MOORING, BENT, LOOP], ids=["mooring", "bent_3d", "loop"])
@pytest.mark.parametrize("tau", [1e-3, 0.1, 10.0])
def test_the_differenced_matrix_is_the_analytic_one_where_that_is_exact(raw, tau):
    raw = {**raw, "initial": {**raw["initial"], "shape": raw["initial"]["shape"].replace("equilibrium", "line")}}
    model = build(scene_of(raw), solve=False)
    x = _taut(model)
    if raw is MOORING:   # sunk into the seabed at its low end: the contact's stiffness and friction too
        x[1, 1:5] = -20.02
    dim, n = x.shape
    w, cyclic = band_width(any(line.closed for line in model.lines), n, coupling_reach(model.scene))
    free, t = np.ascontiguousarray(~model.held), _steady_time(model.scene)
    drag = np.where(model.held, 0.0, model.drag)

    def empty():
        return Jacobian(np.zeros(((w + 1) * dim, n * dim)), np.zeros((w * dim, w * dim)), np.zeros((dim, dim)), w)

    analytic, differenced = empty(), empty()
    model.kernel(newton_matrix)(x, np.zeros_like(x), analytic, tau, (free, model.mass, drag), model.params, t)
    matrix = DifferencedMatrix(model, model.kernel(accelerations), w, cyclic, free, model.mass, drag, t,
                               model.velocity_dependent)
    rest = matrix.fill(x, differenced, tau)
    largest = np.abs(analytic.band).max()
    assert np.abs(differenced.band - analytic.band).max() < 1e-6 * largest
    assert np.abs(differenced.corner - analytic.corner).max() < 1e-6 * largest
    assert (np.abs(analytic.corner).max() > 0.0) == cyclic   # the loop's wrap-around was there to check
    assert np.abs(rest).max() < 1e-6 * largest                # symmetric, to the differences' error


def _both(raw: dict):
    """The static shape with the differenced matrix (rk4) and with the analytic one (sdirk2)."""
    return [solve_equilibrium(build(scene_of(raw, method), solve=False)) for method in ("rk4", "sdirk2")]


CURRENT = {   # a 50 m line hanging in 1.5 m/s of current (tests/test_statics_current.py's, 3-D)
    "dimension": 3,
    "rope": {"length": 50.0, "segments": 20, "mass_per_length": 4.0, "diameter": 0.05, "EA": 1.0e6},
    "initial": {"shape": "line", "start": [0.0, -1.0, 0.0], "end": [0.0, -51.0, 0.0]},
    "pinned": {"nodes": [0]}, "gravity": {"g": 9.81}, "fluid": {"density": 1025.0}, "buoyancy": {},
    "flow": {"velocity": [1.5, 0.0, 0.6]}, "added_mass": {"ca_normal": 1.0},
    "fluid_drag": {"cd_normal": 1.2, "cd_tangential": 0.3},
}


@pytest.mark.parametrize("raw", [MOORING, CURRENT], ids=["mooring", "current"])
def test_either_matrix_finds_the_same_static_shape_in_as_many_iterations(raw):
    differenced, analytic = _both(raw)
    assert differenced.converged and analytic.converged
    assert abs(differenced.iterations - analytic.iterations) <= max(2, analytic.iterations // 10)
    # both balanced to 1e-10 of the force scale; the shapes then differ by that force over the line's softest
    # stiffness: well below a micrometre on these lines
    assert np.abs(differenced.x - analytic.x).max() < 1e-6


@pytest.mark.slow
def test_an_explicit_static_start_compiles_no_newton_matrix(tmp_path):
    """With an empty cache, an rk4 mooring line's static start compiles none of the analytic matrix's kernels,
    nor the drag's tangent stiffness, nor (no flow: nothing non-conservative at rest) the merit's
    non-conservative forces; sdirk2's compiles the matrix its loop uses anyway, and still no tangent stiffness of
    the drag (zero at rest without a flow)."""
    code = f"""
        import ropesim, tomli_w
        from ropesim.model.build import build
        from ropesim.model.jit import template_name
        raw = {dict(MOORING)!r}
        raw["integrator"] = {{"method": "rk4", "dt": 0.001, "t_end": 0.1}}
        build(ropesim.scene_from_toml(tomli_w.dumps(raw)))
        print(json.dumps(sorted({{template_name(n.rsplit(".", 1)[1]) for n in compiled}})))
    """
    names = _probe(code, tmp_path / "cache")
    assert "accelerations" in names and "factor" in names   # the probe saw the compiles
    for kernel in ("newton_matrix", "add_fluid_jacobian", "add_seabed_jacobian", "pair_spring_blocks",
                   "add_added_mass_jacobian", "add_fluid_tangent_stiffness", "nonconservative_forces"):
        assert kernel not in names, kernel
    implicit = _probe(code.replace('"rk4"', '"sdirk2"'), tmp_path / "cache")
    assert "newton_matrix" in implicit
    assert "add_fluid_tangent_stiffness" not in implicit and "nonconservative_forces" not in implicit


def test_a_stalled_differenced_solve_starts_again_with_the_analytic_matrix(monkeypatch):
    """The safety net: should the differenced iteration stall (its pseudo-time step shrunk to nothing) or not
    converge in the full iteration count, the solve is repeated from the same guess with the analytic matrix,
    whose result is returned (not after a caller's own shorter limit); sdirk2 and EI bending go to the analytic
    matrix at once."""
    import ropesim.model.statics as statics

    calls = []

    def solver(stalls: bool):
        def solve(model, x, tol, max_iterations, pose, differenced):
            """the differenced iteration fails (stalled, or out of iterations); the analytic one converges"""
            calls.append((x, differenced))
            return Equilibrium(model.x0, 0.0, 1.0, 7, not differenced), differenced and stalls
        return solve

    model = build(scene_of(MOORING), solve=False)
    guess = model.x0 + 0.5
    for stalls in (True, False):
        monkeypatch.setattr(statics, "_solve", solver(stalls))
        calls.clear()
        assert solve_equilibrium(model, guess).converged
        assert [d for _, d in calls] == [True, False] and calls[0][0] is calls[1][0] is guess
    calls.clear()
    assert not solve_equilibrium(model, guess, max_iterations=1).converged   # a caller's own limit
    assert [d for _, d in calls] == [True]
    sdirk2 = build(scene_of(MOORING, "sdirk2"), solve=False)
    beam = {"rope": {"length": 2.0, "segments": 4, "mass_per_length": 1.0, "EA": 1.0e5, "EI": 10.0},
            "initial": {"shape": "line", "start": [0.0, 0.0], "end": [2.0, 0.0]},
            "pinned": {"nodes": [0]}, "gravity": {"g": 9.81}}
    for analytic in (sdirk2, build(scene_of(beam), solve=False)):
        calls.clear()
        assert solve_equilibrium(analytic).converged and [d for _, d in calls] == [False]
