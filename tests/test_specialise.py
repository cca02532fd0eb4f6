"""A scene compiles only what it uses: compile-time switches (:mod:`ropesim.model.jit`) and what each scene compiles.

What compiles is observed, never inferred from timings: Numba broadcasts a ``numba:compile`` event for every
function it compiles (none for one it loads from its cache), and the probes count them by function name in a
fresh process with an empty cache.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import specialise_sample as sample
from ropesim.model import jit

ROOT = Path(__file__).resolve().parent.parent
TESTS = Path(__file__).resolve().parent

LISTENER = textwrap.dedent("""
    import json, sys
    from numba.core import event

    compiled = []

    class Listener(event.Listener):
        def on_start(self, ev):
            f = ev.data["dispatcher"].py_func
            compiled.append(f"{f.__module__}.{f.__qualname__}")

        def on_end(self, ev):
            pass

    event.register("numba:compile", Listener())
""")


def _probe(code: str, cache: Path) -> list:
    """Run ``code`` after LISTENER in a fresh process with Numba's cache at ``cache``; the JSON it prints last."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": os.pathsep.join([str(TESTS), str(ROOT)])}
    done = subprocess.run([sys.executable, "-c", LISTENER + textwrap.dedent(code)], capture_output=True, text=True,
                          env=env, timeout=600, cwd=ROOT)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


# ---------------------------------------------------------------------------------------------- the mechanism

def test_a_kernel_that_reads_no_switch_is_its_own_copy():
    assert jit.specialise(sample.squares, frozenset({"sample_squares"})) is sample.squares
    assert jit.switches_read(sample.plain_sum) == frozenset()


def test_switches_are_read_through_callees_and_inlined_helpers():
    assert jit.switches_read(sample.total) == {"sample_squares", "sample_cubes"}
    assert jit.switches_read(sample.only_squares) == {"sample_squares"}


def test_each_copy_computes_with_its_switches_and_is_made_once():
    a = np.array([1.0, 2.0, 3.0])
    expected = {(): 6.0, ("sample_squares",): 6.0 + 14.0, ("sample_cubes",): 6.0 + 36.0,
                ("sample_squares", "sample_cubes"): 6.0 + 14.0 + 36.0}
    copies = {}
    for on, value in expected.items():
        copy = jit.specialise(sample.total, frozenset(on))
        assert copy(a) == value, on
        assert jit.specialise(sample.total, frozenset(on)) is copy
        assert jit.template_of(copy) is sample.total
        assert jit.template_name(copy.py_func.__qualname__) == "total"
        copies[on] = copy
    assert len({id(c) for c in copies.values()}) == 4
    # a copy depends only on the switches it reads: unrelated switches share it
    assert jit.specialise(sample.only_squares, frozenset({"sample_cubes"})) is jit.specialise(sample.only_squares,
                                                                                               frozenset())


def test_integer_constants_passed_to_a_kernel_compile_it_once(tmp_path):
    """A kernel called from compiled code with three integer constants compiles once (Numba alone compiles it
    for each constant, as a literal: a driven body's motion law seven times), and computes the same."""
    code = """
        import numpy as np
        import specialise_sample as sample
        value = sample.first_three(np.array([1.0, 2.0, 4.0, 8.0]))
        twin = sample.element.internal   # what a call from compiled code compiles (jit.Kernel)
        print(json.dumps([value, [str(s) for s in twin.signatures], sample.element.signatures]))
    """
    value, signatures, python_signatures = _probe(code, tmp_path / "cache")
    assert value == 7.0
    assert signatures == ["(Array(float64, 1, 'C', False, aligned=True), int64)"] and python_signatures == []


def test_a_kernel_called_from_compiled_code_compiles_without_wrappers_and_python_still_calls_it(tmp_path):
    """A kernel first compiled for another kernel's call compiles its wrapper-less twin (jit.Kernel.internal)
    and a later call from Python compiles the kernel itself; a kernel compiled for Python first is what a
    compiled caller links, without a second compile. Both orders compute the same."""
    twin = sample.element.internal
    assert twin.targetoptions["no_cpython_wrapper"] and twin.targetoptions["no_cfunc_wrapper"]
    assert jit.template_name(twin.py_func.__qualname__) == "element" and jit.template_of(twin) is sample.element
    code = """
        import numpy as np
        import specialise_sample as sample
        a = np.array([1.0, 2.0, 4.0, 8.0])
        calls = [lambda: sample.first_three(a), lambda: sample.element(a, 3)]
        values = [call() for call in (calls if sys.argv[1:] == ["caller"] else calls[::-1])]
        print(json.dumps([sorted(values), [n.rsplit(".", 1)[-1] for n in compiled]]))
    """
    caller_first = _probe(code.replace("sys.argv[1:]", "['caller']"), tmp_path / "one")
    assert caller_first == [[7.0, 8.0], ["first_three", "element__i", "element"]]
    python_first = _probe(code.replace("sys.argv[1:]", "['python']"), tmp_path / "two")
    assert python_first == [[7.0, 8.0], ["element", "first_three"]]


def test_a_template_cannot_run_unspecialised():
    from numba.core.errors import TypingError

    with pytest.raises(TypingError, match="WITH_SQUARES|WITH_CUBES"):
        sample.total(np.ones(2))


def test_a_switched_off_kernel_is_never_compiled_and_copies_load_from_the_cache(tmp_path):
    code = """
        import numpy as np
        from ropesim.model import jit
        import specialise_sample as sample
        on = frozenset(sys.argv[1:])
        value = jit.specialise(sample.total, on)(np.array([1.0, 2.0]))
        print(json.dumps([value, compiled]))
    """
    cache = tmp_path / "cache"
    first = _probe(code.replace("sys.argv[1:]", "[]"), cache)
    assert first[0] == 3.0
    names = [jit.template_name(name.rsplit(".", 1)[-1]) for name in first[1]]
    assert "squares" not in names and "cubes" not in names and jit.template_name(names[0]) == "total"
    squares = _probe(code.replace("sys.argv[1:]", "['sample_squares']"), cache)
    assert squares[0] == 3.0 + 5.0
    assert "squares" in [jit.template_name(n.rsplit(".", 1)[-1]) for n in squares[1]]
    assert "cubes" not in [jit.template_name(n.rsplit(".", 1)[-1]) for n in squares[1]]
    again = _probe(code.replace("sys.argv[1:]", "[]"), cache)
    assert again == [3.0, []]   # loaded from Numba's cache in a new process: nothing compiles


# ------------------------------------------------------------------------------------------- what scenes compile

RUNS = """
    import ropesim
    from ropesim.model.jit import template_name
    for method in ("symplectic_euler", "rk4", "sdirk2"):
        scene = ropesim.load_scene(SCENE, [f"integrator.method={method}", "integrator.t_end=0.02"] + SETS)
        ropesim.simulate(scene)
    print(json.dumps(sorted({n.rsplit(".", 1)[0] + "." + template_name(n.rsplit(".", 1)[1]) for n in compiled})))
"""
LOOPS = ("ropesim.integrate.splitting.advance_splitting", "ropesim.integrate.rk.advance_rk",
         "ropesim.integrate.sdirk.advance_sdirk")

UNUSED = ("ropesim.model.forces.fluid", "ropesim.model.forces.seabed", "ropesim.model.forces.bending",
          "ropesim.model.forces.thrower", "ropesim.model.forces.guides", "ropesim.model.forces.added_mass",
          "ropesim.model.forces.flow_inertia", "ropesim.model.forces.buoyancy", "ropesim.integrate.contact",
          "ropesim.integrate.velocity_kick", "ropesim.model.motion")


def _compiled_by(tmp_path, scene: str, sets: list[str]) -> list[str]:
    """The functions (module.name, switch values left out) a run of ``scene`` with each family compiles."""
    names = _probe(RUNS.replace("SCENE", repr(scene)).replace("SETS", repr(sets)), tmp_path / "cache")
    assert all(loop in names for loop in LOOPS), names   # the probe saw the compiles
    return names


@pytest.mark.slow
def test_a_rope_of_springs_and_gravity_compiles_no_other_term(tmp_path):
    """helicopter_uniform in 3-D (off the plain stage, so the general stage's term list compiles too): none
    of the fluid, seabed, bending, thrower or guide kernels, nor the velocity kick, contacts or motion."""
    sets = ["dimension=3", "initial.top=[0.0, 0.0, 0.0]", "initial.velocity=[8.0, 0.0, 0.0]",
            "driven.0.velocity=[8.0, 0.0, 0.0]"]
    names = _compiled_by(tmp_path, "helicopter_uniform", sets)
    assert "ropesim.model.forces.springs.set_chain_springs" in names
    assert [n for n in names if n.startswith(UNUSED) or n.endswith("add_pair_springs")] == []
    assert not any(".plain." in n for n in names)   # 3-D: no plain stage


@pytest.mark.slow
def test_a_declared_term_is_what_compiles(tmp_path):
    """The same probe sees a term's kernels as soon as a scene declares it: the seabed's, and no other term's
    (its friction depends on velocity, so the splitting schemes' velocity kick compiles too)."""
    names = _compiled_by(tmp_path, "helicopter_uniform", ["seabed.height=-100.0", "seabed.contact_width=0.05"])
    assert {"ropesim.model.forces.seabed.add_seabed_contact", "ropesim.model.forces.seabed.add_seabed_friction",
            "ropesim.model.forces.seabed.add_seabed_jacobian"} <= set(names)
    assert [n for n in names if n.startswith(UNUSED[:8]) and not n.startswith("ropesim.model.forces.seabed")] == []


def test_the_bytecode_scan_finds_the_globals_dis_finds_in_every_kernel():
    """jit._globals_read reads LOAD_GLOBAL straight from the bytecode; dis decodes it the slow, sure way."""
    import dis
    import importlib
    import pkgutil

    from numba.core.registry import CPUDispatcher

    import ropesim

    checked = 0
    for info in pkgutil.walk_packages(ropesim.__path__, "ropesim."):
        if info.name.endswith("__main__"):
            continue
        module = importlib.import_module(info.name)
        for value in vars(module).values():
            if isinstance(value, CPUDispatcher) and value.py_func.__module__ == module.__name__:
                code = value.py_func.__code__
                want = {op.argval for op in dis.get_instructions(code) if op.opname == "LOAD_GLOBAL"}
                assert jit._globals_read(value.py_func) == want, value.py_func.__qualname__
                checked += 1
    assert checked > 80


SEA_PROBE = """
import json
import numpy as np
import ropesim
from ropesim.model.build import build
from ropesim.model.forces.sea import water_state

model = build(ropesim.load_scene(SCENE), solve=False)
model.kernel(water_state)(np.ascontiguousarray(model.x0), model.params, 0.5)
print(json.dumps([jit_name for jit_name in compiled]))
"""


@pytest.mark.slow
@pytest.mark.parametrize("scene, used, unused", [
    ("floating_hose", "direct_kinematics", "recurrence_kinematics"),          # a regular wave
    ("mooring_chain_waves", "recurrence_kinematics", "direct_kinematics"),    # a JONSWAP spectrum
])
def test_the_sea_compiles_only_the_wave_evaluation_its_waves_take(tmp_path, scene, used, unused):
    names = [jit.template_name(n) for n in _probe(SEA_PROBE.replace("SCENE", repr(scene)), tmp_path / "cache")]
    assert f"ropesim.model.waves.{used}" in names, names
    assert f"ropesim.model.waves.{unused}" not in names, names
    assert ("ropesim.model.waves.water_at" in names) == (used == "direct_kinematics"), names


def test_the_seas_switches_follow_its_waves_and_fraction_rule():
    import ropesim
    from ropesim.model.terms import switches

    hose = switches(ropesim.load_scene("floating_hose"))
    assert {"sea", "waves"} <= hose and not {"wave_recurrence", "moordyn_fraction"} & hose
    chain = switches(ropesim.load_scene("mooring_chain_waves", ['sea.fraction="moordyn"']))
    assert {"sea", "waves", "wave_recurrence", "moordyn_fraction"} <= chain
    assert not {"waves", "wave_recurrence", "moordyn_fraction"} & switches(ropesim.load_scene("mooring_chain"))
