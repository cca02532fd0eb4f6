"""The ramp-in of the flow and the waves: r(t) = (1 - cos(pi t / T)) / 2 over the ramp time T [s], then 1.

Currents (forces/fluid.py), the water's inertia (forces/flow_inertia.py) and the waves (waves.py) scale by r(t)
and their accelerations by its rate r'(t), so that a run starts from still water without a jolt.
"""

import math

from . import jit


@jit.kernel
def ramp(t, ramp_time):
    """The flow's ramp factor at time t [s]: (1 - cos(pi t / T)) / 2 until T, then 1."""
    if ramp_time <= 0.0 or t >= ramp_time:
        return 1.0
    if t <= 0.0:
        return 0.0
    return 0.5 * (1.0 - math.cos(math.pi * t / ramp_time))


@jit.kernel
def ramp_rate(t, ramp_time):
    """The rate r'(t) [1/s] of the flow's ramp r(t) = (1 - cos(pi t / T)) / 2 (0 before 0 and after T)."""
    if ramp_time <= 0.0 or t <= 0.0 or t >= ramp_time:
        return 0.0
    return 0.5 * math.pi / ramp_time * math.sin(math.pi * t / ramp_time)
