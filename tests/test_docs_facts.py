"""Facts the docs state that the code decides: they are read here and compared with what the code says, so a
page cannot go stale (issue 24 found three: the scene count, the suite's duration, the typo message)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from ropesim.scene.builtin import builtin_names
from ropesim.scene.loader import SceneError, load_scene

DOCS = Path(__file__).resolve().parent.parent / "docs"
NUMBERS = {"eight": 8, "nine": 9, "ten": 10, "eleven": 11, "twelve": 12, "thirteen": 13, "fourteen": 14,
           "fifteen": 15, "sixteen": 16,
           "seventeen": 17, "eighteen": 18, "nineteen": 19, "twenty": 20}


def test_the_scene_count_on_getting_started_is_the_number_of_built_in_scenes():
    text = (DOCS / "getting-started.md").read_text(encoding="utf-8")
    word = re.search(r"ships (\w+) scenes", text).group(1)
    assert NUMBERS[word] == len(builtin_names())


def test_the_typo_message_in_the_tutorial_is_the_one_ropesim_prints(tmp_path):
    page = (DOCS / "tutorials" / "your-own-rope.md").read_text(encoding="utf-8")
    scene = re.search(r'```toml title="falling_chain.toml"\n(.*?)```', page, re.S).group(1)
    shown = re.search(r"\$ ropesim run falling_chain.toml --set rope.nodse=31\n(ropesim: .*)\n", page).group(1)
    (tmp_path / "falling_chain.toml").write_text(scene, encoding="utf-8")
    with pytest.raises(SceneError) as caught:
        load_scene(tmp_path / "falling_chain.toml", ["rope.nodse=31"])
    message = str(caught.value).replace(str(tmp_path / "falling_chain.toml"), "falling_chain.toml")
    assert shown == f"ropesim: {message}"


def test_the_typo_message_on_getting_started_is_the_one_ropesim_prints(monkeypatch):
    page = (DOCS / "getting-started.md").read_text(encoding="utf-8")
    command = re.search(r"\$ ropesim run (\S+) --set (\S+)\n(ropesim: .*)\n", page)
    scene, override, shown = command.groups()
    monkeypatch.chdir(DOCS.parent)                 # the page's commands run at the root of a clone
    with pytest.raises(SceneError) as caught:
        load_scene(scene, [override])
    assert shown == f"ropesim: {caught.value}"
