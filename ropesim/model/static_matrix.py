"""The static solver's Newton matrix by coloured finite differences of the compiled force, for scenes whose
integrator compiles no Newton matrix of its own (the explicit methods).

The static solver (:mod:`ropesim.model.statics`) steps with the matrix

    A = M + tau (b + C) + tau^2 K,    K = -dF/dx,  C = -dF/dv  (at x and v = 0),

M the nodes' masses with their added mass, b the linear drag and F the net force on each node
(:func:`~ropesim.model.terms.accelerations` times the mass, the loop's own compiled term list). A stiff method
(sdirk2, galpha) compiles the analytic A anyway (:func:`~ropesim.model.terms.newton_matrix`) and the static
solver takes it; an explicit method would compile it for the static start alone, about a third of such a
scene's first run. Here K and C are differenced instead, so the static start compiles nothing the run does
not link anyway but the banded factor and solve.

**Colouring.** A force term couples a node only to nodes at most w places away along its line
(:mod:`ropesim.model.jacobian`), so nodes 2 w + 1 or more places apart share no row: moving them all at once
and differencing the force gives each one's columns. With (2 w + 1) colours (a few more on a closed loop whose
length is not a multiple) and D axes, K costs (2 w + 1) D force evaluations and C as many again (only when a
force depends on velocity), whatever the number of nodes: O(N) per matrix. A system's lines are runs of
consecutive nodes that share no term, so one colouring serves them all; a free point's or body's line ends are
nodes of their own (the Schur complement maps them to the point's or body's unknowns,
:mod:`ropesim.model.schur`).

**Step.** Forward differences: positions moved by h = sqrt(eps) l (l the shortest segment), velocities by
sqrt(eps) max(U, 1 m/s) (U the flow's largest speed), each step taken as the coordinate actually moves
((x + h) - x). A term's force changes on the scale of a segment (its direction, its stretch), so the
truncation error, h |F''| / 2, is about sqrt(eps) k (k a segment's stiffness), and the force's round-off,
eps k |x| / h, about sqrt(eps) k |x| / l: 1e-6 k for a chain 80 segments from the origin. The step is not
scaled with |x|, as it usually is, because of the seabed: its contact has a kink where a node touches it, and
a stiff seabed sinks a node by micrometres (3e-6 m under the spread-moored spar of tests/test_body_statics.py).
A step of sqrt(eps) |x| (4.5e-6 m, 300 m out) crossed the kink, halved the contact's stiffness at the
touchdown and stalled that spar's solve at 2 m/s of current (8e-7 of the force scale left after 2000
iterations); with sqrt(eps) l it takes 169 iterations (the analytic matrix 165).

**Where it serves.** Newton's iteration with this matrix converges as with the analytic one where the
structure's softest stiffness is well above that error: each built-in static start takes as many iterations
and its residual after each of the last ones agrees to two digits (``scripts/static_convergence.py``). A beam
with EI bending is the exception: its softest mode (3 EI / L^3, 4.3 kN/m for cantilever_beam) is 3e-6 of a
segment's axial stiffness (1.5 GN/m), below the differences' round-off, and the differenced iteration stalled
at 6e-9 of the force scale. Such a scene takes the analytic matrix, as does any solve whose differenced
iteration stalls or does not converge (:func:`ropesim.model.statics.solve_equilibrium`). Where the drag's
tangent stiffness is large (a rope in a side wind), its symmetric part in the banded matrix can make it
indefinite at a large pseudo-time step, which the solver then shortens: helicopter_crosswind solved with rk4
takes 38 iterations against the analytic matrix's 20 (6 factorisations refused), to the same shape.

**What A holds.** The differenced K is the whole tangent: the springs' compressive geometric stiffness (which
the analytic matrix leaves out to stay positive definite), the seabed's contact and the drag's dependence on
each node's tangent in a flow. The banded Cholesky takes A's symmetric part, S = (A + A^T) / 2, and the rest,
A - S, is returned as node blocks for the static solver's Krylov step where a drag in a flow makes it matter
(:meth:`DifferencedMatrix.apply`); without a flow it is round-off and left out. Where S is not positive
definite (a compressed segment at a large pseudo-time step) the factorisation fails and the solver shortens
its pseudo-time step, as it does with the analytic matrix.
"""

from __future__ import annotations

import math

import numpy as np

SQRT_EPS = math.sqrt(np.finfo(float).eps)


def colours(n: int, w: int, cyclic: bool) -> list[np.ndarray]:
    """Node indices grouped so that no two nodes of a group are within 2 w places of each other (around the
    loop when ``cyclic``): their columns of a Jacobian of half-width w do not overlap."""
    stride = 2 * w + 1
    colour = np.arange(n) % stride
    if cyclic and n % stride:                # the last, short round: clear of the first nodes around the wrap
        for i in range(n - n % stride, n):
            near = {int(colour[(i + k) % n]) for k in range(-2 * w, 2 * w + 1) if (i + k) % n != i}
            colour[i] = min(c for c in range(4 * w + 1) if c not in near)
    return [np.flatnonzero(colour == c) for c in range(int(colour.max()) + 1) if np.any(colour == c)]


class DifferencedMatrix:
    """Fills the static solver's :class:`~ropesim.model.jacobian.Jacobian` with M + tau (b + C) + tau^2 K, K
    and C by coloured finite differences of ``acceleration`` (the scene's compiled
    :func:`~ropesim.model.terms.accelerations`). ``free`` (N,) bool, ``mass`` and ``drag`` (N,): the nodes'."""

    def __init__(self, model, acceleration, w: int, cyclic: bool, free: np.ndarray, mass: np.ndarray,
                 drag: np.ndarray, t: float, with_velocity: bool):
        dim, n = model.x0.shape
        self.acceleration, self.w, self.t = acceleration, w, t
        self.free, self.mass, self.drag = free, mass, drag
        self.params = model.params
        self.groups = [g[free[g]] for g in colours(n, w, cyclic)]
        self.groups = [g for g in self.groups if g.size]
        self.with_velocity = with_velocity
        self.dx = SQRT_EPS * min(line.segment_length for line in model.lines)
        flow = model.scene.flow
        speed = max((float(np.abs(np.asarray(u, dtype=float)).max(initial=0.0)) for u in
                     (flow.velocity, flow.velocities) if u is not None), default=0.0) if flow is not None else 0.0
        self.dv = SQRT_EPS * max(speed, 1.0)
        added = model.params.added_mass
        self.added = added if added.shape[1] == n and np.any(added[:, free]) else None
        self.blocks = np.zeros((2 * w + 1, dim, dim, n))   # [k + w, a, b, j] = A[(j + k) D + a, j D + b]
        self.rows = np.arange(n)[None, :] + np.arange(-w, w + 1)[:, None]   # (2 w + 1, N) row node of each
        if cyclic:
            self.rows %= n
        self.inside = (self.rows >= 0) & (self.rows < n)
        self.rows = np.clip(self.rows, 0, n - 1)
        self._placement(dim, n)
        self._x, self._v = np.zeros((dim, n)), np.zeros((dim, n))
        self._acc, self._f0, self._f1 = np.zeros((dim, n)), np.zeros((dim, n)), np.zeros((dim, n))

    def _placement(self, dim: int, n: int) -> None:
        """Where each entry of the symmetric part goes: band[q, c] = A[c + q, c] for c + q's node at most w after
        c's, corner[(i - (N - w)) D + a, c] for the wrap-around pairs (see :mod:`ropesim.model.jacobian`)."""
        w = self.w
        k, a, b, j = np.meshgrid(np.arange(-w, w + 1), np.arange(dim), np.arange(dim), np.arange(n), indexing="ij")
        i = self.rows[k + w, j]
        r, c = i * dim + a, j * dim + b
        inside = self.inside[k + w, j] & (r >= c)
        band = inside & (i - j >= 0) & (i - j <= w)
        corner = inside & (i - j > w)
        source = np.arange(k.size).reshape(k.shape)
        rows = (w + 1) * dim
        self._band_source, self._band_target = source[band], ((r - c) * (n * dim) + c)[band]
        self._corner_source = source[corner]
        self._corner_target = ((i - (n - w)) * dim + a)[corner] * (w * dim) + c[corner]
        assert np.all((r - c)[band] < rows)

    def _force(self, x: np.ndarray, v: np.ndarray, out: np.ndarray) -> None:
        """F = m a (D, N) at (x, v), held nodes' included."""
        self.acceleration(x, v, self._acc, self.params, self.t)
        np.multiply(self._acc, self.mass, out=out)

    def _difference(self, x: np.ndarray, on_velocity: bool, scale: float) -> None:
        """Add ``scale`` times -dF/dx (or -dF/dv) into the blocks, one colour and axis at a time."""
        dim = x.shape[0]
        base = np.zeros_like(x)
        self._force(x, base, self._f0)
        w = self.w
        for nodes in self.groups:
            for e in range(dim):
                moved = self._v if on_velocity else self._x
                moved[:] = base if on_velocity else x
                if on_velocity:
                    moved[e, nodes] = self.dv
                    step = moved[e, nodes].copy()
                    self._force(x, moved, self._f1)
                else:
                    moved[e, nodes] = x[e, nodes] + self.dx
                    step = moved[e, nodes] - x[e, nodes]
                    self._force(moved, base, self._f1)
                change = self._f1 - self._f0        # (D, N)
                for k in range(-w, w + 1):
                    rows = self.rows[k + w, nodes]
                    keep = self.inside[k + w, nodes]
                    self.blocks[k + w, :, e, nodes[keep]] -= (scale * change[:, rows[keep]] / step[keep]).T

    def fill(self, x: np.ndarray, jac, tau: float) -> np.ndarray:
        """Overwrite ``jac``'s band and corner with the symmetric part of A at ``x`` for the pseudo-time step
        ``tau``; returns A's node blocks (2 w + 1, D, D, N) minus their symmetric part (see :meth:`apply`)."""
        dim = x.shape[0]
        free = self.free
        blocks = self.blocks
        blocks[:] = 0.0
        self._difference(x, False, tau * tau)
        if self.with_velocity:
            self._difference(x, True, tau)
        blocks[:, :, :, ~free] = 0.0                    # a held node's column: it does not move
        held_rows = ~free[self.rows]                   # (2 w + 1, N): a held node's rows are the identity's
        blocks.transpose(0, 3, 1, 2)[held_rows | ~self.inside] = 0.0
        w = self.w
        diagonal = blocks[w]
        own = np.where(free, self.mass + tau * self.drag, 1.0)
        for d in range(dim):
            diagonal[d, d] += own
        if self.added is not None:
            diagonal += _added_mass_blocks(x, self.added, self.params.neighbours, free)
        mirrored = np.empty_like(blocks)                # A[j, i]^T in A[i, j]'s place
        for k in range(-w, w + 1):
            mirrored[k + w] = blocks[-k + w][:, :, self.rows[k + w]].transpose(1, 0, 2)
        mirrored[~np.broadcast_to(self.inside[:, None, None, :], blocks.shape)] = 0.0
        symmetric = 0.5 * (blocks + mirrored)
        jac.band.ravel()[:] = 0.0
        jac.corner.ravel()[:] = 0.0
        jac.band.ravel()[self._band_target] = symmetric.ravel()[self._band_source]
        if self._corner_source.size:
            jac.corner.ravel()[self._corner_target] = symmetric.ravel()[self._corner_source]
        return blocks - symmetric

    def apply(self, rest: np.ndarray, z: np.ndarray) -> np.ndarray:
        """(A - S) z for the node blocks ``rest`` that :meth:`fill` returned and z flat node-major."""
        width, dim, _, n = rest.shape
        zz = z.reshape(n, dim).T
        out = np.zeros((dim, n))
        for k in range(width):
            keep = self.inside[k]
            np.add.at(out, (slice(None), self.rows[k][keep]), np.einsum("abj,bj->aj", rest[k], zz)[:, keep])
        return out.T.reshape(-1)


def _added_mass_blocks(x: np.ndarray, added: np.ndarray, around: np.ndarray, free: np.ndarray) -> np.ndarray:
    """Each free node's added-mass block a_n (I - q q^T) + a_t q q^T (D, D, N), q its tangent along the chord
    between its neighbours (:func:`~ropesim.model.forces.fluid.node_tangent`; none for a node without)."""
    dim = x.shape[0]
    chord = x[:, around[1]] - x[:, around[0]]
    length = np.sqrt((chord * chord).sum(axis=0))
    q = np.divide(chord, length, out=np.zeros_like(chord), where=length > 0.0)
    qq = q[:, None, :] * q[None, :, :]
    eye = np.eye(dim)[:, :, None]
    a_n, a_t = np.where(free, added[0], 0.0), np.where(free, added[1], 0.0)
    return a_n * (eye - qq) + a_t * qq
