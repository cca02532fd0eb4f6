"""Where the test suite's CPU goes: compiling against running, per test and per file, and the kernels that only
one test needs.

    python -m pytest -n 2 --compile-profile=/tmp/profile            # any selection; -m slow for the slow suite
    python scripts/suite_profile.py /tmp/profile [--top 40]

The first command (tests/compile_profile, an option of tests/conftest.py) writes one line per test; add
``ROPESIM_TEST_FRESH_CACHE=1`` to start from an empty compile cache, as CI does, or leave it out to see what a
second run on unchanged sources costs (give each run a new folder: records are appended). This script
prints:

- the totals: CPU seconds in the pytest workers and in the subprocesses the tests ran, and how much of it
  Numba spent compiling (outermost compiles only: a loop's compile includes its callees');
- per file and for the costliest tests: CPU, compile CPU, subprocesses' CPU, compiles, and ``own``: the
  compiled copies (:func:`ropesim.model.jit.specialise`; a family's loop for one set of terms) that no other
  test of the run asks for, with their compile seconds. Moving such a test to the slow suite, or giving it a
  term set other tests already compile, saves its ``own`` seconds; moving a test whose compiles other tests
  also need only moves the bill to them (a compile is charged to the first test that needs the kernel);
- the functions compiled again by another test, by the files involved: another signature, or two workers
  that both missed the cache and compiled the same kernel side by side (``SHARED_LOOPS`` in
  tests/conftest.py puts such files on one worker, one after the other).

A kernel that is not a specialised copy (a helper, the static solver) is charged to the test that compiled it
first and is never counted as ``own``.
"""

from __future__ import annotations

import argparse
import json
from collections import defaultdict
from pathlib import Path


def load(folder: Path) -> dict[str, dict]:
    """Every test's record, its subprocesses' compiles and copies asked for merged in."""
    tests: dict[str, dict] = {}
    for path in sorted(folder.glob("tests-*.jsonl")):
        for line in path.read_text().splitlines():
            record = json.loads(line)
            tests[record["test"]] = {**record, "asked": set(record["asked"]), "child_compile_cpu": 0.0}
    for path in sorted((folder / "children").glob("*.jsonl")):
        for line in path.read_text().splitlines():
            try:
                record = json.loads(line)
            except json.JSONDecodeError:   # a child killed mid-line (the fault tests)
                continue
            test = tests.get(record["test"])
            if test is None:
                continue
            if "asked" in record:
                test["asked"].add(record["asked"])
            else:
                test["compiles"].append([record["compile"], record["seconds"], record["depth"]])
                if record["depth"] == 0:
                    test["child_compile_cpu"] += record["seconds"]
    return tests


def own_compiles(tests: dict[str, dict]) -> dict[str, list]:
    """Per test: ``[name, seconds, depth]`` of the copies it compiled that no other test asked for."""
    askers: dict[str, int] = defaultdict(int)
    for test in tests.values():
        for name in test["asked"]:
            askers[name] += 1
    return {nodeid: [row for row in test["compiles"] if askers.get(row[0]) == 1 and row[0] in test["asked"]]
            for nodeid, test in tests.items()}



def file_own_compiles(tests: dict[str, dict]) -> dict[str, float]:
    """Per file: seconds compiling the copies that only its tests ask for (moving the file, or the tests of it
    that ask for them, saves these)."""
    files_asking: dict[str, set] = defaultdict(set)
    for nodeid, test in tests.items():
        for name in test["asked"]:
            files_asking[name].add(nodeid.split("::")[0])
    out: dict[str, float] = defaultdict(float)
    for nodeid, test in tests.items():
        rows = [row for row in test["compiles"] if files_asking.get(row[0]) == {nodeid.split("::")[0]}]
        out[nodeid.split("::")[0]] += outermost(rows)
    return out


def repeated_compiles(tests: dict[str, dict]) -> dict[tuple, float]:
    """Seconds spent compiling again a function that another test compiled too (outermost compiles beyond the
    longest one of each name), by the files whose tests compiled it. Either another signature of the same
    function, or, across two workers, the same kernel compiled side by side, both having missed the cache (the
    files to run one after the other on one worker: ``SHARED_LOOPS`` in tests/conftest.py)."""
    by_name: dict[str, list] = defaultdict(list)
    for nodeid, test in tests.items():
        for name, seconds, depth in test["compiles"]:
            if depth == 0:
                by_name[name].append((seconds, nodeid.split("::")[0]))
    out: dict[tuple, float] = defaultdict(float)
    for rows in by_name.values():
        if len(rows) > 1:
            out[tuple(sorted({file for _, file in rows}))] += sum(s for s, _ in rows) - max(s for s, _ in rows)
    return dict(out)


def outermost(rows: list) -> float:
    """The seconds of ``rows`` (compiles) counted once: a callee compiled inside its caller (depth 1 and more)
    is in its caller's seconds. (A copy only one test needs is called only by copies only that test needs.)"""
    return sum(seconds for _, seconds, depth in rows if depth == 0)

def table(tests: dict[str, dict], top: int) -> str:
    own = own_compiles(tests)
    lines = []
    cpu = sum(t["cpu"] for t in tests.values())
    children = sum(t["children"] for t in tests.values())
    compile_cpu = sum(t["compile_cpu"] for t in tests.values())
    child_compile = sum(t["child_compile_cpu"] for t in tests.values())
    events = sum(len(t["compiles"]) for t in tests.values())
    own_total = sum(outermost(rows) for rows in own.values())
    lines += [f"{len(tests)} tests: {cpu:.0f} s CPU in the pytest workers ({compile_cpu:.0f} s compiling), "
              f"{children:.0f} s in their subprocesses ({child_compile:.0f} s compiling); {events} compile events; "
              f"{own_total:.0f} s compiling copies only one test needs", ""]
    header = f"{'CPU s':>7} {'compile':>7} {'subproc':>7} {'compiles':>8} {'own s':>6}  "
    file_own = file_own_compiles(tests)

    files: dict[str, list[float]] = defaultdict(lambda: [0.0, 0.0, 0.0, 0, 0.0])
    for nodeid, t in tests.items():
        row = files[nodeid.split("::")[0]]
        row[0] += t["cpu"]
        row[1] += t["compile_cpu"] + t["child_compile_cpu"]
        row[2] += t["children"]
        row[3] += len(t["compiles"])
        row[4] += outermost(own[nodeid])
    lines += ["per file (CPU: pytest worker; compile: worker and subprocesses; own s: copies only one of its tests "
              "needs; file's: copies only its tests need)", header + f"{'file s':>6}  file"]
    for name, (c, comp, ch, n, o) in sorted(files.items(), key=lambda kv: -(kv[1][0] + kv[1][2])):
        lines.append(f"{c:7.1f} {comp:7.1f} {ch:7.1f} {n:8d} {o:6.1f} {file_own[name]:6.1f}  {name}")

    lines += ["", f"the {top} costliest tests (worker + subprocesses)", header + "test"]
    ranked = sorted(tests.items(), key=lambda kv: -(kv[1]["cpu"] + kv[1]["children"]))[:top]
    for nodeid, t in ranked:
        lines.append(f"{t['cpu']:7.1f} {t['compile_cpu'] + t['child_compile_cpu']:7.1f} {t['children']:7.1f} "
                     f"{len(t['compiles']):8d} {outermost(own[nodeid]):6.1f}  {nodeid}")

    repeated = repeated_compiles(tests)
    lines += ["", f"compiled again by another test: {sum(repeated.values()):.0f} s (seconds beyond the first, "
              "by the files that compiled it)"]
    lines += [f"{s:7.1f}  {' + '.join(files)}" for files, s in sorted(repeated.items(), key=lambda kv: -kv[1])]

    lines += ["", "copies only one test needs (seconds to compile, copy, test)"]
    rows = sorted(((s, name, nodeid) for nodeid, r in own.items() for name, s, depth in r if depth == 0),
                  reverse=True)
    lines += [f"{s:7.1f}  {name}  {nodeid}" for s, name, nodeid in rows]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", type=Path, help="the folder given to pytest's --compile-profile")
    parser.add_argument("--top", type=int, default=40, help="how many of the costliest tests to list")
    args = parser.parse_args()
    print(table(load(args.folder), args.top))


if __name__ == "__main__":
    main()
