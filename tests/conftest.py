"""Test set-up: one compile cache per test run, keyed by the package's sources.

The cache is the folder ropesim itself chooses for these sources (:mod:`ropesim.io.numba_cache`: named by a
fingerprint of every source file, so any edit starts an empty one and a stale kernel never hides a change),
never a ``NUMBA_CACHE_DIR`` the environment points at, which may hold kernels of other sources. So a second
run of the suite on unchanged sources loads what the first compiled, and pytest-xdist's workers share one
cache. ``ROPESIM_TEST_FRESH_CACHE=1`` starts from an empty folder instead (what a fresh checkout pays, as CI
does); with ``ROPESIM_TEST_CACHE=DIR`` beside it, from DIR as an earlier such run left it (the slow suite on
what the fast one compiled, say).
"""

import importlib.util
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


# With -n, pytest-xdist hands out a file's tests to one worker (`--dist loadfile`, pyproject.toml: module fixtures
# run once), and here a few files together as one unit (pytest_xdist_make_scheduler below; xdist 3.8's own
# `--dist loadgroup` groups nothing under pytest 9.2, whose node ids it can no longer suffix). The files in
# SHARED_LOOPS run every built-in scene's loop (the CLI's run folder, the bit-identity records, the MoorDyn imports
# of the same terms): side by side on two workers both missed the cache and compiled the same loops (85-112 s of
# CPU again in a cold run); one after the other on one worker, the second loads what the first compiled.
SHARED_LOOPS = {"test_bit_identity.py", "test_cli.py", "test_moordyn_import.py"}
# In the slow suite, `ropesim compile` of every built-in scene under every family (test_compile) and the loader's
# rescaled fuzz (built-in scenes under random methods) ask for the same loops (32 of the fuzz's 34 pairs of method
# and switches are a built-in scene's): one worker, one after the other, for the same reason.
EVERY_FAMILY = {"test_compile.py", "test_loader.py"}


def work_unit(file_name: str) -> str:
    """The unit of work, for xdist, that a test file's tests belong to."""
    if file_name in SHARED_LOOPS:
        return "built-in loops"
    return "every family" if file_name in EVERY_FAMILY else file_name


if importlib.util.find_spec("xdist") is not None:
    @pytest.hookimpl(optionalhook=True)   # xdist's hook: unknown to pytest when xdist is not loaded
    def pytest_xdist_make_scheduler(config, log):
        """`--dist loadfile`, with the files above sharing a unit (any other --dist: xdist's own)."""
        if config.getvalue("dist") != "loadfile":
            return None
        from xdist.scheduler import LoadScopeScheduling

        class FileUnits(LoadScopeScheduling):
            def _split_scope(self, nodeid: str) -> str:
                path = nodeid.split("::", 1)[0]
                return work_unit(path.rsplit("/", 1)[-1]) if path.startswith("tests/") else path

        return FileUnits(config, log)
