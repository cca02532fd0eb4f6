"""Uniform gravity: every node accelerates at g along -y (E = m g y)."""

from numba import njit


@njit(cache=True, error_model="numpy")
def add_gravity(acc, g):
    """Add -g [m/s^2] to the y acceleration of every node."""
    n = acc.shape[1]
    for i in range(n):
        acc[1, i] -= g
