"""Study summaries of disjoint seeds or models (say, run on two machines) combined into one.

A ``study.json`` keeps per model and output the mean and the standard deviation over its
seeds (``ddof = 0``); with the seed counts these give the sums of the values and of their
squares, so summaries of disjoint seed sets combine to exactly the summary of all the
runs together, without the run folders. Summaries may also hold different models of the
same seeds (shares of a study by model, ``cphysfno study --models``): each model combines
the summaries that hold it, and at the end every model must stand on the same seeds.
"""

from __future__ import annotations

import re

import numpy as np

from ..model.labels import ModelLabel
from ..signals.errors import ConfigError
from .study_document import EDPSummary, MeanStd, StudySummary, SummaryRow, Sweep

_SAME = ("epochs", "sizes", "output_names")
_DEVICES = re.compile(r", (?![^()]*\))")  # the commas between devices, not inside "(...)"


def combine_summaries(summaries: list[StudySummary]) -> StudySummary:
    """One summary of the union of the seeds and models of ``summaries``.

    Args:
        summaries: ``study.json`` documents (or ``cphysfno summarise`` outputs) of the same
            experiment (same epochs, split sizes, outputs and test response): per model, the
            summaries holding it have disjoint ``seeds``; the rows of the physics
            preprocessors alone (``physics-*``), which do not depend on the seed, are the
            same in all.

    Returns:
        Per model and metric the mean and standard deviation (``ddof = 0``) over all its
        seeds, equal to what :func:`summarise` gives on all the runs; sweeps' per-seed
        errors joined; seeds in the order first given; the devices of all.

    Raises:
        ConfigError: fewer than two summaries, a model's seed in two of them, models that
            end on different seeds, or summaries that differ in what they summarise
            (a physics row included).
    """
    if len(summaries) < 2:
        raise ConfigError("combining needs at least two summaries")
    first = summaries[0]
    recorded = [s.response_rms for s in summaries if s.response_rms is not None]
    response = recorded[0] if recorded else None
    for i, summary in enumerate(summaries[1:], start=1):
        for key in _SAME:
            ours, theirs = getattr(summary, key), getattr(first, key)
            if ours != theirs:
                raise ConfigError(f"summary {i} has {key} {ours}, summary 0 has {theirs}")
    for i, summary in enumerate(summaries):
        if not _same_response(summary.response_rms, response):
            raise ConfigError(f"summary {i} has another test response than the others")
    labels = dict.fromkeys(label for summary in summaries for label in summary.models)
    models, seeds_of = {}, {}
    for label in labels:
        holding = [summary for summary in summaries if label in summary.models]
        if ModelLabel.parse(label).is_physics:
            models[label] = _physics_row(holding, label)
            continue
        seeds = [seed for summary in holding for seed in summary.seeds]
        repeated = sorted({seed for seed in seeds if seeds.count(seed) > 1})
        if repeated:
            raise ConfigError(f"{label}: seeds {repeated} are in more than one summary")
        counts = [len(summary.seeds) for summary in holding]
        rows = [summary.models[label] for summary in holding]
        models[label] = _combine_model(rows, counts, label)
        seeds_of[label] = seeds
    _check_same_seeds(seeds_of)
    devices = [part for summary in summaries for part in _DEVICES.split(summary.device)]
    return StudySummary(
        models=models,
        baselines=_baselines(summaries),
        sweeps=_combine_sweeps([summary.sweeps for summary in summaries]),
        seeds=list(dict.fromkeys(seed for summary in summaries for seed in summary.seeds)),
        epochs=first.epochs,
        sizes=first.sizes,
        output_names=first.output_names,
        response_rms=response,
        device=", ".join(dict.fromkeys(devices)),
    )


def _baselines(summaries: list[StudySummary]) -> dict[str, EDPSummary]:
    """The baselines' rows, fitted on the training data alone and so the same in every
    summary of the same data (the first one that has them)."""
    return next((summary.baselines for summary in summaries if summary.baselines), {})


def _physics_row(holding: list[StudySummary], label: str) -> SummaryRow:
    """The row of a physics preprocessor alone, which no training seed changes: the same
    in every summary of the same data (raises ConfigError where it is not)."""
    first = holding[0].models[label]
    for summary in holding[1:]:
        row = summary.models[label]
        same_extras = row.model_extra == first.model_extra
        if not (same_extras and all(map(_same, _statistics(row), _statistics(first)))):
            raise ConfigError(f"{label} differs between the summaries: not the same data")
    return first


def _statistics(row: SummaryRow) -> list[MeanStd | None]:
    return [getattr(row, key) for key in SummaryRow.model_fields]


def _same(a: MeanStd | None, b: MeanStd | None) -> bool:
    if a is None or b is None:
        return a is b
    return bool(np.allclose(a.mean, b.mean, rtol=1e-9, atol=0.0))


def _check_same_seeds(seeds_of: dict[str, list[int]]) -> None:
    """Raise ConfigError unless every model stands on the same set of seeds."""
    sets = {label: sorted(seeds) for label, seeds in seeds_of.items()}
    if len({tuple(seeds) for seeds in sets.values()}) > 1:
        listed = "; ".join(f"{label} {seeds}" for label, seeds in sets.items())
        raise ConfigError(
            f"the models end on different seeds ({listed}): combine the shares that "
            "complete each model's seeds"
        )


def _same_response(a: list[float] | None, b: list[float] | None) -> bool:
    """Whether two test responses agree; one that was not recorded (a summary written
    before ``response_rms`` existed) cannot disagree."""
    if a is None or b is None:
        return True
    return bool(np.allclose(a, b, rtol=1e-9, atol=0.0))


def _combine_model(rows: list[SummaryRow], counts: list[int], label: str) -> SummaryRow:
    """The statistics of ``rows`` pooled, and the keys of their own, which must agree."""
    combined = {}
    for key, value in rows[0].model_extra.items():
        if any(row.model_extra.get(key) != value for row in rows):
            raise ConfigError(f"model {label}: {key} differs between the summaries")
        combined[key] = value
    for key in SummaryRow.model_fields:
        parts = [getattr(row, key) for row in rows]
        if all(part is None for part in parts):
            continue
        if any(part is None for part in parts):
            raise ConfigError(f"model {label}: {key} is in some of the summaries only")
        combined[key] = _pooled(parts, counts)
    return SummaryRow.model_validate(combined)


def _pooled(parts: list[MeanStd], counts: list[int]) -> MeanStd:
    """Mean and ``ddof = 0`` std of the union, from each part's mean, std and count."""
    n = np.asarray(counts, dtype=np.float64)[:, None]
    mean = np.asarray([part.mean for part in parts], dtype=np.float64)
    std = np.asarray([part.std for part in parts], dtype=np.float64)
    total = (n * mean).sum(axis=0) / n.sum()
    # spread within each part plus the parts' offsets from the total mean
    variance = (n * (std**2 + (mean - total) ** 2)).sum(axis=0) / n.sum()
    return MeanStd(mean=total.tolist(), std=np.sqrt(variance).tolist())


def _combine_sweeps(sweeps: list[dict[str, Sweep]]) -> dict[str, Sweep]:
    out: dict[str, Sweep] = {}
    for part in sweeps:
        for name, sweep in part.items():
            into = out.setdefault(
                name, Sweep(field=sweep.field, label=sweep.label, values=[], rel_l2={}, edp={})
            )
            if sweep.field != into.field:
                raise ConfigError(f"sweep {name} sets {sweep.field} and {into.field}")
            into.values += [v for v in sweep.values if v not in into.values]
            for key in ("rel_l2", "edp"):
                for label, by_value in getattr(sweep, key).items():
                    for value, rows in by_value.items():
                        getattr(into, key).setdefault(label, {}).setdefault(value, []).extend(rows)
    return out
