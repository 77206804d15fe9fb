"""The study report: a per-DOF table printed to the terminal, ``report.md`` and figures."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from . import figures
from .config import ExperimentConfig
from .pipeline import MODELS, Evaluation

# Table 1 of the paper (Example 1, mean of 10 seeds): label -> (RMSE [m], relative L2).
PAPER_EXAMPLE1 = {
    "fno": ([0.0038, 0.0072, 0.0105, 0.0140, 0.0187], [0.9653, 0.9569, 0.9561, 0.9578, 0.9582]),
    "c-physfno-els": (
        [0.0022, 0.0040, 0.0054, 0.0070, 0.0102],
        [0.5775, 0.5314, 0.4957, 0.4819, 0.5245],
    ),
    "c-physfno-modal": (
        [0.0028, 0.0053, 0.0077, 0.0103, 0.0139],
        [0.7196, 0.7059, 0.7025, 0.7034, 0.7134],
    ),
    "c-physfno-relaxed": (
        [0.0025, 0.0048, 0.0070, 0.0094, 0.0126],
        [0.6398, 0.6393, 0.6404, 0.6421, 0.6485],
    ),
    "refined-c-physfno-els": (
        [0.0021, 0.0039, 0.0053, 0.0069, 0.0100],
        [0.5492, 0.5200, 0.4882, 0.4780, 0.5208],
    ),
    "refined-c-physfno-modal": (
        [0.0027, 0.0052, 0.0076, 0.0102, 0.0138],
        [0.7015, 0.6820, 0.6832, 0.6850, 0.7002],
    ),
    "refined-c-physfno-relaxed": (
        [0.0024, 0.0047, 0.0069, 0.0093, 0.0125],
        [0.6180, 0.6282, 0.6302, 0.6310, 0.6402],
    ),
}


def describe_operators(config: ExperimentConfig) -> str:
    """The config's operators with their parameters, for a report header."""
    return ", ".join(f"`{o.name}` {o.params}" for o in config.operator)


def format_table(models: dict[str, dict], output_names: list[str], metric: str = "rel_l2") -> str:
    """A fixed-width table: one row per model, one column per output DOF."""
    width = max(len(label) for label in models) + 2
    header = "model".ljust(width) + "".join(name.rjust(10) for name in output_names)
    lines = [header, "-" * len(header)]
    for label, row in models.items():
        lines.append(label.ljust(width) + "".join(f"{v:10.4f}" for v in row[metric]))
    return "\n".join(lines)


def _markdown_table(
    models: dict[str, dict], names: list[str], metric: str, digits: int, paper: dict | None
) -> list[str]:
    index = 0 if metric == "rmse" else 1
    lines = ["| model | " + " | ".join(names) + " |", "|---" * (len(names) + 1) + "|"]
    for label, row in models.items():
        cells = [f"{v:.{digits}f}" for v in row[metric]]
        if paper and label in paper and len(paper[label][index]) == len(cells):
            cells = [
                f"{c} ({p:.{digits}f})" for c, p in zip(cells, paper[label][index], strict=True)
            ]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return lines


def write_figures(evaluation: Evaluation, out: Path) -> list[Path]:
    """The study's figures into ``out/figures`` (nothing if there is no trained model)."""
    data = evaluation.data
    stages = evaluation.predictions
    if not stages:
        return []
    directory = out / "figures"
    directory.mkdir(parents=True, exist_ok=True)
    names = list(data.output_names)
    rows = data.rows("test")
    truth = data.u[rows]
    time = np.arange(truth.shape[1]) * data.dt
    true_peak = np.max(np.abs(truth[:, :, -1]), axis=1)
    record = int(np.argsort(true_peak)[len(true_peak) // 2])  # a typical record: median peak
    written = []
    physics = [label for label in stages if stages[label].z is not None]
    main = next((label for label in stages if label.startswith("c-phys")), next(iter(stages)))
    written.append(
        figures.trajectories(
            time,
            truth[record],
            stages[main].mean[record],
            names,
            main,
            directory / "trajectories.png",
        )
    )
    written.append(
        figures.model_comparison(
            time,
            truth[record, :, -1],
            {k: v.mean[record, :, -1] for k, v in stages.items()},
            names[-1],
            directory / "top_story_models.png",
        )
    )
    refined = [label for label in stages if label.startswith("refined-")]
    if refined:
        s = stages[refined[0]]
        written.append(
            figures.refined_band(
                time,
                truth[record, :, -1],
                s.mean[record, :, -1],
                s.std[record, :, -1],
                refined[0],
                names[-1],
                directory / "refined_band.png",
            )
        )
    written.append(
        figures.peaks(
            true_peak,
            {k: np.max(np.abs(v.mean[:, :, -1]), axis=1) for k, v in stages.items()},
            names[-1],
            directory / "peaks.png",
        )
    )
    if {"story_drift", "story_shear"} <= set(data.extras):
        drift = data.extras["story_drift"][rows][record]
        shear = data.extras["story_shear"][rows][record]
        written.append(
            figures.hysteresis(
                drift, shear, sorted({0, drift.shape[1] - 1}), names, directory / "hysteresis.png"
            )
        )
    if physics:
        z = stages[physics[0]].z[record, :, -1]
        written.append(
            figures.spectra(
                data.ag[rows][record],
                z,
                truth[record, :, -1],
                data.dt,
                time,
                names[-1],
                directory / "spectra.png",
            )
        )
    histories = {}
    for label in stages:
        model_json = out / MODELS / label / "model.json"
        if not label.startswith("refined-") and model_json.exists():
            histories[label] = json.loads(model_json.read_text())["history"]
    if histories:
        written.append(figures.training_curves(histories, directory / "training.png"))
    return written


def write_report(config: ExperimentConfig, evaluation: Evaluation, out: str | Path) -> Path:
    """Write ``report.md`` (and the figures, if configured) into ``out``."""
    out = Path(out)
    names = list(evaluation.data.output_names)
    models = evaluation.metrics
    paper = PAPER_EXAMPLE1 if config.output.paper_reference == "example1" else None
    written = write_figures(evaluation, out) if config.output.figures else []
    sizes = evaluation.data.sizes
    lines = [
        "# cphysfno study report",
        "",
        f"- structure: `{config.structure.name}`, ground motion: `{config.ground_motion.name}`",
        f"- records: {sizes['train']} train / {sizes['val']} validation / {sizes['test']} test,"
        f" dt = {evaluation.data.dt} s, {evaluation.data.u.shape[1]} steps",
        f"- operators: {describe_operators(config)}, "
        f"{config.training.epochs} epochs, batch {config.training.batch_size}, "
        f"Adam lr {config.training.learning_rate}, x{config.training.decay_factor} every "
        f"{config.training.decay_step} epochs",
        "",
        "Rows `physics-*` are the physics response z alone, untrained: the number a learned "
        "model must beat.",
    ]
    if paper:
        lines.append(
            "Values in parentheses are the paper's Table 1 (mean of 10 seeds, "
            "400/100/200 records, full training)."
        )
    lines += ["", "## Relative L2 error (test split)", ""]
    lines += _markdown_table(models, names, "rel_l2", 4, paper)
    lines += ["", "## RMSE (m, test split)", ""]
    lines += _markdown_table(models, names, "rmse", 4, paper)
    lines += [
        "",
        "## Peak response and intervals",
        "",
        "| model | peak R² (" + names[-1] + ") | 68 % interval coverage per DOF "
        "| 90 % interval coverage per DOF |",
        "|---|---|---|---|",
    ]
    for label, row in models.items():
        cells = [
            ", ".join(f"{c:.2f}" for c in row[key]) if key in row else "-"
            for key in ("coverage_68", "coverage_90")
        ]
        lines.append(f"| {label} | {row['peak_r2']:.3f} | {' | '.join(cells)} |")
    if written:
        lines += ["", "## Figures", ""]
        lines += [f"![{p.stem}](figures/{p.name})" for p in written]
    path = out / "report.md"
    path.write_text("\n".join(lines) + "\n")
    return path
