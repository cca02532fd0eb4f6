"""In a subprocess of a profiled test (``--compile-profile``): note each Numba compile and each specialised copy
asked for, one JSON line each, to ``$ROPESIM_PROFILE_DIR/<pid>.jsonl`` under the test's id. Nothing is imported
until the child imports Numba (or ropesim's ``jit``) itself, so a child that never compiles is not slowed."""

import importlib.abc
import importlib.util
import json
import os
import sys

_FOLDER, _TEST = os.environ.get("ROPESIM_PROFILE_DIR"), os.environ.get("ROPESIM_PROFILE_TEST")


def _write(record: dict) -> None:
    with open(os.path.join(_FOLDER, f"{os.getpid()}.jsonl"), "a", encoding="utf-8") as out:
        out.write(json.dumps({"test": _TEST, **record}) + "\n")


def _after_event(module) -> None:
    import time

    open_starts = []

    class Listener(module.Listener):
        def on_start(self, ev):
            open_starts.append(time.process_time())

        def on_end(self, ev):
            seconds = time.process_time() - open_starts.pop()
            function = ev.data["dispatcher"].py_func
            name = f"{getattr(function, '__module__', '?')}.{function.__qualname__}"
            _write({"compile": name, "seconds": seconds, "depth": len(open_starts)})

    module.register("numba:compile", Listener())


def _after_jit(module) -> None:
    asked = set()

    class Noting(dict):
        def get(self, key, default=None):
            dispatcher, values = key
            bits = sum(1 << i for i, value in enumerate(values) if value)
            function = dispatcher.py_func
            name = f"{function.__module__}.{function.__qualname__}__s{bits:x}"
            if name not in asked:
                asked.add(name)
                _write({"asked": name})
            return super().get(key, default)

    module._copies = Noting(module._copies)


class _Finder(importlib.abc.MetaPathFinder):
    """Runs ``_after_*`` once the named module has been executed."""

    hooks = {"numba.core.event": _after_event, "ropesim.model.jit": _after_jit}

    def find_spec(self, name, path, target=None):
        if name not in self.hooks:
            return None
        for finder in sys.meta_path:
            if finder is self or not hasattr(finder, "find_spec"):
                continue
            spec = finder.find_spec(name, path, target)
            if spec is not None:
                break
        else:
            return None
        execute, hook = spec.loader.exec_module, self.hooks[name]

        def exec_module(module):
            execute(module)
            hook(module)

        spec.loader.exec_module = exec_module
        return spec


if _FOLDER and _TEST:
    sys.meta_path.insert(0, _Finder())
