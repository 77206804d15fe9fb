"""Registers this distribution's structures and story laws with cphysfno."""

from __future__ import annotations

import cphysfno_core

from .laws import BUILT_IN_LAWS
from .shear_building import ShearBuilding
from .structure import BoucWenShearBuilding


@cphysfno_core.hookimpl
def cphysfno_structures() -> list[type]:
    """The structures of this distribution."""
    return [ShearBuilding, BoucWenShearBuilding]


@cphysfno_core.hookimpl
def cphysfno_story_laws() -> list[type]:
    """The story laws of this distribution."""
    return list(BUILT_IN_LAWS)
