"""How ropesim compiles its kernels: one decorator for every compiled function, and compile-time switches.

``kernel`` (used as ``@jit.kernel``, the module named at every use so that a reader, and
``../shared/tools/shape.py``, sees a compiled function) is Numba's ``njit`` in nopython mode with four
settings fixed for the whole code base:

- ``cache=True``: compiled machine code is kept on disk (see :mod:`ropesim.io.numba_cache`), so only the
  first run of a scene's methods compiles;
- ``error_model="numpy"``: a division by zero gives inf or nan, as in NumPy, instead of raising (the blow-up
  check then stops the run, and the loops need no zero tests);
- no C wrapper (``no_cfunc_wrapper``): Numba would lower, optimise and emit one for every function, for its
  use as a first-class function or C callback, which no kernel is (:class:`Kernel` drops the CPython wrapper
  too, for the kernels only kernels call);
- no reference counting (Numba's private ``_nrt=False``). Numba counts references to every array a compiled
  function receives: an atomic increment on entry and a decrement on exit, per array and per call. The
  force terms receive the model's parameter bundle (some twenty arrays) several times per stage, so the
  counting cost more than the forces on ropes of tens of nodes (rk4 on ``helicopter_mass``: 7.2 µs per step
  with counting, 1.8 µs without, measured on one loaded machine). A kernel only *borrows* the arrays it is
  given (the integrator holds them for the whole call) and allocates none, so the counting protects nothing.
  Numba refuses to compile a kernel that would allocate, so this cannot go wrong silently: such a function
  uses plain ``njit``. ``tests/test_performance_invariants.py`` checks that the compiled term list counts no
  references, so a Numba release that changed the option would be noticed.

**Compile-time switches.** A scene compiles only the parts it uses. A kernel tests a part with a
:class:`Switch`, a module-level name it reads as a plain condition (``if WITH_SEABED:``, also inside ``and``,
``or`` and ``x if WITH_GRAVITY else 0.0``). Such a kernel is a template: :func:`specialise` makes a copy of
it for given switch values, with each switch replaced by True or False in the copy's globals, and Numba's
dead-branch pruning removes the false branches *before* typing, so the kernels behind them are never typed
nor compiled. Kernels that call a switched kernel are copied too, down the call graph, so a family's loop
specialised for a scene calls that scene's term list; kernels that read no switch, directly or through
their callees (the force terms themselves, the banded solver), are shared by every copy.

Each copy is an ordinary cached Numba function: its qualified name carries the values of the switches it
reads (``accelerations__s1a`` for one set), so Numba's on-disk cache keeps one entry per set, found again by
a new process, and stamped by the source file as every cached function is. Two scenes that agree on the
switches a kernel reads share its copy (and its cache entry): the energy check of a scene with fluid drag is
the one of the same scene without it. A template itself cannot run: a switch's module-level value is a
:class:`Switch` object, which Numba refuses to type, so calling an unspecialised template fails at once
instead of compiling every part.

Measured on the 2-core machine (numba 0.68): this is one of the two designs that reload from the cache in a
new process (generated source files are the other, with a code generator to maintain); a closure composed at
run time, ``literal_unroll`` over a tuple of kernels and a kernel passed as an argument all recompile in
every process; runtime flags (the design before this) compile every term for every scene.
"""

from __future__ import annotations

import dis
import re
import types
from dataclasses import dataclass

from numba import njit
from numba.core import types as numba_types
from numba.core.registry import CPUDispatcher

OPTIONS = {"cache": True, "error_model": "numpy", "_nrt": False, "no_cfunc_wrapper": True}


def kernel(function=None, *, inline: str = "never", literal_integers: bool = True):
    """Compile ``function`` as a ropesim kernel (see the module doc); ``@kernel`` or ``@kernel(inline="always")``
    (Numba's inlining at its own IR level, for small helpers called in the innermost loops);
    ``literal_integers=False``: compiled once for integer constants (:class:`PlainIntegers`)."""
    def decorate(fn):
        dispatcher = njit(inline=inline, **OPTIONS)(fn)
        if inline == "never":   # an inlined helper is never compiled for a kernel's call: no twin needed
            dispatcher.__class__ = PlainIntegers if not literal_integers else Kernel
        dispatcher.ropesim_inline = inline   # for specialise's copies (Numba keeps no record of the jit options)
        return dispatcher

    return decorate(function) if function is not None else decorate


INTERNAL_SUFFIX = "__i"
"""Appended to a kernel's qualified name for its :attr:`Kernel.internal` twin (its own entry in Numba's cache)."""


class Kernel(CPUDispatcher):
    """Numba's dispatcher for a kernel that other kernels call: a call from compiled code goes to an internal twin
    compiled without Numba's two wrappers, unless this dispatcher already has the call's types compiled.

    Numba gives every function it compiles a CPython wrapper (unboxing each argument from Python objects: some
    140 values for a bundle of twenty arrays) and a C wrapper, lowers them to LLVM IR, optimises them and emits
    their machine code, and does so again in every caller its library is linked into, only to discard them
    there. Only a kernel called from Python needs them. A kernel's first compile for a call from another kernel
    therefore compiles :attr:`internal`, a copy of the same function (same code, same globals) under the name
    ``<qualname>__i`` with ``no_cpython_wrapper`` and ``no_cfunc_wrapper`` set: the machine code of its body
    is the same, and its cache entry is its own, so a process never finds a wrapper-less copy when Python calls
    the kernel. ``mooring_chain``'s first run: about 2.5 s of CPU less of 17 (``scripts/profile_compile.py``,
    see the performance log). A kernel compiled for Python first is linked as it is (one compile, not two)."""

    @property
    def internal(self):
        twin = self.__dict__.get("ropesim_internal")
        if twin is None:
            function = self.py_func
            clone = types.FunctionType(function.__code__, function.__globals__, function.__name__,
                                       function.__defaults__, function.__closure__)
            clone.__qualname__ = function.__qualname__ + INTERNAL_SUFFIX
            clone.__module__, clone.__doc__ = function.__module__, function.__doc__
            twin = njit(no_cpython_wrapper=True, **OPTIONS)(clone)
            twin.ropesim_template = template_of(self)
            self.__dict__["ropesim_internal"] = twin
        return twin

    def _target(self, args):
        """Who compiles a call from compiled code with argument types ``args``: this dispatcher when it has them
        compiled already (for Python), else its internal twin."""
        return self if tuple(args) in self.overloads else self.internal

    def get_call_template(self, args, kws):
        target = self._target(self._compiler.fold_argument_types(args, kws)[1])
        return super().get_call_template(args, kws) if target is self else target.get_call_template(args, kws)

    def get_overload(self, sig):
        args = sig if isinstance(sig, tuple) else sig.args
        target = self._target(args)
        return super().get_overload(sig) if target is self else target.get_overload(sig)


class PlainIntegers(Kernel):
    """Numba's dispatcher, but a call from compiled code passes a constant integer as a plain integer.

    Numba types an integer constant argument (``offset(m, j, 3, t)``) as a literal, and compiles the callee
    once for every constant it is called with: a driven rigid body's six degrees of freedom compiled the
    motion law seven times (0.35 s each). A kernel made with ``literal_integers=False`` is compiled once, for
    int64. Not the default: a constant stride or offset (``add_pair_springs(..., 2, ...)``) lets LLVM fold it
    into the loop, and the stiff integrator's Newton matrix ran up to a fifth slower without it
    (``scripts/bench_compare.py``, one loaded run). Boolean constants stay literal either way."""

    def get_call_template(self, args, kws):
        return super().get_call_template(tuple(_plain(a) for a in args), {k: _plain(a) for k, a in kws.items()})


def _plain(numba_type):
    """An integer literal's type as a plain integer (int64); any other type as it is."""
    return numba_types.unliteral(numba_type) if isinstance(numba_type, numba_types.IntegerLiteral) else numba_type


@dataclass(frozen=True)
class Switch:
    """A compile-time switch: a part of the model (a force term, the plain stage, prescribed motion) that a
    kernel compiles only when a scene has it. Bound to a module-level name that kernels test
    (``if WITH_SEABED:``); :func:`specialise` replaces it with True or False. ``name`` is its key in a set of
    switches (:data:`Switches`)."""

    name: str
    doc: str = ""


Switches = frozenset
"""The names of the switches that are on, for :func:`specialise` (every other switch is off)."""


_reads: dict = {}
_copies: dict = {}
COPY_SUFFIX = re.compile(r"(__s[0-9a-f]+)?(__i)?$")


LOAD_GLOBAL, EXTENDED_ARG = dis.opmap["LOAD_GLOBAL"], dis.EXTENDED_ARG


def _globals_read(function) -> set[str]:
    """The global names ``function``'s code loads (nested code objects included; not attribute names, which
    share ``co_names`` with them). Read straight from the bytecode (``dis.get_instructions`` took a tenth of a
    second per run for the families' call graphs): LOAD_GLOBAL's argument is the name's index times two
    (Python 3.11 and later), an EXTENDED_ARG prefix its high bits."""
    names, stack = set(), [function.__code__]
    while stack:
        code = stack.pop()
        raw, high = code.co_code, 0
        for i in range(0, len(raw), 2):
            op, arg = raw[i], raw[i + 1] | high
            high = arg << 8 if op == EXTENDED_ARG else 0
            if op == LOAD_GLOBAL:
                names.add(code.co_names[arg >> 1])
        stack.extend(c for c in code.co_consts if isinstance(c, types.CodeType))
    return names


def switches_read(dispatcher) -> frozenset:
    """The names of the switches ``dispatcher`` reads, itself or through the kernels it calls."""
    if dispatcher in _reads:
        return _reads[dispatcher]
    _reads[dispatcher] = frozenset()   # a recursive kernel reads what its other callees read
    function, found = dispatcher.py_func, set()
    for name in _globals_read(function):
        value = function.__globals__.get(name)
        if isinstance(value, Switch):
            found.add(value.name)
        elif isinstance(value, CPUDispatcher):
            found |= switches_read(value)
    _reads[dispatcher] = frozenset(found)
    return _reads[dispatcher]


def specialise(dispatcher, on: Switches):
    """``dispatcher``'s copy for the switches named in ``on`` (every other switch off); ``dispatcher`` itself
    when it reads no switch. Copies are made once per process and per values of the switches they read."""
    reads = switches_read(dispatcher)
    if not reads:
        return dispatcher
    values = tuple(name in on for name in sorted(reads))
    key = (dispatcher, values)
    copy = _copies.get(key)
    if copy is None:
        function = dispatcher.py_func
        namespace = dict(function.__globals__)
        for name in _globals_read(function):
            value = namespace.get(name)
            if isinstance(value, Switch):
                namespace[name] = value.name in on
            elif isinstance(value, CPUDispatcher) and switches_read(value):
                namespace[name] = specialise(value, on)
        clone = types.FunctionType(function.__code__, namespace, function.__name__, function.__defaults__,
                                   function.__closure__)
        bits = sum(1 << i for i, value in enumerate(values) if value)
        clone.__qualname__ = f"{function.__qualname__}__s{bits:x}"   # its own entry in Numba's cache (COPY_SUFFIX)
        clone.__module__, clone.__doc__ = function.__module__, function.__doc__
        copy = kernel(clone, inline=getattr(dispatcher, "ropesim_inline", "never"),
                      literal_integers=not isinstance(dispatcher, PlainIntegers))
        copy.ropesim_template = dispatcher
        _copies[key] = copy
    return copy


def template_of(dispatcher):
    """The template a :func:`specialise` copy was made from (``dispatcher`` itself when it is none)."""
    return getattr(dispatcher, "ropesim_template", dispatcher)


def template_name(qualname: str) -> str:
    """A compiled function's name without the switch values :func:`specialise` appends to a copy's."""
    return COPY_SUFFIX.sub("", qualname)


class Direct:
    """``dispatcher`` called without Numba's type dispatch: the first call goes through it (compiling if need
    be) and finds the compiled copy for its arguments' types; every later call enters that copy directly.

    Numba's dispatch types every argument at every call, and the bundles (namedtuples of arrays) cost tens of
    microseconds to type, several times a small system's step: what a coupling step of one internal step must
    not pay (:mod:`ropesim.coupling`). Only for calls whose arguments keep their types from call to call (the
    same bundles, arrays of the same dtype, dimensions and layout, Python ints and floats where they were):
    the copy checks nothing."""

    def __init__(self, dispatcher):
        self.dispatcher, self.entry = dispatcher, None

    @property
    def fast(self):
        """What to call: the compiled copy itself once the first call has found it (a call through this object
        costs about a microsecond more, in Python), this object before."""
        return self if self.entry is None else self.entry

    def __call__(self, *args):
        if self.entry is not None:
            return self.entry(*args)
        from numba import typeof

        out = self.dispatcher(*args)
        compiled = self.dispatcher.overloads.get(tuple(typeof(a) for a in args))
        if compiled is not None:
            self.entry = compiled.entry_point
        return out
