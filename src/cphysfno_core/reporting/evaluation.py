"""What evaluating a run gives: each model's test-split predictions and metrics, and the
metric rows and interval coverage those are made of."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..api.interfaces import Refiner
from ..data.datasets import Dataset
from . import metrics


@dataclass
class Evaluation:
    """Test-split predictions of every model and its metrics."""

    data: Dataset
    predictions: dict[str, Any]
    metrics: dict[str, dict[str, Any]]
    worse_than_physics: dict[str, dict[str, list]] = field(default_factory=dict)
    chosen_forms: dict[str, str] = field(default_factory=dict)


COVERAGE_LEVELS = (0.68, 0.90)
"""Nominal levels of the prediction intervals whose test coverage is reported."""


def metric_row(prediction: np.ndarray, truth: np.ndarray) -> dict:
    """``rmse`` (m) and ``rel_l2`` per DOF and ``peak_r2`` of the last DOF, for
    ``[n, T, dof]`` predictions and truth."""
    return {
        "rmse": metrics.rmse(prediction, truth).tolist(),
        "rel_l2": metrics.relative_l2(prediction, truth).tolist(),
        "peak_r2": metrics.peak_r2(prediction, truth),
    }


def interval_coverage_scores(
    refiner: Refiner,
    z: np.ndarray | None,
    operator_output: np.ndarray,
    truth: np.ndarray,
    calibration_records: int,
) -> dict[str, list[float]]:
    """Coverage per DOF of a fitted refiner's intervals at each of :data:`COVERAGE_LEVELS`
    (``coverage_68``, ``coverage_90``) and its standard error from the draw of the
    ``[n, T, dof]`` records scored and of the ``calibration_records`` the refiner was fitted
    on (``coverage_68_se``, ``coverage_90_se``)."""
    found = {}
    for level in COVERAGE_LEVELS:
        lower, upper = refiner.interval(z, operator_output, level)
        key = f"coverage_{round(100 * level)}"
        found[key] = metrics.interval_coverage(lower, upper, truth).tolist()
        found[f"{key}_se"] = metrics.coverage_standard_error(
            lower, upper, truth, calibration_records
        ).tolist()
    return found
