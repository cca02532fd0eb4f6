"""Numba's compiled kernels: what a run compiles, and compiling all of them ahead of time (``ropesim compile``).

Every compiled function of ropesim is ``cache=True``. The first run of a scene with an integrator compiles
that family's loop with the force terms the scene declares, and nothing else (a few seconds;
``scripts/bench_first_run.py`` measures every built-in scene), and Numba writes it to its cache
(:mod:`ropesim.io.numba_cache` says where); later runs load it in a fraction of a second.

What compiles depends on the integrator's family (splitting, Runge-Kutta, SDIRK) and on the scene's
compile-time switches: its declared terms, prescribed motion and, for the splitting family, the plain stage
(:mod:`ropesim.model.jit`, :func:`ropesim.model.terms.switches`). Scenes with the same switches share every
compiled function, 2-D or 3-D, and the four splitting methods share one loop. Besides the loop a run compiles
the helpers it calls from Python: the plain stage's set-up, the support forces of each saved frame, and, for
a scene that starts in its static equilibrium, the static solver.

:func:`warm_up` compiles (or loads) everything a run of one scene compiles; :func:`compile_all` does it for
every method on every built-in scene (or the scenes given), and for the static solver of each.
``tests/test_compile.py`` checks that after it a run of those scenes, with any method, compiles nothing.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import Callable

STATIC_SOLVER = "static solver"
FIRST_COMPILE_SECONDS = (5, 15)   # a scene's loop and terms, compiled once (scripts/bench_first_run.py)


def loop_cached(scene) -> bool | None:
    """Whether the time loop a run of ``scene`` calls (its method's, for its parts) is in Numba's cache for the
    running source (a run then compiles nothing), read from the cache's index without compiling; None when
    Numba's cache cannot be read that way."""
    from .integrate.methods import get_method
    from .model.build import build

    method = get_method(scene.integrator.method)
    loop = method.family.compiled_loop(build(scene, solve=False), method)
    try:
        return bool(loop._cache._cache_file._load_index())   # {} unless an entry matches the source's stamp
    except Exception:   # Numba's private cache API moved: say nothing rather than guess
        return None


@dataclass
class Compiled:
    """What compiling one method (or the static solver) did: ``functions`` of ropesim compiled by Numba in
    ``seconds`` (0 functions: everything came from the cache, or was compiled already for an earlier method of
    the same family, ``shared_with``), over ``scenes`` scenes."""

    name: str
    family: str
    seconds: float
    functions: int
    scenes: int
    shared_with: str = ""


def one_step(scene):
    """``scene`` cut to its first step (t_end = dt): a run of it compiles what the whole run would."""
    return replace(scene, integrator=replace(scene.integrator, t_end=scene.integrator.dt))


def warm_up(scene) -> None:
    """Compile, or load from Numba's cache, everything a run of ``scene`` compiles.

    The integrator's loop, the per-frame tension and support forces, and then a one-step run in memory for
    whatever else a run calls (nothing else compiles today; the tests check that a run afterwards compiles
    nothing). Ctrl-C stops it at once while the loop compiles.
    """
    import numpy as np

    from .integrate.grid import TimeGrid
    from .integrate.methods import make_integrator
    from .io.trajectory import FrameStore
    from .model.build import build
    from .model.tension import frame_arrays
    from .run import INTERRUPTED, simulate
    from .scene.frame import frame_of
    from .stop import Stopped

    short = one_step(scene)
    model = build(short)                  # a scene starting in equilibrium runs (and compiles) the static solver
    integrator = make_integrator(model, TimeGrid.of(short))
    integrator.warm_up()                  # the loop, outside the run's signal handling: Ctrl-C stops it
    store = FrameStore(0, model.nodes, model.dim, derive=lambda t, x, v, body: frame_arrays(model, t, x, v, body),
                       frame=frame_of(model.scene))
    store.rows(np.zeros(1), integrator.x[None], integrator.v[None], None, integrator.body_rows()[None])   # as the run derives its frames
    summary = simulate(short).summary
    if summary["status"] == INTERRUPTED:
        raise Stopped(summary.get("stopped_by", "SIGINT"))


def warm_up_static_solver(scene) -> None:
    """Compile (or load) the static solver of ``initial.shape = 'equilibrium'`` and `ropesim equilibrium` for
    ``scene``'s parts: one Newton iteration of it on ``scene``'s model, from a guess off equilibrium, with each
    matrix it may take (an explicit method's differenced one and its analytic fallback), and the support forces
    it reports."""
    import numpy as np

    from .analysis.statics import static_loads
    from .model.build import build
    from .model.statics import warm_up

    model = build(scene, solve=False)
    result = warm_up(model, model.x0 * 1.001 + 0.01)
    static_loads(model, np.ascontiguousarray(result.x))


class _Counter:
    """Counts the functions of ropesim that Numba compiles (its ``numba:compile`` events; none for a function
    loaded from the cache)."""

    def __init__(self):
        from numba.core import event

        class Listener(event.Listener):
            def on_start(inner, ev):
                if (getattr(ev.data["dispatcher"].py_func, "__module__", "") or "").startswith("ropesim"):
                    self.functions += 1

            def on_end(inner, ev):
                pass

        self.functions = 0
        self._event, self._listener = event, Listener()

    def __enter__(self) -> "_Counter":
        self._event.register("numba:compile", self._listener)
        return self

    def __exit__(self, *exc) -> None:
        self._event.unregister("numba:compile", self._listener)


def compile_all(methods: list[str] | None = None, scenes: list | None = None, static_solver: bool = True,
                on_start: Callable[[str, int, int], None] | None = None) -> list[Compiled]:
    """Compile every method's kernels (default: all of ``METHODS``) for every scene in ``scenes`` (default:
    the built-in scenes), and the static solver; returns what each took. ``on_start(name, i, n)`` is called
    before each of the n items."""
    from .integrate.methods import METHODS

    if scenes is None:
        from .scene.builtin import builtin_names, builtin_path
        from .scene.loader import load_scene

        scenes = [load_scene(builtin_path(name)) for name in builtin_names()]
    names = list(methods) if methods is not None else list(METHODS)
    items = names + ([STATIC_SOLVER] if static_solver else [])
    results: list[Compiled] = []
    first_of_family: dict = {}
    with _Counter() as counter:
        for i, name in enumerate(items):
            if on_start is not None:
                on_start(name, i, len(items))
            before, start = counter.functions, time.perf_counter()
            if name == STATIC_SOLVER:
                for scene in scenes:
                    warm_up_static_solver(scene)
                family, shared, count = "statics", "", len(scenes)
            else:
                method = METHODS[name]
                runs = [replace(scene, integrator=replace(scene.integrator, method=name)) for scene in scenes]
                for scene in runs:
                    warm_up(scene)
                family, count = method.kind, len(runs)
                shared = first_of_family.setdefault(method.family, name)
                shared = "" if shared == name else shared
            results.append(Compiled(name, family, time.perf_counter() - start, counter.functions - before, count,
                                    shared))
    return results
