"""Entry point of the ``cphysfno-neuralop`` distribution: registers ``neuralop-fno``.

Registering does not import ``neuralop`` (a few seconds): that happens when the first
operator is built.
"""

from __future__ import annotations

from cphysfno_core.plugin import hookimpl

from .adapter import NeuralopFNO


@hookimpl
def cphysfno_operators() -> list[type]:
    """The operators of this distribution."""
    return [NeuralopFNO]
