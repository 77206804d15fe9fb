"""Entry point of the ``cphysfno-fno`` distribution: registers the ``fno`` operator."""

from __future__ import annotations

from cphysfno_core.plugin import hookimpl

from .model import FNO1d


@hookimpl
def cphysfno_operators() -> list[type]:
    """The operators of this distribution."""
    return [FNO1d]
