"""``study.md``: the study's table as mean ± std over seeds beside the paper's, interval
coverage, and the sweep figures."""

from __future__ import annotations

from pathlib import Path

from ..config.experiment import ExperimentConfig
from ..reporting import figures
from ..reporting.paper_tables import PaperTable, paper_table
from ..reporting.report import describe_operators
from .study import RUNS, TABLE
from .study_document import StudySummary


def _table(summary: StudySummary, metric: str, digits: int, paper: PaperTable | None) -> list[str]:
    names = summary.output_names
    lines = ["| model | " + " | ".join(names) + " |", "|---" * (len(names) + 1) + "|"]
    for label, row in summary.models.items():
        mean, std = getattr(row, metric).mean, getattr(row, metric).std
        cells = [f"{m:.{digits}f} ± {s:.{digits}f}" for m, s in zip(mean, std, strict=True)]
        if paper:
            cells = paper.beside(label, metric, cells, digits)
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return lines


def _coverage(summary: StudySummary) -> list[str]:
    rows = {k: v for k, v in summary.models.items() if v.coverage_68 is not None}
    if not rows:
        return []
    lines = [
        "",
        "## Interval coverage (test split, mean over seeds)",
        "",
        "| model | 68 % interval, per DOF | 90 % interval, per DOF |",
        "|---|---|---|",
    ]
    for label, row in rows.items():
        cells = [
            ", ".join(f"{c:.3f}" for c in part.mean) for part in (row.coverage_68, row.coverage_90)
        ]
        lines.append(f"| {label} | {cells[0]} | {cells[1]} |")
    return lines


def _edp_tables(summary: StudySummary) -> list[str]:
    """Median test ``|ln|`` errors of PID per story and PFA per floor, models and baselines
    (mean ± std over seeds; the baselines have no seed)."""
    rows = {
        **{k: v for k, v in summary.models.items() if v.pid_median is not None},
        **summary.baselines,
    }
    if not rows:
        return []
    lines = [
        "",
        "## EDP errors (test split)",
        "",
        "Median |ln(predicted / simulated)| over the test records; `baseline-*` rows are "
        "regressions on intensity measures fitted on the same training simulations.",
    ]
    for key, what in (
        ("pid_median", "Peak story drift ratio"),
        ("pfa_median", "Peak floor acceleration"),
        ("pfv_median", "Peak floor velocity"),
        ("pd_median", "Peak output displacement"),
    ):
        having = {label: row for label, row in rows.items() if getattr(row, key) is not None}
        if not having:
            continue
        width = len(getattr(next(iter(having.values())), key).mean)
        lines += [
            "",
            f"### {what}",
            "",
            "| model | " + " | ".join(f"{i + 1}" for i in range(width)) + " |",
        ]
        lines.append("|---" * (width + 1) + "|")
        for label, row in having.items():
            part = getattr(row, key)
            cells = [f"{m:.3f} ± {d:.3f}" for m, d in zip(part.mean, part.std, strict=True)]
            lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return lines


def _panels(n_outputs: int) -> list[int]:
    """The outputs with a panel in sweep figures: first, middle, last (paper: 1, 3, 5)."""
    return sorted({0, n_outputs // 2, n_outputs - 1})


def write_study_report(config: ExperimentConfig, summary: StudySummary, out: str | Path) -> Path:
    """Write ``out/study.md`` and ``out/figures/sweep-<name>.png``; return the report path."""
    out = Path(out)
    paper = paper_table(config.output.paper_reference)
    names = summary.output_names
    sizes = summary.sizes
    lines = [
        "# cphysfno study",
        "",
        f"- structure `{config.structure.name}`, ground motion `{config.ground_motion.name}`, "
        f"operators {describe_operators(config)}",
        f"- {len(summary.seeds)} training seeds {summary.seeds}, {summary.epochs} "
        f"epochs, {sizes['train']} / {sizes['val']} / {sizes['test']} records, "
        f"trained on {summary.device}",
        "- cells: mean ± standard deviation over seeds; `physics-*` rows are z alone",
    ]
    planned = config.study.seeds if config.study else summary.seeds
    if len(summary.seeds) < len(planned):
        lines.append(
            f"- in progress: {len(summary.seeds)} of the config's {len(planned)} seeds "
            "have finished; sweeps show the runs finished so far"
        )
    if paper:
        lines.append(f"- in parentheses: the paper's {paper.caption}")
    lines += ["", "## Relative L2 error (test split)", "", *_table(summary, "rel_l2", 4, paper)]
    if all(row.record_rel_l2 is not None for row in summary.models.values()):
        lines += [
            "",
            "## Relative L2 error record by record (test split)",
            "",
            "The median over the test records of each record's relative L2 error (the "
            "pooled error above is ruled by the strongest records).",
            "",
            *_table(summary, "record_rel_l2", 4, None),
        ]
    lines += ["", "## RMSE (m, test split)", "", *_table(summary, "rmse", 4, paper)]
    lines += _coverage(summary)
    lines += _edp_tables(summary)
    if summary.sweeps:
        directory = out / "figures"
        directory.mkdir(parents=True, exist_ok=True)
        lines += ["", "## Parametric sweeps", ""]
        for name, sweep in summary.sweeps.items():
            path = figures.sweep_boxes(
                sweep.values,
                sweep.rel_l2,
                _panels(len(names)),
                names,
                sweep.label,
                directory / f"sweep-{name}.png",
            )
            lines.append(f"![{name}](figures/{path.name})")
            if sweep.field == "training.train_records" and sweep.edp:
                curve = figures.learning_curve(
                    sweep.values, sweep.edp, directory / f"learning-curve-{name}.png"
                )
                lines += [
                    "",
                    "EDP error against the number of training simulations, for the models, "
                    "their physics inputs and the baselines fitted on the same simulations "
                    "(median |ln(predicted / simulated)| on the test records, mean over "
                    "stories or floors; bars span the seeds):",
                    "",
                    f"![learning curve](figures/{curve.name})",
                ]
    first = f"{RUNS}/{TABLE}/seed-{summary.seeds[0]}"
    lines += [
        "",
        f"Trajectories, peak scatter and distributions of seed {summary.seeds[0]}: "
        f"[{first}/report.md]({first}/report.md).",
    ]
    path = out / "study.md"
    path.write_text("\n".join(lines) + "\n")
    return path
