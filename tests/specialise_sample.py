"""Kernels for tests/test_specialise.py: a small template family with two switches (not a test module)."""

from ropesim.model import jit

WITH_SQUARES = jit.Switch("sample_squares", "add the sum of squares")
WITH_CUBES = jit.Switch("sample_cubes", "add the sum of cubes")


@jit.kernel
def squares(a):
    s = 0.0
    for i in range(a.shape[0]):
        s += a[i] * a[i]
    return s


@jit.kernel
def cubes(a):
    s = 0.0
    for i in range(a.shape[0]):
        s += a[i] * a[i] * a[i]
    return s


@jit.kernel
def plain_sum(a):
    return a.sum()


@jit.kernel(inline="always")
def extras(a):
    s = 0.0
    if WITH_SQUARES:
        s += squares(a)
    if WITH_CUBES or WITH_SQUARES:
        s += cubes(a) if WITH_CUBES else 0.0
    return s


@jit.kernel
def total(a):
    """plain_sum(a) plus the switched parts, through an inlined helper."""
    return plain_sum(a) + extras(a)


@jit.kernel
def only_squares(a):
    """Reads one switch alone."""
    return squares(a) if WITH_SQUARES else 0.0


@jit.kernel(literal_integers=False)
def element(a, k):
    return a[k]


@jit.kernel
def first_three(a):
    """Calls ``element`` with three integer constants."""
    return element(a, 0) + element(a, 1) + element(a, 2)
