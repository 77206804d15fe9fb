"""Hook specifications: how a plugin hands its components to the registry.

A plugin module (named by an entry point in the group ``cphysfno``) implements any of
these hooks with ``@cphysfno_core.hookimpl``; each returns a list of component classes,
each with a class attribute ``name`` unique within its kind.
"""

from __future__ import annotations

import pluggy

PROJECT = "cphysfno"
hookspec = pluggy.HookspecMarker(PROJECT)
hookimpl = pluggy.HookimplMarker(PROJECT)


@hookspec
def cphysfno_structures() -> list[type]:
    """Structure classes (subclasses of :class:`cphysfno_core.Structure`)."""


@hookspec
def cphysfno_ground_motions() -> list[type]:
    """Ground-motion source classes (subclasses of :class:`cphysfno_core.GroundMotionSource`)."""


@hookspec
def cphysfno_preprocessors() -> list[type]:
    """Physics preprocessor classes (subclasses of :class:`cphysfno_core.PhysicsPreprocessor`)."""


@hookspec
def cphysfno_operators() -> list[type]:
    """Neural operator classes (subclasses of :class:`cphysfno_core.NeuralOperator`)."""


@hookspec
def cphysfno_refiners() -> list[type]:
    """Refiner classes (subclasses of :class:`cphysfno_core.Refiner`)."""


HOOK_OF_KIND = {
    "structure": "cphysfno_structures",
    "ground_motion": "cphysfno_ground_motions",
    "preprocessor": "cphysfno_preprocessors",
    "operator": "cphysfno_operators",
    "refiner": "cphysfno_refiners",
}
