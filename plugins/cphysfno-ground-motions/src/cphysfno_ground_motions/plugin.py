"""Registers this distribution's ground-motion sources with cphysfno."""

from __future__ import annotations

from cphysfno_core.plugin import hookimpl

from .recorded import Recorded
from .spectrum_compatible import SpectrumCompatible
from .white_noise import WhiteNoise


@hookimpl
def cphysfno_ground_motions() -> list[type]:
    """The ground-motion sources of this distribution."""
    return [WhiteNoise, SpectrumCompatible, Recorded]
