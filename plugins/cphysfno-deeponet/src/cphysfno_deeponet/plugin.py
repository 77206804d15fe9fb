"""Entry point of the ``cphysfno-deeponet`` distribution: registers the ``deeponet`` operator."""

from __future__ import annotations

from cphysfno_core.plugin import hookimpl

from .model import DeepONet


@hookimpl
def cphysfno_operators() -> list[type]:
    """The operators of this distribution."""
    return [DeepONet]
