"""MoorDyn's wave case on equal physics: its chain of ``tests/Mooring/wavekin_wave_1.txt`` in regular and irregular
waves, the fairlead held at the surface. Used by ``scripts/compare_moordyn_waves.py`` and
``tests/test_moordyn_waves.py``.

``wavekin_wave_1.txt`` is MoorDyn's WD0050_Chain (tests/data/moordyn/cases, :mod:`.moordyn_own_cases`: 410 m of
studless chain in 50 m of water, 82 segments, its fairlead at the mean water level) with ``WaveKin = 1``: the
caller hands MoorDyn the water's velocity and acceleration at every node. With that option MoorDyn's surface
elevation stays 0, so its buoyancy would ignore the waves while its drag feels them. The case is therefore run
with ``WaveKin = 7`` instead (MoorDyn's ``SpectrumKin``): MoorDyn sums the same Airy components itself at every
node and every stage, surface included. The wave components are handed to it in ``wave_frequencies.txt``.
Both codes then have the same physics, item by item (MoorDyn 2.7's source):

- kinematics (``Waves/SpectrumKin.cpp``): eta = sum A sin(w t - k x + phi_MD), velocity and acceleration
  from Airy theory at the Wheeler-stretched height d (z - eta) / (d + eta), clamped to the surface above it.
  That is ropesim's ``stretching = "wheeler"`` (its default), with ropesim's phase phi = pi/2 - phi_MD
  (ropesim writes eta = sum a cos(k x - w t + phi)). The wave numbers come from the dispersion relation: Newman's
  one-step solution in MoorDyn (7 significant digits), exact in ropesim;
- evaluated at every stage (``Time.cpp``: ``CalcStateDeriv`` calls ``updateWaves`` with the stage's time and
  positions), as ropesim does;
- the submerged fraction (``Line::calcSubSeg``): per segment, under the mean of its two nodes' surface
  heights, the share of a diagonal below the surface. This is ropesim's ``[sea] fraction = "moordyn"``; ropesim's
  own rule (``"cylinders"``) is exact for a cylinder under a flat surface at each node;
- on the submerged length: buoyancy, added mass, drag on the velocity relative to the water, and the inertia
  force rho V (1 + Ca) a_w (``Line::getStateDeriv``), as ropesim's ``[sea]`` applies them;
- no air drag in MoorDyn: ropesim's ``air_density = 0``;
- the IC in still water (MoorDyn switches the waves on after its IC solve, ``MoorDyn2.cpp``). ropesim starts at
  rest from MoorDyn's IC state, and both see the waves at full height from t = 0 (no ramp on either side).

Compared: the fairlead tension |T + Td| of the top segment from each code's state at every frame
(:func:`.moordyn_own_cases.segment_tension`; the fairlead is held, so its velocity is 0 on both sides).
MoorDyn integrates with its RK2 at the file's dtM = 1 ms, ropesim with rk4 at the same step. Units: SI.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .moordyn_own_cases import (ChainCase, chain_case, chain_scene_dict, moordyn_chain_text, segment_tension,
                                to_ropesim)

CHAIN = "WD0050_Chain"   # wavekin_wave_1.txt without its WaveKin option


@dataclass(frozen=True)
class WaveCase:
    """Waves on the chain: ropesim's ``[waves]`` table (kind and keys), simulated time t_end (s), frames every
    dt_out (s)."""

    name: str
    waves: dict
    t_end: float
    dt_out: float = 0.1


CASES = {
    "regular": WaveCase("regular", {"kind": "regular", "height": 6.0, "period": 10.0}, t_end=60.0),
    "jonswap": WaveCase("jonswap", {"kind": "jonswap", "significant_height": 6.0, "peak_period": 10.0,
                                    "gamma": 3.3, "components": 50, "seed": 1}, t_end=60.0),
}


def components(chain: ChainCase, waves: dict):
    """The wave components ropesim makes of a ``[waves]`` table on the chain's water (its Components)."""
    import tomli_w

    import ropesim
    from ropesim.model.waves import components_of

    scene = ropesim.scene_from_toml(tomli_w.dumps(ropesim_scene_dict(chain, None, waves, 1.0)))
    return components_of(scene.waves, chain.depth, chain.g)


def moordyn_frequencies(comps) -> str:
    """MoorDyn's ``wave_frequencies.txt`` for ropesim's components: rows w, Re A, Im A, beta, A = a e^(i phi_MD)
    with phi_MD = pi/2 - phi (the module doc), after the zero-frequency row MoorDyn asks for first."""
    rows = ["0.0 0.0 0.0 0.0"]
    for a, w, phi, beta in zip(comps.amplitude, comps.omega, comps.phase, comps.direction):
        a, w, beta, phase = float(a), float(w), float(beta), 0.5 * math.pi - float(phi)
        rows.append(f"{w!r} {a * math.cos(phase)!r} {a * math.sin(phase)!r} {beta!r}")
    return "\n".join(rows) + "\n"


@dataclass
class MoorDynWaveRun:
    """MoorDyn's run: times t (F,), fairlead tension from its state (F,), its own ``GetLineFairTen`` (F,, from
    its last force evaluation, half a step before the frame), node positions (F, N+1, 3), node N-1's velocity
    (F, 3), the Step calls' wall time (s)."""

    t: np.ndarray
    tension: np.ndarray
    reported: np.ndarray
    positions: np.ndarray
    wall: float


def run_moordyn(chain: ChainCase, case: WaveCase, t_end: float | None = None) -> MoorDynWaveRun:
    """MoorDyn on the chain in the case's waves (``WaveKin = 7``), its IC in still water, then the fairlead held
    at rest, coupled every dt_out."""
    import time

    from .moordyn_harness import moordyn_system, quiet_fd

    t_end = case.t_end if t_end is None else t_end
    steps = int(round(t_end / case.dt_out))
    fair, n = np.asarray(chain.fairlead, dtype=float), chain.segments
    extra = {"wave_frequencies.txt": moordyn_frequencies(components(chain, case.waves))}
    pos, vel, reported, wall = [], [], [], 0.0
    with moordyn_system(moordyn_chain_text(chain, {"WaveKin": 7}), fair, ic=True, extra_files=extra) as (md, system):
        line = md.GetLine(system, 1)

        def record():
            pos.append(np.array([md.GetLineNodePos(line, i) for i in range(n + 1)]))
            vel.append(np.asarray(md.GetLineNodeVel(line, n - 1), dtype=float))
            reported.append(md.GetLineFairTen(line))

        record()
        with quiet_fd():
            for k in range(steps):
                tic = time.perf_counter()
                md.Step(system, list(fair), [0.0, 0.0, 0.0], k * case.dt_out, case.dt_out)
                wall += time.perf_counter() - tic
                record()
    positions, velocity = np.array(pos), np.array(vel)
    x = to_ropesim(positions)
    v = np.zeros_like(x)
    v[:, n - 1] = to_ropesim(velocity)
    tension = np.abs(segment_tension(chain, x, v, n - 1))
    return MoorDynWaveRun(case.dt_out * np.arange(steps + 1), tension, np.array(reported), positions, wall)


def ropesim_scene_dict(chain: ChainCase, start, waves: dict, t_end: float, fraction: str = "moordyn",
                       method: str = "rk4", dt: float | None = None, dt_out: float = 0.1) -> dict:
    """ropesim's scene: the chain from ``start`` (MoorDyn positions (N+1, 3), at rest; None: its own static
    shape) with the fairlead pinned, under a ``[sea]`` at level 0 with no air, and ``waves``."""
    scene = chain_scene_dict(chain, start, method=method, dt=dt or chain.dtM, t_end=t_end, moving=False,
                             interval=dt_out)
    scene["sea"] = {"level": 0.0, "air_density": 0.0, "fraction": fraction}
    scene["waves"] = dict(waves)
    return scene


def run_ropesim(chain: ChainCase, start, case: WaveCase, t_end: float | None = None, **kw):
    """ropesim's run (arguments as :func:`ropesim_scene_dict`): (Trajectory, fairlead tension (F,))."""
    import tomli_w

    import ropesim

    t_end = case.t_end if t_end is None else t_end
    scene = ropesim.scene_from_toml(tomli_w.dumps(ropesim_scene_dict(chain, start, case.waves, t_end,
                                                                     dt_out=case.dt_out, **kw)))
    traj = ropesim.simulate(scene)
    return traj, np.abs(segment_tension(chain, traj.x, traj.v, chain.segments - 1))


def agreement(reference: np.ndarray, other: np.ndarray) -> dict:
    """The RMS and largest difference (N) of two tension records, and the RMS relative to the reference's mean
    and to its standard deviation (the waves' part of the tension)."""
    d = np.asarray(other) - np.asarray(reference)
    rms = float(np.sqrt(np.mean(d * d)))
    return {"rms": rms, "max": float(np.abs(d).max()), "rms_of_mean": rms / float(np.mean(reference)),
            "rms_of_std": rms / float(np.std(reference))}


def chain() -> ChainCase:
    """The chain of wavekin_wave_1.txt (MoorDyn's WD0050_Chain)."""
    return chain_case(CHAIN)
