"""The velocity kick with exact linear drag, and the energy it books, as loops that vectorise.

A kick of length c (one stage of a splitting scheme) moves every velocity component as
v <- decay v + gain a and the node over ``way`` = gain v + travel a (see :func:`ropesim.integrators.kick_factors`
for the factors). The energy drag takes out of the rope in that kick is

    D = sum_i m_i sum_d [ a way - (v_new^2 - v_old^2) / 2 ],

the work of the forces minus the kinetic energy gained. These sums are reductions: written as one running
sum they add one term at a time, each waiting for the last. :func:`kick_drift` and :func:`box_work` keep four
running sums instead (terms i, i + 1, i + 2, i + 3), combined at the end in a fixed order; the order is written
out, so the result is the same to the last bit however the code is compiled or inlined (no fast-math
reordering). The loss terms are computed in the same vectorised pass that kicks (and drifts) each row, into a
scratch row, before the sums.
"""

from ..model.jit import kernel

LANES = 4   # running sums per reduction
SCRATCH_NODES = 256   # from this many nodes kick_drift sums each node's loss over the rows before the lanes


@kernel(inline="always")
def _add_lanes(t, s0, s1, s2, s3):
    """The four running sums (s0, s1, s2, s3) with ``t`` added: term i to sum i % 4, the tail to s0."""
    n = t.shape[0]
    whole = n - n % LANES
    for i in range(0, whole, LANES):
        s0 += t[i]
        s1 += t[i + 1]
        s2 += t[i + 2]
        s3 += t[i + 3]
    for i in range(whole, n):
        s0 += t[i]
    return s0, s1, s2, s3


@kernel(inline="always")
def _lanes(t):
    """Sum of ``t`` as four running sums combined in a fixed order."""
    s0, s1, s2, s3 = _add_lanes(t, 0.0, 0.0, 0.0, 0.0)
    return (s0 + s1) + (s2 + s3)


@kernel
def _work(vo, a, a_box, gain, travel, m):
    return m * a_box * (gain * vo + travel * a)


@kernel
def box_work(v, acc, acc_box, gain, travel, k, mass):
    """Work [J] of the accelerations ``acc_box`` (the thrower's and guides') over kick ``k``."""
    dim, n = v.shape
    s0 = s1 = s2 = s3 = 0.0
    whole = n - n % LANES
    for d in range(dim):
        for i in range(0, whole, LANES):
            s0 += _work(v[d, i], acc[d, i], acc_box[d, i], gain[k, i], travel[k, i], mass[i])
            s1 += _work(v[d, i + 1], acc[d, i + 1], acc_box[d, i + 1], gain[k, i + 1], travel[k, i + 1], mass[i + 1])
            s2 += _work(v[d, i + 2], acc[d, i + 2], acc_box[d, i + 2], gain[k, i + 2], travel[k, i + 2], mass[i + 2])
            s3 += _work(v[d, i + 3], acc[d, i + 3], acc_box[d, i + 3], gain[k, i + 3], travel[k, i + 3], mass[i + 3])
        for i in range(whole, n):
            s0 += _work(v[d, i], acc[d, i], acc_box[d, i], gain[k, i], travel[k, i], mass[i])
    return (s0 + s1) + (s2 + s3)


@kernel
def kick_drift(x, v, acc, decay, gain, travel, k, mass, c, buf):
    """Kick ``k`` and then, when ``c`` != 0, the drift x <- x + c v, in as few passes as the ledger allows.

    Returns the energy [J] drag takes out during the kick (see the module docstring). The new velocities are
    v <- decay v + gain a (drag integrated exactly) and the drift uses them. ``buf`` is (N,) scratch.
    Each row is one pass (it vectorises) that kicks, drifts and writes each term of the loss into ``buf``;
    only the running sums that follow are sequential.
    """
    dim, n = v.shape
    # the four versions of a row's pass are written out: a flag tested inside the loop stops it vectorising
    if n >= SCRATCH_NODES:   # buf sums each node's loss over the rows
        for i in range(n):
            buf[i] = 0.0
        for d in range(dim):
            if c != 0.0:
                for i in range(n):
                    vo = v[d, i]
                    a = acc[d, i]
                    vn = decay[k, i] * vo + gain[k, i] * a
                    buf[i] += a * (gain[k, i] * vo + travel[k, i] * a) - 0.5 * (vn * vn - vo * vo)
                    v[d, i] = vn
                    x[d, i] += c * vn
            else:
                for i in range(n):
                    vo = v[d, i]
                    a = acc[d, i]
                    vn = decay[k, i] * vo + gain[k, i] * a
                    buf[i] += a * (gain[k, i] * vo + travel[k, i] * a) - 0.5 * (vn * vn - vo * vo)
                    v[d, i] = vn
        for i in range(n):
            buf[i] *= mass[i]
        return _lanes(buf)
    s0 = s1 = s2 = s3 = 0.0
    for d in range(dim):   # buf holds one row's terms
        if c != 0.0:
            for i in range(n):
                vo = v[d, i]
                a = acc[d, i]
                vn = decay[k, i] * vo + gain[k, i] * a
                buf[i] = mass[i] * (a * (gain[k, i] * vo + travel[k, i] * a) - 0.5 * (vn * vn - vo * vo))
                v[d, i] = vn
                x[d, i] += c * vn
        else:
            for i in range(n):
                vo = v[d, i]
                a = acc[d, i]
                vn = decay[k, i] * vo + gain[k, i] * a
                buf[i] = mass[i] * (a * (gain[k, i] * vo + travel[k, i] * a) - 0.5 * (vn * vn - vo * vo))
                v[d, i] = vn
        s0, s1, s2, s3 = _add_lanes(buf, s0, s1, s2, s3)
    return (s0 + s1) + (s2 + s3)
