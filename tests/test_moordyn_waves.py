"""ropesim against MoorDyn in waves, run live (MoorDyn 2.7, ``WaveKin = 7``): the chain of MoorDyn's
``tests/Mooring/wavekin_wave_1.txt``, its fairlead held at the mean water level, 20 s of a regular wave (H 6 m,
T 10 s: the chain's tension swings by +-1.5 %). tests/references/moordyn_waves.py sets out the equal physics;
scripts/compare_moordyn_waves.py runs the longer regular and JONSWAP cases and draws the figure.

Tolerances: the issue asks for the fairlead tension within 2 % RMS. With MoorDyn's submerged-fraction rule
(``[sea] fraction = "moordyn"``) the two codes solve the same equations, so what remains is MoorDyn's RK2 against
ropesim's rk4, both at 1 ms: measured 5e-7 of the mean tension, 5e-5 of its wave-driven standard deviation; the
test allows 1e-3 of the latter. With ropesim's own rule (cylinders cut at each node's own surface height) the
top segment's buoyancy differs while it breaks the surface: measured 4 % of the standard deviation (0.04 % of
the mean), which must stay within the issue's 2 % of the mean and be visible (above 1 % of the std), so that the
comparison shows the rule is what it measures."""

from __future__ import annotations

import pytest

pytest.importorskip("moordyn")

from references.moordyn_waves import CASES, agreement, chain, run_moordyn, run_ropesim  # noqa: E402

T_END = 20.0


@pytest.fixture(scope="module")
def runs():
    line, case = chain(), CASES["regular"]
    md = run_moordyn(line, case, T_END)
    own = {rule: run_ropesim(line, md.positions[0], case, T_END, fraction=rule)[1]
           for rule in ("moordyn", "cylinders")}
    return md, own


@pytest.mark.slow
def test_fairlead_tension_in_waves_equals_moordyn_on_equal_physics(runs):
    md, own = runs
    assert md.tension.std() > 5e-3 * md.tension.mean()     # the waves do move the tension
    a = agreement(md.tension, own["moordyn"])
    assert a["rms_of_mean"] < 0.02
    assert a["rms_of_std"] < 1e-3


@pytest.mark.slow
def test_ropesims_own_fraction_rule_stays_within_two_percent(runs):
    md, own = runs
    a = agreement(md.tension, own["cylinders"])
    assert a["rms_of_mean"] < 0.02
    assert a["rms_of_std"] > 1e-2
