"""Griffe extension for the API pages: the docstrings' Sphinx roles as Markdown code.

ropesim's docstrings cross-reference with reST roles (:func:`load_scene`, :class:`~ropesim.io.trajectory.Trajectory`),
which mkdocstrings would print as they are. This turns each into a code span (the last dotted part with ``~``,
as Sphinx shows it), so the API pages read cleanly without any docstring being edited.
"""

from __future__ import annotations

import re

import griffe

ROLE = re.compile(r":(?:py:)?(?:class|func|mod|meth|attr|data|exc|obj|const):`(~?)([^`]+)`")


def _code(match: re.Match) -> str:
    target = match.group(2)
    return f"`{target.rsplit('.', 1)[-1] if match.group(1) else target}`"


class SphinxRolesAsCode(griffe.Extension):
    def on_instance(self, *, obj, **kwargs) -> None:
        if obj.docstring is not None and ":`" in obj.docstring.value:
            obj.docstring.value = ROLE.sub(_code, obj.docstring.value)
