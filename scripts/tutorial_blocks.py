"""The tutorials' command blocks, run as a reader would run them: shared by tests/test_docs.py (which runs them
in the test suite) and scripts/make_tutorial_images.py (which keeps the pictures they draw for the pages).

A fenced block preceded by ``<!-- run -->`` (or ``<!-- run: slow -->``) is run in page order in a scratch
folder holding copies of scenarios/ and scripts/; a ```` ```toml title="NAME" ```` block is saved as the file
NAME instead. A picture a page shows of what its commands drew names the drawn file in its title:
``![falling chain](../images/tutorials/your-own-rope/falling_chain_frames.png "runs/falling_chain/frames.png")``.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BLOCK = re.compile(r"^<!-- run(: slow)? -->\n+```(\w+)([^\n]*)\n(.*?)^```", re.M | re.S)
PICTURE = re.compile(r'!\[[^\]]*\]\(([^ )]+) "([^"]+)"\)')
PICTURE_SUFFIXES = (".png", ".gif")


def runnable_blocks(page: Path) -> list[tuple[bool, str, str, str]]:
    """(slow, language, fence info, code) of every block marked <!-- run --> or <!-- run: slow -->."""
    return [(bool(m.group(1)), m.group(2), m.group(3), m.group(4))
            for m in BLOCK.finditer(page.read_text(encoding="utf-8"))]


def workspace(folder: Path) -> None:
    """A scratch folder with copies of scenarios/ and scripts/, as at the root of a clone."""
    for name in ("scenarios", "scripts"):
        shutil.copytree(ROOT / name, folder / name, ignore=shutil.ignore_patterns("__pycache__"))


def run_block(page: Path, language: str, info: str, code: str, folder: Path, env: dict, timeout: float = 900) -> str:
    """Run (or save) one block in ``folder``; returns its output; AssertionError naming the block if it fails."""
    title = re.search(r'title="([^"]+)"', info)
    if title:
        (folder / title.group(1)).write_text(code, encoding="utf-8")
        return ""
    if language == "bash":
        command = ["bash", "-euo", "pipefail", "-c", code]
    elif language == "python":
        command = [sys.executable, "-c", code]
    else:
        raise AssertionError(f"{page.name}: a runnable ```{language} block must be bash, python or have a title=")
    proc = subprocess.Popen(command, cwd=folder, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, start_new_session=True)
    try:
        output, _ = proc.communicate(timeout=timeout)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, 9)
    assert proc.returncode == 0, (f"{page.name}: this block failed (exit {proc.returncode}):\n"
                                  f"{textwrap.indent(code, '    ')}\n{output[-4000:]}")
    return output


def pictures_in(folder: Path) -> set[str]:
    """The pictures under ``folder`` (paths relative to it), leaving out the copies of scenarios/ and scripts/."""
    return {p.relative_to(folder).as_posix() for p in folder.rglob("*")
            if p.suffix in PICTURE_SUFFIXES and p.relative_to(folder).parts[0] not in ("scenarios", "scripts")}


def shown_pictures(page: Path) -> dict[str, str]:
    """{the drawn file a picture names in its title: the picture's path on the page} for every such picture."""
    return {title: src for src, title in PICTURE.findall(page.read_text(encoding="utf-8"))}
