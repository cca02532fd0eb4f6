"""How to compile only the force terms a scene declares: five designs measured on one toy term list.

The toy: K = 6 force terms, each a compiled kernel of the size of one of ropesim's (a loop over the nodes of a
(3, N) rope with a square root, a division and trigonometry), a term list that adds the declared ones, and a
time loop that calls the term list. A "scene" declares a set of terms. Every design is run in new processes
with an empty Numba cache (cold), then again on the cache it left (warm, a new process), for a scene
declaring one term and for one declaring all six:

- ``flags``: the terms behind runtime flags (``if flags[i]:``), one signature for every scene: ropesim's
  design before issue 19;
- ``literal``: the switches as ``numba.literally`` arguments of the loop, so that Numba's dead-branch pruning
  removes the undeclared terms for each literal signature;
- ``closure``: the term list composed at run time, a closure over the declared terms' switches;
- ``generated``: source text generated per term set, written to a file in the cache folder and imported;
- ``copies``: ``ropesim.model.jit.specialise``, a copy of the template loop and term list per set of
  switches, with the switches bound as constants in the copy's globals (the design chosen).

Columns: CPU seconds of the cold process and of the warm one (Python and Numba start-up included), the
number of functions Numba compiled in each (0 when warm: everything came from the cache), and whether the
one-term scene, run on the cache the all-terms scene left (one cache for every scene, as a user has), gives
the answer it gives alone: a design whose cache entries do not tell term sets apart loads another set's code.

    python scripts/bench_specialisation.py [--terms 6] [--rounds 1]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

from rich.console import Console
from rich.table import Table

ROOT = Path(__file__).resolve().parent.parent

TERM = '''
@njit(cache=True)
def term{i}(x, acc):
    n = x.shape[1]
    for j in range(n - 1):
        d0 = x[0, j + 1] - x[0, j]
        d1 = x[1, j + 1] - x[1, j]
        d2 = x[2, j + 1] - x[2, j]
        r = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2) + {i}.0 + 1.0
        c = math.sin(r) * math.cos(d1) / r + math.tanh(d2 * {i}.0) + math.atan2(d0, r)
        acc[0, j] += c * d0
        acc[1, j] += c * d1 - math.exp(-r)
        acc[2, j] += c * d2 + math.log1p(r)
        if j > 0:
            acc[0, j - 1] -= c * d0 * 0.5
    for j in range(1, n - 1):
        q0 = x[0, j + 1] - x[0, j - 1]
        q1 = x[1, j + 1] - x[1, j - 1]
        q2 = x[2, j + 1] - x[2, j - 1] if x.shape[0] == 3 else 0.0
        s = math.hypot(q0, math.hypot(q1, q2)) + 1.0
        u = (acc[0, j] * q0 + acc[1, j] * q1 + acc[2, j] * q2) / s
        w = math.sqrt(abs(acc[0, j] - u * q0 / s)) * {i}.5
        acc[0, j] -= w * q0 / s + math.erf(u)
        acc[1, j] -= w * q1 / s + math.expm1(-abs(u))
        acc[2, j] -= w * q2 / s + math.cosh(u * 1e-3)
'''

COMMON = "import math, sys, json\nimport numpy as np\nfrom numba import njit, literally\nfrom numba.core import event\n"

LISTEN = '''
compiled = []
class _L(event.Listener):
    def on_start(self, ev): compiled.append(ev.data["dispatcher"].py_func.__qualname__)
    def on_end(self, ev): pass
event.register("numba:compile", _L())
'''

LOOP = '''
    for s in range(steps):
        for d in range(3):
            for j in range(x.shape[1]):
                acc[d, j] = 0.0
        forces(x, acc{extra})
        for d in range(3):
            for j in range(x.shape[1]):
                x[d, j] += 1e-6 * acc[d, j]
    return x[0, 0]
'''


def designs(k: int) -> dict[str, str]:
    '''Each design's module source; the module defines ``run(on)`` that steps a rope with the terms ``on``
    through a time loop ``loop`` that calls the term list ``forces``, as ropesim's loops call theirs.'''
    terms = "".join(TERM.format(i=i) for i in range(k))
    start = "    return loop(np.ones((3, 50)), np.zeros((3, 50)), 10"
    out = {}

    calls = "\n".join(f"    if flags[{i}]:\n        term{i}(x, acc)" for i in range(k))
    out["flags"] = COMMON + terms + f'''
@njit(cache=True)
def forces(x, acc, flags):
{calls}

@njit(cache=True)
def loop(x, acc, steps, flags):
{LOOP.format(extra=", flags")}

def run(on):
{start}, np.array([i in on for i in range({k})], dtype=np.uint8))
'''

    args = ", ".join(f"s{i}" for i in range(k))
    lits = "\n".join(f"    literally(s{i})" for i in range(k))
    calls = "\n".join(f"    if s{i}:\n        term{i}(x, acc)" for i in range(k))
    out["literal"] = COMMON + terms + f'''
@njit(cache=True)
def forces(x, acc, {args}):
{lits}
{calls}

@njit(cache=True)
def loop(x, acc, steps, {args}):
{lits}
{LOOP.format(extra=", " + args)}

def run(on):
{start}, *[i in on for i in range({k})])
'''

    calls = "\n".join(f"        if c{i}:\n            term{i}(x, acc)" for i in range(k))
    assign = "\n".join(f"    c{i} = {i} in on" for i in range(k))
    out["closure"] = COMMON + terms + f'''
def run(on):
{assign}

    def list_of_terms(x, acc):
{calls}

    forces = njit(cache=True)(list_of_terms)

    def loop(x, acc, steps):
{textwrap.indent(LOOP.format(extra=""), "    ")}

    loop = njit(cache=True)(loop)
{start})
'''

    out["generated"] = COMMON + terms + f'''
import importlib.util, os
def run(on):
    key = "".join("1" if i in on else "0" for i in range({k}))
    calls = "\\n".join(f"    term{{i}}(x, acc)" for i in range({k}) if i in on) or "    pass"
    source = ("from numba import njit\\nfrom __main__ import *\\n@njit(cache=True)\\ndef forces(x, acc):\\n" + calls
              + "\\n\\n@njit(cache=True)\\ndef loop(x, acc, steps):\\n" + {LOOP!r}.format(extra=""))
    path = os.path.join(os.environ["NUMBA_CACHE_DIR"], f"generated_{{key}}.py")
    if not os.path.exists(path):
        open(path, "w").write(source)
    spec = importlib.util.spec_from_file_location(f"generated_{{key}}", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    loop = module.loop
{start})
'''

    switches = "\n".join(f'S{i} = jit.Switch("toy{i}")' for i in range(k))
    calls = "\n".join(f"    if S{i}:\n        term{i}(x, acc)" for i in range(k))
    out["copies"] = COMMON + "from ropesim.model import jit\n" + switches + terms.replace(
        "@njit(cache=True)", "@jit.kernel") + f'''
@jit.kernel
def forces(x, acc):
{calls}

@jit.kernel
def loop(x, acc, steps):
{LOOP.format(extra="")}

def run(on):
    loop_for_scene = jit.specialise(loop, frozenset(f"toy{{i}}" for i in on))
{start.replace("loop(", "loop_for_scene(")})
'''
    return out


def measure(source: str, on: list[int], cache: Path, work: Path) -> dict:
    """CPU seconds, compiled functions and result of one new process running the design on the terms ``on``."""
    script = work / "toy_main.py"
    script.write_text(source + LISTEN + f"\nvalue = run({on!r})\nprint(json.dumps([compiled, value]))\n")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=os.pathsep.join([str(ROOT), str(work)]))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run([sys.executable, str(script)], env=env, capture_output=True, text=True, cwd=work)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise SystemExit(done.stderr[-3000:])
    compiled, value = json.loads(done.stdout.strip().splitlines()[-1])
    return {"cpu": (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime),
            "compiled": len(compiled), "value": value}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--terms", type=int, default=6)
    parser.add_argument("--rounds", type=int, default=1)
    args = parser.parse_args()
    results: dict = {}
    correct: dict = {}
    with tempfile.TemporaryDirectory(prefix="ropesim-specialise-") as tmp:
        work = Path(tmp)
        for r in range(args.rounds):
            for name, source in designs(args.terms).items():
                for label, on in (("one term", [0]), ("all terms", list(range(args.terms)))):
                    cache = Path(tempfile.mkdtemp(prefix="cache-", dir=work))
                    cold, warm = measure(source, on, cache, work), measure(source, on, cache, work)
                    results.setdefault((name, label), []).append((cold, warm))
                    print(f"round {r + 1} {name:<10} {label:<9} cold {cold['cpu']:5.2f} s ({cold['compiled']} "
                          f"compiled), warm {warm['cpu']:5.2f} s ({warm['compiled']} compiled)", flush=True)
                # the one-term scene on the cache the all-terms scene left: the right answer, or another set's code
                shared = measure(source, [0], cache, work)
                right = measure(source, [0], Path(tempfile.mkdtemp(prefix="cache-", dir=work)), work)["value"]
                correct.setdefault(name, []).append(shared["value"] == right)
    table = Table(title=f"A toy term list of {args.terms} terms: new processes, CPU seconds (median of {args.rounds})")
    for col in ("design", "scene", "cold CPU [s]", "compiled", "warm CPU [s]", "compiled when warm",
                "right answer from\na shared cache"):
        table.add_column(col, justify="left" if col in ("design", "scene") else "right")
    for (name, label), runs in results.items():
        table.add_row(name, label, f"{statistics.median(c['cpu'] for c, _ in runs):.2f}",
                      str(runs[0][0]["compiled"]), f"{statistics.median(w['cpu'] for _, w in runs):.2f}",
                      str(runs[0][1]["compiled"]), "yes" if all(correct[name]) else "NO")
    Console(width=120).print(table)


if __name__ == "__main__":
    main()
