"""Registers this distribution's structures and story laws with cphysfno."""

from __future__ import annotations

from cphysfno_core.plugin import hookimpl

from .laws import BUILT_IN_LAWS
from .shear_building import ShearBuilding
from .structure import BoucWenShearBuilding


@hookimpl
def cphysfno_structures() -> list[type]:
    """The structures of this distribution."""
    return [ShearBuilding, BoucWenShearBuilding]


@hookimpl
def cphysfno_story_laws() -> list[type]:
    """The story laws of this distribution."""
    return list(BUILT_IN_LAWS)
