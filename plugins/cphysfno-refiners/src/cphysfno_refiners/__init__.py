"""Refiners of operator predictions for cphysfno."""

from .linear_regression import LinearRegressionParams, LinearRegressionRefiner

__all__ = ["LinearRegressionParams", "LinearRegressionRefiner"]
