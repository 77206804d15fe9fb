"""The module the entry point names: one hook per kind of component this package adds."""

from __future__ import annotations

from cphysfno_core.plugin import hookimpl

from .duffing import DuffingChain
from .kanai_tajimi import KanaiTajimi


@hookimpl
def cphysfno_structures() -> list[type]:
    """The structures of this distribution."""
    return [DuffingChain]


@hookimpl
def cphysfno_ground_motions() -> list[type]:
    """The ground-motion sources of this distribution."""
    return [KanaiTajimi]
