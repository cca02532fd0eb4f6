"""The run's time grid: uniform steps reaching t_end exactly, and which of them save a frame."""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class TimeGrid:
    """The run's steps: ``steps`` uniform steps of ``dt`` reaching t_end exactly; a frame every ``save_every``.

    When t_end is not a whole number of the scene's dt, dt shrinks slightly (never grows) to fit.
    """

    dt: float
    steps: int
    save_every: int
    requested_dt: float

    @classmethod
    def of(cls, scene) -> "TimeGrid":
        dt, t_end = scene.integrator.dt, scene.integrator.t_end
        steps = math.ceil(t_end / dt * (1 - 1e-12)) if t_end > 0 else 0
        h = t_end / steps if steps else dt
        # at most every step count: an interval past t_end saves t = 0 and t_end alone (and never overflows)
        save_every = max(1, round(min(scene.output.interval / h, max(steps, 1))))
        return cls(dt=h, steps=steps, save_every=save_every, requested_dt=dt)

    @property
    def frames(self) -> int:
        """Saved frames, t = 0 included: every save_every-th step and the last one."""
        return 1 + self.steps // self.save_every + (1 if self.steps % self.save_every else 0)

    @property
    def dt_adjusted(self) -> bool:
        return abs(self.dt - self.requested_dt) > 1e-12 * self.requested_dt
