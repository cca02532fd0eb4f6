"""ropesim installs under a name that is its own: every install hint in the source names an installable thing.

The index's ``ropesim`` is an unrelated project, so the distribution is ``pyropesim`` (import name and command
``ropesim``). Every ``pip install`` written anywhere in the project (README, docs, scripts, messages, comments)
is read here: each target must be the checkout (``.``, ``.[extra]``, a variable holding its path), the
distribution ``pyropesim[extra]``, or a package the project itself declares; every extra must exist. The hints
ropesim prints at run time come from one function, checked from a checkout and as a wheel would see it.
"""

from __future__ import annotations

import re
import shlex
import subprocess
import tomllib
from pathlib import Path

import pytest

from ropesim import install
from ropesim.install import DISTRIBUTION, install_hint

ROOT = Path(__file__).resolve().parent.parent
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
EXTRAS = set(PROJECT["optional-dependencies"])
REQUIREMENT = re.compile(r"^([A-Za-z0-9][A-Za-z0-9._-]*)(?:\[([^\]]*)\])?")
OPTIONS = {"-e", "--editable", "-q", "--quiet", "-U", "--upgrade", "--no-deps", "--user"}


def declared_packages() -> set[str]:
    """Every package pyproject.toml names (dependencies and extras), normalised."""
    names = set()
    for spec in PROJECT["dependencies"] + [s for group in PROJECT["optional-dependencies"].values() for s in group]:
        names.add(re.split(r"[\[<>=! ;]", spec, maxsplit=1)[0].lower().replace("_", "-"))
    return names


def hints() -> list[tuple[str, int, str]]:
    """(file, line, the command from `pip install` on) for every pip install in the project's tracked files."""
    files = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout.split()
    out = []
    for name in files:
        path = ROOT / name
        if path.suffix not in {".py", ".md", ".toml", ".sh", ".yml", ".cff", ".ipynb", ".txt", ""} or not path.is_file():
            continue
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            continue
        for number, line in enumerate(text.splitlines(), 1):
            for match in re.finditer(r"pip(?:3)? install\b(.*)", line):
                out.append((name, number, match.group(1)))
    return out


def targets(rest: str) -> list[str]:
    """What a `pip install` line installs: its first argument that is not an option, quotes and escapes off."""
    for word in rest.split():
        word = word.replace("\\", "").strip("'\"`")
        if word in OPTIONS or word.startswith("-"):
            continue
        word = word if word == "." else re.sub(r"[^\w\]]+$", "", word)
        return [word] if word else []
    return []


def problem(target: str) -> str | None:
    """Why ``target`` is not an installable thing of this project, or None."""
    if "{" in target or target.startswith(("$", "/", "<")):
        return None                                  # a variable or a formatted path: the checkout
    if target.startswith("."):
        extras = re.fullmatch(r"\.(?:\[([^\]]*)\])?", target)
        if extras is None:
            return "not the checkout"
        wanted = {e.strip() for e in (extras.group(1) or "").split(",") if e.strip()}
        return f"no extra {sorted(wanted - EXTRAS)}" if wanted - EXTRAS else None
    match = REQUIREMENT.match(target)
    if match is None:
        return "not a requirement"
    name = match.group(1).lower().replace("_", "-")
    if name == "ropesim":
        return "the index's ropesim is another project: install pyropesim"
    if name == DISTRIBUTION:
        wanted = {e.strip() for e in (match.group(2) or "").split(",") if e.strip()}
        return f"no extra {sorted(wanted - EXTRAS)}" if wanted - EXTRAS else None
    return None if name in declared_packages() | {"pip"} else f"{name} is not a package the project declares"


def test_every_install_hint_in_the_source_names_an_installable_thing():
    found = hints()
    assert len(found) >= 20, "the scan found too few hints to be reading the project"
    bad = [f"{name}:{line}: pip install{rest} -> {target}: {why}" for name, line, rest in found
           for target in targets(rest) if (why := problem(target))]
    assert bad == []


@pytest.mark.parametrize("target,fragment", [
    ("ropesim[export]", "another project"), (".[exprot]", "no extra"), ("pyropesim[vtk]", "no extra"),
    ("leftpad", "not a package the project declares"),
])
def test_the_scan_catches_a_wrong_hint(target, fragment):
    assert fragment in (problem(target) or "")
    assert problem(".[export]") is None and problem("pyropesim[dask]") is None and problem("moordyn") is None


def test_the_printed_hint_names_the_checkout_or_the_distribution(monkeypatch, tmp_path):
    monkeypatch.chdir(ROOT)
    assert install_hint("export") == "pip install -e '.[export]'"          # editable, from the checkout
    monkeypatch.chdir(tmp_path)
    assert install_hint("dask") == f"pip install -e '{ROOT}[dask]'"
    monkeypatch.setattr(install, "checkout", lambda: None)                 # as from an installed wheel
    assert install_hint("export") == "pip install 'pyropesim[export]'"
    assert install_hint() == "pip install 'pyropesim'"


def test_the_distribution_is_not_the_index_ropesim_and_carries_its_licence():
    assert PROJECT["name"] == DISTRIBUTION != "ropesim"
    assert PROJECT["license"] == "MIT" and "MIT License" in (ROOT / "LICENSE").read_text(encoding="utf-8")
    urls = PROJECT["urls"]
    assert {"Homepage", "Documentation", "Repository", "Issues", "Changelog"} <= set(urls)
    citation = (ROOT / "CITATION.cff").read_text(encoding="utf-8")
    assert f'repository-code: "{urls["Repository"]}"' in citation and "license: MIT" in citation
    import ropesim
    assert f'version: "{ropesim.__version__}"' in citation
    mkdocs = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    assert f"repo_url: {urls['Repository']}" in mkdocs and f"site_url: {urls['Documentation']}" in mkdocs
