"""MoorDyn's call shapes (ropesim.compat.moordyn): one script, run with MoorDyn's own module and with ropesim's.

OC3-Hywind's three chains, MoorDyn's tests/Mooring/lines.txt (copied below, its output and IC file options left
out so that it writes nothing but its log beside itself), against tests/data/systems/oc3_hywind.toml with the
spar left out and the three fairleads coupled points (MoorDyn's Vessel points): the same physics (MoorDyn's
damping ratio -0.8 is the hand port's BA; drag, added mass, seabed and g as MoorDyn's). The script surges the
three fairleads 5 m at a 60 s period from t = 0 and reads the forces MoorDyn's Step returns. Tolerances: the
initial forces (MoorDyn's dynamic relaxation against ropesim's static solve) within 0.2 %; the force histories
within 1 % RMS (measured: 6e-5 and 4e-5 of the RMS force for 20 s, `pytest tests/test_compat_moordyn.py`).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import ropesim.compat.moordyn as compat

# MoorDyn's tests/Mooring/lines.txt (github.com/FloatingArrayDesign/MoorDyn, BSD 3-Clause, see
# tests/data/moordyn/cases/README.md), its options writeLog, fileIC and disableOutTime left out
LINES_TXT = """--------------------- MoorDyn Input File ------------------------------------
MoorDyn input file of the mooring system for OC3-Hywind
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
main       0.09    77.7066    384.243E6  -0.8        0          1.6    1.0    0.1     0.0
---------------------- POINT PROPERTIES --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)
1     Fixed     853.87  0       -320.0  0      0       0      0
2     Fixed     -426.94 739.47  -320.0  0      0       0      0
3     Fixed     -426.94 -739.47 -320.0  0      0       0      0
4     Vessel    5.2     0.0     -70.0   0      0       0      0
5     Vessel    -2.6    4.5     -70.0   0      0       0      0
6     Vessel    -2.6    -4.5    -70.0   0      0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     main       1        4         902.2     20      -
2     main       2        5         902.2     20      -
3     main       3        6         902.2     20      -
---------------------- OPTIONS -----------------------------------------
0.002         dtM           time step to use in mooring integration (s)
3.0e6         kBot          bottom stiffness (Pa/m)
3.0e5         cBot          bottom damping (Pa-s/m)
1025.0        WtrDnsty      water density (kg/m^3)
320           WtrDpth       water depth (m)
1.0           dtIC          time interval for analyzing convergence during IC gen (s)
100.0         TmaxIC        max time for ic gen (s)
4.0           CdScaleIC     factor by which to scale drag coefficients during dynamic relaxation (-)
0.001         threshIC      threshold for IC convergence (-)
------------------------- need this line --------------------------------------
"""

PORT = (Path(__file__).parent / "data" / "systems" / "oc3_hywind.toml").read_text()
FAIRLEADS = np.array([5.2, 0, -70, -2.6, 4.5, -70, -2.6, -4.5, -70.0])   # MoorDyn's frame, z up


def points_port(tmp_path: Path) -> Path:
    """The hand port with the spar left out and its fairleads coupled points (MoorDyn's Vessel points)."""
    text = re.sub(r"\[\[bodies\]\]\n(?:[^\n]+\n)+\n", "", PORT).replace('body = "spar"\n', 'kind = "coupled"\n')
    assert text.count('kind = "coupled"') == 3 and "[[bodies]]" not in text
    path = tmp_path / "oc3_points.toml"
    path.write_text(text)
    return path


def script(moordyn, path: Path, seconds: float, dt: float = 0.02) -> np.ndarray:
    """A MoorDyn user's script: the fairleads surge 5 m at a 60 s period; the forces of every Step."""
    system = moordyn.Create(str(path))
    n = moordyn.NCoupledDOF(system)
    moordyn.Init(system, FAIRLEADS, np.zeros(n))
    w = 2 * np.pi / 60.0
    out = [moordyn.Step(system, FAIRLEADS, np.zeros(n), 0.0, 0.0)]
    for k in range(round(seconds / dt)):
        t = k * dt
        x, v = FAIRLEADS.copy(), np.zeros(n)
        x[0::3] += 5.0 * np.sin(w * t)
        v[0::3] = 5.0 * w * np.cos(w * t)
        out.append(moordyn.Step(system, x, v, t, dt))
    moordyn.Close(system)
    return np.array(out)


@pytest.fixture(scope="module")
def both(tmp_path_factory):
    moordyn = pytest.importorskip("moordyn")
    folder = tmp_path_factory.mktemp("oc3")
    (folder / "lines.txt").write_text(LINES_TXT)
    return script(moordyn, folder / "lines.txt", 20.0), script(compat, points_port(folder), 20.0)


def test_the_same_script_gives_moordyns_fairlead_forces_within_1_percent_rms(both):
    theirs, ours = both
    assert ours.shape == theirs.shape == (1001, 9)
    for k in range(3):
        a, b = theirs[:, 3 * k:3 * k + 3], ours[:, 3 * k:3 * k + 3]
        rms = np.sqrt(np.mean(np.sum((a - b) ** 2, axis=1)) / np.mean(np.sum(a ** 2, axis=1)))
        assert rms < 0.01, (k, rms)
        assert np.linalg.norm(a[0] - b[0]) < 0.002 * np.linalg.norm(a[0])   # statics against MoorDyn's IC


def test_the_getters_read_the_state_in_moordyns_frame(tmp_path):
    system = compat.Create(str(points_port(tmp_path)))
    assert compat.NCoupledDOF(system) == 9
    assert (compat.GetNumberLines(system), compat.GetNumberPoints(system), compat.GetNumberBodies(system)) == (3, 6, 0)
    compat.Init(system, FAIRLEADS, np.zeros(9))
    forces = compat.Step(system, FAIRLEADS, np.zeros(9), 0.0, 0.1)
    fairlead, anchor = compat.GetPoint(system, 4), compat.GetPoint(system, 1)
    assert np.allclose(compat.GetPointPos(fairlead), FAIRLEADS[:3], atol=1e-9)
    assert np.allclose(compat.GetPointPos(anchor), [853.87, 0, -320.0], atol=1e-9)
    assert np.allclose(compat.GetPointForce(fairlead), forces[:3], rtol=1e-12)
    line = compat.GetLine(system, 1)
    assert compat.GetLineNumberNodes(line) == 21 and compat.GetLineUnstretchedLength(line) == 902.2
    assert np.allclose(compat.GetLineNodePos(line, 20), FAIRLEADS[:3], atol=1e-9)
    top = compat.GetLineNodeTen(line, 20)
    assert compat.GetLineFairTen(line) == pytest.approx(np.linalg.norm(top), rel=1e-12)
    assert top[2] > 0 and top[0] < 0      # along the last segment, from node 19 up and in to the fairlead
    horizontal, vertical, _, _ = compat.GetFASTtens(system, 3)
    assert horizontal[0] == pytest.approx(np.hypot(*forces[:2]), rel=1e-12) and vertical[0] == forces[2]
    state = tmp_path / "state.npz"
    compat.SaveState(system, str(state))
    after = compat.Step(system, FAIRLEADS, np.zeros(9), 0.1, 0.1)
    compat.LoadState(system, str(state))
    assert np.array_equal(compat.Step(system, FAIRLEADS, np.zeros(9), 0.1, 0.1), after)
    with pytest.raises(NotImplementedError, match="ropesim has no rods"):
        compat.GetRod(system, 1)
    with pytest.raises(compat.MoorDynError, match="need 9 numbers each"):
        compat.Step(system, FAIRLEADS[:6], np.zeros(9), 0.2, 0.1)
