"""Test set-up: one compile cache per test run, keyed by the package's sources.

The cache is the folder ropesim itself chooses for these sources (:mod:`ropesim.io.numba_cache`: named by a
fingerprint of every source file, so any edit starts an empty one and a stale kernel never hides a change),
never a ``NUMBA_CACHE_DIR`` the environment points at, which may hold kernels of other sources. So a second
run of the suite on unchanged sources loads what the first compiled, and pytest-xdist's workers share one
cache. ``ROPESIM_TEST_FRESH_CACHE=1`` starts from an empty folder instead (what a fresh checkout pays, as CI
does); with ``ROPESIM_TEST_CACHE=DIR`` beside it, from DIR as an earlier such run left it (the slow suite on
what the fast one compiled, say).
"""

import os
import tempfile
from pathlib import Path

os.environ.pop("NUMBA_CACHE_DIR", None)
if (os.environ.get("ROPESIM_TEST_FRESH_CACHE") and not os.environ.get("PYTEST_XDIST_WORKER")
        and not os.environ.get("ROPESIM_TEST_CACHE")):
    os.environ["ROPESIM_TEST_CACHE"] = tempfile.mkdtemp(prefix="ropesim-numba-")   # the workers inherit it
if os.environ.get("ROPESIM_TEST_FRESH_CACHE"):
    os.environ["NUMBA_CACHE_DIR"] = os.environ["ROPESIM_TEST_CACHE"]
os.environ.setdefault("MPLBACKEND", "Agg")

import ropesim  # noqa: E402,F401  (chooses the sources' cache folder unless one was set just above)
import pytest  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = ROOT / "scenarios"


@pytest.fixture
def scenarios() -> Path:
    return SCENARIOS


def pytest_addoption(parser):
    parser.addoption("--compile-profile", metavar="DIR", default=None,
                     help="write each test's CPU, Numba compiles and specialised kernels asked for to DIR "
                          "(tests/compile_profile; scripts/suite_profile.py prints the table)")


def pytest_configure(config):
    if config.getoption("compile_profile"):
        import compile_profile

        compile_profile.configure(config)
