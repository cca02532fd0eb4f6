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
    python scripts/profile_compile.py mooring_chain --passes

``--passes`` adds where the compile goes by stage, summed over every function: each of Numba's compiler
passes (type inference, lowering to LLVM IR, ...), the wrappers Numba lowers for calls from Python, and
LLVM's stages (function passes, each library's final module, machine-code emission), each stage's own CPU
seconds (what a nested stage spent left out, so the rows add up to the compile); then the largest
(function, stage) pairs, each stage charged to the function whose compile ran it (a loop's final module and
machine code hold every callee linked in; a ``__i`` twin's are never run).

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
    parser.add_argument("--passes", action="store_true", help="also CPU seconds per compiler pass and LLVM stage")
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
    stages, by_function = time_stages(stack) if args.passes else ({}, {})
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
    if stages:
        print("by stage (own CPU seconds, summed over every function):")
        for name, seconds in sorted(stages.items(), key=lambda item: -item[1])[:args.top]:
            print(f"{seconds:7.2f}  {name}")
        print("by function and stage (the largest; own CPU seconds):")
        for (function, name), seconds in sorted(by_function.items(), key=lambda item: -item[1])[:args.top]:
            print(f"{seconds:7.2f}  {function.rsplit('.', 1)[-1]:<40} {name}")


def time_stages(compiling: list) -> tuple[dict, dict]:
    """Wrap Numba's compiler passes, the wrappers' lowering and its code library's LLVM stages to sum each one's
    own CPU seconds (a stage nested in another, such as a callee's compile inside its caller's type inference,
    is left out of the outer one) into the first dict returned, and per (function, stage) into the second, the
    function the innermost compile on ``compiling`` (the compile events' stack); both filled as the run
    compiles."""
    from numba.core import codegen, compiler_machinery, lowering

    own, by_function, stack = {}, {}, []

    def timed(name, method):
        def run(*args, **kwargs):
            stack.append([time.process_time(), 0.0])
            try:
                return method(*args, **kwargs)
            finally:
                start, nested = stack.pop()
                spent = time.process_time() - start
                own[name] = own.get(name, 0.0) + spent - nested
                key = (compiling[-1][0] if compiling else "(none)", name)
                by_function[key] = by_function.get(key, 0.0) + spent - nested
                if stack:
                    stack[-1][1] += spent
        return run

    run_pass = compiler_machinery.PassManager._runPass

    def _runPass(self, index, pss, state):
        return timed(f"pass {pss.name()}", run_pass)(self, index, pss, state)

    compiler_machinery.PassManager._runPass = _runPass
    for cls, method, name in [
            (lowering.Lower, "create_cpython_wrapper", "lowering the CPython wrapper"),
            (lowering.Lower, "create_cfunc_wrapper", "lowering the C wrapper"),
            (codegen.CPUCodeLibrary, "add_ir_module", "LLVM IR text parsed"),
            (codegen.CPUCodeLibrary, "_optimize_functions", "LLVM function passes"),
            (codegen.CPUCodeLibrary, "_optimize_final_module", "LLVM final module (callees linked in)"),
            (codegen.JITCodeLibrary, "_finalize_specific", "LLVM machine code")]:
        setattr(cls, method, timed(name, getattr(cls, method)))
    return own, by_function


if __name__ == "__main__":
    main()
