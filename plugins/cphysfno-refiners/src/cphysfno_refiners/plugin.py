"""Entry point of the ``cphysfno-refiners`` distribution: registers its refiners."""

from __future__ import annotations

import cphysfno_core

from .conformal import ConformalRefiner
from .linear_regression import LinearRegressionRefiner


@cphysfno_core.hookimpl
def cphysfno_refiners() -> list[type]:
    """The refiners of this distribution."""
    return [LinearRegressionRefiner, ConformalRefiner]
