"""The study report: a per-DOF table printed to the terminal, ``report.md`` and figures."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..api.registry import get_registry
from ..config.experiment import ExperimentConfig
from ..data.datasets import SPLITS
from ..data.layout import MODELS
from ..model.labels import ModelLabel
from ..signals import ResponseChannel
from ..signals.intensity import SpectrumBand
from . import edp, figures
from .against_physics import describe_shortfalls
from .baselines import describe_beaten
from .edp import ACCELERATION_EXTRA
from .evaluation import Evaluation
from .paper_tables import PaperTable, paper_table
from .parameter_draws import draws_section


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
    models: dict[str, dict],
    names: list[str],
    metric: str,
    digits: int,
    paper: PaperTable | None,
) -> list[str]:
    lines = ["| model | " + " | ".join(names) + " |", "|---" * (len(names) + 1) + "|"]
    for label, row in models.items():
        cells = [f"{v:.{digits}f}" for v in row[metric]]
        if paper:
            cells = paper.beside(label, metric, cells, digits)
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return lines


def _record_by_record(
    models: dict[str, dict], names: list[str], n_records: int, share: float
) -> list[str]:
    """The median over the ``n_records`` test records of each record's relative L2 error,
    with the ``share`` of the test response the largest record holds."""
    rows = {label: row for label, row in models.items() if row.get("record_rel_l2")}
    if not rows:
        return []
    lines = [
        "",
        "## Relative L2 error record by record (test split)",
        "",
        "The median over the test records of each record's relative L2 error: how a typical "
        f"record is predicted. The pooled error above is ruled by the strongest records: the "
        f"largest of the {n_records} holds {share:.0%} of the test response's sum of squares.",
        "",
    ]
    return lines + _markdown_table(rows, names, "record_rel_l2", 4, None)


def _physics_past_zero(models: dict[str, dict], names: list[str]) -> list[str]:
    """A warning for each physics input farther from the test records than predicting zero
    at some output (relative L2 at or above 1): a composite on it starts from a response
    worse than none there."""
    lines = []
    for label, row in models.items():
        if not ModelLabel.parse(label).is_physics:
            continue
        far = [(n, e) for n, e in zip(names, row["rel_l2"], strict=True) if e >= 1.0]
        if far:
            where = ", ".join(f"{n} ({e:.2f})" for n, e in far)
            lines.append(
                f"- **`{label}` is farther from the simulation than predicting zero** at "
                f"{where}: its z does not follow this structure on these records (see "
                "*Physics inputs* for how it was fitted); a composite on it leans on its "
                "operator there."
            )
    return [""] + lines if lines else []


def _physics_section(out: Path) -> list[str]:
    """What each fitted preprocessor shows of itself (its ``summary.md`` and figures,
    written with the first saved model that uses it), if any does."""
    shown: dict[str, Path] = {}
    for folder in sorted((out / MODELS).glob("*/preprocessor")):
        name = json.loads((folder.parent / "model.json").read_text())["preprocessor"]["name"]
        shown.setdefault(name, folder)
    lines = []
    for name, folder in shown.items():
        summary = folder / "summary.md"
        figures_of = sorted(folder.glob("*.png"))
        if not summary.exists() and not figures_of:
            continue
        lines += ["", f"### `{name}`", ""]
        if summary.exists():
            lines += summary.read_text().strip().splitlines()
        lines += [f"![{name}]({p.relative_to(out).as_posix()})" for p in figures_of]
    return ["", "## Physics inputs", *lines] if lines else []


def _acceleration_table(rows: dict[str, dict], names: list[str]) -> list[str]:
    lines = ["| model | " + " | ".join(names) + " |", "|---" * (len(names) + 1) + "|"]
    for label, row in rows.items():
        cells = [f"{e:.4f} ({r:.3g})" for e, r in zip(row["rel_l2"], row["rmse"], strict=True)]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return lines


def _named_response_lines(
    models: dict[str, dict], channels: tuple[ResponseChannel, ...]
) -> list[str]:
    """The error table of the named responses' histories, for the models that learn them."""
    learning = {k: v["responses"] for k, v in models.items() if "responses" in v}
    if not learning:
        return []
    names = [c.name for c in channels]
    units = ", ".join(f"{c.name} in {c.unit}" for c in channels)
    lines = [
        "",
        "## Named responses (test split)",
        "",
        "The models that learn the structure's named responses beside their displacements "
        f"(`formulation.responses`): relative L2 and, in parentheses, RMSE ({units}).",
        "",
        "| model | " + " | ".join(names) + " |",
        "|---" * (len(names) + 1) + "|",
    ]
    for label, row in learning.items():
        cells = [
            f"{row[n]['rel_l2'][0]:.4f} ({row[n]['rmse'][0]:.3g})" if n in row else "-"
            for n in names
        ]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return lines


def write_figures(
    evaluation: Evaluation, out: Path, *, target: SpectrumBand | None = None
) -> list[Path]:
    """The study's figures into ``out/figures`` (nothing if there is no trained model).

    ``target`` is the spectrum the ground motions were made to follow, drawn under the
    records' spectra (paper Fig. 10(b)); without it the records' own band is drawn."""
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
    labels = {label: ModelLabel.parse(label) for label in stages}
    main = next((label for label in stages if labels[label].is_composite), next(iter(stages)))
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
    refined = [label for label in stages if labels[label].refined]
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
    written.append(
        figures.motion_spectra(
            data.ag[np.concatenate([data.rows(split) for split in SPLITS])],
            data.dt,
            directory / "motion_spectra.png",
            target=target,
            title=f"ground motions: {len(data.ag)} records",
        )
    )
    if evaluation.true_edps is not None and evaluation.predicted_edps:
        written.append(
            figures.edp_scatter(
                evaluation.true_edps.pid,
                {k: v.pid for k, v in evaluation.predicted_edps.items()},
                list(evaluation.true_edps.stories.names),
                directory / "edp_scatter.png",
            )
        )
    histories = {}
    for label in stages:
        model_json = out / MODELS / label / "model.json"
        if not labels[label].refined and model_json.exists():
            histories[label] = json.loads(model_json.read_text())["history"]
    if histories:
        written.append(figures.training_curves(histories, directory / "training.png"))
    return written


def write_report(config: ExperimentConfig, evaluation: Evaluation, out: str | Path) -> Path:
    """Write ``report.md`` (and the figures, if configured) into ``out``."""
    out = Path(out)
    names = list(evaluation.data.output_names)
    models = evaluation.metrics
    paper = paper_table(config.output.paper_reference)
    written = []
    if config.output.figures:
        registry = get_registry()
        source = registry.create(
            "ground_motion", config.ground_motion.name, **config.ground_motion.params
        )
        structure = registry.create("structure", config.structure.name, **config.structure.params)
        written = write_figures(evaluation, out, target=source.target_spectrum())
        written += [
            path for path in structure.write_artifacts(out / "structure") if path.suffix == ".png"
        ]
    sizes = evaluation.data.sizes
    precision = config.training.precision
    lines = [
        "# cphysfno study report",
        "",
        f"- structure: `{config.structure.name}`, ground motion: `{config.ground_motion.name}`",
        f"- records: {sizes['train']} train / {sizes['val']} validation / {sizes['test']} test,"
        f" dt = {evaluation.data.dt} s, {evaluation.data.u.shape[1]} steps",
        *_left_out_line(evaluation.data.left_out()),
        f"- operators: {describe_operators(config)}, "
        f"{config.training.epochs} epochs, batch {config.training.batch_size}, "
        f"Adam lr {config.training.learning_rate}, x{config.training.decay_factor} every "
        f"{config.training.decay_step} epochs"
        + ("" if precision == "float32" else f", trained in {precision}"),
        "",
        "Rows `physics-*` are the physics response z alone, untrained: the number a learned "
        "model must beat.",
    ]
    if paper:
        lines.append(f"Values in parentheses are the paper's {paper.caption}.")
    figure = out / "figures" / "parameter_draws.png" if config.output.figures else None
    lines += draws_section(config.uncertain_parameters(), evaluation.data, figure)
    lines += ["", "## Relative L2 error (test split)", ""]
    lines += _markdown_table(models, names, "rel_l2", 4, paper)
    lines += _physics_past_zero(models, names)
    lines += _record_by_record(
        models, names, len(evaluation.data.rows("test")), evaluation.largest_record_share
    )
    lines += ["", "## RMSE (m, test split)", ""]
    lines += _markdown_table(models, names, "rmse", 4, paper)
    accelerating = {k: v["acceleration"] for k, v in models.items() if "acceleration" in v}
    if accelerating:
        lines += [
            "",
            "## Absolute acceleration (test split)",
            "",
            "The models that learn the outputs' absolute accelerations beside their "
            "displacements (`formulation.accelerations`): relative L2 and, in parentheses, "
            "RMSE in m/s².",
            "",
        ]
        lines += _acceleration_table(accelerating, names)
    lines += _named_response_lines(models, evaluation.data.response_channels)
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
    lines += _coverage_error_note(models)
    lines += _physics_section(out)
    lines += _edp_section(evaluation, config.structure.name)
    lines += _against_physics_section(evaluation)
    if written:
        lines += ["", "## Figures", ""]
        lines += [f"![{p.stem}]({p.relative_to(out).as_posix()})" for p in written]
    path = out / "report.md"
    path.write_text("\n".join(lines) + "\n")
    return path


def _coverage_error_note(models: dict[str, dict]) -> list[str]:
    """One sentence with the largest coverage standard error of the refined models."""
    largest = {
        level: max(
            (
                max(row[f"coverage_{level}_se"])
                for row in models.values()
                if f"coverage_{level}_se" in row
            ),
            default=None,
        )
        for level in (68, 90)
    }
    if largest[68] is None:
        return []
    return [
        "",
        "A measured coverage moves with the records drawn for the test split and for the "
        "refiner's calibration: its standard error is at most "
        f"{100 * largest[68]:.1f} points at 68 % and {100 * largest[90]:.1f} at 90 % here "
        "(per DOF: `coverage_68_se`, `coverage_90_se` in metrics.json).",
    ]


def _against_physics_section(evaluation: Evaluation) -> list[str]:
    """Which C-Phys models end worse than their physics input, and which formulation the
    validation split chose where both were trained."""
    if not any("physics_input" in row for row in evaluation.metrics.values()):
        return []
    lines = ["", "## Against the physics input", ""]
    worse = describe_shortfalls(evaluation.worse_than_physics)
    lines += [f"- {line}." for line in worse] or [
        "Every C-Phys model is at or below its physics input z on every output, on the "
        "validation and the test split."
    ]
    if evaluation.chosen_forms:
        lines += ["", "Chosen on the validation split, where both forms were trained:", ""]
        lines += [f"- {paper}: `{chosen}`" for paper, chosen in evaluation.chosen_forms.items()]
    return lines


def _edp_section(evaluation: Evaluation, structure: str) -> list[str]:
    """Each model's EDP errors on the test records and the coverage of the refined models'
    drift bounds; a one-line note for a structure without stories."""
    lines = ["", "## Engineering demand parameters (test split)", ""]
    truth = evaluation.true_edps
    if truth is None:
        return lines + [
            f"The structure `{structure}` declares no stories, so no story drifts or floor "
            "accelerations are computed."
        ]
    models = {k: v for k, v in evaluation.metrics.items() if "edp" in v}
    source = (
        "Simulated PFA is read from the structure's absolute acceleration channel; predicted PFA"
        if evaluation.data.extras.get(ACCELERATION_EXTRA) is not None
        else "PFA, simulated and predicted, is"
    )
    learned = [k for k, v in models.items() if v.get("pfa_from") == "predicted acceleration"]
    if learned:
        source += (
            " of " + ", ".join(f"`{k}`" for k in learned) + " comes from the accelerations "
            "they predict; that of the other rows is"
        )
    if not truth.stories.has_heights:
        lines += [
            f"{', '.join(truth.stories.without_height())} of `{structure}` have no height: "
            "their PID below is their peak drift in m, not a ratio (give the structure "
            "story_heights or drift_pairs for ratios, which fragility on PID and pelicun "
            "demands need).",
            "",
        ]
    median_pid = ", ".join(f"{100 * v:.3g}" for v in np.nanmedian(truth.pid, axis=0))
    median_pfa = ", ".join(f"{v:.3g}" for v in np.nanmedian(truth.pfa[:, 1:], axis=0))
    lines += [
        f"|ln(predicted / simulated)| over the {truth.n_records} test records, median "
        "(90th percentile), of each EDP at each story, floor above the ground or output; "
        f"0.10 is about a 10 % error. {source} computed from displacement by a centred "
        "second difference (`cphysfno_core.edp.compute`), which turns wiggles of e m in a "
        "predicted history into up to 4 e / dt² m/s².",
        "",
        f"Simulated median PID per story: {median_pid} %; median PFA per floor: {median_pfa} m/s².",
    ]
    rows = {**models, **evaluation.baselines}
    for key, names in edp.scored_columns(truth).items():
        what = edp.EDP_TABLE[key]
        lines += ["", f"### {what.title[0].upper()}{what.title[1:]} ({key}, {what.unit})", ""]
        lines += _edp_table(rows, key, names)
    lines += _named_response_peaks(truth)
    lines += _baseline_lines(evaluation)
    refined = {k: v for k, v in models.items() if "edp_coverage_68" in v}
    if refined:
        lines += [
            "",
            "### Drift bounds from the refined intervals",
            "",
            "Share of test records whose simulated PID (RID) lies within the bounds that the "
            "68 % and 90 % displacement intervals give by interval arithmetic on the floors' "
            "bands (`cphysfno_core.edp.band_interval`), per story:",
            "",
            "| model | PID, 68 % | PID, 90 % | RID, 68 % | RID, 90 % |",
            "|---|---|---|---|---|",
        ]
        for label, row in refined.items():
            cells = [
                ", ".join(f"{c:.2f}" for c in row[f"edp_coverage_{level}"][key])
                for key in ("PID", "RID")
                for level in (68, 90)
            ]
            lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return lines


def _baseline_lines(evaluation: Evaluation) -> list[str]:
    """What the baseline rows are, and where one beats every trained model."""
    if not evaluation.baselines:
        return []
    lines = ["", "The baselines, fitted on the simulated EDPs of the same training records:", ""]
    lines += [f"- `{label}`: {row['description']}" for label, row in evaluation.baselines.items()]
    beaten = describe_beaten(evaluation.baseline_beats)
    lines += [""] + (
        [f"**Note:** {line}." for line in beaten]
        or [
            "Every EDP a trained model predicts is predicted better, at every story and "
            "floor, by a trained model than by both baselines."
        ]
    )
    return lines


def _named_response_peaks(truth: edp.EDPs) -> list[str]:
    """The median simulated peak of each named response (EDP ``PR``)."""
    if "PR" not in truth.values:
        return []
    medians = np.nanmedian(truth["PR"], axis=0)
    cells = [
        f"{name} {value:.4g} {unit}"
        for name, value, unit in zip(truth.columns["PR"], medians, truth.units["PR"], strict=True)
    ]
    return [
        "",
        "Named responses, simulated median peak over the test records: "
        + ", ".join(cells)
        + " (predicted only by the models that learn them: `formulation.responses`).",
    ]


def _edp_table(models: dict[str, dict], key: str, names: list[str]) -> list[str]:
    lines = ["| model | " + " | ".join(names) + " |", "|---" * (len(names) + 1) + "|"]
    for label, row in models.items():
        if key not in row["edp"]:
            continue
        errors = row["edp"][key]
        cells = [f"{m:.3f} ({p:.3f})" for m, p in zip(errors["median"], errors["p90"], strict=True)]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return lines


def _left_out_line(left_out: dict[str, dict[str, int]]) -> list[str]:
    """The report's line on the records left out (collapsed, non-converged, failed), if
    there are any."""
    parts = []
    for name, what in (
        ("collapsed", "collapsed the structure"),
        ("non_converged", "did not converge below the collapse (a numerical failure)"),
        ("failed", "failed"),
    ):
        counts = left_out.get(name, {})
        if sum(counts.values()):
            labels = {"train": "train", "val": "validation", "test": "test"}
            split = " / ".join(f"{counts[s]} {labels[s]}" for s in SPLITS)
            parts.append(f"{sum(counts.values())} {what} ({split})")
    if not parts:
        return []
    return [f"- left out of training and of the error tables: {'; '.join(parts)}"]
