"""What evaluating a run gives: each model's test-split predictions and metrics, and the
metric rows, interval coverage and EDP scores those are made of."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..api.interfaces import Refiner
from ..data.datasets import Dataset
from ..signals import GroundMotions, Responses, Stories
from . import edp, metrics


@dataclass
class Evaluation:
    """Test-split predictions of every model and its metrics.

    Attributes:
        true_edps: the EDPs of the simulated test records, None when the structure declares
            no stories.
        predicted_edps: the EDPs of each row of ``metrics`` (models and physics inputs), by
            label, on the same records.
    """

    data: Dataset
    predictions: dict[str, Any]
    metrics: dict[str, dict[str, Any]]
    worse_than_physics: dict[str, dict[str, list]] = field(default_factory=dict)
    chosen_forms: dict[str, str] = field(default_factory=dict)
    true_edps: edp.EDPs | None = None
    predicted_edps: dict[str, edp.EDPs] = field(default_factory=dict)


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


def edp_interval_scores(
    refiner: Refiner,
    z: np.ndarray | None,
    operator_output: np.ndarray,
    stories: Stories,
    motions: GroundMotions,
    truth: edp.EDPs,
) -> dict[str, dict[str, list[float]]]:
    """Fraction of records per story whose true PID and RID lie within the bounds that a
    fitted refiner's displacement intervals give (:func:`~cphysfno_core.edp.band_interval`),
    at each of :data:`COVERAGE_LEVELS` (``edp_coverage_68``, ``edp_coverage_90``, each
    ``{"PID": [n_stories], "RID": [n_stories]}``)."""
    found = {}
    for level in COVERAGE_LEVELS:
        lower, upper = refiner.interval(z, operator_output, level)
        bounds = edp.band_interval(lower, upper, stories, motions)
        found[f"edp_coverage_{round(100 * level)}"] = bounds.coverage(truth)
    return found


class EDPScorer:
    """The EDPs of the test records, simulated and predicted, for a structure with stories
    (for one without, every method gives nothing)."""

    def __init__(self, stories: Stories | None, data: Dataset, motions: GroundMotions) -> None:
        self.stories = stories
        self.motions = motions
        self.predicted: dict[str, edp.EDPs] = {}
        self.truth: edp.EDPs | None = None
        self.output_names = list(data.output_names)
        rows = data.rows("test")
        extras = {}
        if edp.ACCELERATION_EXTRA in data.extras:
            extras[edp.ACCELERATION_EXTRA] = data.extras[edp.ACCELERATION_EXTRA][rows]
        self.pfa_from = edp.ACCELERATION_EXTRA if extras else "displacement"
        if stories is not None:
            responses = Responses(data.u[rows], data.dt, extras=extras)
            self.truth = edp.compute(responses, stories, motions)

    def errors(self, label: str, displacement: Any) -> dict[str, Any]:
        """``{"edp": log errors}`` of a ``[n, T, n_outputs]`` prediction, or ``{}``."""
        if self.truth is None:
            return {}
        predicted = edp.compute(displacement, self.stories, self.motions)
        self.predicted[label] = predicted
        return {"edp": edp.log_errors(predicted, self.truth)}

    def describe(self) -> dict[str, Any] | None:
        """What the ``edp`` entries of ``metrics.json`` are computed over."""
        if self.truth is None:
            return None
        return {
            "stories": list(self.stories.names),
            "heights_m": list(self.stories.heights_m),
            "floors": self.truth.floor_names(self.output_names),
            "true_pfa_from": self.pfa_from,
            "errors": "|ln(predicted / simulated)| over the test records: median and p90 "
            "per story (PID) and per floor above the ground (PFA)",
        }
