"""The report's account of a structure's random parameters: each one's distribution and
the records' draws per split, in a table and a figure."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..config.uncertainty import UncertainParameters
from ..data.datasets import SPLITS, Dataset
from .figures import parameter_draws

SPLIT_NAMES = {"train": "training", "val": "validation", "test": "test"}


def draws_section(space: UncertainParameters, data: Dataset, figure: Path | None) -> list[str]:
    """The report's lines on the random parameters ``space`` and the draws of ``data``'s
    records (none for a fixed structure): per parameter its distribution and the minimum,
    median and maximum draw of each split; with ``figure``, their histograms are written
    there (a PNG path) and shown, the path taken relative to the report's folder,
    ``figure``'s grandparent."""
    if not data.param_names:
        return []
    distributions = {p.path: p.distribution.describe() for p in space.parameters}
    draws = {split: data.parameter_draws(split) for split in SPLITS}
    lines = [
        "",
        "## Random structural parameters",
        "",
        "Each record's structure drew its own values (a model labelled `-params` also takes "
        "them as input channels). Draws per split: minimum / median / maximum."
        + _tails_note(space.test_tails),
        "",
        "| parameter | unit | distribution | "
        + " | ".join(SPLIT_NAMES[s] for s in SPLITS)
        + " |",
        "|---|---|---|" + "---|" * len(SPLITS),
    ]
    for name, unit in zip(data.param_names, data.param_units, strict=True):
        cells = [_range(draws[split][name]) for split in SPLITS]
        known = distributions.get(name, "-")
        lines.append(f"| `{name}` | {unit or '-'} | {known} | {' | '.join(cells)} |")
    if figure is not None:
        columns = {
            SPLIT_NAMES[split]: np.column_stack([draws[split][n] for n in data.param_names])
            for split in SPLITS
            if data.sizes[split]
        }
        path = parameter_draws(columns, list(data.param_names), list(data.param_units), figure)
        lines += ["", f"![parameter draws]({path.parent.name}/{path.name})"]
    return lines


def _range(values: np.ndarray) -> str:
    if not values.size:
        return "-"
    return f"{values.min():.4g} / {np.median(values):.4g} / {values.max():.4g}"


def _tails_note(edge: float | None) -> str:
    if edge is None:
        return ""
    return (
        f" The test records drew every parameter from its tails, beyond {edge:g} standard "
        "deviations of the standard normal number behind it, the training and validation "
        "records from within (`uncertainty.test_tails`): the test split is outside the "
        "family the models were trained on."
    )
