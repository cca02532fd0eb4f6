"""Where the test suite's CPU goes: per test, Numba compiling against the rest (``--compile-profile=DIR``).

A pytest plugin (enabled by tests/conftest.py when the option is given) that writes, for each test, one JSON
line to ``DIR/tests-<worker>.jsonl``:

- ``cpu``: the test's CPU seconds in the pytest process (user+sys, set-up and tear-down included);
- ``children``: CPU seconds of the subprocesses it ran and waited for (the CLI tests, scripts, mkdocs);
- ``compiles``: every function Numba compiled for it, in this process or in a subprocess, as
  ``[module.qualname, CPU seconds, depth]`` (a specialised copy's name carries its switch values, ``__s1a``);
  a compile that compiles its callees (depth 1 and more) includes their seconds: ``compile_cpu`` counts the
  outermost only;
- ``asked``: the specialised copies (:func:`ropesim.model.jit.specialise`) the test asked for, compiled or
  not: what it *needs*, so that ``scripts/suite_profile.py`` can tell the kernels only one test needs.

A subprocess reports through ``sitecustomize.py`` in this folder (put first on ``PYTHONPATH``), which
registers the same listener when the child imports Numba; each test's id is passed down in
``ROPESIM_PROFILE_TEST``. Loading a kernel from the cache fires no compile event, so a warm run shows what
is left: the tests' own CPU. ``scripts/suite_profile.py`` runs the suite with the option and prints the table.
"""

from __future__ import annotations

import json
import os
import resource
import time
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent


class CompileLog:
    """Numba's ``numba:compile`` events of this process, as ``[name, CPU seconds, depth]`` (depth 0: outermost)."""

    def __init__(self):
        self.events: list[list] = []
        self._open: list[float] = []

    def listener(self):
        from numba.core import event

        log = self

        class Listener(event.Listener):
            def on_start(self, ev):
                log._open.append(time.process_time())

            def on_end(self, ev):
                start = log._open.pop()
                function = ev.data["dispatcher"].py_func
                name = f"{getattr(function, '__module__', '?')}.{function.__qualname__}"
                log.events.append([name, time.process_time() - start, len(log._open)])

        return Listener()

    def install(self) -> None:
        from numba.core import event

        event.register("numba:compile", self.listener())

    def take(self) -> list[list]:
        events, self.events = self.events, []
        return events


def _asked_log(asked: set):
    """Make :func:`ropesim.model.jit.specialise` note each copy it is asked for (its ``_copies.get``)."""
    from ropesim.model import jit

    class Noting(dict):
        def get(self, key, default=None):
            dispatcher, values = key
            bits = sum(1 << i for i, value in enumerate(values) if value)
            function = dispatcher.py_func
            asked.add(f"{function.__module__}.{function.__qualname__}__s{bits:x}")
            return super().get(key, default)

    jit._copies = Noting(jit._copies)


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _own_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


class Profile:
    """The pytest plugin: one JSON line per test."""

    def __init__(self, folder: Path):
        folder.mkdir(parents=True, exist_ok=True)
        worker = os.environ.get("PYTEST_XDIST_WORKER", "main")
        self.out = open(folder / f"tests-{worker}.jsonl", "a", encoding="utf-8")
        self.child_dir = folder / "children"
        self.child_dir.mkdir(exist_ok=True)
        self.log, self.asked = CompileLog(), set()
        self.log.install()
        _asked_log(self.asked)
        os.environ["ROPESIM_PROFILE_DIR"] = str(self.child_dir)
        os.environ["PYTHONPATH"] = os.pathsep.join([str(HERE), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep)

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_protocol(self, item, nextitem):
        os.environ["ROPESIM_PROFILE_TEST"] = item.nodeid
        self.log.take()
        self.asked.clear()
        own, children, wall = _own_cpu(), _children_cpu(), time.perf_counter()
        yield
        events = self.log.take()
        record = {"test": item.nodeid, "cpu": _own_cpu() - own, "children": _children_cpu() - children,
                  "wall": time.perf_counter() - wall,
                  "compile_cpu": sum(seconds for _, seconds, depth in events if depth == 0),
                  "compiles": events, "asked": sorted(self.asked)}
        self.out.write(json.dumps(record) + "\n")
        self.out.flush()


def configure(config) -> None:
    folder = config.getoption("compile_profile")
    if folder:
        config.pluginmanager.register(Profile(Path(folder).resolve()), "ropesim-compile-profile")
