"""MoorDyn's own statics of its OC3-Hywind mooring (tests/Mooring/lines.txt), stored for
``tests/test_moordyn_import.py`` so that the test needs no MoorDyn: ``python -m tests.references.moordyn_lines_statics``
(with ``pip install moordyn``) writes ``tests/data/moordyn/import/lines_statics.json``.

MoorDyn runs the file as it is but for its initial-condition settings: its dynamic relaxation (``ICgenDynamic 1``)
run tight (threshIC 1e-10, TmaxIC 3000 s, CdScaleIC 10) so that it stops at the static state itself (to about 2e-6
of the tensions; its default settings stop 1e-4 short), without the stored state ``fileIC``, and with its log and
output files off. The fairleads (Vessel points) are held at their positions in the file. Stored: each line's fairlead
tension (``GetLineFairTen``), the tension at its anchor node (``GetLineNodeTen(0)``, its magnitude) and its node
positions, in MoorDyn's frame (z up).
"""

from __future__ import annotations

import json
import re
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
SOURCE = HERE.parent / "data" / "moordyn" / "mooring" / "lines.txt"
STORED = HERE.parent / "data" / "moordyn" / "import" / "lines_statics.json"
TIGHT = {"ICgenDynamic": 1, "threshIC": 1e-10, "TmaxIC": 3000, "CdScaleIC": 10, "writeLog": 0}


def moordyn_text() -> str:
    """lines.txt with the tight IC settings and without fileIC."""
    lines = [line for line in SOURCE.read_text().splitlines() if not re.search(r"\s(fileIC|writeLog|threshIC|TmaxIC|"
                                                                               r"CdScaleIC)\b", line)]
    at = next(i for i, line in enumerate(lines) if "OPTIONS" in line) + 1
    lines[at:at] = [f"{value} {name}" for name, value in TIGHT.items()]
    return "\n".join(lines) + "\n"


def _version() -> str:
    from importlib.metadata import version

    return version("moordyn")


def run() -> dict:
    import moordyn

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "lines.txt"
        path.write_text(moordyn_text())
        system = moordyn.Create(str(path))
        fairleads = np.array([5.2, 0.0, -70.0, -2.6, 4.5, -70.0, -2.6, -4.5, -70.0])
        moordyn.Init(system, fairleads, np.zeros(9))
        out = {"moordyn": _version(), "ic": TIGHT, "lines": {}}
        for i in (1, 2, 3):
            line = moordyn.GetLine(system, i)
            n = moordyn.GetLineN(line)
            out["lines"][f"line{i}"] = {
                "fairlead_tension_N": moordyn.GetLineFairTen(line),
                "anchor_tension_N": float(np.linalg.norm(moordyn.GetLineNodeTen(line, 0))),
                "nodes_m": [list(moordyn.GetLineNodePos(line, k)) for k in range(n + 1)]}
        moordyn.Close(system)
    return out


if __name__ == "__main__":
    STORED.write_text(json.dumps(run(), indent=1) + "\n")
    print(f"wrote {STORED}")
