"""What evaluating a run gives: each model's test-split predictions and metrics, and the
metric rows, interval coverage and EDP scores those are made of."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..api.interfaces import Refiner
from ..data.datasets import Dataset
from ..signals import GroundMotions, ResponseChannel, Responses, Stories
from . import baselines, edp, metrics


@dataclass
class Evaluation:
    """Test-split predictions of every model and its metrics.

    Attributes:
        true_edps: the EDPs of the simulated test records, None when the structure declares
            no stories.
        predicted_edps: the EDPs of each row of ``metrics`` (models and physics inputs) and
            of each baseline, by label, on the same records.
        baselines: the baselines' rows (:meth:`EDPScorer.baselines`), by label.
        largest_record_share: the share of the test response its largest record holds
            (:func:`~cphysfno_core.reporting.metrics.largest_record_share`), NaN where
            not computed.
        baseline_beats: where a baseline beats every trained model
            (:func:`~cphysfno_core.reporting.baselines.beaten_surrogates`).
    """

    data: Dataset
    predictions: dict[str, Any]
    metrics: dict[str, dict[str, Any]]
    worse_than_physics: dict[str, dict[str, list]] = field(default_factory=dict)
    chosen_forms: dict[str, str] = field(default_factory=dict)
    true_edps: edp.EDPs | None = None
    predicted_edps: dict[str, edp.EDPs] = field(default_factory=dict)
    baselines: dict[str, dict[str, Any]] = field(default_factory=dict)
    baseline_beats: list[dict] = field(default_factory=list)
    largest_record_share: float = float("nan")


COVERAGE_LEVELS = (0.68, 0.90)
"""Nominal levels of the prediction intervals whose test coverage is reported."""


def metric_row(prediction: np.ndarray, truth: np.ndarray) -> dict:
    """``rmse`` (m), ``rel_l2`` and ``record_rel_l2`` (the median over records of each
    record's) per DOF and ``peak_r2`` of the last DOF, for ``[n, T, dof]`` predictions and
    truth."""
    return {
        "rmse": metrics.rmse(prediction, truth).tolist(),
        "rel_l2": metrics.relative_l2(prediction, truth).tolist(),
        "record_rel_l2": metrics.record_relative_l2(prediction, truth).tolist(),
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
    heights: np.ndarray | None = None,
) -> dict[str, dict[str, list[float]]]:
    """Fraction of records per story whose true PID and RID lie within the bounds that a
    fitted refiner's displacement intervals give (:func:`~cphysfno_core.edp.band_interval`,
    with the records' story ``heights [n, n_stories]`` in m where they differ), at each of
    :data:`COVERAGE_LEVELS` (``edp_coverage_68``, ``edp_coverage_90``, each ``{"PID":
    [n_stories], "RID": [n_stories]}``)."""
    found = {}
    for level in COVERAGE_LEVELS:
        lower, upper = refiner.interval(z, operator_output, level)
        bounds = edp.band_interval(lower, upper, stories, motions, heights=heights)
        found[f"edp_coverage_{round(100 * level)}"] = bounds.coverage(truth)
    return found


def simulated_edps(
    data: Dataset, rows: np.ndarray, stories: Stories, heights: np.ndarray | None = None
) -> edp.EDPs:
    """The EDPs of the simulated records ``rows`` of ``data`` (PFA from the absolute
    acceleration channel where the dataset has one; PR of its named responses), with
    those records' story ``heights [len(rows), n_stories]`` in m where they differ."""
    kept = [edp.ACCELERATION_EXTRA, *(c.name for c in data.response_channels)]
    extras = {name: data.extras[name][rows] for name in kept if name in data.extras}
    motions = GroundMotions(data.ag[rows], data.dt)
    return edp.compute(
        Responses(data.u[rows], data.dt, extras=extras),
        stories,
        motions,
        output_names=data.output_names,
        channels=data.response_channels,
        heights=heights,
    )


class EDPScorer:
    """The EDPs of the validation and test records, simulated and predicted, and the
    baselines' predictions of them, for a structure with stories (for one without, every
    method gives nothing).

    Args:
        stories: the structure's stories, or None.
        data: the dataset.
        train_rows: the training records the models learn from (and the baselines are
            fitted on).
        heights: ``[n_records, n_stories]`` the story heights in m of every record of
            ``data`` where a family's records differ in them, else None.
    """

    def __init__(
        self,
        stories: Stories | None,
        data: Dataset,
        train_rows: np.ndarray,
        heights: np.ndarray | None = None,
    ) -> None:
        self.stories = stories
        self.data = data
        self.train_rows = train_rows
        self.record_heights = heights
        self.motions = {split: data.motions(split) for split in ("val", "test")}
        self.predicted: dict[str, edp.EDPs] = {}
        self.truth: edp.EDPs | None = None
        self.validation_truth: edp.EDPs | None = None
        self.output_names = list(data.output_names)
        self.pfa_from = (
            edp.ACCELERATION_EXTRA if edp.ACCELERATION_EXTRA in data.extras else "displacement"
        )
        if stories is not None:
            self.truth = simulated_edps(data, data.rows("test"), stories, self.heights("test"))
            self.validation_truth = simulated_edps(
                data, data.rows("val"), stories, self.heights("val")
            )

    def heights(self, split: str) -> np.ndarray | None:
        """``[n, n_stories]`` the story heights (m) of the split's records, or None where
        every record has the structure's own."""
        if self.record_heights is None:
            return None
        rows = self.train_rows if split == "train" else self.data.rows(split)
        return self.record_heights[rows]

    def errors(
        self, label: str, displacement: Any, validation: Any | None = None
    ) -> dict[str, Any]:
        """``{"edp": test log errors, "validation_edp": validation log errors,
        "pfa_from": ...}`` of predictions of the test (and validation) records, or ``{}``:
        ``[n, T, n_outputs]`` displacements, or :class:`Responses` that may carry predicted
        absolute accelerations (``pfa_from`` then says ``"predicted acceleration"``, else
        ``"displacement"``) and predicted named responses (scored as PR)."""
        if self.truth is None:
            return {}
        names = self.output_names
        predicted = edp.compute(
            displacement,
            self.stories,
            self.motions["test"],
            output_names=names,
            channels=self._predicted_channels(displacement),
            heights=self.heights("test"),
        )
        self.predicted[label] = predicted
        learned = isinstance(displacement, Responses) and edp.ACCELERATION_EXTRA in (
            displacement.extras
        )
        found = {
            "edp": edp.log_errors(predicted, self.truth),
            "pfa_from": "predicted acceleration" if learned else "displacement",
        }
        if validation is not None:
            on_validation = edp.compute(
                validation,
                self.stories,
                self.motions["val"],
                output_names=names,
                channels=self._predicted_channels(validation),
                heights=self.heights("val"),
            )
            found["validation_edp"] = edp.log_errors(on_validation, self.validation_truth)
        return found

    def _predicted_channels(self, predicted: Any) -> tuple[ResponseChannel, ...]:
        """The dataset's named responses that a prediction carries (all of them, or none)."""
        extras = predicted.extras if isinstance(predicted, Responses) else {}
        return tuple(c for c in self.data.response_channels if c.name in extras)

    def baselines(self, first_period: float) -> dict[str, dict[str, Any]]:
        """The rows of :data:`~cphysfno_core.reporting.baselines.BASELINES`, fitted on the
        training records' simulated PID and PFA: ``{label: {"description", "edp",
        "validation_edp"}}`` (``{}`` for a structure without stories)."""
        if self.truth is None:
            return {}
        train = simulated_edps(self.data, self.train_rows, self.stories, self.heights("train"))
        train_motions = GroundMotions(self.data.ag[self.train_rows], self.data.dt)
        fitted = baselines.fit_and_predict(
            train, train_motions, self.motions, first_period
        )
        rows = {}
        for label, predicted in fitted.items():
            self.predicted[label] = predicted["test"]
            rows[label] = {
                "description": baselines.BASELINES[label],
                "edp": edp.log_errors(predicted["test"], self.truth),
                "validation_edp": edp.log_errors(predicted["val"], self.validation_truth),
            }
        return rows

    def locations(self) -> dict[str, list[str]]:
        """The columns each scored EDP is scored at (:func:`~cphysfno_core.edp.scored_columns`:
        stories for ``"PID"``, floors above the ground for ``"PFA"`` and ``"PFV"``, outputs
        for ``"PD"``)."""
        return edp.scored_columns(self.truth)

    def describe(self) -> dict[str, Any] | None:
        """What the ``edp`` entries of ``metrics.json`` are computed over."""
        if self.truth is None:
            return None
        return {
            "stories": list(self.stories.names),
            "heights_m": list(self.stories.heights_m),
            "floors": list(self.truth.columns["PFA"]),
            "true_pfa_from": self.pfa_from,
            "edps": {
                key: {
                    "title": what.title,
                    "unit": what.unit,
                    "method": what.method,
                    "scored_at": self.locations().get(key, []),
                }
                for key, what in edp.EDP_TABLE.items()
                if key in self.truth.values
            },
            "not_scored": {
                key: {
                    "columns": list(self.truth.columns[key]),
                    "units": list(self.truth.units[key]),
                }
                for key in self.truth.values
                if not edp.EDP_TABLE[key].scored
            },
            "errors": "|ln(predicted / simulated)| over the test records (edp) and the "
            "validation records (validation_edp): median and p90 at each column an EDP is "
            "scored at (edps: scored_at)",
            "baselines": "fitted on the simulated scored EDPs of the training records the "
            "models learn from",
        }
