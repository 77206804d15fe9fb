"""Registers this distribution's structures with cphysfno."""

from __future__ import annotations

import cphysfno_core

from .structure import BoucWenShearBuilding


@cphysfno_core.hookimpl
def cphysfno_structures() -> list[type]:
    """The structures of this distribution."""
    return [BoucWenShearBuilding]
