"""The module the entry point names: one hook per kind of component this package adds."""

from __future__ import annotations

import cphysfno_core

from .duffing import DuffingChain
from .kanai_tajimi import KanaiTajimi


@cphysfno_core.hookimpl
def cphysfno_structures() -> list[type]:
    """The structures of this distribution."""
    return [DuffingChain]


@cphysfno_core.hookimpl
def cphysfno_ground_motions() -> list[type]:
    """The ground-motion sources of this distribution."""
    return [KanaiTajimi]
