"""ropesim against MoorDyn on MoorDyn's own system cases: OC3-Hywind's three chains on a surging vessel
(``lines.txt``: lines, fixed and coupled points, a seabed, Morison drag, added mass, buoyancy), a free rigid body
turned by a line (``body_tests/rotatingBody.txt``: a 6-DOF body, its line ends slaved to it, large rotations about
three axes) and a mass dropped onto its slack line (``lifting.txt``: a free point, snap loads); and a free body in
water, the speed benchmark's spar on lines.txt's chains (``spar_free.txt``, not MoorDyn's own: buoyancy, drag and
an offset centre of gravity on a body).
tests/references/moordyn_systems.py builds each case from MoorDyn's own input file and holds the conventions;
scripts/compare_moordyn_systems.py the full comparison behind docs/background/validation.md.

Everything here runs on MoorDyn 2.7.2's stored runs (tests/data/moordyn/own_systems.npz and .json, from
``scripts/compare_moordyn_systems.py --regenerate``): MoorDyn is not needed at test time.

What the tolerances rest on (measured; the issue asks for 0.5 % static and 2 % RMS dynamic):

- static: ropesim's static solve is within 5e-9 (fairleads) and 1.4e-8 (anchors) of MoorDyn's IC run tight on
  lines.txt, its nodes within 2 um; the IC as the file sets it up (its saved .ic state, threshIC 1e-3) is 0.77 %
  low, which is MoorDyn's own IC stopping short (its tight IC differs from it by as much). On lifting.txt ropesim's
  static shape is the closed form to 1e-10 while MoorDyn's IC stalls 0.43 m short. Tolerances 1e-7 and 1e-8 m;
- lines.txt dynamic: rk4 at MoorDyn's 2 ms against its RK2: 1.4e-6 to 2.4e-6 of each fairlead tension's range
  RMS, 2e-5 at most; at 1 ms against MoorDyn's RK4 at 1 ms, 1.5e-13 to 3.9e-13: the same numbers to round-off.
  Tolerances 1e-5 (RMS) and 1e-4 (max) of the range, 1e-10 at equal steps;
- rotatingBody: line 7's tension 1.8e-4 of its range RMS and the body's orientation 4.8e-5 rad RMS from MoorDyn's
  RK2, which is MoorDyn's own step error (1.7e-4, 4.6e-5 rad from its converged RK4); at 0.25 ms against MoorDyn's
  RK4 at 0.25 ms, 2.9e-12 and 7e-13 rad. Tolerances 5e-4, 1.5e-4 rad; 1e-9 and 1e-10 rad at equal steps;
- lifting: the drop and the first snap (0-0.6 s, 283 kN of tension range) the same to 1.7e-9 m and 0.063 N; then
  the slack-taut switching of 20 segments is chaotic, and ropesim drifts from MoorDyn as MoorDyn drifts from itself
  started 1 nm off (1 mm apart at 1.17 s and 1.15 s);
- spar: rk4 against MoorDyn's RK4 at 2 ms, 2e-10 to 1.3e-8 of each signal's range; with the body's added mass,
  MoorDyn's centripetal force of the offset centre of gravity takes it in (1.85 mm of heave in 30 s). Tolerance 1e-7;
- one wrong coefficient breaks the agreement by 5 times the tolerances or more: Cd 10 % high, the added mass 10 %
  low, kBot doubled (6 times: it moves only the touchdown), BA 50 % high on lines.txt, the body's inertia 10 % high
  on rotatingBody, the spar 10 % light.
Units: SI.
"""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest
from references.moordyn_systems import (
    DATA,
    EULER_CHECK,
    LIFTING_RUN,
    SPAR_RUN,
    P,
    body_rotations_moordyn,
    differences,
    drive_of,
    from_ropesim,
    gyroscopic_share,
    lifting_closed_form,
    load_stored,
    moordyn_centripetal_excess,
    moordyn_rotation,
    read_system,
    ropesim_anchor_state,
    ropesim_angles,
    ropesim_fairlead_tensions,
    rotation_angle_between,
    run_system,
    run_system_from,
    spar_changes,
    static_positions,
    static_tensions,
    system_scene_dict,
)


@pytest.fixture(scope="module")
def stored():
    return load_stored()


# ------------------------------------------------------------------------------------------------ the input files


def test_the_cases_are_read_as_moordyn_reads_them():
    """Every number comes from MoorDyn's files and its 2.7.2 defaults: line types by column position (rotatingBody's
    header names its columns "tbd Can Cat Cdn Cdt"; MoorDyn reads them as Cd, Ca, CdAx, CaAx and a lift
    coefficient), a negative BA as a damping ratio per line, the body's one inertia for every axis."""
    s = read_system("lines")
    (t,) = s.types.values()
    assert (t.d, t.w, t.EA, t.Cd, t.Ca, t.CdAx, t.CaAx) == (0.09, 77.7066, 384.243e6, 1.6, 1.0, 0.1, 0.0)
    assert [(ln.a, ln.b, ln.length, ln.segments) for ln in s.lines] == [(1, 4, 902.2, 20), (2, 5, 902.2, 20),
                                                                       (3, 6, 902.2, 20)]
    assert s.coupled == [4, 5, 6]
    assert s.ba(s.lines[0]) == pytest.approx(0.8 * 45.11 * math.sqrt(384.243e6 * 77.7066), rel=1e-12)
    assert (s.file.depth, s.file.rho_w, s.file.g, s.file.dtM, s.file.scheme) == (320.0, 1025.0, 9.80665, 0.002,
                                                                                 "RK2")
    # the same physics as the system example tests/data/systems/oc3_hywind.toml (its BA rounded to 5 digits)
    example = tomllib.loads((DATA.parent / "systems" / "oc3_hywind.toml").read_text(encoding="utf-8"))
    scene = system_scene_dict("lines", drive_of("lines"))
    assert scene["line_types"]["main"]["EA"] == example["line_types"]["chain"]["EA"]
    assert scene["lines"][0]["axial_damping"] == pytest.approx(example["line_types"]["chain"]["axial_damping"],
                                                               rel=1e-4)
    assert np.array([p["position"] for p in scene["points"][:3]]) == pytest.approx(
        np.array([p["position"] for p in example["points"][:3]]), abs=1e-12)
    r = read_system("rotatingBody")
    (body,) = r.bodies
    assert (body.kind, body.mass, body.inertia, body.cg, body.volume, body.cda) == (
        "free", 10.0, (5.0, 5.0, 5.0), (0.0, 0.0, 0.0), 0.0, (0.0,) * 6)
    (t,) = r.types.values()
    assert (t.Cd, t.Ca, t.CdAx, t.CaAx) == (0.0, 1.0, 0.0, 1.6)   # out of the water here: no fluid acts
    assert r.coupled == [9] and r.file.g == 0.0 and "fluid" not in system_scene_dict("rotatingBody", None)
    lift = read_system("lifting")
    (t,) = lift.types.values()
    assert t.w == pytest.approx(1000.0 * math.pi / 4 * t.d ** 2, rel=3e-7)     # as dense as the water
    assert [(p.kind, p.mass) for p in lift.points] == [("fixed", 0.0), ("free", 1000.0)]


def test_moordyns_orientation_angles_are_rx_ry_rz_and_map_to_ropesims():
    """MoorDyn turns a body by R = Rx(r) Ry(p) Rz(y) (``Euler2Quat``; the stored check is MoorDyn placing a point on
    a turned body), not ropesim's R = Rz Ry Rx; its frame maps to ropesim's by a proper rotation, and
    :func:`ropesim_angles` gives the ropesim angles of the same orientation."""
    from ropesim.model.rotation import quaternion_from_angles, rotation_matrix

    _, record = load_stored()
    check = record["euler_check"]
    assert check["angles_deg"] == list(EULER_CHECK["angles_deg"])
    placed = moordyn_rotation(check["angles_deg"]) @ np.array(check["point"])
    assert placed == pytest.approx(check["moordyn_position_m"], abs=1e-12)
    r, p, y = np.radians(check["angles_deg"])
    rx = np.array([[1, 0, 0], [0, math.cos(r), -math.sin(r)], [0, math.sin(r), math.cos(r)]])
    ry = np.array([[math.cos(p), 0, math.sin(p)], [0, 1, 0], [-math.sin(p), 0, math.cos(p)]])
    rz = np.array([[math.cos(y), -math.sin(y), 0], [math.sin(y), math.cos(y), 0], [0, 0, 1]])
    assert moordyn_rotation(check["angles_deg"]) == pytest.approx(rx @ ry @ rz, abs=1e-15)
    assert not np.allclose(rz @ ry @ rx @ np.array(check["point"]), check["moordyn_position_m"], atol=0.1)
    assert np.linalg.det(P) == pytest.approx(1.0) and P @ P.T == pytest.approx(np.eye(3))
    rng = np.random.default_rng(20)
    for angles in rng.uniform(-170.0, 170.0, size=(20, 3)):
        target = P @ moordyn_rotation(angles) @ P.T
        assert rotation_matrix(quaternion_from_angles(ropesim_angles(moordyn_rotation(angles)))) == pytest.approx(
            target, abs=1e-12)
    assert body_rotations_moordyn(np.array([0, 0, 0, *np.radians(check["angles_deg"])])) == pytest.approx(
        P @ moordyn_rotation(check["angles_deg"]) @ P.T, abs=1e-15)


# ------------------------------------------------------------------------------------------------ static


def test_lines_static_solve_is_moordyns_tight_ic(stored):
    """ropesim's static solve of OC3-Hywind's spread within 1e-7 of MoorDyn's IC run tight (measured 4.7e-9 at the
    fairleads, 1.4e-8 at the anchors; nodes 2 um apart); MoorDyn's IC as its file sets it up stops 0.77 % short
    (its own tight IC is that far from it), and the stored runs started from this very static shape."""
    arrays, record = stored
    ics = record["cases"]["lines"]["ic"]
    x = static_positions("lines")
    fair, anchor = static_tensions("lines", x)
    tight = np.array(ics["tight"]["fairlead_tension_N"]), np.array(ics["tight"]["anchor_tension_N"])
    assert fair == pytest.approx(tight[0], rel=1e-7)
    assert anchor == pytest.approx(tight[1], rel=1e-7)
    assert np.abs(x - arrays["lines_ic_tight_positions"]).max() < 1e-4
    assert np.abs(x - arrays["lines_start"]).max() < 1e-8
    filed = np.array(ics["filed"]["fairlead_tension_N"])
    assert 0.005 < (tight[0] / filed - 1.0).min() and (tight[0] / filed - 1.0).max() < 0.01
    grounded = x[:21, 2] < -319.9
    assert 2 <= grounded.sum() <= 5                     # 135 m of each chain on the seabed: nodes 0 to 3


def test_lifting_static_solve_is_the_closed_form_where_moordyns_ic_stalls(stored):
    """The 1 t mass on its neutrally buoyant line: ropesim's static solve within 1e-8 m and 1e-9 of the closed form
    (each segment carries the mass and the wet weight below it); MoorDyn's stationary IC solver, as filed and run
    1000 s, stalls with the line still slack (every segment starts compressed, so it has no force to relax on)."""
    _, record = stored
    exact = lifting_closed_form()
    x = static_positions("lifting")
    fair, anchor = static_tensions("lifting", x)
    assert x[-1, 2] == pytest.approx(exact["point_z"], abs=1e-8)
    assert fair[0] == pytest.approx(exact["tension_b"], rel=1e-9)
    assert anchor[0] == pytest.approx(exact["tension_a"], rel=1e-9)
    for kind in ("filed", "long"):
        assert record["cases"]["lifting"]["ic"][kind]["point_m"][1][2] > exact["point_z"] + 0.4


# ------------------------------------------------------------------------------------------------ dynamic


def test_lines_fairlead_tensions_follow_moordyn_through_the_surge(stored):
    """80 s of the vessel surging 5 m at 20 s, from the static state: rk4 at MoorDyn's 2 ms against its RK2, each
    fairlead tension within 1e-5 of its range RMS and 1e-4 at most (measured 2.4e-6 and 2e-5), the anchors' too
    (4.9e-6), every node within 0.2 mm (0.02 mm)."""
    arrays, _ = stored
    drive = drive_of("lines")
    traj = run_system("lines", drive, start="equilibrium")
    assert traj.summary["status"] == "completed"
    fair = ropesim_fairlead_tensions("lines", traj, drive)
    anchor = ropesim_anchor_state("lines", traj)
    assert np.abs(traj.t - arrays["lines_t"]).max() < 1e-9     # frames on the coupling instants
    for i in range(3):
        d = differences(arrays["lines_fairlead"][:, i], fair[:, i])
        assert d["range"] > 2.5e5 and d["rms_of_range"] < 1e-5 and d["max_of_range"] < 1e-4, (i, d)
        a = differences(arrays["lines_anchor"][:, i], anchor[:, i])
        assert a["rms_of_range"] < 2e-5, (i, a)
    every = len(arrays["lines_t"]) // (len(arrays["lines_positions"]) - 1)
    assert np.abs(from_ropesim(np.asarray(traj.x))[::every] - arrays["lines_positions"]).max() < 2e-4


@pytest.mark.slow
def test_lines_at_equal_steps_and_schemes_is_moordyn_to_round_off(stored):
    """rk4 at 1 ms against MoorDyn's RK4 at 1 ms: the fairlead tensions agree to 1e-10 of their range (measured
    1.5e-13 to 3.9e-13): the same equations, discretised the same way."""
    arrays, _ = stored
    drive = drive_of("lines")
    traj = run_system("lines", drive, start="equilibrium", dt=0.001)
    fair = ropesim_fairlead_tensions("lines", traj, drive)
    for i in range(3):
        d = differences(arrays["lines_converged_fairlead"][:, i], fair[:, i])
        assert d["rms_of_range"] < 1e-10 and d["max_of_range"] < 1e-9, (i, d)


def rotating_results(traj, arrays) -> dict:
    from ropesim.model.rotation import rotation_matrix

    drive = drive_of("rotatingBody")
    fair = ropesim_fairlead_tensions("rotatingBody", traj, drive)
    r = rotation_matrix(np.asarray(traj.body_q)[:, 0])
    return {"line7": differences(arrays["rotatingBody_fairlead"][:, 6], fair[:, 6]),
            "line7_conv": differences(arrays["rotatingBody_converged_fairlead"][:, 6], fair[:, 6]),
            "springs": [differences(arrays["rotatingBody_fairlead"][:, i], fair[:, i]) for i in range(6)],
            "angle": rotation_angle_between(body_rotations_moordyn(arrays["rotatingBody_body_r6"][:, 0]), r),
            "angle_conv": rotation_angle_between(
                body_rotations_moordyn(arrays["rotatingBody_converged_body_r6"][:, 0]), r),
            "position": np.abs(from_ropesim(np.asarray(traj.body_x)[:, 0])
                               - arrays["rotatingBody_body_r6"][:, 0, :3]).max()}


def test_a_free_body_turned_by_a_line_follows_moordyn(stored):
    """The body turned -90 degrees about y, then x, then z by its dragging line: rk4 at MoorDyn's 0.5 ms against its
    RK2, line 7's tension within 5e-4 of its range RMS (measured 1.8e-4, MoorDyn's own RK2 error 1.7e-4), the
    springs' too, the orientation within 1.5e-4 rad RMS (4.8e-5), the position within 20 um (6 um); at 0.25 ms
    against MoorDyn's RK4 at 0.25 ms the same to round-off (2.9e-12, 7e-13 rad). The gyroscopic moment MoorDyn
    leaves out vanishes here: the body turns about axes perpendicular to the arm of the one mass off its centre."""
    arrays, _ = stored
    drive = drive_of("rotatingBody")
    traj = run_system("rotatingBody", drive)
    assert traj.summary["status"] == "completed"
    r = rotating_results(traj, arrays)
    turned = rotation_angle_between(body_rotations_moordyn(arrays["rotatingBody_body_r6"][0, 0]),
                                    body_rotations_moordyn(arrays["rotatingBody_body_r6"][:, 0]))
    assert turned.max() > math.radians(110.0) and r["line7"]["range"] > 300.0
    assert r["line7"]["rms_of_range"] < 5e-4 and r["line7"]["max_of_range"] < 3e-3, r["line7"]
    assert max(d["rms_of_range"] for d in r["springs"]) < 6e-4
    assert np.sqrt(np.mean(r["angle"] ** 2)) < 1.5e-4 and r["angle"].max() < 5e-4
    assert r["position"] < 2e-5
    assert gyroscopic_share("rotatingBody", traj)["body1"]["gyroscopic_max_Nm"] < 1e-9
    fine = rotating_results(run_system("rotatingBody", drive, dt=2.5e-4), arrays)
    assert fine["line7_conv"]["rms_of_range"] < 1e-9 and fine["angle_conv"].max() < 1e-10, fine["line7_conv"]


def test_the_lifted_mass_drops_and_snaps_as_in_moordyn_until_the_slack_line_turns_chaotic(stored):
    """The mass dropped onto its slack line (RK4 at 0.1 ms in both): through the fall and the first snap (0-0.6 s,
    283 kN of tension range) the mass within 1e-7 m and the tension at it within 1 N (measured 1.7e-9 m, 0.063 N);
    then 20 segments switching between slack and taut amplify round-off, and ropesim parts from MoorDyn when
    MoorDyn parts from itself started 1 nm off: 1 mm apart within 0.15 s of each other (measured 1.17, 1.15 s)."""
    arrays, _ = stored
    t = arrays["lifting_t"]
    traj = run_system("lifting", None, t_end=LIFTING_RUN["t_end"], interval=LIFTING_RUN["dt_out"])
    assert np.abs(traj.t - t).max() < 1e-9
    z = from_ropesim(np.asarray(traj.x))[:, -1, 2]
    fair = ropesim_fairlead_tensions("lifting", traj, None)[:, 0]
    md_z, md_f = arrays["lifting_points"][:, 1, 2], arrays["lifting_fairlead"][:, 0]
    early = t <= 0.6
    assert np.ptp(md_f[early]) > 2e5
    assert np.abs(z - md_z)[early].max() < 1e-7
    assert np.abs(fair - md_f)[early].max() < 1.0

    def apart(err, level=1e-3):
        return t[np.flatnonzero(err > level)[0]]

    self_apart = apart(np.abs(arrays["lifting_perturbed_points"][:, 1, 2] - md_z))
    assert abs(apart(np.abs(z - md_z)) - self_apart) < 0.15
    assert z.min() > -100.6 and z[1:].max() < -100.0   # it falls from its start and bounces on the line


# ------------------------------------------------------------------------------------------------ sensitivity


LINES_WRONG = {   # each as {section: {key: value}} merged into the scene; fast ones first
    "Cd 10 % high": {"line_types": {"main": {"diameter": 0.09, "mass_per_length": 77.7066, "EA": 384.243e6,
                                             "compression": False, "cd_normal": 1.76, "cd_tangential": 0.1,
                                             "ca_normal": 1.0, "ca_tangential": 0.0}}},
    "added mass 10 % low": {"line_types": {"main": {"diameter": 0.09, "mass_per_length": 77.7066, "EA": 384.243e6,
                                                    "compression": False, "cd_normal": 1.6, "cd_tangential": 0.1,
                                                    "ca_normal": 0.9, "ca_tangential": 0.0}}},
    "kBot doubled": {"seabed": {"stiffness": 6.0e6}},
}


@pytest.mark.parametrize("wrong", [pytest.param(k, marks=[] if i == 0 else [pytest.mark.slow])
                                   for i, k in enumerate(LINES_WRONG)])
def test_a_wrong_coefficient_breaks_the_lines_agreement(wrong, stored):
    """Each of these moves the fairlead tensions (tolerance 1e-5 of the range RMS) or the anchor tension (2e-5) from
    MoorDyn's by at least 5 times the tolerance: Cd and Ca by more than 20 times; kBot doubled, which only moves
    the touchdown, by 6.2 times (25 times the measured difference)."""
    arrays, _ = stored
    drive = drive_of("lines")
    traj = run_system("lines", drive, start="equilibrium", changes=LINES_WRONG[wrong])
    fair = ropesim_fairlead_tensions("lines", traj, drive)
    anchor = ropesim_anchor_state("lines", traj)
    worst = max(max(differences(arrays["lines_fairlead"][:, i], fair[:, i])["rms_of_range"] / 1e-5,
                    differences(arrays["lines_anchor"][:, i], anchor[:, i])["rms_of_range"] / 2e-5) for i in range(3))
    assert worst > 5.0, (wrong, worst)


@pytest.mark.slow
def test_axial_damping_half_again_breaks_the_lines_agreement(stored):
    """BA 50 % high (the damping ratio 1.2 for 0.8) on every line: the fairlead tensions move well past tolerance."""
    arrays, _ = stored
    drive = drive_of("lines")
    scene = system_scene_dict("lines", drive, start="equilibrium")
    lines = [{**ln, "axial_damping": 1.5 * ln["axial_damping"]} for ln in scene["lines"]]
    traj = run_system("lines", drive, start="equilibrium", changes={"lines": lines})
    fair = ropesim_fairlead_tensions("lines", traj, drive)
    worst = max(differences(arrays["lines_fairlead"][:, i], fair[:, i])["rms_of_range"] for i in range(3))
    assert worst > 20 * 1e-5, worst


def test_a_body_inertia_ten_per_cent_high_breaks_the_rotating_body_agreement(stored):
    """The body's moments of inertia 10 % high: line 7's tension and the orientation move at least 10 times their
    tolerances (5e-4 of the range, 1.5e-4 rad RMS)."""
    arrays, _ = stored
    traj = run_system("rotatingBody", drive_of("rotatingBody"),
                      changes={"bodies": [{**system_scene_dict("rotatingBody", None)["bodies"][0],
                                           "inertia": [5.5, 5.5, 5.5]}]})
    r = rotating_results(traj, arrays)
    assert r["line7"]["rms_of_range"] > 10 * 5e-4 or np.sqrt(np.mean(r["angle"] ** 2)) > 10 * 1.5e-4, r


# ------------------------------------------------------------------------------------------------ a free body in water


def spar_signals(traj) -> np.ndarray:
    """(F, 5): the three fairlead tensions (N), the spar's heave and surge (m), MoorDyn's axes."""
    return np.column_stack([ropesim_fairlead_tensions("spar", traj, None),
                            from_ropesim(np.asarray(traj.body_x)[:, 0])[:, [2, 0]]])


def test_a_free_spar_in_water_follows_moordyn(stored):
    """The speed benchmark's spar (lines.txt's chains on a free body 10 % too buoyant, its centre of gravity 78 m
    down and 0.5 m off its axis, buoyancy, translational and rotational drag, no added mass) released from the
    lines' static shape for 30 s: rk4 at 2 ms against MoorDyn's RK4 at 2 ms, every fairlead tension and the heave,
    surge and pitch within 1e-7 of their ranges RMS (measured 2e-10 to 1.3e-8: the centripetal moment of the
    offset centre of gravity MoorDyn leaves out). A 10 % lighter spar is far outside."""
    from ropesim.model.rotation import rotation_matrix

    arrays, _ = stored
    start = static_positions("lines")
    kw = {"t_end": SPAR_RUN["t_end"], "interval": SPAR_RUN["dt_out"]}
    traj = run_system_from("spar", start, **kw)
    assert traj.summary["status"] == "completed"
    md = np.column_stack([arrays["spar_fairlead"], arrays["spar_body_r6"][:, 0, [2, 0]]])
    rs = spar_signals(traj)
    for k in range(5):
        d = differences(md[:, k], rs[:, k])
        assert d["rms_of_range"] < 1e-7 and d["max_of_range"] < 5e-7, (k, d)
    assert np.ptp(md[:, 3]) > 5.0 and np.ptp(md[:, 4]) > 1.0        # it heaves and surges metres
    r = rotation_matrix(np.asarray(traj.body_q)[:, 0])
    pitch = differences(arrays["spar_body_r6"][:, 0, 4], np.arctan2(r[:, 0, 1], r[:, 0, 0]))
    assert pitch["range"] > 0.02 and pitch["rms_of_range"] < 1e-7, pitch
    body = system_scene_dict("spar", None)["bodies"][0]
    light = spar_signals(run_system_from("spar", start, changes={"bodies": [{**body, "mass": 0.9 * body["mass"]}]},
                                         **kw))
    assert differences(md[:, 3], light[:, 3])["rms_of_range"] > 0.01


def test_moordyns_body_puts_its_added_mass_in_its_centripetal_force(stored):
    """With the spar's Ca = 1 in both codes, MoorDyn's heave falls behind ropesim's by 1.85 mm in 30 s (1.5e-4 of
    its range): MoorDyn's ``Body::doRHS`` takes the offset centre of gravity's centripetal force as
    M_t w x (w x c) with M_t its translational mass matrix, added mass included, where the rigid body's is
    m w x (w x c). That excess, integrated twice over the heave's mass from ropesim's own run, predicts 2.08 mm
    (the lines' restoring force and the drag left out): the difference is that term, within 20 %."""
    arrays, _ = stored
    traj = run_system_from("spar", static_positions("lines"), changes=spar_changes(SPAR_RUN["ca"]),
                           t_end=SPAR_RUN["t_end"], interval=SPAR_RUN["dt_out"])
    apart = arrays["spar_added_mass_body_r6"][:, 0, 2] - from_ropesim(np.asarray(traj.body_x)[:, 0])[:, 2]
    predicted = moordyn_centripetal_excess(traj, SPAR_RUN["ca"])
    assert apart[-1] < -1e-3 and 0.8 < apart[-1] / predicted[-1] < 1.0, (apart[-1], predicted[-1])
    late = traj.t > 10.0
    assert np.all(np.sign(apart[late]) == np.sign(predicted[late]))
