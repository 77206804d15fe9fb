"""Entry point of the ``cphysfno-opensees`` distribution: registers its structures."""

from __future__ import annotations

import cphysfno_core


@cphysfno_core.hookimpl
def cphysfno_structures() -> list[type]:
    """The OpenSees structures."""
    return []
