"""Refiners of operator predictions for cphysfno."""

from .conformal import ConformalParams, ConformalRefiner
from .linear_regression import LinearRegressionParams, LinearRegressionRefiner

__all__ = [
    "ConformalParams",
    "ConformalRefiner",
    "LinearRegressionParams",
    "LinearRegressionRefiner",
]
