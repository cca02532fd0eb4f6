"""The worked example of docs/tutorials/coupling.md, run from the page: a spar surging and heaving on a linear
hydrostatic spring with radiation damping, moored by three chains, coupled to ropesim through
ropesim.Coupling (the spar's model written on the page, explicit staggered steps) against the same spar as a
free body inside ropesim (its stiffness and damping keys).

Both carry the same physics: the coupled model adds the fairlead's inertia (coupling.mass()) that a free body
carries itself. So the difference is the coupling scheme's error alone, and it halves with the coupling step:
first order, the spar's velocity taking each step's forces at its end. Measured over 60 s: 12.4, 6.4, 3.3 and
1.7 cm at steps of 0.4, 0.2, 0.1 and 0.05 s (ratios 1.93, 1.95, 1.99); here 30 s at 0.4, 0.2, 0.1 s.
"""

import importlib.util
import re
from pathlib import Path

import numpy as np
import pytest

PAGE = Path(__file__).resolve().parent.parent / "docs" / "tutorials" / "coupling.md"


@pytest.fixture(scope="module")
def example(tmp_path_factory):
    code = re.search(r'```python title="coupled_spar.py"\n(.*?)```', PAGE.read_text(encoding="utf-8"), re.S)
    path = tmp_path_factory.mktemp("example") / "coupled_spar.py"
    path.write_text(code.group(1), encoding="utf-8")
    spec = importlib.util.spec_from_file_location("coupled_spar", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


# slow: the coupled spar's splitting loop is compiled for this example alone (6 s of a cold run); the coupling's
# own checks stay quick (tests/test_coupling.py)
@pytest.mark.slow
def test_the_coupled_spar_converges_to_the_free_one_at_first_order_in_the_coupling_step(example):
    reference = example.free_body(30.0)
    moved = np.max(np.linalg.norm(reference[1] - reference[1][0], axis=1))
    assert moved > 5.0                    # the spar really surges and heaves
    errors = np.array([example.difference(30.0, dt, reference) for dt in (0.4, 0.2, 0.1)])
    order = np.log2(errors[:-1] / errors[1:])
    assert np.all((order > 0.85) & (order < 1.15)), (errors, order)
    assert errors[-1] < 0.01 * moved, errors
