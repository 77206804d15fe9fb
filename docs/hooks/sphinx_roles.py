"""Griffe extension for the API reference: the docstrings cross-reference in Sphinx's roles
(``:class:`~cphysfno_core.CompositeModel```), which Markdown would print as they are; here
each becomes a code span of the name Sphinx would show (``CompositeModel``; ``fit()`` for
a function or method)."""

from __future__ import annotations

import re
from typing import Any

import griffe

ROLE = re.compile(
    r":(?:py:)?(?P<role>class|func|meth|attr|mod|data|exc|obj|const):`(?P<tilde>~?)(?P<target>[^`]+)`"
)
CALLABLE = {"func", "meth"}


def _shown(match: re.Match[str]) -> str:
    """The code span of one role, as Sphinx shows it."""
    target = match["target"].lstrip(".")
    name = target.rsplit(".", 1)[-1] if match["tilde"] else target
    if match["role"] in CALLABLE and not name.endswith(")"):
        name += "()"
    return f"`{name}`"


def convert(text: str) -> str:
    """``text`` with every Sphinx role replaced by a code span."""
    return ROLE.sub(_shown, text)


class SphinxRoles(griffe.Extension):
    """Rewrite the roles of every docstring as it is loaded."""

    def on_instance(self, *, obj: griffe.Object, **kwargs: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = convert(obj.docstring.value)
