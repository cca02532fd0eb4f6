"""Force terms, one file each, and the :class:`Term` record that tells the rest of ropesim about a term.

Every term is a compiled kernel that *adds* its acceleration [m/s^2] to ``acc``. State arrays are
structure-of-arrays: ``x``, ``v`` and ``acc`` have shape (D, N), so each coordinate is contiguous. The compiled
term list that calls the kernels, each behind its switch, is :mod:`ropesim.model.terms`; the Python side of
each term (its parameters, its energy, what it does to the stability bound) is its :class:`Term` record,
listed in ``ropesim.model.terms.TERMS``. Adding a term is described in ``CONTRIBUTING.md``.

Linear isotropic drag (``[drag]``, per-node b) is not a kernel here: each integrator family treats it itself,
exactly inside the splitting schemes' kicks (see :mod:`ropesim.integrate.splitting`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..jit import Switch


def _none(*_args) -> None:
    return None


def _zero(*_args) -> float:
    return 0.0


@dataclass(frozen=True)
class Term:
    """What ropesim needs to know about one force term, besides its compiled kernel.

    ``switch`` is the term's compile-time :class:`~ropesim.model.jit.Switch` (None for a term that is always
    on): the term list calls the term's kernel behind it (``if WITH_SEABED:``), so a scene that does not declare
    the term never compiles its kernel (:func:`ropesim.model.jit.specialise`). ``params(scene, mass)`` builds
    the term's parameters (a float64 array, or a tuple of arrays) for a scene that declares the term, and
    ``empty`` is what an undeclared term gets instead: the same types, so the parameter bundle has one layout
    for every scene. The hooks, each optional:

    - ``energy(model, x)``: a conservative term's potential energy [J] for frames x (..., N, D), as NumPy
      (the analyses, the energy ledger's E(t) and the blow-up check's energy scale use it; the compiled check
      uses :func:`ropesim.model.terms.mechanical_energy`, which must agree);
    - ``springs(model)``: the springs this term couples nodes with, for the stability bound's stiffness
      Laplacian: (i, j, k) arrays, node pairs and their k [N/m] (:func:`ropesim.model.forces.springs.pairs`);
    - ``node_stiffness(model)``: the largest omega^2 [1/s^2] the term adds to a single node (a centring spring);
    - ``damping(model)``: the largest velocity-damping rate [1/s] the term applies, which explicit methods
      must resolve;
    - ``ledger``: for a non-conservative term, the energy ledger's column that books its work: "box" (the
      thrower and guides: :func:`ropesim.model.terms.applied_accelerations`), "fluid" (drag on the velocity
      relative to the flow, added mass) or "internal" (the rope's axial damping); None for a conservative term;
    - ``velocity``: True when its force depends on the velocities or on time (the splitting schemes then
      integrate their kicks with RK4 sub-steps, see :mod:`ropesim.integrate.velocity_kick`), except the
      thrower's and guides', which keep their own exact or plain kicks;
    - ``active(scene)``: whether the scene switches the term on, when that is more than declaring its table;
    - ``reach``: how many places along the rope the term couples nodes (0 for a node-local term), which sets
      the stiff integrator's band width; its Jacobian blocks go in through
      :func:`ropesim.model.terms.coupling_jacobian` (couplings) or :func:`ropesim.model.terms.node_jacobian`
      (node-local blocks), see :mod:`ropesim.model.jacobian`.
    """

    name: str                                   # the scene's table (or array of tables) that declares it
    switch: Switch | None                       # its compile-time switch; None: always on
    params: Callable[[Any, np.ndarray], Any]
    empty: Callable[[], Any]
    energy: Callable | None = None
    springs: Callable = _none
    node_stiffness: Callable = _zero
    damping: Callable = _zero
    ledger: str | None = None
    velocity: bool = False
    label: str = ""                             # its energy's name in energy_terms (default: ``name``)
    reach: int = 0
    active: Callable | None = None

    def declared(self, scene) -> bool:
        """True when ``scene`` switches this term on (or the term is always on)."""
        if self.switch is None:
            return True
        if self.active is not None:
            return bool(self.active(scene))
        part = getattr(scene, self.name)
        return part is not None and part != ()
