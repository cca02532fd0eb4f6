"""scripts/suite_profile.py: the table of `--compile-profile`'s records, on records written by hand."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
spec = importlib.util.spec_from_file_location("suite_profile", ROOT / "scripts" / "suite_profile.py")
suite_profile = importlib.util.module_from_spec(spec)
spec.loader.exec_module(suite_profile)

LOOP, TERM, SHARED = "m.loop__s3", "m.term__s1", "m.shared__s0"


def _write(folder: Path) -> None:
    """Three tests: a compiles a loop (with a term inside it) that only it needs; b compiles a loop c needs too;
    c compiles nothing in its process, but its subprocess compiles a helper."""
    records = [
        {"test": "tests/test_a.py::a", "cpu": 10.0, "children": 0.0, "wall": 11.0, "compile_cpu": 8.0,
         "compiles": [[TERM, 2.0, 1], [LOOP, 8.0, 0]], "asked": [LOOP, TERM]},
        {"test": "tests/test_a.py::b", "cpu": 5.0, "children": 0.0, "wall": 5.0, "compile_cpu": 4.0,
         "compiles": [[SHARED, 4.0, 0]], "asked": [SHARED]},
        {"test": "tests/test_c.py::c", "cpu": 1.0, "children": 3.0, "wall": 4.0, "compile_cpu": 0.0,
         "compiles": [], "asked": [SHARED]},
    ]
    (folder / "tests-gw0.jsonl").write_text("".join(json.dumps(r) + "\n" for r in records))
    (folder / "children").mkdir()
    (folder / "children" / "123.jsonl").write_text(
        json.dumps({"test": "tests/test_c.py::c", "compile": "m.helper", "seconds": 2.5, "depth": 0}) + "\n"
        + json.dumps({"test": "tests/test_c.py::c", "asked": "m.other__s2"}) + "\n" + '{"test": "tests/te')


def test_a_copy_only_one_test_needs_is_its_own_and_callees_count_once(tmp_path):
    _write(tmp_path)
    tests = suite_profile.load(tmp_path)
    assert tests["tests/test_c.py::c"]["asked"] == {SHARED, "m.other__s2"}   # the torn last line is skipped
    assert tests["tests/test_c.py::c"]["child_compile_cpu"] == 2.5
    own = suite_profile.own_compiles(tests)
    assert [row[0] for row in own["tests/test_a.py::a"]] == [TERM, LOOP]
    assert suite_profile.outermost(own["tests/test_a.py::a"]) == 8.0          # the term inside the loop's 8 s
    assert own["tests/test_a.py::b"] == [] and own["tests/test_c.py::c"] == []   # c asks for the shared loop too
    assert suite_profile.file_own_compiles(tests) == {"tests/test_a.py": 8.0, "tests/test_c.py": 0.0}


def test_the_table_sums_workers_and_subprocesses(tmp_path):
    _write(tmp_path)
    text = suite_profile.table(suite_profile.load(tmp_path), top=2)
    assert text.splitlines()[0] == ("3 tests: 16 s CPU in the pytest workers (12 s compiling), 3 s in their "
                                    "subprocesses (2 s compiling); 4 compile events; 8 s compiling copies only "
                                    "one test needs")
    rows = {line.split()[-1]: line.split()[:-1] for line in text.splitlines() if line.strip().endswith(".py")}
    assert rows["tests/test_a.py"] == ["15.0", "12.0", "0.0", "3", "8.0", "8.0"]
    assert rows["tests/test_c.py"] == ["1.0", "2.5", "3.0", "1", "0.0", "0.0"]
    assert "    8.0  m.loop__s3  tests/test_a.py::a" in text.splitlines()


def test_a_function_compiled_by_two_tests_counts_beyond_the_first(tmp_path):
    _write(tmp_path)
    tests = suite_profile.load(tmp_path)
    assert suite_profile.repeated_compiles(tests) == {}
    tests["tests/test_c.py::c"]["compiles"].append([SHARED, 3.0, 0])   # c compiled b's loop as well
    tests["tests/test_c.py::c"]["compiles"].append([TERM, 1.0, 1])     # inside it: not counted again
    assert suite_profile.repeated_compiles(tests) == {("tests/test_a.py", "tests/test_c.py"): 3.0}
    assert "    3.0  tests/test_a.py + tests/test_c.py" in suite_profile.table(tests, top=2).splitlines()
