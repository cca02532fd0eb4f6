"""MoorDyn v2 input files as scenes: ``ropesim import moordyn FILE`` and ``ropesim run FILE.txt``.

Every file of MoorDyn's ``tests/Mooring/`` is listed with what ropesim does with it: imports and runs, or refuses
in one line (its input files are copied in ``tests/data/moordyn/mooring/``; the data files they read are named but
not copied, but three). lines.txt (OC3-Hywind) gives MoorDyn's statics, stored by
``tests/references/moordyn_lines_statics.py``. Bad input is one line naming the file, the line number and what is
wrong, exit 2.
"""

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import ropesim
from ropesim.model.rotation import rotation_matrix
from ropesim.scene.loader import SceneError, load_scene, scene_from_toml
from ropesim.scene.moordyn import read_moordyn, scene_text

DATA = Path(__file__).parent / "data" / "moordyn"
MOORING = DATA / "mooring"
RUNS, DATA_FILE = "imports and runs", "a data file another input reads (not copied)"
ROD = "uses rods (ROD TYPES): ropesim has no rods yet"
WAVES = ("uses wave kinematics from MoorDyn's wave files or grids (WaveKin = {}): ropesim reads WaveKin = 1 "
         "(kinematics given through the coupling calls); its own waves are [waves]").format
CURRENTS = ("uses currents that vary in time or across the sea (Currents = {}): ropesim's [flow] is steady and varies "
            "with height only (Currents = 1 is read)")
NOT_INPUT = "not a MoorDyn input file: no line of it opens a MoorDyn section (---- LINE TYPES ----, ---- LINES ----, ...)"

# Every file in MoorDyn's tests/Mooring/ (commit 319ff99), and what `ropesim import moordyn` does with it: RUNS, or
# the refusal's line number and message.
MOORDYN_TESTS_MOORING = {
    "3D_seafloor/current_profile.txt": DATA_FILE,
    "3D_seafloor/hanging_lines.txt": (55, WAVES(3)),
    "3D_seafloor/make_3d_seafloor.py": DATA_FILE,
    "3D_seafloor/make_waves.py": DATA_FILE,
    "3D_seafloor/seafloor_profile_3d.txt": DATA_FILE,
    "3D_seafloor/water_grid.txt": DATA_FILE,
    "3D_seafloor/wave_elevation.txt": DATA_FILE,
    "BeamCantilevered.txt": (10, ROD),
    "BeamSimplySupported.txt": RUNS,
    "BodiesAndRods.dat": (11, ROD),
    "QuasiStatic/WD0050_Chain_ZZP1_A1.txt": DATA_FILE,
    "QuasiStatic/WD0050_Chain_ZZP1_A2.txt": DATA_FILE,
    "QuasiStatic/WD0200_Chain_ZZP1_A1.txt": DATA_FILE,
    "QuasiStatic/WD0200_Chain_ZZP1_A2.txt": DATA_FILE,
    "QuasiStatic/WD0600_Chain_ZZP1_A1.txt": DATA_FILE,
    "QuasiStatic/WD0600_Chain_ZZP1_A2.txt": DATA_FILE,
    "QuasiStatic/ZZP1_A1.txt": (None, NOT_INPUT),
    "QuasiStatic/ZZP1_A2.txt": DATA_FILE,
    "RodHanging.txt": (11, ROD),
    "RodPinnedFloating.txt": (8, ROD),
    "WD0050_Chain.txt": RUNS,
    "WD0050_Chain.txt.ic": DATA_FILE,
    "WD0200_Chain.txt": RUNS,
    "WD0200_Chain.txt.ic": DATA_FILE,
    "WD0600_Chain.txt": RUNS,
    "WD0600_Chain.txt.ic": DATA_FILE,
    "body_tests/bodyDrag.txt": RUNS,
    "body_tests/orbitalBody.txt": (6, ROD),
    "body_tests/pinnedBody.txt": (9, ROD),
    "body_tests/rotatingBody.txt": (5, "line type 'nylon' has a lift coefficient Cl (VIV): ropesim has no "
                                       "vortex-induced vibration"),
    "lifting.txt": RUNS,
    "lines.txt": RUNS,
    "lines.txt.ic": (None, NOT_INPUT),   # MoorDyn's stored state (binary), copied for its own run of lines.txt
    "local_euler/complex_system.txt": (14, ROD),
    "local_euler/duplicated.txt": RUNS,
    "local_euler/hanging.txt": RUNS,
    **{f"lowe_and_langley_2006/Case {i}.csv": DATA_FILE for i in range(1, 7)},
    "lowe_and_langley_2006/line.txt": RUNS,
    "moorpy_ic.py": DATA_FILE,
    "pendulum.txt": RUNS,
    "polyester/motion.csv": DATA_FILE,
    "polyester/simple.txt": RUNS,
    "polyester/visco.txt": (5, "line type 'rope' is viscoelastic (EA '1.424e+08|1.586e+08|0.4'): ropesim's lines "
                               "are linear elastic"),
    "polyester/viscoelastic/stress_strain_curve.csv": DATA_FILE,
    "polyester/viscoelastic/visco_motion.csv": DATA_FILE,
    "riser/riser.txt": (11, ROD),
    "riser/riser_ic1.txt": (11, ROD),
    "riser/riser_ic2.txt": (11, ROD),
    "rod_tests/AddedMass.txt": (12, ROD),
    "rotations/nwu.txt": (None, "has no LINE TYPES: ropesim's systems are lines between points and bodies"),
    "seafloor.txt": (23, "uses a 3-D seafloor (SeafloorFile): ropesim's seabed is a plane"),
    "syrope/exp_wc/line.txt": (16, "uses SYROPE IC: ropesim has no Syrope line model"),
    "syrope/exp_wc/syrope.dat": DATA_FILE,
    "syrope/linear_wc/line.txt": (16, "uses SYROPE IC: ropesim has no Syrope line model"),
    "syrope/linear_wc/syrope.dat": DATA_FILE,
    "syrope/owc.dat": DATA_FILE,
    "syrope/quadratic_wc/line.txt": (16, "uses SYROPE IC: ropesim has no Syrope line model"),
    "syrope/quadratic_wc/syrope.dat": DATA_FILE,
    "time_schemes.txt": (19, "option dtM must be a number, got '@DT@'"),   # a template MoorDyn's test fills in
    "tripod.txt": RUNS,
    "viv/current_profile.txt": (None, NOT_INPUT),
    "viv/viv.txt": (6, "line type 'cable' has a lift coefficient Cl (VIV): ropesim has no vortex-induced vibration"),
    "wave_surface/wave_frequencies.txt": DATA_FILE,
    "wave_surface/wave_surface.txt": (40, WAVES(7)),
    "wavekin_2/current_profile.txt": DATA_FILE,
    "wavekin_2/current_profile_4d.txt": DATA_FILE,
    "wavekin_2/current_profile_dynamic.txt": DATA_FILE,
    "wavekin_2/make_waves.py": DATA_FILE,
    "wavekin_2/water_grid.txt": DATA_FILE,
    "wavekin_2/wave_elevation.txt": DATA_FILE,
    "wavekin_2/wave_frequencies.txt": DATA_FILE,
    **{f"wavekin_2/{name}.txt": (28, WAVES(name[8])) for name in ("wavekin_2", "wavekin_2_curr2",
                                                                    "wavekin_2_curr5", "wavekin_3", "wavekin_3_curr2",
                                                                    "wavekin_3_curr5")},
    "wavekin_3/current_profile_dynamic.txt": DATA_FILE,
    "wavekin_3/test_dynamic_currents.txt": (31, CURRENTS.format(2)),
    "wavekin_4/current_profile_4d.txt": DATA_FILE,
    "wavekin_4/hanging_lines.txt": (54, CURRENTS.format(5)),
    "wavekin_4/make_4d_currents.py": DATA_FILE,
    "wavekin_4/water_grid.txt": DATA_FILE,
    "wavekin_7/water_grid.txt": DATA_FILE,
    "wavekin_7/wave_frequencies.txt": DATA_FILE,
    "wavekin_7/wavekin_7.txt": (29, WAVES(7)),
    "wavekin_current_1.txt": RUNS,     # WaveKin = 1: a [sea], the waves given through the coupling calls
    "wavekin_wave_1.txt": RUNS,
}
COPIED = sorted(name for name, what in MOORDYN_TESTS_MOORING.items() if what != DATA_FILE)
IMPORTED = sorted(name for name, what in MOORDYN_TESTS_MOORING.items() if what == RUNS)


def test_every_copied_file_is_listed_and_every_listed_input_is_copied():
    copied = sorted(str(p.relative_to(MOORING)) for p in MOORING.rglob("*") if p.is_file() and p.name != "README.md")
    assert copied == COPIED


# Importing a file solves its statics (the time step is fitted at the static shape), which compiles the static
# solver for the file's terms: these five files' terms no other quick test uses (20 s of CPU to compile,
# `scripts/suite_profile.py`), so they import in the slow suite, which also runs them.
IMPORTED_SLOWLY = {"body_tests/bodyDrag.txt", "lowe_and_langley_2006/line.txt", "local_euler/hanging.txt",
                   "BeamSimplySupported.txt", "tripod.txt"}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n in IMPORTED_SLOWLY else n
                                  for n in COPIED])
def test_each_file_imports_or_is_refused_in_its_one_line(name):
    expected = MOORDYN_TESTS_MOORING[name]
    text = (MOORING / name).read_text(errors="replace")
    folder = (MOORING / name).parent      # where MoorDyn reads the files an input names (current_profile.txt)
    if expected == RUNS:
        translation = read_moordyn(text, name, folder)
        scene = scene_from_toml(scene_text(translation, name, "imported"))
        assert scene.is_system and scene.lines and scene.dimension == 3
        return
    line, message = expected
    with pytest.raises(SceneError) as exc:
        read_moordyn(text, name, folder)
    assert str(exc.value) == f"{name}: {f'line {line}: ' if line else ''}{message}"


@pytest.mark.slow
@pytest.mark.parametrize("name", IMPORTED)
def test_each_imported_file_runs_a_few_steps_from_its_statics(name):
    """`ropesim run FILE` as a short run: the statics solved, then five steps, every number finite and every line
    end on its point."""
    scene = load_scene(MOORING / name)
    dt = scene.integrator.dt
    scene = load_scene(MOORING / name, [f"integrator.t_end={5 * dt}", f"output.interval={dt}"])
    traj = ropesim.simulate(scene)
    assert len(traj.t) == 6 and np.all(np.isfinite(traj.x)) and np.all(np.isfinite(traj.tension))


def test_lines_txt_statics_agree_with_moordyns_own():
    """OC3-Hywind's three chains, their fairleads held: each line's fairlead and anchor tension within 1e-5 of
    MoorDyn's (the issue asks 0.2 %; MoorDyn's relaxation stops about 2e-6 short, see the reference), and every node
    within 2 mm of MoorDyn's (of a 902 m line), in MoorDyn's own frame (the imported scene is z-up)."""
    stored = json.loads((DATA / "import" / "lines_statics.json").read_text())
    scene = load_scene(MOORING / "lines.txt", ["integrator.t_end=0.002", "output.interval=0.002"])
    traj = ropesim.simulate(scene)
    for line_id, figures in stored["lines"].items():
        line = traj.line(line_id)
        assert line.tension[0, -1] == pytest.approx(figures["fairlead_tension_N"], rel=1e-5)
        assert line.tension[0, 0] == pytest.approx(figures["anchor_tension_N"], rel=1e-5)
        moordyn = np.array(figures["nodes_m"])
        assert np.max(np.linalg.norm(line.positions[0] - moordyn, axis=1)) < 2e-3


def test_the_imported_scene_carries_moordyns_numbers_and_says_where_laws_differ():
    translation = read_moordyn((MOORING / "lines.txt").read_text(), "lines.txt")
    scene = translation.scene
    assert scene["line_types"]["main"] == {"diameter": 0.09, "mass_per_length": 77.7066, "EA": 384.243e6,
                                           "axial_damping_ratio": 0.8, "cd_normal": 1.6, "ca_normal": 1.0,
                                           "cd_tangential": 0.1, "ca_tangential": 0.0}
    assert scene["up"] == "z"      # MoorDyn's numbers as its file gives them
    assert scene["points"][1] == {"id": "point2", "kind": "fixed", "position": [-426.94, 739.47, -320.0]}
    assert [p["kind"] for p in scene["points"]] == ["fixed"] * 3 + ["coupled"] * 3
    assert scene["seabed"] == {"height": -320.0, "stiffness": 3.0e6, "damping": 3.0e5, "damping_both_ways": True}
    assert scene["gravity"] == {"g": 9.80665} and scene["fluid"] == {"density": 1025.0}
    assert scene["integrator"]["dt"] == 0.002 and scene["initial"] == {"shape": "equilibrium"}
    assert translation.notes == [
        "option writeLog = 2: MoorDyn's own output files and log; ropesim writes its run folder",
        "option fileIC = lines.txt.ic: MoorDyn's stored initial state; ropesim solves the statics itself",
        "option disableOutTime = 1: MoorDyn's own output files and log; ropesim writes its run folder"]
    text = scene_text(translation, "lines.txt", "lines")
    assert "# MoorDyn's BA = -0.8: a fraction of each segment's critical damping\naxial_damping_ratio = 0.8" in text
    words = " ".join(text.replace("#", " ").split())
    assert "`ropesim run` of this scene alone holds it where it starts" in words
    assert "ropesim has no free surface" in words


BODY = """--------------------- MoorDyn Input File ------------------------------------
a body turned by roll, pitch and yaw, on one line to an anchor
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
rope       0.05    2.0        1.0e6      -0.5        0          1.2    1.0    0.01    0.0
---------------------------- BODIES -----------------------------------------------------
ID   Attachment  X0     Y0    Z0     r0      p0     y0     Mass  CG*   I*      Volume   CdA*   Ca
(#)     (-)      (m)    (m)   (m)   (deg)   (deg)  (deg)   (kg)  (m)  (kg-m^2)  (m^3)   (m^2)  (-)
1       free     1.0    2.0   -5.0   20      -30     45    100   0|0|-0.5  10|20|30  0.05  0.5  0.8
----------------------- POINTS ----------------------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)
1     Body1     0.3     0.4     -1.0    0      0       0      0
2     Fixed     10.0    2.0     -20.0   0      0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     rope       2        1         20.0      10      -
---------------------- OPTIONS -----------------------------------------
0.001         dtM
30            WtrDpth
------------------------- need this line --------------------------------------
"""


def _euler2quat_matrix(roll, pitch, yaw):
    """MoorDyn's Euler2Quat, R = Rx(roll) Ry(pitch) Rz(yaw) (intrinsic x-y-z: scipy's "XYZ"), angles in degrees."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_euler("XYZ", [roll, pitch, yaw], degrees=True).as_matrix()


def test_a_bodys_pose_and_its_points_land_where_moordyn_puts_them():
    """The body's rotation is MoorDyn's Rx Ry Rz, seen in ropesim's frame (P R P^T, P: (x, y, z) -> (x, z, -y)); its
    point, turned with it, is where MoorDyn's would be; its inertia, drag areas and added masses lie on the matching
    body axes; its buoyancy acts at its centre of gravity (MoorDyn's)."""
    scene = scene_from_toml(scene_text(read_moordyn(BODY, "body.txt"), "body.txt", "body"))
    body = scene.rigid_bodies[0]
    P = np.array([[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]])
    turn = _euler2quat_matrix(20.0, -30.0, 45.0)
    from ropesim.model.rotation import quaternion_from_angles

    assert np.allclose(rotation_matrix(quaternion_from_angles(body.orientation)), P @ turn @ P.T, atol=1e-12)
    from ropesim.model.build import point_position

    fairlead = point_position(scene, scene.points[0])
    moordyn = np.array([1.0, 2.0, -5.0]) + turn @ np.array([0.3, 0.4, -1.0])
    assert np.allclose(fairlead, P @ moordyn, atol=1e-12)
    assert body.inertia == (10.0, 30.0, 20.0) and body.center_of_gravity == (0.0, -0.5, 0.0)
    assert body.center_of_buoyancy == body.center_of_gravity and body.volume == 0.05
    assert body.added_mass == pytest.approx((1025 * 0.05 * 0.8,) * 3) and body.cd_area == (0.5, 0.5, 0.5)
    assert scene.lines[0].axial_damping == pytest.approx(0.5 * 2.0 * math.sqrt(1.0e6 * 2.0))


def _cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "ropesim", *args], capture_output=True, text=True, cwd=cwd,
                          timeout=300)


def test_import_writes_a_commented_scene_that_loads_as_the_file_runs(tmp_path):
    out = tmp_path / "oc3.toml"
    done = _cli("import", "moordyn", str(MOORING / "lines.txt"), "--out", str(out))
    assert done.returncode == 0, done.stderr
    assert done.stderr.count("not translated: ") == 3
    assert load_scene(out).lines == load_scene(MOORING / "lines.txt").lines
    again = _cli("import", "moordyn", str(MOORING / "lines.txt"), "--out", str(out))
    assert again.returncode == 2 and "exists; add --force" in again.stderr
    checked = _cli("check", str(MOORING / "lines.txt"))
    assert checked.returncode == 0 and checked.stderr.count("not translated: ") == 3


BAD = {   # (what to change in lines.txt, the line number, the message)
    "unknown section": (("---------------------- OPTIONS", "---------------------- WAVES AND OPTIONZ"), 22,
                        "unknown section 'WAVES AND OPTIONZ'"),
    "malformed row": (("2     main       2        5         902.2     20      -", "2     main       2        5"), 20,
                      "malformed line row: 7 columns needed, got 4"),
    "missing point": (("3     main       3        6 ", "3     main       3        9 "), 21,
                      "line 3: AttachB is point 9, but POINTS gives 6 points"),
    "missing line type": (("2     main       2        5 ", "2     chain      2        5 "), 20,
                          "line 2 is of type 'chain', which LINE TYPES does not give (types: main)"),
    "inconsistent units": (("(name)     (m)     (kg/m)     (N) ", "(name)     (m)     (kg/m)     (kN)"), 5,
                           "inconsistent units: column 4 (EA) says (kn), but MoorDyn reads it in N"),
}


@pytest.mark.parametrize("case", BAD)
def test_bad_input_is_one_line_naming_the_file_and_line_exit_2(case, tmp_path):
    (old, new), line, message = BAD[case]
    text = (MOORING / "lines.txt").read_text()
    assert old in text
    path = tmp_path / "bad.txt"
    path.write_text(text.replace(old, new))
    for command in (("import", "moordyn", str(path), "--out", str(tmp_path / "bad.toml")), ("run", str(path))):
        done = _cli(*command, cwd=tmp_path)
        assert done.returncode == 2
        [said] = done.stderr.strip().splitlines()
        assert said.startswith(f"ropesim: {path}: line {line}: {message}")
        assert "Traceback" not in done.stderr and not (tmp_path / "bad.toml").exists()


PROFILE = """--------------------- MoorDyn steady currents File ----------------------------------
Tabulated file with the water currents components
z (m), ux (m/s), uy (m/s), uz (m/s)
-320.0 0.1 0.0 0.0
-160.0 0.3 -0.2
0.0 0.6 -0.4 0.05
"""


def test_a_steady_current_profile_becomes_flows_table_with_the_files_values(tmp_path):
    """MoorDyn's Currents = 1 reads current_profile.txt beside the input (z, ux [, uy [, uz]], three header lines;
    a missing component is 0) and interpolates it linearly in z, held beyond its end rows: [flow]'s table, heights
    the file's z (ropesim's y is MoorDyn's z), velocities turned (ux, uy, uz) -> (ux, uz, -uy). The drag then sees
    it: a node 240 m down feels the current interpolated there."""
    text = (MOORING / "lines.txt").read_text().replace("1       disableOutTime", "1       disableOutTime\n1 Currents")
    (tmp_path / "lines.txt").write_text(text)
    (tmp_path / "current_profile.txt").write_text(PROFILE)
    scene = load_scene(tmp_path / "lines.txt")
    assert scene.flow.profile == "table" and scene.flow.heights == (-320.0, -160.0, 0.0)
    assert np.array_equal(scene.flow.velocities, [[0.1, 0.0, -0.0], [0.3, 0.0, 0.2], [0.6, 0.05, 0.4]])
    from ropesim.model.forces.fluid import _flow, flow_at

    scalars, table = _flow(scene, None)
    assert np.allclose(flow_at(-240.0, 1e9, scalars, table), [0.2, 0.0, 0.1], rtol=1e-15)   # halfway, turned
    assert np.allclose(flow_at(-400.0, 1e9, scalars, table), [0.1, 0.0, 0.0], rtol=1e-15)   # held below
    written = scene_text(read_moordyn(text, "lines.txt", tmp_path), "lines.txt", "lines")
    assert "MoorDyn's Currents = 1: the steady current profile of current_profile.txt (3 depths)" in " ".join(
        written.replace("#", " ").split())
    (tmp_path / "current_profile.txt").unlink()
    done = _cli("run", str(tmp_path / "lines.txt"))
    assert done.returncode == 2
    [said] = done.stderr.strip().splitlines()
    assert said.startswith(f"ropesim: {tmp_path / 'lines.txt'}: line 35: Currents = 1 reads "
                           f"{tmp_path / 'current_profile.txt'}, which cannot be read"), said
