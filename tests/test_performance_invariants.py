"""What the speed-ups must never change, checked without timing anything.

- The compile cache: a kernel compiled in one process loads from the cache in the next, an edit to any
  module starts a fresh cache folder, and an install whose package folder cannot be written still gets a
  writable cache folder (ropesim/io/numba_cache.py).
- Memory: a run folder's frames stream to disk, so the memory a run allocates does not grow with the
  number of saved frames (counted with tracemalloc, which sees NumPy's allocations).
- Parallel kernels give bit-identical results to the serial ones.
- The kernels count no references: every compiled function of the model and the integrators is a
  ``ropesim.model.jit.kernel`` (Numba's ``_nrt=False``), and the compiled term list holds no reference-count
  call (see ropesim/model/jit.py for why this matters: it was most of a small rope's step).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tracemalloc
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import ropesim
from ropesim.io import numba_cache

ROOT = Path(__file__).resolve().parent.parent


def _blocked(tmp_path: Path) -> Path:
    """A folder that cannot be created, even by root: its parent is a regular file."""
    plain = tmp_path / "a-file"
    plain.write_text("")
    return plain / "folder"


def _package(tmp_path: Path) -> Path:
    package = tmp_path / "ropesim"
    (package / "forces").mkdir(parents=True)
    (package / "kernel.py").write_text("x = 1\n")
    (package / "forces" / "thrower.py").write_text("y = 2\n")
    return package


def test_writable_package_caches_in_its_own_pycache_under_its_fingerprint(tmp_path):
    package = _package(tmp_path)
    chosen = numba_cache.choose_cache_dir(package, environ={})
    assert chosen == str(package / "__pycache__" / "kernels" / numba_cache.source_fingerprint(package))
    assert numba_cache.writable(Path(chosen))


def test_an_edit_to_any_module_starts_a_fresh_kernel_folder(tmp_path):
    """Numba checks only the defining file's stamp, so a kernel compiled with an old helper from another module
    would load after the helper changed; the fingerprint covers every module instead."""
    package = _package(tmp_path)
    before = numba_cache.choose_cache_dir(package, environ={})
    helper = package / "forces" / "thrower.py"
    helper.write_text("y = 3\n")   # same size: only the modification time tells
    os.utime(helper, ns=(helper.stat().st_atime_ns, helper.stat().st_mtime_ns + 1_000_000))
    after = numba_cache.choose_cache_dir(package, environ={})
    assert after != before
    (package / "forces" / "guides.py").write_text("")
    assert numba_cache.choose_cache_dir(package, environ={}) not in (before, after)


def test_only_the_most_recently_used_kernel_folders_are_kept(tmp_path):
    package = _package(tmp_path)
    base = package / "__pycache__" / "kernels"
    for age, name in enumerate(["old3", "old2", "old1", "old0"]):
        (base / name).mkdir(parents=True)
        os.utime(base / name, (1e9 - age, 1e9 - age))   # old0 the oldest
    chosen = Path(numba_cache.choose_cache_dir(package, environ={}))
    assert sorted(p.name for p in base.iterdir()) == sorted([chosen.name, "old3", "old2"])


def test_cache_dir_respects_the_users_numba_cache_dir(tmp_path):
    assert numba_cache.choose_cache_dir(_blocked(tmp_path), environ={"NUMBA_CACHE_DIR": "/x"}) is None


def test_read_only_install_caches_in_the_user_cache_folder(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.setattr(sys, "platform", "linux")
    chosen = numba_cache.choose_cache_dir(_blocked(tmp_path), environ={})
    assert Path(chosen).parent == tmp_path / "xdg" / "ropesim" / "numba"
    assert numba_cache.writable(Path(chosen))


def test_read_only_install_without_a_writable_home_caches_in_the_temporary_folder(tmp_path, monkeypatch):
    monkeypatch.setattr(sys, "platform", "linux")
    monkeypatch.setenv("XDG_CACHE_HOME", str(_blocked(tmp_path)))
    monkeypatch.setattr(numba_cache.tempfile, "tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    chosen = numba_cache.choose_cache_dir(_blocked(tmp_path), environ={})
    assert chosen is not None and Path(chosen).parent.parent == tmp_path / "tmp"


def test_ensure_writable_cache_tells_an_already_imported_numba(tmp_path, monkeypatch):
    import numba.core.config as config

    monkeypatch.setattr(numba_cache, "choose_cache_dir", lambda: str(tmp_path))
    monkeypatch.setattr(config, "CACHE_DIR", config.CACHE_DIR)
    monkeypatch.setenv("NUMBA_CACHE_DIR", os.environ["NUMBA_CACHE_DIR"])
    assert numba_cache.ensure_writable_cache() == str(tmp_path)
    assert config.CACHE_DIR == str(tmp_path) and os.environ["NUMBA_CACHE_DIR"] == str(tmp_path)


PROBE = """
import json, sys
import ropesim
from ropesim.integrate.grid import TimeGrid
from ropesim.integrate.methods import make_integrator
from ropesim.model.build import build
scene = ropesim.load_scene(sys.argv[1], ["integrator.t_end=0.05"])
loop = make_integrator(build(scene), TimeGrid.of(scene)).loop   # the scene's copy of its family's loop
ropesim.simulate(scene)
stats = loop.stats
print(json.dumps({"hits": sum(stats.cache_hits.values()), "misses": sum(stats.cache_misses.values())}))
"""


def _compiled_functions():
    """Every Numba dispatcher defined in ropesim.model and ropesim.integrate: (module.name, dispatcher)."""
    import importlib
    import pkgutil

    from numba.core.registry import CPUDispatcher

    found = []
    for package in ("ropesim.model", "ropesim.model.forces", "ropesim.integrate"):
        pkg = importlib.import_module(package)
        for info in pkgutil.iter_modules(pkg.__path__):
            module = importlib.import_module(f"{package}.{info.name}")
            for name, value in vars(module).items():
                if isinstance(value, CPUDispatcher) and value.py_func.__module__ == module.__name__:
                    found.append((f"{module.__name__}.{name}", value))
    return found


def test_every_kernel_is_compiled_without_reference_counting():
    found = _compiled_functions()
    assert len(found) > 60   # the force terms, the term list, the integrators, the banded solver, ...
    counting = [name for name, fn in found if fn.targetoptions.get("_nrt", True)]
    assert counting == []


@pytest.mark.slow
def test_the_compiled_term_list_holds_no_reference_count_call(tmp_path):
    """Compiled fresh in a subprocess (a function loaded from Numba's cache cannot be inspected): the LLVM IR of
    the term list and the RK4 loop, as one module each, calls neither NRT_incref nor NRT_decref."""
    probe = (
        "import re, ropesim\n"
        "from ropesim.model.build import build\n"
        "from ropesim.integrate.grid import TimeGrid\n"
        "from ropesim.integrate.methods import make_integrator\n"
        "from ropesim.model import terms\n"
        "scene = ropesim.load_scene('helicopter_crosswind', ['integrator.method=rk4'])\n"
        "model = build(scene)\n"
        "it = make_integrator(model, TimeGrid.of(scene), 'rk4'); it.warm_up()\n"
        "forces = model.kernel(terms.accelerations)\n"
        "forces(model.x0, model.v0, model.x0 * 0.0, model.params, 0.0)\n"
        "for fn in (forces, it.loop):\n"
        "    ir = list(fn.inspect_llvm().values())[0]\n"
        "    own = [m.group(0) for m in re.finditer(r'define [^\\n]*ropesim[^\\n]*\\{.*?\\n\\}', ir, re.S)\n"
        "           if 'cpython' not in m.group(0).split('(')[0]]\n"
        "    print(fn.py_func.__name__, len(own), sum(body.count('@NRT_incref') + body.count('@NRT_decref') for body in own))\n")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, env=env, check=True).stdout
    counts = {name: (int(functions), int(calls)) for name, functions, calls in (line.split() for line in
                                                                               out.splitlines())}
    # the functions were found (the loop's own and its callees' definitions; no C wrappers since jit.OPTIONS
    # makes kernels without them: 9 in the loop)
    assert counts["accelerations"][0] >= 3 and counts["advance_rk"][0] >= 8
    assert counts == {name: (functions, 0) for name, (functions, _) in counts.items()}


def test_a_compiled_kernel_loads_from_the_cache_in_a_fresh_process(scenarios):
    scene_file = scenarios / "helicopter_uniform.toml"
    ropesim.simulate(ropesim.load_scene(scene_file, ["integrator.t_end=0.05"]))   # compiled and cached here
    out = subprocess.run([sys.executable, "-c", PROBE, str(scene_file)], capture_output=True, text=True,
                         env=dict(os.environ), timeout=600, check=True).stdout
    stats = json.loads(out.strip().splitlines()[-1])
    assert stats == {"hits": 1, "misses": 0}


@pytest.mark.parametrize("shape", [(7, 40, 2), (3, 5, 33, 3), (40, 2), (1, 9, 2)])
def test_spring_helpers_give_the_same_numbers_block_by_block(shape, monkeypatch):
    from ropesim.model.forces import springs

    x = np.random.default_rng(len(shape)).normal(size=shape)
    whole = [springs.pair_spring_energy(x, 3.0, 0.5, 1, True), springs.pair_spring_stretch(x, 0.5, 2, False)]
    monkeypatch.setattr(springs, "BLOCK_BYTES", x[..., :1, :, :].nbytes if x.ndim > 2 else 8)
    blocked = [springs.pair_spring_energy(x, 3.0, 0.5, 1, True), springs.pair_spring_stretch(x, 0.5, 2, False)]
    for a, b in zip(whole, blocked):
        assert a.shape == b.shape == (shape[:-2] if a is whole[0] else shape[:-2] + (shape[-2] - 2,))
        np.testing.assert_array_equal(a, b)


def _traced_peak(fn) -> int:
    """Peak bytes allocated through Python and NumPy while ``fn`` runs (file-backed memory maps excluded)."""
    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_a_run_folder_does_not_hold_its_frames_in_memory(scenarios, tmp_path, monkeypatch):
    """Eight times the saved frames (about 18 MB more trajectory) must not raise the peak by 1 MB.

    The run loop holds at most FRAME_BUFFER_BYTES of frames between chunks, the rest go to disk, and the
    summary reads them back in blocks of at most BLOCK_BYTES (all 256 kB here, so that 320 frames are many).
    """
    from ropesim import run as run_module
    from ropesim.analysis import summary
    from ropesim.model.forces import springs

    for module, name in ((run_module, "FRAME_BUFFER_BYTES"), (summary, "BLOCK_BYTES"), (springs, "BLOCK_BYTES")):
        monkeypatch.setattr(module, name, 256 * 1024)
    nodes, steps = 2000, 1600
    frame = nodes * 2 * 8

    def run(frames: int):
        scene = ropesim.load_scene(scenarios / "helicopter_uniform.toml", [
            f"rope.nodes={nodes}", f"integrator.t_end={steps * 0.001}", f"output.interval={steps * 0.001 / frames}"])
        return lambda: ropesim.simulate(scene, tmp_path / f"run{frames}")

    run(2)()   # compile outside the measurement
    few, many = _traced_peak(run(40)), _traced_peak(run(320))
    assert 2 * (320 - 40) * frame > 17e6
    assert many - few < 1e6, (few, many)


@settings(max_examples=60, deadline=None)
@given(dim=st.sampled_from([2, 3]), n=st.integers(1, 40), closed=st.booleans(), seed=st.integers(0, 2 ** 31),
       before=st.integers(0, 5), after=st.integers(0, 5))
def test_vectorised_chain_springs_equal_the_pairwise_springs(dim, n, closed, seed, before, after):
    """set_chain_springs (two vectorised passes, gravity included) = add_pair_springs(stride 1) + gravity, on a
    line of n nodes among other nodes (a system's lines follow each other), which it leaves alone."""
    from ropesim.model.forces.springs import add_pair_springs, set_chain_springs

    rng = np.random.default_rng(seed)
    x = rng.normal(size=(dim, n))
    if n > 2:
        x[:, 2] = x[:, 1]   # coincident nodes: that spring has no direction and pushes nothing
    inv_mass = rng.uniform(0.1, 3.0, size=n)
    expected = np.zeros((dim, n))
    add_pair_springs(x, expected, inv_mass, 40.0, 0.3, 1, closed)
    expected[1] -= 9.81
    wide = np.concatenate([rng.normal(size=(dim, before)), x, rng.normal(size=(dim, after))], axis=1)
    masses = np.concatenate([np.ones(before), inv_mass, np.ones(after)])
    got = np.full(wide.shape, np.nan)   # overwritten on the line, not added to; left alone elsewhere
    set_chain_springs(wide, got, masses, 40.0, 0.3, closed, 9.81, False, before, before + n)
    np.testing.assert_allclose(got[:, before:before + n], expected, rtol=1e-12, atol=1e-10)
    assert np.isnan(got[:, :before]).all() and np.isnan(got[:, before + n:]).all()


@settings(max_examples=40, deadline=None)
@given(n=st.one_of(st.integers(1, 30), st.integers(250, 300)), seed=st.integers(0, 2 ** 31),
       c=st.sampled_from([0.0, 1e-3]))
def test_kick_bookkeeping_matches_the_plain_sums(n, seed, c):
    """The four-lane sums of kick.py are the energy the kick books, to rounding; the kick and drift are exact.

    Both of kick_drift's paths (below and from SCRATCH_NODES nodes) and both of its row passes (with a drift,
    c != 0, and without) are exercised.
    """
    from ropesim.integrate.kick import box_work, kick_drift

    rng = np.random.default_rng(seed)
    x, v, acc, acc_box = (rng.normal(size=(2, n)) for _ in range(4))
    decay, gain, travel = (rng.uniform(0.1, 1.0, size=(2, n)) for _ in range(3))
    mass = rng.uniform(0.5, 2.0, size=n)
    vn = decay[1] * v + gain[1] * acc
    way = gain[1] * v + travel[1] * acc
    loss = np.sum(mass * (acc * way - 0.5 * (vn * vn - v * v)))
    scale = np.sum(mass * (np.abs(acc * way) + v * v + vn * vn))
    assert abs(box_work(v, acc, acc_box, gain, travel, 1, mass) - np.sum(mass * acc_box * way)) <= 1e-13 * np.sum(
        mass * np.abs(acc_box * way))
    xn = x + c * vn if c != 0.0 else x.copy()
    booked = kick_drift(x, v, acc, decay, gain, travel, 1, mass, c, np.empty(n))
    assert abs(booked - loss) <= 1e-13 * scale
    np.testing.assert_array_equal(v, vn)
    np.testing.assert_array_equal(x, xn)


@pytest.mark.slow
@pytest.mark.parametrize("script, args", [
    ("bench_kernel.py", ["--repeats", "1", "--work", "2e4", "--sizes", "21", "--method-sizes", "21,100"]),
    ("bench_parallel.py", ["--repeats", "1", "--sizes", "1000"]),
    ("bench_kernel_parts.py", ["--repeats", "1", "--work", "2e4", "--sizes", "21"]),
])
def test_benchmark_scripts_run(script, args):
    """The benchmarks still run against the current kernel (tiny sizes; their figures are not checked here)."""
    proc = subprocess.run([sys.executable, str(ROOT / "scripts" / script), *args], capture_output=True, text=True,
                          timeout=900)
    assert proc.returncode == 0, proc.stderr
    assert "M/s" in proc.stdout or "speed-up" in proc.stdout or "ns per step" in proc.stdout
