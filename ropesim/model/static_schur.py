"""The Schur complement of :mod:`ropesim.model.schur` in NumPy around the banded factor and solve, for the static
solver of a scene whose loop compiles no Schur solver of its own (an explicit method's).

A stiff method (sdirk2, galpha) with free points or bodies compiles :func:`~ropesim.model.schur.schur_factor`
and :func:`~ropesim.model.schur.schur_solve` for its loop, and its static start shares them. An explicit
method's loop links neither, and compiling them for its static start alone took 3.6 s of spread_mooring_free's
first run. The static start already compiles the banded Cholesky factor and solve of a rope's Newton matrix
(:func:`~ropesim.model.banded.factor`, :func:`~ropesim.model.banded.solve`, a few tenths of a second, shared
on disk with every other scene), so here the few group unknowns are eliminated in NumPy around them:

- A: the node-ordered matrix with every constrained node's rows and columns the identity. It is still block
  diagonal over the lines, each block banded, so the whole band is factored at once (O(N w^2 D^3)).
- B = (J G) with the constrained rows left out, and C = O + G^T J G, from J's columns at the constrained nodes
  (each nonzero only within w nodes of its node): O(m w D) entries for m group unknowns.
- W = A^-1 B by m banded solves (O(N w D) each), S = C - B^T W (m x m), factored by NumPy's LU.

A solve is one banded solve and a small dense one, as in :func:`~ropesim.model.schur.schur_solve`:
f = A^-1 r_f, du = S^-1 (r_u - B^T f), dx_f = f - W du, dx_c = G_c du. Where the compiled version carries a
group's columns only over the rows its factor reaches, W here is full length: m more banded solves per
factorisation, O(N m) (m = 6 for a body), a few milliseconds per Newton iteration on a built-in scene.
"""

from __future__ import annotations

import numpy as np


def levers(arm: np.ndarray, dim: int, dof: int) -> np.ndarray:
    """G_c (K, D, dof) of K members at world arms ``arm`` (3, K) (:func:`~ropesim.model.schur.lever`): the
    identity on the translations; -[rho]x on a 3-D rotation vector; (-rho_y, rho_x) on a 2-D rotation."""
    count = arm.shape[1]
    out = np.zeros((count, dim, dof))
    out[:, np.arange(dim), np.arange(dim)] = 1.0
    if dof == dim:
        return out
    if dim == 2:
        out[:, 0, 2], out[:, 1, 2] = -arm[1], arm[0]
        return out
    x, y, z = arm
    out[:, 0, 4], out[:, 0, 5] = z, -y           # -[rho]x
    out[:, 1, 3], out[:, 1, 5] = -z, x
    out[:, 2, 3], out[:, 2, 4] = y, -x
    return out


class NumpySchur:
    """Factor and solve the static solver's Newton system with ``groups``
    (:class:`~ropesim.model.schur.Groups`) by their Schur complement, with the model's compiled banded
    ``factor`` and ``solve`` (non-cyclic) for the lines. Same contract as :func:`~ropesim.model.schur.schur_factor`
    and :func:`~ropesim.model.schur.schur_solve` (``groups.own``, ``own_rhs``, ``arm`` read, ``du`` written)."""

    def __init__(self, groups, dim: int, factor, solve, corner, wood):
        self.groups, self.dim, self.factor_band, self.solve_band = groups, dim, factor, solve
        self.corner, self.wood = corner, wood
        self.dofs = (groups.nodes[:, None] * dim + np.arange(dim)).reshape(-1)   # the constrained rows
        self.m = int(groups.offset[-1])

    def _lever_matrix(self) -> np.ndarray:
        """P (K D, m): every constrained row's G_c in its group's columns."""
        groups, dim = self.groups, self.dim
        out = np.zeros((groups.nodes.size * dim, self.m))
        for g in range(groups.offset.size - 1):
            members = slice(groups.start[g], groups.start[g + 1])
            dof = int(groups.offset[g + 1] - groups.offset[g])
            blocks = levers(groups.arm[:, members], dim, dof)
            rows = (np.arange(members.start, members.stop)[:, None] * dim + np.arange(dim)).reshape(-1)
            out[rows, groups.offset[g]:groups.offset[g + 1]] = blocks.reshape(-1, dof)
        return out

    def factor(self, band: np.ndarray) -> bool:
        """Factor the matrix whose lower triangle ``band`` holds (overwritten); False where A or S is singular."""
        p = band.shape[0] - 1
        nt = band.shape[1]
        dofs = self.dofs
        # J's columns at the constrained rows: J[i, j] for |i - j| <= p
        offsets = np.arange(-p, p + 1)
        rows = dofs[:, None] + offsets[None, :]
        inside = (rows >= 0) & (rows < nt)
        rows_c = np.clip(rows, 0, nt - 1)
        low = np.maximum(rows_c, dofs[:, None])
        high = np.minimum(rows_c, dofs[:, None])
        columns = np.where(inside, band[low - high, high], 0.0)     # (K D, 2 p + 1)
        self.lever = lever = self._lever_matrix()
        jg = np.zeros((nt, self.m))                                   # J P
        np.add.at(jg, rows_c[inside], (columns[:, :, None] * lever[:, None, :])[inside])
        s = self.groups.own + lever.T @ jg[dofs]                      # C = O + P^T J P
        jg[dofs] = 0.0                                                # B: the free rows
        self.b = jg
        band[:, dofs] = 0.0                                           # A: the constrained rows the identity
        above = np.broadcast_to(np.arange(1, p + 1), (dofs.size, p))
        back = dofs[:, None] - above                                  # J[j, j - q] = band[q, j - q]
        keep = back >= 0
        band[above[keep], back[keep]] = 0.0
        band[0, dofs] = 1.0
        if not self.factor_band(band, self.corner, False, p, self.wood):
            return False
        self.band = band
        w = np.empty_like(jg)
        for col in range(self.m):
            z = np.ascontiguousarray(jg[:, col])
            self.solve_band(band, self.corner, False, p, z, self.wood)
            w[:, col] = z
        self.w = w
        s = s - jg.T @ w
        if not np.all(np.isfinite(s)):
            return False
        try:
            np.linalg.inv(s)              # a singular S (an exactly zero pivot) fails here, as lu_factor does
        except np.linalg.LinAlgError:
            return False
        self.s = s
        return True

    def solve(self, rhs: np.ndarray) -> None:
        """Solve the factored system in place into ``rhs`` (flat, node-major): a constrained node's entries are
        its share of its group's equation on entry, its displacement G_c du on return; du into ``groups.du``."""
        dofs, p = self.dofs, self.band.shape[0] - 1
        r_u = self.groups.own_rhs + self.lever.T @ rhs[dofs]
        rhs[dofs] = 0.0
        self.solve_band(self.band, self.corner, False, p, rhs, self.wood)
        du = np.linalg.solve(self.s, r_u - self.b.T @ rhs)
        rhs -= self.w @ du
        rhs[dofs] = self.lever @ du
        self.groups.du[:] = du
