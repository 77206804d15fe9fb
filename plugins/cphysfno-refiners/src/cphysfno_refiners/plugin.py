"""Entry point of the ``cphysfno-refiners`` distribution: registers its refiners."""

from __future__ import annotations

from cphysfno_core.plugin import hookimpl

from .conformal import ConformalRefiner
from .linear_regression import LinearRegressionRefiner


@hookimpl
def cphysfno_refiners() -> list[type]:
    """The refiners of this distribution."""
    return [LinearRegressionRefiner, ConformalRefiner]
