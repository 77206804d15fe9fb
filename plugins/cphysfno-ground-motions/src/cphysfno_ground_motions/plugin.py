"""Registers this distribution's ground-motion sources with cphysfno."""

from __future__ import annotations

import cphysfno_core

from .recorded import Recorded
from .spectrum_compatible import SpectrumCompatible
from .white_noise import WhiteNoise


@cphysfno_core.hookimpl
def cphysfno_ground_motions() -> list[type]:
    """The ground-motion sources of this distribution."""
    return [WhiteNoise, SpectrumCompatible, Recorded]
