"""Where a first run's compile time goes: CPU seconds per compiled function, from Numba's own events.

Runs ``ropesim run SCENE --set integrator.t_end=DT`` in this process with an empty, temporary Numba cache
(as a newcomer's first command does) and listens to Numba's ``numba:compile`` events (one per function it
compiles, nested when compiling a caller types a callee) and ``numba:llvm_lock`` (LLVM's optimisation and
code emission). Prints, per function (a :func:`ropesim.model.jit.specialise` copy under its own name, with
its switch values), the CPU seconds of its own compile (``own``: its callees' compiles left out), with its
callees (``with callees``) and how many times it compiled (more than once: several type signatures), then
the functions compiled at the top level (what the run asked for) and the LLVM share::

    python scripts/profile_compile.py mooring_chain
    python scripts/profile_compile.py helicopter_mass --set integrator.method=sdirk2

Figures are CPU seconds of one process: compare them with each other, or with another revision's in the
same load (``scripts/bench_first_run.py`` measures whole first runs against another revision).
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", help="a built-in scene's name or a scene file")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="a scene override, as `ropesim run --set` (repeatable)")
    parser.add_argument("--t-end", default="0.01", help="the run's end time [s] (default: 0.01, a few steps)")
    parser.add_argument("--top", type=int, default=40, help="functions listed (default: 40)")
    args = parser.parse_args()

    work = tempfile.mkdtemp(prefix="ropesim-compile-profile-")
    os.environ["NUMBA_CACHE_DIR"] = os.path.join(work, "cache")   # before Numba is imported: an empty cache
    os.environ.setdefault("MPLBACKEND", "Agg")
    from numba.core import event

    stack, own, total, count, top, llvm = [], {}, {}, {}, [], [0.0, 0.0]

    class Compiles(event.Listener):
        def on_start(self, ev):
            f = ev.data["dispatcher"].py_func
            stack.append([f"{f.__module__}.{f.__qualname__}", time.process_time(), 0.0])

        def on_end(self, ev):
            name, start, callees = stack.pop()
            spent = time.process_time() - start
            total[name] = total.get(name, 0.0) + spent
            own[name] = own.get(name, 0.0) + spent - callees
            count[name] = count.get(name, 0) + 1
            if stack:
                stack[-1][2] += spent
            else:
                top.append((name, spent))

    class Llvm(event.Listener):
        def on_start(self, ev):
            llvm[1] = time.process_time()

        def on_end(self, ev):
            llvm[0] += time.process_time() - llvm[1]

    event.register("numba:compile", Compiles())
    event.register("numba:llvm_lock", Llvm())
    from ropesim.cli import main as ropesim_main

    command = ["run", args.scene, "--set", f"integrator.t_end={args.t_end}", "--out", os.path.join(work, "run"),
               "--quiet", "--force"]
    for override in args.set:
        command += ["--set", override]
    start = time.process_time()
    sys.argv = ["ropesim", *command]
    try:
        ropesim_main()
    except SystemExit:
        pass
    finally:
        shutil.rmtree(work, ignore_errors=True)
    spent = time.process_time() - start
    compiling = sum(s for _, s in top)
    print(f"ropesim {' '.join(command[:2] + args.set)}: {spent:.1f} s CPU in the command, {compiling:.1f} s of it "
          f"compiling ({llvm[0]:.1f} s in LLVM); {len(count)} functions, {sum(count.values())} compiles")
    print(f"{'own':>7} {'with callees':>12} {'times':>5}  function")
    for name, seconds in sorted(own.items(), key=lambda item: -item[1])[:args.top]:
        print(f"{seconds:7.2f} {total[name]:12.2f} {count[name]:5d}  {name}")
    print("compiled at the top level (what the run called):")
    for name, seconds in top:
        print(f"{seconds:7.2f}  {name}")


if __name__ == "__main__":
    main()
