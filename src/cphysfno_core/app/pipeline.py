"""The stages of a study, each reading and writing files in one output folder:

``generate`` -> ``dataset.h5``; ``train`` -> ``models/<label>/``; ``evaluate`` ->
``metrics.json``, ``figures/`` and ``report.md``.
"""

from __future__ import annotations

import functools
import json
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import torch

from ..api.interfaces import Structure
from ..api.registry import get_registry
from ..config.calibration_surface import CalibrationSurface
from ..config.experiment import ExperimentConfig
from ..data.datasets import Dataset, load_dataset
from ..data.generation import generate_dataset
from ..data.layout import CONFIG, DATASET, MODELS
from ..data.record_stories import RecordStories
from ..model.composite import CompositeModel, Prediction
from ..model.labels import ModelLabel
from ..model.training import resolve_device
from ..reporting import against_physics, baselines, metrics
from ..reporting.evaluation import (
    EDPScorer,
    Evaluation,
    edp_interval_scores,
    interval_coverage_scores,
    metric_row,
)
from ..signals import Responses, Stories
from ..signals.errors import ConfigError, DatasetError
from ..signals.progress import show_progress
from .metrics_document import MetricsDocument


def model_labels(config: ExperimentConfig) -> list[str]:
    """The labels ``train`` produces for ``config``, in training order (those of
    ``output.models`` only, where it names some).

    Raises:
        ConfigError: ``output.models`` names a model the config does not train.
    """
    labels = []
    for variant in _variants(config):
        labels.append(_label(*variant))
        if variant[1] is not None and config.refiner is not None:
            labels.append(_label(*variant, refined=True))
    return labels


def _label(operator: Any, pp: Any, form: Any, refined: bool = False) -> str:
    label = ModelLabel(
        operator.name,
        pp and pp.name,
        refined=refined,
        residual=bool(form.residual),
        parameters=bool(form.parameter_input),
    )
    return str(label)


def _variants(config: ExperimentConfig) -> list[tuple[Any, Any, Any]]:
    """``(operator, preprocessor, formulation)`` of every model trained (not refined) for
    ``config`` in training order, the baseline with preprocessor None and the response
    kinds of the formulation alone; only
    those ``output.models`` names, where it names some."""
    baseline = config.formulation.physics_free().forms()
    variants: list[Any] = [(None, form) for form in baseline] if config.output.baseline else []
    variants += [(pp, form) for pp in config.preprocessor for form in config.formulation.forms()]
    every = {
        _label(operator, pp, form): (operator, pp, form)
        for operator in config.operator
        for pp, form in variants
    }
    chosen = config.output.models
    if chosen is None:
        return list(every.values())
    unknown = [label for label in chosen if label not in every]
    if unknown:
        raise ConfigError(
            f"output.models: {unknown} are not models this config trains; it trains "
            f"{list(every)} (a refined model comes with its own)"
        )
    return [variant for label, variant in every.items() if label in chosen]


def generate(config: ExperimentConfig, out: str | Path) -> Path:
    """Stage 1: simulate the dataset into ``out/dataset.h5``."""
    out = Path(out)
    show_progress(f"generating {config.data.n_records} records into {out / DATASET}")
    return generate_dataset(config, out / DATASET)


def _set_threads(config: ExperimentConfig) -> None:
    if config.training.threads is not None:
        torch.set_num_threads(config.training.threads)


def train(
    config: ExperimentConfig,
    out: str | Path,
    resume: bool = False,
    dataset: str | Path | None = None,
) -> dict[str, Path]:
    """Stage 2: for each operator, train the baseline and one C-Phys model per
    preprocessor (those of ``config.output.models`` only, where it names some); save each
    model.

    Every epoch writes ``models/<label>.checkpoint.pt``; with ``resume``, models already
    saved are kept and an interrupted one continues from its checkpoint. ``dataset``
    defaults to ``out/dataset.h5``; ``config.training.train_records`` keeps the first
    records of its training split.
    """
    out = Path(out)
    data = load_dataset(dataset or out / DATASET)
    _set_threads(config)
    registry = get_registry()
    structure = registry.create("structure", config.structure.name, **config.structure.params)
    kept = slice(config.training.train_records)
    train_gm, val_gm = data.motions("train")[kept], data.motions("val")
    train_u, val_u = data.targets("train")[kept], data.targets("val")
    train_a = val_a = None
    if config.formulation.accelerations:
        train_a, val_a = data.accelerations("train")[kept], data.accelerations("val")
    train_r = val_r = None
    if config.formulation.responses:
        train_r = {name: v[kept] for name, v in data.named_responses("train").items()}
        val_r = data.named_responses("val")
    train_p = {name: values[kept] for name, values in data.parameter_draws("train").items()}
    val_p = data.parameter_draws("val")
    saved: dict[str, Path] = {}
    fitted: dict[str, Any] = {}  # each preprocessor fitted once, shared by the models on it
    for operator, pp, form in _variants(config):
        surface = None if pp is None else data.calibration_surfaces.get(pp.name)
        model = CompositeModel(
            operator,
            structure=structure,
            preprocessor=None
            if pp is None
            else registry.create("preprocessor", pp.name, **pp.params),
            training=config.training,
            formulation=form,
            calibration_surface=None if surface is None else CalibrationSurface.from_dict(surface),
        )
        z_train = z_val = None
        if pp is not None:
            z_train, z_val = data.physics(pp.name, "train")[kept], data.physics(pp.name, "val")
        directory = out / MODELS / model.label
        checkpoint = out / MODELS / f"{model.label}.checkpoint.pt"
        if resume and (directory / "model.json").exists() and not checkpoint.exists():
            show_progress(f"{model.label} is trained already")
            model = CompositeModel.load(directory).to(config.training.device)
        else:
            precision = config.training.precision
            arithmetic = "" if precision == "float32" else f", in {precision}"
            show_progress(
                f"training {model.label} ({config.training.epochs} epochs, "
                f"{train_gm.n_records} records{arithmetic})"
            )
            if pp is not None:
                key = json.dumps([pp.name, pp.params], sort_keys=True, default=str)
                if key not in fitted:
                    fitted[key] = model.preprocessor.fit(structure)
                model.preprocessor = fitted[key]
            model.fit(
                train_gm,
                train_u,
                validation=(val_gm, val_u),
                z=z_train,
                validation_z=z_val,
                acceleration=train_a,
                validation_acceleration=val_a,
                responses=train_r,
                validation_responses=val_r,
                params=train_p,
                validation_params=val_p,
                param_units=data.parameter_units,
                checkpoint=checkpoint,
                resume=resume,
                refit_physics=False,
            )
            _replace_dir(model, directory)
            checkpoint.unlink()
        saved[model.label] = directory
        if pp is not None and config.refiner is not None:
            refiner = registry.create("refiner", config.refiner.name, **config.refiner.params)
            split = (
                (val_gm, val_u, z_val, val_p)
                if refiner.calibration_split == "validation"
                else (train_gm, train_u, z_train, train_p)
            )
            refined = model.refine(refiner, split[0], split[1], z=split[2], params=split[3])
            saved[refined.label] = _replace_dir(refined, out / MODELS / refined.label)
    return saved


def _replace_dir(model: CompositeModel, directory: Path) -> Path:
    if directory.exists():
        shutil.rmtree(directory)
    return model.save(directory)


def evaluate(
    config: ExperimentConfig, out: str | Path, dataset: str | Path | None = None
) -> Evaluation:
    """Stage 3: predict the test split with every trained model; write ``metrics.json``.

    Refined models also report the test coverage of their 68 % and 90 % intervals and its
    standard error (:func:`~cphysfno_core.reporting.metrics.coverage_standard_error` over the test
    records and the records the refiner was calibrated on).

    ``response_rms`` is the root mean square of the simulated test response per output
    (m, over records and time): how hard the records drive the structure.

    Where the structure declares its stories, every row also gets its EDP errors on the
    test records (``edp``: :func:`~cphysfno_core.edp.log_errors` of PID per story and PFA
    per floor), refined models the coverage of the drift bounds their intervals give
    (``edp_coverage_68``, ``edp_coverage_90``), and the document an ``edp`` block naming
    the stories and floors (``null`` for a structure without stories).
    """
    out = Path(out)
    data = load_dataset(dataset or out / DATASET)
    _set_threads(config)
    test_gm, test_u = data.motions("test"), data.targets("test")
    train_rows = data.rows("train")[slice(config.training.train_records)]
    calibration_records = {"validation": len(data.rows("val")), "training": len(train_rows)}
    val_gm, val_u = data.motions("val"), data.targets("val")
    results: dict[str, dict[str, Any]] = {}
    predictions: dict[str, Any] = {}
    structure = get_registry().create("structure", config.structure.name, **config.structure.params)
    stories = structure.stories() if "stories" in structure.capabilities else None
    scorer = EDPScorer(stories, data, train_rows, _record_heights(structure, stories, data))
    accelerations = functools.cache(data.accelerations)  # read once, for every model
    named_responses = functools.cache(data.named_responses)
    for pp in config.preprocessor:
        label = str(ModelLabel.physics(pp.name))
        z_test, z_val = data.physics(pp.name, "test"), data.physics(pp.name, "val")
        results[label] = {
            **metric_row(z_test, test_u),
            "validation_rel_l2": metrics.relative_l2(z_val, val_u).tolist(),
        }
        results[label].update(scorer.errors(label, z_test, z_val))
    for label in model_labels(config):
        directory = out / MODELS / label
        if not (directory / "model.json").exists():
            raise DatasetError(f"no trained model '{label}' in {out / MODELS}: run train first")
        model = CompositeModel.load(directory).to(config.training.device)
        z = None if model.preprocessor is None else data.physics(model.preprocessor.name, "test")
        stages = model.predict_stages(test_gm, z=z, params=data.parameter_draws("test"))
        predictions[label] = stages
        z_val = None if model.preprocessor is None else data.physics(model.preprocessor.name, "val")
        validation = model.predict_stages(val_gm, z=z_val, params=data.parameter_draws("val"))
        results[label] = metric_row(stages.mean, test_u)
        results[label]["validation_rel_l2"] = metrics.relative_l2(validation.mean, val_u).tolist()
        if stages.acceleration is not None:
            results[label]["acceleration"] = {
                **metric_row(stages.acceleration, accelerations("test")),
                "validation_rel_l2": metrics.relative_l2(
                    validation.acceleration, accelerations("val")
                ).tolist(),
            }
        if stages.responses:
            results[label]["responses"] = {
                name: {
                    **metric_row(values, named_responses("test")[name]),
                    "validation_rel_l2": metrics.relative_l2(
                        validation.responses[name], named_responses("val")[name]
                    ).tolist(),
                }
                for name, values in stages.responses.items()
            }
        results[label].update(
            scorer.errors(label, _predicted(stages, data.dt), _predicted(validation, data.dt))
        )
        if model.preprocessor is not None:
            results[label]["physics_input"] = str(ModelLabel.physics(model.preprocessor.name))
        if model.refiner is not None:
            calibrated_on = calibration_records[model.refiner.calibration_split]
            results[label].update(
                interval_coverage_scores(
                    model.refiner, stages.z, stages.operator_output, test_u, calibrated_on
                )
            )
            if scorer.truth is not None:
                results[label].update(
                    edp_interval_scores(
                        model.refiner,
                        stages.z,
                        stages.operator_output,
                        scorer.stories,
                        test_gm,
                        scorer.truth,
                        scorer.heights("test"),
                    )
                )
        results[label]["best_epoch"] = model.history_.best_epoch
        results[label]["train_seconds"] = model.history_.seconds
        results[label]["device"] = model.history_.device
    share = metrics.largest_record_share(test_u)
    worse = against_physics.shortfalls(results, list(data.output_names))
    for line in against_physics.describe_shortfalls(worse):
        show_progress(f"warning: {line}")
    chosen = against_physics.chosen_forms(results)
    baseline_rows = {}
    beaten = []
    if scorer.truth is not None:
        baseline_rows = scorer.baselines(float(structure.periods(1)[0]))
        beaten = baselines.beaten_surrogates(results, baseline_rows, scorer.locations())
    for line in baselines.describe_beaten(beaten):
        show_progress(f"note: {line}")
    document = {
        "models": results,
        "output_names": list(data.output_names),
        "sizes": {**data.sizes, "train": calibration_records["training"]},
        "left_out": data.left_out(),
        "response_rms": np.sqrt(np.mean(test_u**2, axis=(0, 1))).tolist(),
        "largest_record_share": share,
        "epochs": config.training.epochs,
        "precision": config.training.precision,
        "worse_than_physics": worse,
        "chosen_forms": chosen,
        "edp": scorer.describe(),
        "baselines": baseline_rows,
        "baseline_beats_surrogates": beaten,
    }
    MetricsDocument.model_validate(document).write(out / "metrics.json")
    return Evaluation(
        data,
        predictions,
        results,
        worse,
        chosen,
        scorer.truth,
        scorer.predicted,
        baseline_rows,
        beaten,
        share,
    )


def _record_heights(
    structure: Structure, stories: Stories | None, data: Dataset
) -> np.ndarray | None:
    """``[n_records, n_stories]`` the story heights (m) of every record of a family's
    dataset whose drawn parameters move them, else None."""
    if stories is None or not data.param_names:
        return None
    n = data.ag.shape[0]
    return RecordStories(structure).heights(data.draws_of(np.arange(n)), n)


def _predicted(stages: Prediction, dt: float) -> Responses:
    """A prediction's displacement with its predicted absolute accelerations and named
    responses, where the model learns them, so that its floor accelerations and the
    responses' peaks come from those."""
    return Responses(stages.mean, dt, extras=stages.extras())


def run(config: ExperimentConfig, out: str | Path, resume: bool = False) -> Evaluation:
    """All stages: generate, train, evaluate, report (``resume``: see :func:`train`).

    Raises:
        ConfigError: ``training.device`` is not on this machine (before any simulation).
    """
    from ..reporting.report import write_report

    resolve_device(config.training.device)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    (out / CONFIG).write_text(json.dumps(config.to_dict(), indent=2))
    generate(config, out)
    train(config, out, resume=resume)
    evaluation = evaluate(config, out)
    write_report(config, evaluation, out)
    return evaluation
