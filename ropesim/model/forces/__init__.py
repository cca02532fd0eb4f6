"""Force terms, one file each. Every term is a jitted kernel that *adds* its acceleration to ``acc``.

State arrays are structure-of-arrays: ``x``, ``v`` and ``acc`` have shape (D, N), so each coordinate is
contiguous. Linear air drag is not here: it is integrated exactly inside each velocity kick
(see :mod:`ropesim.integrators`).
"""
