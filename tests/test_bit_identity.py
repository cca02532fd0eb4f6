"""Refactors change no numbers: short runs of every built-in scene (and a few more) under every integrator
reproduce, bit for bit, the frames, ledgers and step counts recorded before the integration layer was
restructured (commit 65782d3, recorded with ``python tests/test_bit_identity.py --record``).

Re-record only for a deliberate change of the numbers, and say so in the commit message.
"""

from __future__ import annotations

import dataclasses
import json
import sys
from pathlib import Path

import numpy as np
import pytest
import tomli_w

HERE = Path(__file__).resolve().parent
DATA = HERE / "data" / "bit_identity"
SCENARIOS = HERE.parent / "scenarios"
METHODS = ("symplectic_euler", "verlet", "yoshida4", "pefrl", "rk4", "sdirk2")
SHORT = ["integrator.t_end=0.3", "output.interval=0.05"]

EXTRA = {   # 3-D, a held and overridden 3-D towed rope, a 3-D shooter with bending, a plain 2-D loop
    "towed_3d": {
        "dimension": 3,
        "rope": {"nodes": 12, "segment_length": 0.5, "stiffness": 5000.0, "mass": 5.0},
        "initial": {"shape": "hanging", "top": [0.0, 0.0, 0.0], "velocity": [8.0, 0.0, 1.0]},
        "driven": [{"nodes": [0], "velocity": [8.0, 0.0, 1.0]}],
        "gravity": {"g": 9.81}, "drag": {"b": 5.0},
        "overrides": [{"index": -1, "mass": 100.0, "drag": 30.0}],
        "integrator": {"dt": 0.001, "t_end": 0.3}, "output": {"interval": 0.05},
    },
    "shooter_3d": {
        "dimension": 3,
        "rope": {"nodes": 8, "segment_length": 1.0, "stiffness": 100.0, "mass": 1.0, "closed": True},
        "initial": {"shape": "square_loop", "velocity": [0.0, 0.0, 0.5]},
        "thrower": {"center": [0.0, 0.0, 0.0], "length": 2.0, "width": 1.0, "v_max": 1.0, "b_thrower": 5.0},
        "guides": [{"center": [-1.0, 0.0, 0.0], "radius": 0.5}, {"center": [1.0, 0.0, 0.0], "radius": 0.5}],
        "bending": {"stiffness": 10.0}, "drag": {"b": 0.1}, "gravity": {"g": 9.81},
        "integrator": {"dt": 0.001, "t_end": 0.3}, "output": {"interval": 0.05},
    },
    "plain_loop": {
        "rope": {"nodes": 16, "segment_length": 0.4, "stiffness": 800.0, "mass": 0.2, "closed": True},
        "initial": {"shape": "points", "velocity": [0.5, 1.0],
                    "points": [[float(np.cos(2 * np.pi * i / 16)), float(np.sin(2 * np.pi * i / 16))]
                               for i in range(16)]},
        "pinned": {"nodes": [3]},
        "gravity": {"g": 9.81}, "drag": {"b": 0.05},
        "overrides": [{"index": 7, "mass": 0.5}],
        "integrator": {"dt": 0.001, "t_end": 0.3}, "output": {"interval": 0.05},
    },
}
SMOOTH = ["thrower.edge_width=0.2", "guides.0.edge_width=0.2", "guides.1.edge_width=0.2"]


def scenes() -> dict:
    """Every case's scene, by name."""
    import ropesim

    out = {f.stem: ropesim.load_scene(f, SHORT) for f in sorted(SCENARIOS.glob("*.toml"))}
    out["shooter_medium_smooth"] = ropesim.load_scene(SCENARIOS / "shooter_medium.toml", SHORT + SMOOTH)
    for name, raw in EXTRA.items():
        out[name] = ropesim.scene_from_toml(tomli_w.dumps(raw), source=name, default_name=name)
    return out


def with_method(scene, method: str):
    return dataclasses.replace(scene, integrator=dataclasses.replace(scene.integrator, method=method))


def run_case(scene) -> dict:
    """Frames (t, x, v), the ledger per frame, status, steps and force evaluations of one run, in memory."""
    from ropesim.model.build import build
    from ropesim.integrate.grid import TimeGrid
    from ropesim.run import integrate
    from ropesim.io.trajectory import FrameStore

    model = build(scene)
    store = FrameStore(TimeGrid.of(scene).frames, model.nodes, model.dim, None)
    outcome = integrate(model, store)
    arrays = store.arrays()
    return {"t": np.array(arrays["t"]), "x": np.array(arrays["x"]), "v": np.array(arrays["v"]),
            "ledger": np.array(outcome.ledger), "status": outcome.status, "steps": outcome.steps,
            "force_evaluations": outcome.force_evaluations}


RECORDED = json.loads((DATA / "index.json").read_text())
# The built-in scenes added after the recording are recorded under their own method only (``--record NAME``):
# the sea's scenes when they were added, the others at 7233daa (the later physical scenes: a fluid, a seabed,
# bending, static starts, systems with points and free bodies; the two free-body scenes re-recorded on branch
# issue20-body, whose trig-free turns and chord-based added mass moved them at rounding level, <= 2e-14 m;
# helicopter_sling again on issue20-bodypack, its container's constant mass matrix applied as its inverse instead of
# two triangular solves: x moved <= 2.4e-14 m, same steps; the three rk4 static starts re-recorded on branch
# issue19-statics, whose static solver differences its Newton matrix for an explicit method: the same static
# shapes to the solver's tolerance, 2.9e-12, 2.2e-12 and 2.9e-10 m; spread_mooring_free again on branch
# issue19-freebody-statics, whose rk4 static start solves the spar's Schur complement in NumPy around the banded
# factor and its own forces at rest in NumPy: the same 22 iterations, x moved <= 8.0e-13 m, same steps). Every
# recorded run is checked (the test below).
LATER = {"mooring_chain_waves": ("sdirk2",), "floating_hose": ("sdirk2",),
         "buoy_tether": ("sdirk2",), "cantilever_beam": ("verlet",), "clump_weight": ("verlet",),
         "helicopter_crosswind": ("sdirk2",), "helicopter_sling": ("verlet",), "mooring_chain": ("rk4",),
         "spread_mooring": ("rk4",), "spread_mooring_free": ("rk4",), "string_shooter_real": ("verlet",)}
ALL_CASES = [(name, method) for name in [p.stem for p in sorted(SCENARIOS.glob("*.toml"))]
             + ["shooter_medium_smooth", *EXTRA] for method in LATER.get(name, METHODS)]
CASES = [(name, method) for name, method in ALL_CASES if f"{name}__{method}" in RECORDED]


def test_every_recorded_run_is_checked():
    assert sorted(f"{name}__{method}" for name, method in CASES) == sorted(RECORDED)
    assert len(CASES) == 72 + sum(len(methods) for methods in LATER.values())


@pytest.fixture(scope="module")
def all_scenes():
    return scenes()


@pytest.fixture(scope="module")
def index():
    return json.loads((DATA / "index.json").read_text())


@pytest.mark.parametrize("name,method", CASES, ids=[f"{n}-{m}" for n, m in CASES])
def test_reproduces_recorded_run_bit_for_bit(all_scenes, index, name, method):
    key = f"{name}__{method}"
    got = run_case(with_method(all_scenes[name], method))
    want = index[key]
    assert (got["status"], got["steps"], got["force_evaluations"]) == (
        want["status"], want["steps"], want["force_evaluations"])
    with np.load(DATA / f"{key}.npz") as rec:
        recorded = {a: rec[a] for a in ("t", "x", "v", "ledger")}
    # the ledger has gained columns since (fluid, internal damping, seabed work): none of these scenes books any
    booked = recorded["ledger"].shape[1]
    assert not np.any(got["ledger"][:, booked:]), "a scene without fluid, damping or seabed booked their work"
    got["ledger"] = got["ledger"][:, :booked]
    for array, want_array in recorded.items():
        assert got[array].shape == want_array.shape, array
        assert np.array_equal(got[array], want_array), f"{array} differs (largest difference " \
            f"{np.max(np.abs(got[array] - want_array))})"


def record(names: list[str] | None = None) -> None:
    """Record every case, or (``names``) only the later scenes named, under their methods (:data:`LATER`),
    added to the index."""
    DATA.mkdir(parents=True, exist_ok=True)
    index = json.loads((DATA / "index.json").read_text()) if names else {}
    cases = scenes()
    todo = [(name, method) for name in names for method in LATER[name]] if names else ALL_CASES
    for name, method in todo:
        got = run_case(with_method(cases[name], method))
        key = f"{name}__{method}"
        np.savez_compressed(DATA / f"{key}.npz", **{a: got[a] for a in ("t", "x", "v", "ledger")})
        index[key] = {k: got[k] for k in ("status", "steps", "force_evaluations")}
        print(key, got["status"], got["steps"])
    (DATA / "index.json").write_text(json.dumps(index, indent=1) + "\n")


if __name__ == "__main__":
    if sys.argv[1:2] == ["--record"]:
        record(sys.argv[2:])
    else:
        print("usage: python tests/test_bit_identity.py --record [LATER_SCENE ...]")
