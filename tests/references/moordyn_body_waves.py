"""A free rigid body in waves, ropesim against MoorDyn on equal physics: a buoy on a taut vertical tether in a
regular wave. Used by ``scripts/compare_moordyn_body_waves.py`` and ``tests/test_moordyn_body_waves.py``.

Not one of MoorDyn's files (MoorDyn's tests have no body in waves): MoorDyn's frame, z up, 50 m of water.

- The buoy: a free body, 2000 kg, inertia 500 kg m^2 about every axis, its centre of gravity at its reference
  point (0, 0, -10), volume 4 m^3 (20.6 kN of net buoyancy), CdA 3 m^2 on each axis and rotational CdA 2 m^5,
  no added mass (MoorDyn would put a body's added mass in its centripetal force too:
  :func:`.moordyn_systems.moordyn_centripetal_excess`; with the centre of gravity at the reference point it
  would not matter, but none keeps the case plain).
- The tether: 38.2 m of rope (d = 5 cm, 3 kg/m, EA = 1 MN, damping ratio 0.5, Cd 1.2, Ca 1, no axial drag or
  added mass), 20 segments, from an anchor on the seabed straight up to a point 1 m below the buoy's reference
  point: 39 m, so the rope starts stretched by about its static stretch. Both codes start it straight with its
  nodes evenly spaced (MoorDyn's ``Init_NoIC`` lays a vertical line so) and everything at rest.
- The wave: regular, H = 4 m, T = 8 s, along x, from t = 0 on both sides (no ramp), ``WaveKin = 7``: MoorDyn sums
  ropesim's component itself at every node, point and body (``Waves::kinematicsForAllNodes``), surface included
  (:mod:`.moordyn_waves` sets out the equal physics of the kinematics and the lines).

MoorDyn's body (``Body::doRHS``) takes the water's velocity at its reference point in its drag, full buoyancy at
its centre of gravity, and no force from the water's acceleration. ropesim's ``[sea] fraction = "moordyn"`` is
that body (and MoorDyn's rule for the lines' wetted part; here all is under water). ropesim's own model
(``"cylinders"``, with the body's ``height``) adds the Froude-Krylov force rho V a_w at the reference point: the
comparison of the two measures that force's effect. No air (``air_density = 0``). MoorDyn integrates with RK2
at dtM = 1 ms, ropesim with rk4 at 1 ms. Compared: the buoy's position (surge x and heave) every 0.1 s.
"""

from __future__ import annotations

import math

import numpy as np

from .moordyn_own_cases import moordyn_ba

DEPTH, G, RHO = 50.0, 9.80665, 1025.0
WAVE = {"kind": "regular", "height": 4.0, "period": 8.0}
ROPE = {"d": 0.05, "w": 3.0, "EA": 1.0e6, "zeta": 0.5, "Cd": 1.2, "Ca": 1.0}
LENGTH, SEGMENTS = 38.2, 20
BUOY = {"mass": 2000.0, "inertia": 500.0, "volume": 4.0, "cda": 3.0, "cda_rot": 2.0, "z": -10.0}
EYE_Z = -1.0      # the tether's point on the buoy, in its frame (MoorDyn's z)
DT, DT_OUT = 0.001, 0.1

MOORDYN_TEXT = f"""--------------------- MoorDyn Input File ------------------------------------
A buoy on a taut tether in a regular wave (ropesim's tests/references/moordyn_body_waves.py)
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA       BA/-zeta    EI     Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)      (N-s/-)     (N-m^2) (-)   (-)    (-)     (-)
rope       {ROPE['d']}    {ROPE['w']}        {ROPE['EA']}    -{ROPE['zeta']}    0      {ROPE['Cd']}    {ROPE['Ca']}    0.0     0.0
---------------------------- BODIES -----------------------------------------------------
ID   Attachment  X0     Y0    Z0     r0      p0     y0     Mass     CG*   I*      Volume   CdA*   Ca
(#)     (-)      (m)    (m)   (m)   (deg)   (deg)  (deg)   (kg)     (m)   (kg-m^2) (m^3)   (m^2)  (-)
1       free      0     0     {BUOY['z']}    0       0      0      {BUOY['mass']}   0     {BUOY['inertia']}   {BUOY['volume']}   {BUOY['cda']}|{BUOY['cda_rot']}   0
---------------------- POINT PROPERTIES --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)
1     Fixed     0       0       {-DEPTH}   0      0       0      0
2     Body1     0       0       {EYE_Z}    0      0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     rope       1        2         {LENGTH}      {SEGMENTS}      -
---------------------- OPTIONS -----------------------------------------
{DT}         dtM           time step (s)
{G}       g             gravity (m/s^2)
{RHO}        WtrDnsty      water density (kg/m^3)
{DEPTH}          WtrDpth       water depth (m)
7             WaveKin       waves: ropesim's components summed by MoorDyn (wave_frequencies.txt)
------------------------- need this line --------------------------------------
"""


def scene_dict(t_end: float, fraction: str = "moordyn", method: str = "rk4", dt: float = DT) -> dict:
    """ropesim's scene of the case (MoorDyn's (x, y, z) is ropesim's (x, z, -y)); ``fraction`` the sea's rule
    (``"cylinders"``: ropesim's own body, its height 2 m, wholly under water here)."""
    ba = moordyn_ba(-ROPE["zeta"], LENGTH, SEGMENTS, ROPE["EA"], ROPE["w"])
    body = {"id": "buoy", "position": [0.0, BUOY["z"], 0.0], "mass": BUOY["mass"],
            "inertia": [BUOY["inertia"]] * 3, "volume": BUOY["volume"], "cd_area": [BUOY["cda"]] * 3,
            "cd_rotation": [BUOY["cda_rot"]] * 3}
    if fraction != "moordyn":
        body["height"] = 2.0
    return {
        "name": "moordyn_body_waves", "dimension": 3,
        "bodies": [body],
        "points": [{"id": "anchor", "kind": "fixed", "position": [0.0, -DEPTH, 0.0]},
                   {"id": "eye", "body": "buoy", "position": [0.0, EYE_Z, 0.0]}],
        "lines": [{"id": "tether", "start": "anchor", "end": "eye", "length": LENGTH, "segments": SEGMENTS,
                   "diameter": ROPE["d"], "mass_per_length": ROPE["w"], "EA": ROPE["EA"], "axial_damping": ba,
                   "compression": False}],
        "gravity": {"g": G}, "fluid": {"density": RHO}, "buoyancy": {},
        "fluid_drag": {"cd_normal": ROPE["Cd"], "cd_tangential": 0.0},
        "added_mass": {"ca_normal": ROPE["Ca"], "ca_tangential": 0.0},
        "sea": {"level": 0.0, "depth": DEPTH, "air_density": 0.0, "fraction": fraction},
        "waves": dict(WAVE),
        "integrator": {"method": method, "dt": dt, "t_end": t_end},
        "output": {"interval": DT_OUT},
    }


def run_ropesim(t_end: float, **kw):
    """ropesim's run: (times (F,), the buoy's reference point (F, 3) in MoorDyn's frame)."""
    import tomli_w

    import ropesim

    traj = ropesim.simulate(ropesim.scene_from_toml(tomli_w.dumps(scene_dict(t_end, **kw)), source="case.toml"))
    p = traj.body("buoy").position
    return np.asarray(traj.t), np.stack([p[:, 0], -p[:, 2], p[:, 1]], axis=1)


def run_moordyn(t_end: float):
    """MoorDyn's run from its file's layout at rest (``Init_NoIC``): (times (F,), the buoy's reference point
    (F, 3), MoorDyn's frame)."""
    import tomli_w

    import ropesim
    from ropesim.model.waves import components_of

    from .moordyn_harness import QUIET_OPTIONS, moordyn_system, quiet_fd, set_options
    from .moordyn_waves import moordyn_frequencies

    scene = ropesim.scene_from_toml(tomli_w.dumps(scene_dict(t_end)), source="case.toml")
    extra = {"wave_frequencies.txt": moordyn_frequencies(components_of(scene.waves, DEPTH, G))}
    steps = int(round(t_end / DT_OUT))
    out = []
    with moordyn_system(set_options(MOORDYN_TEXT, QUIET_OPTIONS), None, ic=False, extra_files=extra) as (md, system):
        body = md.GetBody(system, 1)
        out.append(np.asarray(md.GetBodyState(body)[0][:3], dtype=float))
        with quiet_fd():
            for k in range(steps):
                md.Step(system, [], [], k * DT_OUT, DT_OUT)
                out.append(np.asarray(md.GetBodyState(body)[0][:3], dtype=float))
    return DT_OUT * np.arange(steps + 1), np.array(out)


def agreement(reference: np.ndarray, other: np.ndarray) -> dict:
    """RMS and largest differences [m] of two position records (F, 3) in surge and heave, and the RMS relative to
    the reference's surge and heave standard deviations."""
    out = {}
    for name, axis in (("surge", 0), ("heave", 2)):
        d = other[:, axis] - reference[:, axis]
        rms = float(math.sqrt(np.mean(d * d)))
        out[name] = {"rms": rms, "max": float(np.abs(d).max()), "std": float(np.std(reference[:, axis])),
                     "rms_of_std": rms / float(np.std(reference[:, axis]))}
    return out
