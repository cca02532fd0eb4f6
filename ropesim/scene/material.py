"""A line's material in physical units, resolved the same way for a ``[rope]`` and for each of a system's
``[[lines]]``: the mass per metre (given, or density x pi d^2 / 4, and never both in contradiction), and the
per-node values a line of given length and segments leads to (l = length / segments, k = EA / l, m' l), which
must stay inside the limits the per-node keys obey so that a resolved scene always loads again."""

from __future__ import annotations

import math

from .values import MAX_MAGNITUDE, MIN_POSITIVE

AGREE = 1e-9   # relative: a resolved scene's derived values agree with their physical form to rounding


def agree(a: float, b: float) -> bool:
    return abs(a - b) <= AGREE * max(abs(a), abs(b))


def mass_per_length(given: float | None, diameter: float | None, density: float | None, fail, where: str = "") -> float:
    """The mass per metre [kg/m]: ``given``, or density x pi d^2 / 4; both given must agree. ``fail(key, message)``
    refuses (key: "diameter" or "mass_per_length"); ``where`` ends each message (e.g. " (here or in its type)")."""
    per_metre = given
    if density is not None:
        if diameter is None:
            fail("diameter", f"missing: with density, the mass per metre is density x pi d^2 / 4{where}")
        from_density = density * math.pi * diameter ** 2 / 4.0
        if per_metre is not None and not agree(per_metre, from_density):
            fail("mass_per_length", f"{per_metre:g} kg/m contradicts density x pi d^2 / 4 = {from_density:g} kg/m; "
                                    f"give one of them{where}")
        per_metre = from_density if per_metre is None else per_metre
    if per_metre is None:
        fail("mass_per_length", f"missing: give mass_per_length, or diameter and density{where}")
    return per_metre


def axial_damping_of_ratio(ratio: float, segment_length: float, EA: float, per_metre: float) -> float:
    """The axial damping BA [N s] that damps a segment's stretching at ``ratio`` times critical: MoorDyn's negative
    BA, BA = zeta l sqrt(EA m') (Line.cpp). A segment of length l between two free nodes of mass m' l / 2 each
    stretches with the reduced mass m' l / 4 on the spring EA / l, so its critical damping is 2 sqrt(EA / l m' l / 4)
    = sqrt(EA m'), and the segment's damping BA / l is zeta times that."""
    return ratio * segment_length * math.sqrt(EA * per_metre)


def resolve_axial_damping(coefficient: float | None, ratio: float | None, segment_length: float, EA: float,
                          per_metre: float, fail, where: str = "") -> float | None:
    """The axial damping BA [N s] of a line given as a coefficient or a damping ratio (both only if they agree, as
    in a resolved scene); ``fail(key, message)`` refuses."""
    if ratio is None:
        return coefficient
    from_ratio = axial_damping_of_ratio(ratio, segment_length, EA, per_metre)
    if coefficient is not None and not agree(coefficient, from_ratio):
        fail("axial_damping", f"{coefficient:g} N s contradicts axial_damping_ratio = {ratio:g}, which gives "
                              f"zeta l sqrt(EA m') = {from_ratio:g} N s; give one of them{where}")
    return from_ratio


PER_NODE = {   # derived per-node value: (the physical key it comes from, how, unit)
    "segment_length": ("length", "length / segments", "m"),
    "stiffness": ("EA", "EA / l", "N/m"),
    "mass": ("mass_per_length", "mass_per_length x l", "kg"),
}


def per_node(length: float, segments: int, EA: float, per_metre: float, fail) -> dict:
    """l, k = EA / l and the node mass m' l of a line cut into ``segments``, each within MIN_POSITIVE to
    MAX_MAGNITUDE (its products and ratios would overflow beyond); ``fail`` names the physical key to blame."""
    l0 = length / segments
    derived = {"segment_length": l0, "stiffness": EA / l0, "mass": per_metre * l0}
    for key, (physical, how, unit) in PER_NODE.items():
        value = derived[key]
        if not MIN_POSITIVE <= value <= MAX_MAGNITUDE:
            fail(physical, f"gives {key} = {how} = {value:g} [{unit}], outside {MIN_POSITIVE:g} to "
                           f"{MAX_MAGNITUDE:g} (its products and ratios would overflow)")
    return derived
