"""Hook specifications: how a plugin hands its components to the registry.

A plugin module (named by an entry point in the group ``cphysfno``) implements any of
these hooks with ``@cphysfno_core.plugin.hookimpl``; each returns a list of component classes,
each with a class attribute ``name`` unique within its kind. There is one hook per kind of
:data:`~cphysfno_core.api.kinds.KINDS`: ``cphysfno_structures``,
``cphysfno_ground_motions``, ``cphysfno_preprocessors``, ``cphysfno_operators``,
``cphysfno_refiners``, ``cphysfno_story_laws``.
"""

from __future__ import annotations

import pluggy

PROJECT = "cphysfno"
hookspec = pluggy.HookspecMarker(PROJECT)
hookimpl = pluggy.HookimplMarker(PROJECT)


class Specifications:
    """The hook specifications, one per kind of :data:`~cphysfno_core.api.kinds.KINDS`
    (what ``pluggy`` reads). Each hook returns a list of component classes; a class's
    ``name`` must be unique within its kind."""

    @staticmethod
    @hookspec
    def cphysfno_structures() -> list[type]:
        """Structure classes (subclasses of :class:`cphysfno_core.plugin.Structure`): the models
        that make the training data."""

    @staticmethod
    @hookspec
    def cphysfno_ground_motions() -> list[type]:
        """Ground-motion sources (subclasses of
        :class:`cphysfno_core.plugin.GroundMotionSource`)."""

    @staticmethod
    @hookspec
    def cphysfno_preprocessors() -> list[type]:
        """Physics preprocessors (subclasses of :class:`cphysfno_core.plugin.PhysicsPreprocessor`):
        the simplified physics ``H_p``."""

    @staticmethod
    @hookspec
    def cphysfno_operators() -> list[type]:
        """Neural operator classes (subclasses of :class:`cphysfno_core.plugin.NeuralOperator`)."""

    @staticmethod
    @hookspec
    def cphysfno_refiners() -> list[type]:
        """Refiner classes (subclasses of :class:`cphysfno_core.plugin.Refiner`)."""

    @staticmethod
    @hookspec
    def cphysfno_story_laws() -> list[type]:
        """Story laws of shear buildings (subclasses of :class:`cphysfno_core.plugin.StoryLaw`)."""
