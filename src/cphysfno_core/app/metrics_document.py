"""``metrics.json``, what ``cphysfno evaluate`` writes of a run: :class:`MetricsDocument`.

Errors are per output DOF (``[dof]`` lists) unless said otherwise; EDP errors are the
median and 90th percentile over records of ``|ln(predicted / simulated)|`` at each column
an EDP is scored at (:func:`~cphysfno_core.edp.log_errors`).
"""

from __future__ import annotations

from typing import Any

from pydantic import Field

from .documents import Document, Row

EDPErrors = dict[str, dict[str, list[float]]]
"""EDP name (``"PID"``, ``"PFA"``, ...) -> quantile (``"median"``, ``"p90"``) -> one error
per column."""


class ErrorRow(Row):
    """The errors of one prediction against the simulated test records.

    Attributes:
        rmse: root mean square error (m, or m/s^2 for accelerations).
        rel_l2: relative L2 error.
        record_rel_l2: the median over records of each record's relative L2 error.
        peak_r2: R^2 of the peak of the last DOF.
        validation_rel_l2: relative L2 error on the validation records.
    """

    rmse: list[float]
    rel_l2: list[float]
    record_rel_l2: list[float] | None = None
    peak_r2: float | None = None
    validation_rel_l2: list[float] | None = None


class ModelRow(ErrorRow):
    """A row of ``models``: a trained model, or the physics response of a preprocessor
    alone (``physics-*``).

    Attributes:
        acceleration: the errors of the absolute accelerations of a model that learns them.
        responses: name -> the errors of each named response of a model that learns them
            (``rmse`` in the response's unit).
        edp: EDP errors on the test records (a structure with stories).
        validation_edp: EDP errors on the validation records.
        pfa_from: ``"predicted acceleration"`` or ``"displacement"``, where PFA came from.
        physics_input: the label of the ``physics-*`` row of a C-Phys model's z.
        coverage_68: a refined model's test coverage of its 68 % interval.
        coverage_90: of its 90 % interval.
        coverage_68_se: the standard error of ``coverage_68``.
        coverage_90_se: of ``coverage_90``.
        edp_coverage_68: EDP name -> per story, the share of records whose true EDP lies
            within the bounds of the 68 % interval.
        edp_coverage_90: of the 90 % interval.
        best_epoch: the epoch whose weights were kept.
        train_seconds: wall time of the training, s.
        device: where the model trained.
    """

    acceleration: ErrorRow | None = None
    responses: dict[str, ErrorRow] | None = None
    edp: EDPErrors | None = None
    validation_edp: EDPErrors | None = None
    pfa_from: str | None = None
    physics_input: str | None = None
    coverage_68: list[float] | None = None
    coverage_90: list[float] | None = None
    coverage_68_se: list[float] | None = None
    coverage_90_se: list[float] | None = None
    edp_coverage_68: dict[str, list[float]] | None = None
    edp_coverage_90: dict[str, list[float]] | None = None
    best_epoch: int | None = None
    train_seconds: float | None = None
    device: str | None = None


class BaselineRow(Row):
    """A row of ``baselines``: a regression on intensity measures, fitted on the
    training records' EDPs."""

    description: str
    edp: EDPErrors
    validation_edp: EDPErrors | None = None


class BeatenPlace(Row):
    """An EDP and column where a baseline's test error is below every trained model's."""

    edp: str
    location: str
    baseline: str
    baseline_error: float
    surrogate: str | None
    surrogate_error: float


class MetricsDocument(Document):
    """``metrics.json``.

    Attributes:
        models: label (:class:`~cphysfno_core.model.labels.ModelLabel`) -> its row.
        output_names: the output DOFs.
        sizes: split -> records.
        left_out: ``"collapsed"``, ``"non_converged"``, ``"failed"`` -> split -> records
            left out.
        response_rms: root mean square of the simulated test response per output, m.
        largest_record_share: the share of the test response's sum of squares that its
            largest record holds (:func:`~cphysfno_core.reporting.metrics.largest_record_share`).
        epochs: training epochs.
        precision: the training arithmetic.
        worse_than_physics: label -> split -> ``(output, model error, physics error)``
            where a C-Phys model ends worse than its z alone.
        chosen_forms: paper-form label -> the form chosen on validation error.
        edp: what the EDP errors are computed over (None for a structure without
            stories).
        baselines: label -> its row.
        baseline_beats_surrogates: where a baseline beats every trained model.
    """

    models: dict[str, ModelRow]
    output_names: list[str]
    sizes: dict[str, int]
    left_out: dict[str, dict[str, int]] = Field(default_factory=dict)
    response_rms: list[float] | None = None
    largest_record_share: float | None = None
    epochs: int
    precision: str = "float32"
    worse_than_physics: dict[str, dict[str, list[tuple[str, float, float]]]] = Field(
        default_factory=dict
    )
    chosen_forms: dict[str, str] = Field(default_factory=dict)
    edp: dict[str, Any] | None = None
    baselines: dict[str, BaselineRow] = Field(default_factory=dict)
    baseline_beats_surrogates: list[BeatenPlace] = Field(default_factory=list)
