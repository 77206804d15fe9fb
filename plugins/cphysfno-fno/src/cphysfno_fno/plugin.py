"""Entry point of the ``cphysfno-fno`` distribution: registers the ``fno`` operator."""

from __future__ import annotations

import cphysfno_core

from .model import FNO1d


@cphysfno_core.hookimpl
def cphysfno_operators() -> list[type]:
    """The operators of this distribution."""
    return [FNO1d]
