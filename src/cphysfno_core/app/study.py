"""Repeated runs of one experiment: seeds for the main table, and parametric sweeps.

``cphysfno study CONFIG --out DIR`` generates one dataset, then trains and evaluates every
run into its own folder::

    DIR/dataset.h5
    DIR/runs/table/seed-<s>/             every model of the config, training seed s
    DIR/runs/<sweep>/<value>/seed-<s>/   the baseline and the sweep's C-Phys variants
    DIR/study.json                       mean and std over seeds (see :func:`summarise`)

``--jobs N`` trains N runs at a time in worker processes, each logging to its folder's
``study.log``.

A run whose ``metrics.json`` holds every model it trains is done; an interrupted run
continues from its checkpoints, so the same command resumes a study where it stopped, and
shares of a study by model (``output.models``) can run one after another in one folder,
each training its own models on the dataset generated once. A sweep value that
leaves the models as the table trains them (the table's own width, all training records)
is not trained again: its run copies the table run's models of the same seed.
"""

from __future__ import annotations

import contextlib
import json
import shutil
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch

from ..config.allocator import tune_memory
from ..config.experiment import DataConfig, ExperimentConfig, parse_config
from ..data.executors import run_tasks
from ..data.layout import CONFIG, DATASET, MODELS, STUDY_SUMMARY
from ..model.training import resolve_device
from ..signals.cpus import usable_cpus
from ..signals.errors import ConfigError
from ..signals.progress import show_progress
from . import pipeline
from .metrics_document import BaselineRow, MetricsDocument, ModelRow
from .study_document import StudySummary

RUNS = "runs"
TABLE = "table"
LOG = "study.log"


@dataclass(frozen=True)
class Run:
    """One training run of a study: its configuration and folder, and the table run whose
    models it shares when they would train identically (``None``: it trains its own)."""

    group: str
    value: Any
    seed: int
    config: ExperimentConfig
    folder: Path
    shares: Path | None = None


def _set_field(document: dict[str, Any], path: str, value: Any) -> None:
    """Set ``section.field``; in an array of tables (several operators), in every table."""
    section, field = path.split(".")
    tables = document.get(section)
    tables = [tables] if isinstance(tables, dict) else tables
    if not tables or not all(isinstance(t, dict) for t in tables):
        raise ConfigError(f"study sweep field '{path}': the config has no [{section}] section")
    for table in tables:
        table[field] = value


def _trains_alike(run: ExperimentConfig, table: ExperimentConfig) -> bool:
    """Whether every model ``run`` trains is trained by ``table`` with the same settings
    (a model's training depends on its operator, training settings, formulation and
    preprocessor only; ``train_records`` unset means the whole training split)."""

    def training(config: ExperimentConfig):
        records = config.training.train_records or config.data.n_train
        return config.training.model_copy(update={"train_records": records})

    return (
        run.operator == table.operator
        and training(run) == training(table)
        and run.formulation == table.formulation
        and run.output.baseline <= table.output.baseline
        and all(p in table.preprocessor for p in run.preprocessor)
    )


def with_seeds(config: ExperimentConfig, seeds: list[int]) -> ExperimentConfig:
    """``config`` whose study trains ``seeds`` instead of its own (each seed's runs are the
    same either way, so a study split between machines combines exactly).

    Raises:
        ConfigError: ``config`` has no ``[study]`` section, or ``seeds`` is empty or repeats
            a seed.
    """
    if config.study is None:
        raise ConfigError("the config has no [study] section: add one (see examples/)")
    if not seeds or len(set(seeds)) != len(seeds):
        raise ConfigError(f"seeds must be distinct and at least one, got {seeds}")
    study = config.study.model_copy(update={"seeds": list(seeds)})
    return config.model_copy(update={"study": study})


def plan(config: ExperimentConfig, out: Path) -> list[Run]:
    """Every run of the study of ``config``, table runs first.

    Raises:
        ConfigError: ``config`` has no ``[study]`` section, a sweep sets a field that
            does not validate, or ``output.models`` chooses models of a study with sweeps.
    """
    if config.study is None:
        raise ConfigError("the config has no [study] section: add one (see examples/)")
    study = config.study
    if config.output.models is not None and study.sweeps:
        raise ConfigError(
            "output.models trains a share of a study's table; this study also has sweeps, "
            "which train every model: run the share without the sweeps, or every model"
        )
    runs = []
    base = config.to_dict()
    base.pop("study")
    tables = {}
    for seed in study.seeds:
        document = json.loads(json.dumps(base))
        document["training"]["seed"] = seed
        tables[seed] = Run(
            TABLE, None, seed, parse_config(document), out / RUNS / TABLE / f"seed-{seed}"
        )
    runs.extend(tables.values())
    chosen = study.sweep_preprocessors
    swept = [p for p in base["preprocessor"] if chosen is None or p["name"] in chosen]
    for name, sweep in study.sweeps.items():
        if sweep.field.split(".")[0] in ("data", "structure", "ground_motion", "preprocessor"):
            raise ConfigError(
                f"study sweep '{name}' sets {sweep.field}: the runs share one dataset, so a "
                "sweep may change training, operator or refiner fields only (for the "
                "training size, sweep training.train_records)"
            )
        for value in sweep.values:
            for seed in study.seeds:
                document = json.loads(json.dumps(base))
                document["preprocessor"] = swept
                document.pop("refiner", None)
                document["training"]["seed"] = seed
                _set_field(document, sweep.field, value)
                try:
                    run_config = parse_config(document)
                except ConfigError as error:
                    raise ConfigError(f"study sweep '{name}' = {value!r}: {error}") from None
                folder = out / RUNS / name / str(value) / f"seed-{seed}"
                table = tables[seed]
                shares = table.folder if _trains_alike(run_config, table.config) else None
                runs.append(Run(name, value, seed, run_config, folder, shares))
    return runs


def run_study(config: ExperimentConfig, out: str | Path, jobs: int = 1) -> StudySummary:
    """Generate the dataset, run every run not yet done, write and return the summary.

    Every run shares ``out/dataset.h5`` (a sweep may not change the data).

    Args:
        jobs: runs trained at a time. With more than one, each run trains in a worker
            process (on a GPU they share it) and writes its progress to
            ``<run folder>/study.log``; the table's runs finish before the sweeps' start.
            The cores are shared among the runs of a phase that train side by side (all
            of them to one run when only one is left to train) unless
            ``training.threads`` says otherwise.
    """
    if jobs < 1:
        raise ConfigError(f"jobs = {jobs}: at least one run must train at a time")
    resolve_device(config.training.device)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    (out / CONFIG).write_text(json.dumps(config.to_dict(), indent=2))
    runs = plan(config, out)
    pipeline.generate(config, out)
    dataset = out / DATASET
    report_run = runs[0].folder
    todo = [(n, run) for n, run in enumerate(runs, start=1) if not _finished(run)]
    remaining = TimeLeft(len(todo))
    if jobs == 1:
        for number, run in todo:
            show_progress(f"study run {number}/{len(runs)}: {_describe(run)}")
            execute_run(run, dataset, report=run.folder == report_run)
            show_progress(f"study run {number}/{len(runs)} finished{remaining.one_done()}")
    else:
        show_progress(f"{len(todo)} of {len(runs)} study runs left")
        for phase in (TABLE, None):
            batch = [(n, r) for n, r in todo if (r.group == TABLE) == (phase == TABLE)]
            if not batch:
                continue
            workers = min(jobs, len(batch))
            threads = threads_per_run(workers)
            show_progress(
                f"{len(batch)} {'table' if phase == TABLE else 'sweep'} run"
                f"{'s' if len(batch) > 1 else ''}, {workers} at a time with {threads} "
                f"thread{'s' if threads > 1 else ''} each; each writes its progress to "
                f"<run folder>/{LOG}"
            )

            def finished(key: int, seconds: float, batch=batch) -> None:
                number, run = batch[key]
                show_progress(
                    f"study run {number}/{len(runs)} finished in {seconds:.0f} s: "
                    f"{_describe(run)}{remaining.one_done()}"
                )

            run_tasks(
                _execute_logged,
                range(len(batch)),
                lambda key, batch=batch, threads=threads: (
                    batch[key][1],
                    dataset,
                    batch[key][1].folder == report_run,
                    threads,
                ),
                DataConfig(executor="processes", workers=workers),
                finished,
            )
    summary = summarise(config, runs)
    summary.write(out / STUDY_SUMMARY)
    return summary


def threads_per_run(workers: int, cores: int | None = None) -> int:
    """Torch threads for each of ``workers`` runs training side by side: the cores
    (``cores``, default those this process may run on) shared out, at least one each."""
    return max(1, (cores or usable_cpus()) // workers)


class TimeLeft:
    """The wall time a study has left, from the pace of its runs finished so far."""

    def __init__(self, runs: int, clock: Callable[[], float] = time.perf_counter) -> None:
        self.runs, self.done, self.clock = runs, 0, clock
        self.started = clock()

    def one_done(self) -> str:
        """Count one run as finished; ``"; about N min left"`` while runs remain, else ``""``."""
        self.done += 1
        left = self.runs - self.done
        if left <= 0:
            return ""
        seconds = (self.clock() - self.started) / self.done * left
        runs = f"{left} run" + ("s" if left > 1 else "")
        return f"; about {seconds / 60:.0f} min left for the study ({runs})"


def _finished(run: Run) -> bool:
    """Whether ``run`` is evaluated for every model its config trains: a folder evaluated
    for other models of the same seed (an earlier share of the study) is not finished."""
    metrics = run.folder / "metrics.json"
    if not metrics.exists():
        return False
    evaluated = MetricsDocument.read(metrics).models
    return all(label in evaluated for label in pipeline.model_labels(run.config))


def _describe(run: Run) -> str:
    value = "" if run.value is None else f" = {run.value}"
    return f"{run.group}{value}, seed {run.seed}"


def execute_run(run: Run, dataset: Path, report: bool = False) -> None:
    """Train (resuming) and evaluate one run in this process; with ``report``, also write
    its ``report.md`` (the study's first table run)."""
    run.folder.mkdir(parents=True, exist_ok=True)
    if run.shares is not None:
        _copy_models(run)
    pipeline.train(run.config, run.folder, resume=True, dataset=dataset)
    evaluation = pipeline.evaluate(run.config, run.folder, dataset=dataset)
    if report:
        from ..reporting.report import write_report

        write_report(run.config, evaluation, run.folder)


def _execute_logged(run: Run, dataset: Path, report: bool, threads: int) -> float:
    """:func:`execute_run` in a worker process, its progress appended to the run's log;
    returns the seconds it took."""
    started = time.perf_counter()
    tune_memory()
    if run.config.training.threads is None:
        torch.set_num_threads(threads)
    run.folder.mkdir(parents=True, exist_ok=True)
    with (
        open(run.folder / LOG, "a") as log,
        contextlib.redirect_stderr(log),
        contextlib.redirect_stdout(log),
    ):
        execute_run(run, dataset, report)
    return time.perf_counter() - started


def _copy_models(run: Run) -> None:
    """Copy into ``run.folder`` the models its table run has finished training; any it
    has not, ``run`` trains itself."""
    models = run.shares / MODELS
    for label in pipeline.model_labels(run.config):
        source, target = models / label, run.folder / MODELS / label
        finished = (source / "model.json").exists()
        if finished and not (models / f"{label}.checkpoint.pt").exists() and not target.exists():
            show_progress(f"{label}: the same training as {run.shares.name} of the table, copied")
            shutil.copytree(source, target)


def trained_on(documents: list[MetricsDocument]) -> str:
    """Where the models of ``metrics.json`` documents trained, each place once (runs that
    predate the record count as unknown)."""
    places = [
        row.device or "unknown"
        for document in documents
        for row in document.models.values()
        if row.train_seconds is not None
    ]
    return ", ".join(dict.fromkeys(places)) or "unknown"


def _mean_std(rows: list[list[float]]) -> dict[str, list[float]]:
    values = np.asarray(rows, dtype=np.float64)
    return {"mean": values.mean(axis=0).tolist(), "std": values.std(axis=0).tolist()}


EDP_SUMMARY = {"pid_median": "PID", "pfa_median": "PFA", "pfv_median": "PFV", "pd_median": "PD"}
"""Keys of a summary row -> the EDP whose median test error (per story, floor or output)
they hold, as mean and std over seeds."""


def _edp_summary(rows: list[ModelRow] | list[BaselineRow]) -> dict[str, Any]:
    """The :data:`EDP_SUMMARY` entries over the rows of one model that every row has (``{}``
    without EDPs)."""
    if any(row.edp is None for row in rows):
        return {}
    return {
        key: _mean_std([row.edp[edp_name]["median"] for row in rows])
        for key, edp_name in EDP_SUMMARY.items()
        if all(edp_name in row.edp for row in rows)
    }


def _sweep_edps(rows: list[tuple[Any, MetricsDocument]]) -> dict[str, dict[str, list]]:
    """label -> str(value) -> per-seed ``{"PID": [...], "PFA": [...]}`` median test errors of
    the models and baselines of the ``(value, metrics.json)`` pairs that have EDPs."""
    found: dict[str, dict[str, list]] = {}
    for value, document in rows:
        for label, row in {**document.models, **document.baselines}.items():
            if row.edp is not None:
                medians = {
                    key: row.edp[key]["median"] for key in EDP_SUMMARY.values() if key in row.edp
                }
                found.setdefault(label, {}).setdefault(str(value), []).append(medians)
    return found


def _summary(
    documents: list[MetricsDocument], seeds: list[int], epochs: int, sweeps: dict[str, Any]
) -> StudySummary:
    """The ``study.json`` document: per label (those of the first run) and metric, mean and
    std over the ``metrics.json`` documents of the table's runs, with ``sweeps`` beside."""
    models: dict[str, dict[str, Any]] = {}
    for label in documents[0].models:
        rows = [document.models[label] for document in documents]
        models[label] = {
            key: _mean_std([getattr(row, key) for row in rows])
            for key in ("rel_l2", "rmse", "record_rel_l2", "coverage_68", "coverage_90")
            if all(getattr(row, key) is not None for row in rows)
        }
        models[label].update(_edp_summary(rows))
    first = documents[0]
    return StudySummary.model_validate(
        {
            "models": models,
            "baselines": {label: _edp_summary([row]) for label, row in first.baselines.items()},
            "sweeps": sweeps,
            "seeds": seeds,
            "epochs": epochs,
            "sizes": first.sizes,
            "output_names": first.output_names,
            "response_rms": first.response_rms,
            "device": trained_on(documents),
        }
    )


def summarise_runs(folders: list[Path]) -> StudySummary:
    """The summary :func:`summarise` writes, from finished ``cphysfno run`` folders (e.g.
    one per training seed, made by hand or on several machines).

    Args:
        folders: run folders, each with ``metrics.json`` and ``config.json``; their split
            sizes and outputs must agree.

    Returns:
        The schema of ``study.json`` without sweeps; ``seeds`` are the runs' training seeds
        and ``device`` the machine summarising (the runs do not record theirs).

    Raises:
        ConfigError: a folder is not a finished run, or the runs do not match.
    """
    documents, configs = [], []
    for folder in folders:
        metrics, config = Path(folder) / "metrics.json", Path(folder) / "config.json"
        if not (metrics.is_file() and config.is_file()):
            raise ConfigError(
                f"{folder} is not a finished run: it needs metrics.json and config.json"
            )
        documents.append(MetricsDocument.read(metrics))
        configs.append(parse_config(json.loads(config.read_text())))
    for folder, document in zip(folders[1:], documents[1:], strict=True):
        for key in ("sizes", "output_names"):
            ours, theirs = getattr(document, key), getattr(documents[0], key)
            if ours != theirs:
                raise ConfigError(f"{folder} has {key} {ours}, {folders[0]} has {theirs}")
    seeds = [config.training.seed for config in configs]
    return _summary(documents, seeds, configs[0].training.epochs, sweeps={})


def summarise(config: ExperimentConfig, runs: list[Run]) -> StudySummary:
    """The study's results from the runs' ``metrics.json`` files.

    Args:
        runs: finished runs (every one with ``metrics.json``), at least one of the table.

    Returns:
        ``models``: label -> ``{"rel_l2": {"mean", "std"}, "rmse": {...}, "record_rel_l2":
        {...}}`` per DOF over the table's seeds (standard deviation with ``ddof = 0``), plus
        ``coverage_68`` and ``coverage_90`` likewise for refined models, and the
        :data:`EDP_SUMMARY` entries (``pid_median``, ``pfa_median``, ``pfv_median``,
        ``pd_median``: the median test ``|ln|`` error per story / floor / output) where the
        structure has stories; ``baselines``: label -> those for each baseline (fitted on
        the training data, the same for every seed); ``sweeps``: name -> field, values,
        label -> value -> per-seed ``rel_l2`` per DOF, and ``edp``: label (models and
        baselines) -> value -> per-seed ``{"PID", "PFA", "PFV", "PD"}`` medians (values with
        a finished run only); and the table runs' seeds, epochs, split sizes, output names
        and device.
    """
    documents = {run.folder: MetricsDocument.read(run.folder / "metrics.json") for run in runs}
    table = [run for run in runs if run.group == TABLE]
    sweeps: dict[str, Any] = {}
    for name, sweep in config.study.sweeps.items():
        done = [r for r in runs if r.group == name]
        if not done:
            continue
        by_label: dict[str, dict[str, list]] = {}
        for run in done:
            for label, row in documents[run.folder].models.items():
                by_label.setdefault(label, {}).setdefault(str(run.value), []).append(row.rel_l2)
        sweeps[name] = {
            "field": sweep.field,
            "label": sweep.label or sweep.field,
            "values": [v for v in sweep.values if any(r.value == v for r in done)],
            "rel_l2": by_label,
            "edp": _sweep_edps([(run.value, documents[run.folder]) for run in done]),
        }
    return _summary(
        [documents[run.folder] for run in table],
        [run.seed for run in table],
        config.training.epochs,
        sweeps,
    )


def summarise_finished(config: ExperimentConfig, out: str | Path) -> StudySummary:
    """The summary of the runs of a study in ``out`` finished so far (a study still running,
    or stopped); writes nothing.

    Raises:
        ConfigError: no table run has finished yet.
    """
    runs = [run for run in plan(config, Path(out)) if _finished(run)]
    if not any(run.group == TABLE for run in runs):
        raise ConfigError(f"no table run of the study in {out} has finished yet")
    return summarise(config, runs)
