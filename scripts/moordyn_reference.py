"""Regenerate the MoorDyn reference runs stored in tests/data/moordyn/ (<case>.npz and <case>.json).

Each case is one of MoorDyn's own test inputs, copied to tests/data/moordyn/cases/ (see the README there), run by
the installed MoorDyn (``pip install moordyn``, the ``bench`` extra) through tests/references/moordyn_harness.py:

- the static state: MoorDyn's initial-condition (IC) solve, exactly as the file sets it up;
- a dynamic run: the IC, then the coupled fairlead driven along a ramped sinusoid (or, for the cantilevered beam,
  which has no coupled point, a release from MoorDyn's straight initial shape without IC, under gravity).

Only output options are changed (no log, no output files: ``QUIET_OPTIONS``), never the physics. Units: SI.

    python scripts/moordyn_reference.py [--cases WD0050_Chain,...]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]   # this checkout's ropesim, not an installed one

from references.catenary_closed_form import seabed_catenary  # noqa: E402
from references.moordyn_harness import (  # noqa: E402
    QUIET_OPTIONS,
    MoorDynRun,
    moordyn_version,
    run_input_file,
    sinusoidal_motion,
)

DATA = ROOT / "tests" / "data" / "moordyn"
CASES_DIR = DATA / "cases"
MOORDYN_REPO = "FloatingArrayDesign/MoorDyn"


@dataclass(frozen=True)
class Case:
    """One stored reference.

    input_file: name in tests/data/moordyn/cases; source, commit: where it comes from in MoorDyn's repository;
    rest: the coupled fairlead's position in the file (m), None without a coupled point; amplitude (m), period (s),
    axis (0 = surge x), ramp_periods: the prescribed path (see moordyn_harness.sinusoidal_motion), amplitude 0 for
    none; t_end: simulated time (s); dt_out: coupling step and output interval (s); ic: run the IC before the
    dynamic run; nodes: which node indices to store the positions of (None: quarter points and ends)."""

    input_file: str
    source: str
    commit: str
    rest: tuple[float, float, float] | None
    amplitude: float
    period: float
    t_end: float
    dt_out: float
    axis: int = 0
    ramp_periods: float = 1.0
    ic: bool = True
    note: str = ""


CASES = {
    "WD0050_Chain": Case(
        "WD0050_Chain.txt", "tests/Mooring/WD0050_Chain.txt", "5b80f40e78e45ceb6bd4dbc93808bf19c7771656",
        rest=(0.0, 0.0, 0.0), amplitude=5.0, period=15.0, t_end=75.0, dt_out=0.1,
        note="surge 5 m at 15 s: the 410 m chain has 6.9 m of slack over its 403 m chord, so the far excursion "
             "nearly straightens it (fairlead tension 0.28-3.4 MN around 1.0 MN static, strongly nonlinear)",
    ),
    "WD0200_Chain": Case(
        "WD0200_Chain.txt", "tests/Mooring/WD0200_Chain.txt", "15a85decd46990c7f3b0365aac8a65dc0a9937dd",
        rest=(0.0, 0.0, 0.0), amplitude=10.0, period=20.0, t_end=100.0, dt_out=0.1,
        note="surge 10 m at 20 s (32 m of slack over the 728 m chord)",
    ),
    "WD0600_Chain": Case(
        "WD0600_Chain.txt", "tests/Mooring/WD0600_Chain.txt", "523c2a4dcce49c321860026694ebddb7079540d7",
        rest=(0.0, 0.0, 0.0), amplitude=10.0, period=20.0, t_end=100.0, dt_out=0.1,
        note="surge 10 m at 20 s (85 m of slack over the 1616 m chord); the file sets CFL = 0.1, not dtM",
    ),
    "lowe_and_langley_2006": Case(
        "lowe_and_langley_2006_line.txt", "tests/Mooring/lowe_and_langley_2006/line.txt",
        "b7d49e079f967e86e3458634f029d8eeaa5ca1e9",
        rest=(0.0, 0.0, -5.0), amplitude=10.0, period=27.0, t_end=27.0 + 3 * 27.0, dt_out=0.1,
        note="surge 10 m at 27 s ramped over one period, MoorDyn's own 'Case 1' of tests/lowe_and_langley_2006.cpp",
    ),
    "BeamCantilevered": Case(
        "BeamCantilevered.txt", "tests/Mooring/BeamCantilevered.txt", "0243ffbe11fbe757c3bc80e975f9cf29e07d403c",
        rest=None, amplitude=0.0, period=0.0, t_end=6.0, dt_out=0.005, ic=False,
        note="no coupled point: the dynamic run releases the beam at rest from MoorDyn's initial shape (Init_NoIC: its catenary between the end points, sagging 6.7 cm), under gravity",
    ),
}


def motion_of(case: Case):
    """The prescribed fairlead path of a case: t (s) -> position (m), or None."""
    if case.amplitude == 0.0:
        return None
    return sinusoidal_motion(case.rest, case.amplitude, case.period, case.axis, case.ramp_periods)


def static_run(case: Case) -> MoorDynRun:
    """MoorDyn's IC solve of the case, nothing else (one frame)."""
    return run_input_file(CASES_DIR / case.input_file)


def dynamic_run(case: Case) -> MoorDynRun:
    """The stored dynamic run of the case (see the module docstring)."""
    return run_input_file(CASES_DIR / case.input_file, motion_of(case), case.t_end, case.dt_out, ic=case.ic)


def node_indices(n_segments: int) -> np.ndarray:
    """Nodes whose positions are stored: the ends and the quarter points (indices into 0..N)."""
    return np.unique(np.round(np.linspace(0, n_segments, 5)).astype(int))


def comparisons(name: str, static: MoorDynRun, dynamic: MoorDynRun) -> dict:
    """Independent numbers each case can be held against (units in the keys)."""
    out = {}
    if name.startswith("WD"):
        depth, span, length = {"WD0050_Chain": (50.0, 400.0, 410.0), "WD0200_Chain": (200.0, 700.0, 760.0),
                               "WD0600_Chain": (600.0, 1500.0, 1700.0)}[name]
        w = (390.0 - 1025.0 * math.pi / 4 * 0.252**2) * 9.80665
        cat = seabed_catenary(span, depth, length, 1.674e9, w)
        qs_fair, qs_anchor = {"WD0050_Chain": (991.6e3, 826.2e3), "WD0200_Chain": (2065.4e3, 1402.2e3),
                              "WD0600_Chain": (5232.6e3, 3244.2e3)}[name]
        out["elastic_catenary_rigid_frictionless_seabed"] = {
            "fairlead_tension_N": cat.fairlead_tension, "horizontal_tension_N": cat.H,
            "grounded_length_m": cat.grounded,
            "note": "tests/references/catenary_closed_form.py; MoorDyn's seabed is a spring (kBot = 1e5 Pa/m sinks "
                    "the grounded chain by w/(kBot d) = 0.13 m) and its chain has 5-10 m segments",
        }
        out["moordyn_quasi_static_reference"] = {
            "fairlead_tension_N": qs_fair, "anchor_tension_N": qs_anchor,
            "source": "STATIC_FAIR_TENSION / STATIC_ANCHOR_TENSION of MoorDyn's tests/quasi_static_chain.cpp "
                      "(values 'predicted by quasi-static codes'; that test allows 10 %)",
        }
    if name == "lowe_and_langley_2006":
        after = dynamic.t >= 27.0
        top = np.linalg.norm(dynamic.fairlead_force[after], axis=1)
        out["paper_static_forces_kN"] = {
            "top": [11.40, 0.0, 45.71], "bottom": [-11.40, 0.0, 24.04],
            "source": "tests/lowe_and_langley_2006.cpp (TEST_CASE Stationary; MoorDyn allows 0.2 kN)",
        }
        out["paper_case1_top_tension_range_kN"] = {
            "min": 41.48, "max": 52.24,
            "source": "extremes of MoorDyn's digitised 'tests/Mooring/lowe_and_langley_2006/Case 1.csv' "
                      "(Lowe and Langley, OMAE 2006; MoorDyn's test allows 1 kN)",
        }
        out["this_run_top_tension_range_after_ramp_kN"] = {"min": float(top.min() / 1e3),
                                                          "max": float(top.max() / 1e3)}
    if name == "BeamCantilevered":
        tip = dynamic.positions[:, -1, 2] - 10.0
        # The release oscillates about the static state, so its mean is MoorDyn's discrete static deflection (its
        # IC state is not: the IC stops far from equilibrium, see the README). Mode frequencies: the peaks of the
        # tip's Hann-windowed, zero-padded spectrum below and above 5 Hz.
        x = (tip - tip.mean()) * np.hanning(len(tip))
        freq = np.fft.rfftfreq(16 * len(x), dynamic.t[1] - dynamic.t[0])
        amp = np.abs(np.fft.rfft(x, 16 * len(x)))
        low, high = (freq > 0.5) & (freq < 5.0), (freq > 5.0) & (freq < 20.0)
        beta1, beta2 = 1.875104, 4.694091  # cantilever eigenvalues beta_n L
        f_unit = math.sqrt(1.0e7 / (100.0 * 10.0**4)) / (2 * math.pi)
        out["cantilever_tip"] = {
            "analytic_static_deflection_m": -100.0 * 9.80665 * 10.0**4 / (8 * 1.0e7),
            "ic_static_deflection_m": float(static.positions[0, -1, 2] - 10.0),
            "release_mean_deflection_m": float(tip.mean()),
            "release_mode1_frequency_Hz": float(freq[low][np.argmax(amp[low])]),
            "release_mode2_frequency_Hz": float(freq[high][np.argmax(amp[high])]),
            "analytic_mode1_frequency_Hz": beta1**2 * f_unit,
            "analytic_mode2_frequency_Hz": beta2**2 * f_unit,
            "note": "analytic: Euler-Bernoulli cantilever in air, uniform load 100 kg/m x 9.80665 m/s^2, EI = 1e7 "
                    "N m^2, L = 10 m (MoorDyn's tests/beam.cpp compares its IC state with it at 50 % tolerance); "
                    "the spectrum of a 6 s record resolves frequencies to about 0.1 Hz",
        }
    return out


def store(name: str, case: Case) -> dict:
    """Run a case (static, then the dynamic run twice, checking they agree bit for bit and keeping the faster
    wall time) and write its .npz and .json; returns the JSON dict."""
    static = static_run(case)
    runs = [dynamic_run(case) for _ in range(2)]
    for field in ("positions", "fairlead_tension", "anchor_tension"):
        if not np.array_equal(getattr(runs[0], field), getattr(runs[1], field)):
            raise RuntimeError(f"{name}: two identical MoorDyn runs differ in {field}")
    dynamic = min(runs, key=lambda r: r.wall_time)
    n = dynamic.positions.shape[1] - 1
    nodes = node_indices(n)
    np.savez_compressed(
        DATA / f"{name}.npz",
        t=dynamic.t,
        fairlead_tension=dynamic.fairlead_tension,
        anchor_tension=dynamic.anchor_tension,
        fairlead_force=dynamic.fairlead_force,
        anchor_force=dynamic.anchor_force,
        fairlead_path=dynamic.fairlead_path,
        node_index=nodes,
        node_positions=dynamic.positions[:, nodes],
        static_positions=static.positions[0],
    )
    meta = {
        "case": name,
        "input_file": case.input_file,
        "moordyn_source": {"repository": MOORDYN_REPO, "path": case.source, "commit": case.commit,
                           "license": "BSD-3-Clause"},
        "moordyn_version": dynamic.version,
        "harness": "tests/references/moordyn_harness.py (run_input_file)",
        "options_set_by_harness": QUIET_OPTIONS,
        "n_segments": int(n),
        "static": {
            "fairlead_tension_N": float(static.fairlead_tension[0]),
            "fairlead_force_N": static.fairlead_force[0].tolist(),
            "fairlead_force_magnitude_N": float(np.linalg.norm(static.fairlead_force[0])),
            "anchor_tension_N": float(static.anchor_tension[0]),
            "anchor_force_N": static.anchor_force[0].tolist(),
            "anchor_force_magnitude_N": float(np.linalg.norm(static.anchor_force[0])),
            "ic_wall_time_s": static.init_wall_time,
        },
        "dynamic": {
            "motion": None if case.amplitude == 0.0 else {
                "kind": "x = rest + f(t) A sin(2 pi t / T) along axis; f: smootherstep ramp over ramp_periods T",
                "rest_m": list(case.rest), "axis": case.axis, "amplitude_m": case.amplitude,
                "period_s": case.period, "ramp_periods": case.ramp_periods,
                "coupling": "x(t_n) and the secant velocity passed to Step every dt_out; MoorDyn moves the point "
                            "linearly in between",
            },
            "starts_from": "MoorDyn's IC (Init)" if case.ic else "MoorDyn's initial shape, no IC (Init_NoIC)",
            "t_end_s": case.t_end,
            "dt_out_s": case.dt_out,
            "frames": len(dynamic.t),
            "dtM_s": dynamic.dtM,
            "scheme": dynamic.scheme,
            "wall_time_s": dynamic.wall_time,
            "wall_time_per_simulated_s": dynamic.wall_time / case.t_end,
            "ic_wall_time_s": dynamic.init_wall_time,
            "fairlead_tension_min_max_N": [float(dynamic.fairlead_tension.min()),
                                           float(dynamic.fairlead_tension.max())],
        },
        "npz_fields": {
            "t": "s, (F,)",
            "fairlead_tension": "N, (F,): |T + Td| of the last segment (GetLineFairTen)",
            "anchor_tension": "N, (F,): |T + Td| of the first segment (GetLineNodeTen node 0)",
            "fairlead_force": "N, (F, 3): net force on the last node (GetLineNodeForce node N; MoorDyn's TenB)",
            "anchor_force": "N, (F, 3): net force on node 0 (MoorDyn's TenA)",
            "fairlead_path": "m, (F, 3): the prescribed fairlead position (NaN without a coupled point)",
            "node_index": "(k,): stored nodes, 0 = end A (anchor) .. N = end B (fairlead)",
            "node_positions": "m, (F, k, 3)",
            "static_positions": "m, (N+1, 3): every node after the IC solve alone",
        },
        "comparison": comparisons(name, static, dynamic),
        "note": case.note,
    }
    (DATA / f"{name}.json").write_text(json.dumps(meta, indent=1) + "\n")
    return meta


def main(argv=None) -> None:
    """Regenerate the stored references (all cases, or --cases a,b) and print a summary table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default=",".join(CASES), help="comma-separated case names")
    args = parser.parse_args(argv)
    print(f"MoorDyn {moordyn_version()}")
    for name in args.cases.split(","):
        meta = store(name, CASES[name])
        s, d = meta["static"], meta["dynamic"]
        print(f"{name:24s} static fairlead {s['fairlead_tension_N'] / 1e3:9.2f} kN  "
              f"(|F_N| {s['fairlead_force_magnitude_N'] / 1e3:9.2f} kN, IC {s['ic_wall_time_s']:.2f} s)  "
              f"dynamic {d['t_end_s']:.0f} s in {d['wall_time_s']:.2f} s "
              f"({1e3 * d['wall_time_per_simulated_s']:.1f} ms per simulated s, dtM {d['dtM_s']:.2e} s)")


if __name__ == "__main__":
    main()
