"""Test set-up: a fresh Numba cache for every test session, so a stale compiled kernel never hides a change."""

import os
import tempfile
from pathlib import Path

os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp(prefix="ropesim-numba-")
os.environ.setdefault("MPLBACKEND", "Agg")

import pytest  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = ROOT / "scenarios"


@pytest.fixture
def scenarios() -> Path:
    return SCENARIOS
