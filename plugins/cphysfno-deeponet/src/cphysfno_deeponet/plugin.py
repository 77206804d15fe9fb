"""Entry point of the ``cphysfno-deeponet`` distribution: registers the ``deeponet`` operator."""

from __future__ import annotations

import cphysfno_core

from .model import DeepONet


@cphysfno_core.hookimpl
def cphysfno_operators() -> list[type]:
    """The operators of this distribution."""
    return [DeepONet]
