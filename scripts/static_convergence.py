"""The static solver's convergence with either Newton matrix: the largest residual force after each iteration.

An explicit method's static start differences its Newton matrix from the compiled force
(:mod:`ropesim.model.static_matrix`); sdirk2 and galpha take the analytic one their loops compile. This solves
a scene's static shape both ways (the scene as it is, and with ``integrator.method = sdirk2``, which changes
nothing else of the static problem) and prints, per iteration, the largest residual force over the solver's
force scale, then the iteration counts and the largest difference between the two shapes::

    python scripts/static_convergence.py mooring_chain
    python scripts/static_convergence.py spread_mooring_free --last 8

Each row re-solves from the start with ``max_iterations`` = k (the solver is deterministic), so this costs k
solves: fine for the built-in scenes (a solve takes 10 to 50 ms once compiled).
"""

from __future__ import annotations

import argparse
import dataclasses

import numpy as np


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", help="a built-in scene's name or a scene file")
    parser.add_argument("--last", type=int, default=6, help="iterations listed, counted back from the last")
    args = parser.parse_args()

    import ropesim
    from ropesim.model.build import build
    from ropesim.model.statics import ANALYTIC_MATRIX_METHODS, solve_equilibrium

    scene = ropesim.load_scene(args.scene)
    analytic = dataclasses.replace(scene, integrator=dataclasses.replace(scene.integrator,
                                                                          method=ANALYTIC_MATRIX_METHODS[0]))
    cases = {"analytic": analytic}
    if scene.integrator.method not in ANALYTIC_MATRIX_METHODS:   # (EI bending takes the analytic one too)
        cases = {"differenced": scene, **cases}
    results, histories = {}, {}
    for label, case in cases.items():
        model = build(case, solve=False)
        final = solve_equilibrium(model)
        results[label] = final
        histories[label] = [solve_equilibrium(model, max_iterations=k).residual / final.scale
                            for k in range(max(1, final.iterations - args.last + 1), final.iterations + 1)]
    print(f"{scene.name}: largest residual force / force scale ({results['analytic'].scale:.4g} N) after each of "
          f"the last iterations; converged at {results['analytic'].scale * 1e-10:.3g} N (1e-10)")
    for label, final in results.items():
        start = final.iterations - len(histories[label]) + 1
        rows = "  ".join(f"{k}: {r:.1e}" for k, r in zip(range(start, final.iterations + 1), histories[label]))
        print(f"  {label:11s} {final.iterations:4d} iterations, converged {final.converged}; {rows}")
    if len(results) == 2:
        a, b = results["differenced"], results["analytic"]
        print(f"  shapes differ by at most {np.abs(a.x - b.x).max():.2e} m"
              + (f", poses by {np.abs(a.pose - b.pose).max():.2e}" if a.pose.size else ""))


if __name__ == "__main__":
    main()
