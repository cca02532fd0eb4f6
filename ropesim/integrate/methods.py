"""``METHODS``: every integration method by name, the same name in TOML, on the command line and in code.

Each entry is a :class:`~ropesim.integrate.base.Method` whose ``family`` runs it (see
:mod:`ropesim.integrate.base` for the contract): :func:`make_integrator` is all a caller needs.
"""

from __future__ import annotations

from .base import Integrator
from .galpha import GALPHA
from .rk import RK4
from .sdirk import SDIRK2
from .splitting import SCHEMES

METHODS: dict = {m.name: m for m in (*SCHEMES, RK4, SDIRK2, GALPHA)}


def get_method(name: str):
    try:
        return METHODS[name]
    except KeyError:
        raise ValueError(f"unknown integrator {name!r}: allowed {', '.join(METHODS)}") from None


def make_integrator(model, grid, name: str | None = None) -> Integrator:
    """The integrator of method ``name`` (default: the scene's) for ``model`` on ``grid``."""
    method = get_method(name or model.scene.integrator.method)
    return method.family(model, grid, method)
