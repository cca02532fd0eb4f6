"""Free rigid bodies as groups of the Newton matrix's Schur complement (:mod:`ropesim.model.schur`): what the
static solver and the stiff integrator need of a body beyond its line ends.

A free body's unknowns are the displacement of its reference point and a small rotation vector phi in world
axes (6 in 3-D; x, y and the turn about z in 2-D), its orientation updated on the rotation group,
q <- exp(phi) q (:func:`turn_bodies`), so it stays a unit quaternion to round-off whatever the step. Its line
ends (its attachments) follow through G_c = [I, -[rho_c]x], rho_c = R s_c their world arms
(:func:`set_body_arms`).

A body's own part of the group's equations (:func:`own_parts`) is that of its Newton-Euler equations
(:func:`ropesim.model.bodies.body_own_system`): its mass matrix at its centre of gravity, its inertia and added
mass, and its own forces: weight, buoyancy, drag, centripetal force and gyroscopic moment. A force F that turns
with the body at an arm p (its weight at c = R c_b, its buoyancy at R c_B, each line end's pull at rho_c) makes a
moment p x F whose change under a small rotation phi, F held, is (phi x p) x F = [F]x [p]x phi: the rotational
geometric stiffness K_phi = -[F]x [p]x (:func:`rotational_stiffness`), not symmetric away from balance.
"""

from __future__ import annotations

import numpy as np

from . import jit
from .bodies import body_own_system
from .body_layout import ARM
from .body_sea import WITH_BODY_SEA, heave_stiffness
from .forces.fluid import WITH_FLOW, flow_at
from .forces.gravity import WITH_GRAVITY
from .rotation import matrix_of, rotate


def body_unknowns(dim: int) -> int:
    """A free body's unknowns: 6 in 3-D, 3 in 2-D."""
    return 6 if dim == 3 else 3


def kept_rows(dim: int) -> np.ndarray:
    """Which of the 6 rows of a body's equations (force, then moment) a scene of ``dim`` dimensions keeps."""
    return np.arange(6) if dim == 3 else np.array([0, 1, 5])


@jit.kernel
def set_body_arms(arm, first, bodies, pose):
    """Each body attachment's world arm rho_c = R s_c into the groups' ``arm`` (3, K), body members from
    ``first`` on (in the order of ``bodies.nodes``)."""
    links, index = bodies.links, bodies.index
    for b in range(pose.shape[1]):
        r = matrix_of(pose[3:7], b)
        for k in range(index[links.shape[0] + b], index[links.shape[0] + b + 1]):
            p0, p1, p2 = rotate(r, links[k, ARM], links[k, ARM + 1], links[k, ARM + 2])
            arm[0, first + k] = p0
            arm[1, first + k] = p1
            arm[2, first + k] = p2


@jit.kernel
def own_parts(p, pose, twist, t, out):
    """Every free body's own part of its Newton-Euler equations (:func:`~ropesim.model.bodies.body_own_system`)
    into ``out`` (B, 6, 7) at time t [s]: the matrix, then the right-hand side (force [N], moment [N m])."""
    g = p.gravity[0] if WITH_GRAVITY else 0.0
    for b in range(pose.shape[1]):
        body_own_system(out[b], g, p.flow, p.bodies, pose, twist, b, t, 0.0)


def rotational_stiffness(forces: np.ndarray, arms: np.ndarray) -> np.ndarray:
    """K_phi = -sum [F]x [p]x = sum (F . p) I - p F^T (3, 3) of forces (K, 3) [N] at world arms (K, 3) [m] that turn
    with the body (see the module doc)."""
    return np.eye(3) * float(np.sum(forces * arms)) - arms.T @ forces


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b along the last axis (numpy's cross costs a third of a millisecond on these few vectors)."""
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1], a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


def _matrices(q: np.ndarray) -> np.ndarray:
    """R (B, 3, 3) of unit quaternions q (4, B), w first."""
    w, x, y, z = q
    return np.stack([np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
                     np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
                     np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1)], axis=1)


def turn_bodies(pose: np.ndarray, du: np.ndarray, dim: int, fraction: float = 1.0) -> np.ndarray:
    """The poses (7, B) moved by the groups' unknowns ``du`` (B, 6 or 3) times ``fraction``: r += d, q <- exp(phi) q
    (normalised)."""
    out = pose.copy()
    for b in range(pose.shape[1]):
        step = np.zeros(6)
        step[kept_rows(dim)] = fraction * du[b]
        out[:3, b] += step[:3]
        turn_numpy(out, b, step[3:])
    return out


def turn_numpy(pose: np.ndarray, b: int, phi: np.ndarray) -> None:
    """pose[3:7, b] <- exp(phi) pose[3:7, b], normalised (the compiled :func:`~ropesim.model.rotation.turn`)."""
    from .rotation import exp_map, multiply

    q = multiply(exp_map(phi), pose[3:7, b])
    pose[3:7, b] = q / np.linalg.norm(q)



class StaticBodies:
    """The free bodies' part of the static solver's pseudo-transient Newton iteration
    (:func:`ropesim.model.statics.solve_equilibrium`): each body's balance of forces and moments about its
    reference point, its own block of the step's matrix (its mass matrix plus tau^2 its rotational geometric
    stiffness) and its own right-hand side, its potential energy, and its pose moved by a step."""

    def __init__(self, model, groups, t: float, compiled: bool = True):
        from .bodies import place_attachments

        self.model, self.groups, self.t = model, groups, t
        # compiled False (an explicit method's static start): the bodies' own parts at rest in NumPy
        # (:meth:`own_numpy`), their attachments placed in NumPy, unless the sea's loads act on them
        self.compiled = compiled or WITH_BODY_SEA.name in model.switches
        self.bundle = bundle = model.params.bodies
        self.dim = model.dim
        self.count = bundle.mass.size
        self.keep = kept_rows(self.dim)
        self.k = body_unknowns(self.dim)
        self.first = groups.nodes.size - bundle.nodes.size                 # the bodies' members come last
        self.offset = int(groups.offset[-1]) - self.count * self.k         # ... and so do their unknowns
        self.own = model.kernel(own_parts) if self.compiled else None
        self.place_nodes = place_attachments
        self.work = np.zeros((self.count, 6, 7))
        self.still = np.zeros((6, self.count))
        scene = model.scene
        self.g = scene.gravity.g if scene.gravity is not None else 0.0
        shortest = min(line.segment_length for line in model.lines)
        self.length = np.array([max([shortest, *(float(np.linalg.norm(bundle.arm[:, k]))
                                                   for k in range(bundle.start[b], bundle.start[b + 1])),
                                     float(np.linalg.norm(bundle.cog[:, b])), float(np.linalg.norm(bundle.cob[:, b]))])
                                for b in range(self.count)])
        self.attached = np.zeros(model.nodes, dtype=bool)
        self.attached[bundle.nodes] = True

    def place(self, x: np.ndarray, pose: np.ndarray) -> None:
        """Put the attachment nodes of ``x`` (D, N) where the bodies at ``pose`` hold them, and their arms into
        the groups."""
        if self.compiled:
            self.place_nodes(x, np.zeros_like(x), self.bundle, pose, self.still)
            set_body_arms(self.groups.arm, self.first, self.bundle, pose)
            return
        bundle, turned = self.bundle, _matrices(pose[3:7])
        for b in range(self.count):
            members = slice(bundle.start[b], bundle.start[b + 1])
            arms = turned[b] @ bundle.arm[:, members]                  # rho_c = R s_c
            self.groups.arm[:, self.first + members.start:self.first + members.stop] = arms
            x[:, bundle.nodes[members]] = (pose[:3, b, None] + arms)[:self.dim]

    def own_numpy(self, pose: np.ndarray) -> None:
        """What :func:`own_parts` puts into ``work`` for bodies at rest (no twist: no centripetal force, gyroscopic
        moment, rotational drag or damper's force) out of a sea: the mass matrix at the centre of gravity with the
        inertia and added mass, turned into world axes; the weight at the centre of gravity, the buoyancy at the
        centre of buoyancy, the flow's drag on the reference point (per body axis C_i |u| u_i, u the flow there)
        and the linear spring."""
        from .bodies import constant_mass

        bundle, p, t = self.bundle, self.model.params, self.t
        turned = _matrices(pose[3:7])
        flowing = WITH_FLOW.name in self.model.switches
        for b in range(self.count):
            r = turned[b]
            spin = np.zeros((6, 6))
            spin[:3, :3] = spin[3:, 3:] = r
            own = constant_mass(bundle.mass[b], bundle.cog[:, b], bundle.inertia[:, :, b], bundle.added[:, b],
                                bundle.added_rot[:, b], (), np.zeros((3, 0)))
            self.work[b, :, :6] = spin @ own @ spin.T
            weight = np.array([0.0, -bundle.mass[b] * self.g, 0.0])
            lift = np.array([0.0, bundle.lift[b], 0.0])
            force = weight + lift - bundle.spring[:, b] * (pose[:3, b] - bundle.rest[:, b])
            if flowing:
                u = np.array(flow_at(float(pose[1, b]), t, p.flow[0], p.flow[1]))
                force += r @ (bundle.drag[:, b] * float(np.linalg.norm(u)) * (r.T @ u))
            self.work[b, :3, 6] = force
            self.work[b, 3:, 6] = _cross(r @ bundle.cog[:, b], weight) + _cross(r @ bundle.cob[:, b], lift)

    def evaluate(self, pose: np.ndarray, force: np.ndarray) -> None:
        """The bodies' balance at ``pose`` (7, B) with ``force`` (N D) the net force on every node [N] (the
        attachments' unfolded): ``total`` (B, 6) their net force and moment, ``own_rhs`` (B, 6) their own part
        of it, ``drag`` (B, 6) its non-conservative part, ``matrix`` (B, 6, 6) their mass matrices, ``stiffness``
        (B, 3, 3) their rotational geometric stiffness."""
        bundle, n = self.bundle, self.model.nodes
        if self.compiled:
            self.own(self.model.params, pose, self.still, self.t, self.work)
        else:
            self.own_numpy(pose)
        on_node = np.zeros((n, 3))
        on_node[:, :self.dim] = force.reshape(n, self.dim)
        turned = _matrices(pose[3:7])
        self.total, self.own_rhs = np.zeros((self.count, 6)), self.work[:, :, 6].copy()
        self.drag, self.matrix = self.own_rhs.copy(), self.work[:, :, :6].copy()
        self.stiffness = np.zeros((self.count, 3, 3))
        self.heave = heave_stiffness(self.model, pose, self.t)
        for b in range(self.count):
            members = slice(bundle.start[b], bundle.start[b + 1])
            pulls = on_node[bundle.nodes[members]]
            arms = self.groups.arm[:, self.first + members.start:self.first + members.stop].T
            weight = np.array([0.0, -bundle.mass[b] * self.g, 0.0])
            lift = np.array([0.0, bundle.lift[b], 0.0])
            c, cb = turned[b] @ bundle.cog[:, b], turned[b] @ bundle.cob[:, b]
            self.total[b] = self.own_rhs[b]
            self.total[b, :3] += pulls.sum(axis=0)
            self.total[b, 3:] += _cross(arms, pulls).sum(axis=0)
            spring = -bundle.spring[:, b] * (pose[:3, b] - bundle.rest[:, b])   # a free body's linear spring
            self.drag[b, :3] -= weight + lift + spring
            self.drag[b, 3:] -= _cross(c, weight) + _cross(cb, lift)
            self.stiffness[b] = rotational_stiffness(np.vstack([pulls, weight, lift]), np.vstack([arms, c, cb]))

    def residual(self) -> np.ndarray:
        """The bodies' net forces [N] and moments over their sizes [N] (B, k), the rows the scene keeps."""
        out = self.total.copy()
        out[:, 3:] /= self.length[:, None]
        return out[:, self.keep]

    def worst(self) -> float:
        """The largest force [N] or moment over the body's size [N] left on a body."""
        left = self.residual()
        return float(np.abs(left).max(initial=0.0)) if np.all(np.isfinite(left)) else np.inf

    def norm(self) -> float:
        return float(np.linalg.norm(self.residual()))

    def fill(self, tau: float) -> None:
        """The groups' own blocks M + tau^2 K_phi and right-hand sides tau^2 times the bodies' own forces."""
        groups, k, keep = self.groups, self.k, self.keep
        for b in range(self.count):
            block = self.matrix[b].copy()
            block[3:, 3:] += tau * tau * self.stiffness[b]
            block[:3, :3] += tau * tau * np.diag(self.bundle.spring[:, b])
            block[1, 1] += tau * tau * self.heave[b]   # a floating body's waterplane (model/body_sea.py)
            at = self.offset + b * k
            groups.own[at:at + k, at:at + k] = block[np.ix_(keep, keep)]
            groups.own_rhs[at:at + k] = tau * tau * self.own_rhs[b, keep]

    def step(self) -> np.ndarray:
        """The bodies' unknowns (B, k) the last Schur solve found."""
        return self.groups.du[self.offset:self.offset + self.count * self.k].reshape(self.count, self.k).copy()

    def rates(self, du: np.ndarray) -> tuple[float, float]:
        """(du . own force, du . own non-conservative force) of a step ``du`` (B, k) of the bodies [J]."""
        return float(np.sum(du * self.own_rhs[:, self.keep])), float(np.sum(du * self.drag[:, self.keep]))

    def energy(self, pose: np.ndarray) -> float:
        """The bodies' potential energy [J]: weight at the centre of gravity, buoyancy at the centre of
        buoyancy, a linear spring's stretch."""
        bundle = self.bundle
        turned = _matrices(pose[3:7])
        c = np.einsum("bij,jb->b", turned[:, 1:2, :], bundle.cog)
        cb = np.einsum("bij,jb->b", turned[:, 1:2, :], bundle.cob)
        stretch = pose[:3] - bundle.rest
        return float(np.sum(bundle.mass * self.g * (pose[1] + c) - bundle.lift * (pose[1] + cb))
                     + 0.5 * np.sum(bundle.spring * stretch * stretch))

    def moved(self, pose: np.ndarray, du: np.ndarray, fraction: float) -> np.ndarray:
        return turn_bodies(pose, du, self.dim, fraction)
