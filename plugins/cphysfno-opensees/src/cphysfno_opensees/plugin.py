"""Entry point of the ``cphysfno-opensees`` distribution: registers its structures."""

from __future__ import annotations

from cphysfno_core.plugin import hookimpl

from .bridge.structure import AuburnRavineBridge
from .sac9.structure import Sac9Frame
from .script.structure import OpenSeesModel


@hookimpl
def cphysfno_structures() -> list[type]:
    """The OpenSees structures."""
    return [AuburnRavineBridge, Sac9Frame, OpenSeesModel]
