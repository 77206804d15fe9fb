"""``study.json``, the summary of a study's runs over their seeds (``cphysfno study`` and
``cphysfno summarise``): :class:`StudySummary`."""

from __future__ import annotations

from typing import Any

from pydantic import ConfigDict, Field

from .documents import Document, Row


class MeanStd(Row):
    """The mean and standard deviation (``ddof = 0``) over seeds, per DOF or column."""

    mean: list[float]
    std: list[float]


class EDPSummary(Row):
    """The median test ``|ln(predicted / simulated)|`` of PID per story (``pid_median``),
    of PFA and PFV per floor above the ground (``pfa_median``, ``pfv_median``) and of PD
    per output (``pd_median``), over seeds."""

    pid_median: MeanStd | None = None
    pfa_median: MeanStd | None = None
    pfv_median: MeanStd | None = None
    pd_median: MeanStd | None = None


class SummaryRow(EDPSummary):
    """A model's row: its test errors per DOF over seeds (relative L2, RMSE in m), a
    refined model's interval coverage, and its EDP errors where the structure has
    stories.

    A row may also hold keys of its own that say where it comes from (a summary curated
    by hand: ``selected_on``, ``config``, ...); they are kept as they are."""

    model_config = ConfigDict(extra="allow")

    rel_l2: MeanStd
    rmse: MeanStd
    record_rel_l2: MeanStd | None = None
    coverage_68: MeanStd | None = None
    coverage_90: MeanStd | None = None


class Sweep(Row):
    """A parametric sweep's runs.

    Attributes:
        field: the config field it sets (``section.field``).
        label: the field in words, for figures.
        values: the values with a finished run, in the config's order.
        rel_l2: label -> str(value) -> per-seed relative L2 per DOF.
        edp: label (models and baselines) -> str(value) -> per-seed ``{"PID": [...],
            "PFA": [...], ...}`` median test errors (those of :data:`EDP_SUMMARY` the runs
            have).
    """

    field: str
    label: str
    values: list[Any]
    rel_l2: dict[str, dict[str, list[list[float]]]]
    edp: dict[str, dict[str, list[dict[str, list[float]]]]] = Field(default_factory=dict)


class StudySummary(Document):
    """``study.json``.

    Attributes:
        models: label (:class:`~cphysfno_core.model.labels.ModelLabel`) -> its row.
        baselines: label -> its EDP errors (fitted on the training data, the same for
            every seed).
        sweeps: name -> its runs.
        seeds: the table runs' training seeds.
        epochs: training epochs.
        sizes: split -> records.
        output_names: the output DOFs.
        response_rms: root mean square of the simulated test response per output, m (None
            in a summary of runs that did not record it).
        device: where the models trained.
    """

    models: dict[str, SummaryRow]
    baselines: dict[str, EDPSummary] = Field(default_factory=dict)
    sweeps: dict[str, Sweep]
    seeds: list[int]
    epochs: int
    sizes: dict[str, int]
    output_names: list[str]
    response_rms: list[float] | None = None
    device: str
