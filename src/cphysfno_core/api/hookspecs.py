"""Hook specifications: how a plugin hands its components to the registry.

A plugin module (named by an entry point in the group ``cphysfno``) implements any of
these hooks with ``@cphysfno_core.hookimpl``; each returns a list of component classes,
each with a class attribute ``name`` unique within its kind. There is one hook per kind of
:data:`~cphysfno_core.api.kinds.KINDS`: ``cphysfno_structures``,
``cphysfno_ground_motions``, ``cphysfno_preprocessors``, ``cphysfno_operators``,
``cphysfno_refiners``, ``cphysfno_story_laws``.
"""

from __future__ import annotations

import pluggy

from .kinds import KINDS, Kind

PROJECT = "cphysfno"
hookspec = pluggy.HookspecMarker(PROJECT)
hookimpl = pluggy.HookimplMarker(PROJECT)


class Specifications:
    """The hook specifications, one per kind (what ``pluggy`` reads)."""


def _specification(kind: Kind):
    def specification() -> list[type]:
        """Return the plugin's component classes of this kind."""

    specification.__name__ = specification.__qualname__ = kind.hook
    specification.__doc__ = (
        f"{kind.what} (subclasses of :class:`cphysfno_core.{kind.base.__name__}`)."
    )
    return staticmethod(hookspec(specification))


for _kind in KINDS:
    setattr(Specifications, _kind.hook, _specification(_kind))
