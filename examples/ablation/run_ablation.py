"""Train the rows of an ablation file (e.g. ``examples/ablation/bouc-wen-ablation.toml``) on one
dataset and write their validation and test errors and interval coverage as JSON, with
the row chosen by its validation error (``selection``).

Each ``[[row]]`` is the C-Phys model of the file's ``preprocessor`` with the ``base``
config's operator, training and formulation, changed by the row's ``operator``,
``training`` and ``formulation`` tables. Every trained row is refined by each
``[[refiner]]`` (fitted on the split its ``calibration_split`` names) and scored on the test
split: relative L2 and RMSE per output of the operator and of each refined mean, and the
test coverage of each refiner's 68 % and 90 % intervals with its standard error over the
test records and the records it was calibrated on. Each ``[[ensemble]]`` (a ``name`` and
the names of trained ``rows``) is scored by relative L2 and RMSE on the mean of its rows'
operator outputs. Trained models are saved under ``--out`` and the row in training is
checkpointed after every epoch, so a run that was stopped continues where it stopped; the
JSON is rewritten after every row.

    python examples/ablation/run_ablation.py examples/ablation/bouc-wen-ablation.toml \\
        --dataset runs/example1-study-cpu/dataset.h5 --out runs/example1-ablation \\
        --json results/example1-ablation.json
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import time
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from cphysfno_core import (
    CompositeModel,
    compose,
    generate_dataset,
    load_config,
    load_dataset,
    parse_config,
)
from cphysfno_core.app.pipeline import interval_coverage_scores
from cphysfno_core.model.composite import Prediction
from cphysfno_core.plugin import get_registry
from cphysfno_core.reporting import metrics

TRAINING_FIELDS = ("epochs", "learning_rate", "decay_step", "decay_factor", "seed")
"""Training settings recorded with each row."""

TARGET = 0.25
"""Test relative L2 every output of a row should reach."""


def slug(name: str) -> str:
    """A folder name for a row: lower-case words joined by hyphens."""
    return re.sub(r"[^a-z0-9]+", "-", name.lower()).strip("-")


def scores(prediction: np.ndarray, truth: np.ndarray) -> dict[str, Any]:
    """Relative L2 and RMSE (m) per output of ``[n, T, dof]`` arrays, and the mean
    relative L2 over outputs."""
    rel_l2 = metrics.relative_l2(prediction, truth)
    return {
        "rel_l2": rel_l2.tolist(),
        "rel_l2_mean": float(rel_l2.mean()),
        "rmse": metrics.rmse(prediction, truth).tolist(),
    }


def refined_scores(
    model: CompositeModel,
    refiner: dict[str, Any],
    splits: dict[str, tuple[Any, np.ndarray, np.ndarray]],
    test: Prediction,
    truth: np.ndarray,
) -> dict[str, Any]:
    """Fit ``refiner`` (a ``{"name", ...params}`` table) on a copy of ``model`` and score
    its mean and intervals on the test split, whose operator stage is ``test``."""
    spec = {k: v for k, v in refiner.items() if k != "label"}
    instance = get_registry().create("refiner", spec.pop("name"), **spec)
    motions, u, z = splits["val" if instance.calibration_split == "validation" else "train"]
    refined = model.refine(instance, motions, u, z=z)
    mean, _ = refined.refiner.predict(test.z, test.operator_output)
    row = scores(mean, truth)
    row.update(
        interval_coverage_scores(refined.refiner, test.z, test.operator_output, truth, len(u))
    )
    row["calibration_split"] = refined.refiner.calibration_split
    return row


def run(ablation_path: Path, dataset_path: Path, out: Path, json_path: Path) -> dict[str, Any]:
    """Train, refine and score every row of ``ablation_path``; return the JSON document."""
    ablation = tomllib.loads(ablation_path.read_text())
    base_path = ablation_path.parent / ablation["base"]
    config = load_config(base_path)
    generate_dataset(config, dataset_path)  # checks that an existing file is this dataset
    data = load_dataset(dataset_path)
    preprocessor = next(p for p in config.preprocessor if p.name == ablation["preprocessor"])
    seed = int(ablation["seed"])
    training = config.training.model_copy(update={"seed": seed})
    splits = {
        split: (data.motions(split), data.targets(split), data.physics(preprocessor.name, split))
        for split in ("train", "val", "test")
    }
    test_motions, test_u, test_z = splits["test"]
    val_motions, val_u, val_z = splits["val"]
    document: dict[str, Any] = {
        "ablation": str(ablation_path),
        "base": str(base_path),
        "dataset": str(dataset_path),
        "preprocessor": preprocessor.name,
        "seed": seed,
        "epochs": training.epochs,
        "sizes": {split: int(splits[split][1].shape[0]) for split in splits},
        "output_names": list(data.output_names),
        "target": f"relative L2 <= {TARGET} on every output",
        "physics": scores(test_z, test_u),
        "physics_validation": scores(val_z, val_u),
        "rows": {},
    }
    members = {name for ensemble in ablation.get("ensemble", []) for name in ensemble["rows"]}
    unknown = members - {row["name"] for row in ablation["row"]}
    if unknown:
        raise SystemExit(f"ensemble rows not in the file: {', '.join(sorted(unknown))}")
    outputs = {}
    for row in ablation["row"]:
        operator_spec = {**config.operator[0].to_dict(), **row.get("operator", {})}
        formulation = {**config.formulation.model_dump(), **row.get("formulation", {})}
        row_training = {**training.model_dump(), **row.get("training", {})}
        folder = out / slug(row["name"])
        checkpoint = out / f"{slug(row['name'])}.checkpoint.pt"
        if (folder / "model.json").exists():
            model = CompositeModel.load(folder)
        else:
            print(f"training '{row['name']}'", file=sys.stderr, flush=True)
            name = operator_spec.pop("name")
            model = compose(
                operator=(name, operator_spec),
                structure=(config.structure.name, config.structure.params),
                preprocessor=(preprocessor.name, preprocessor.params),
                training=row_training,
                formulation=formulation,
            )
            model.fit(
                *splits["train"][:2],
                validation=splits["val"][:2],
                z=splits["train"][2],
                validation_z=splits["val"][2],
                checkpoint=checkpoint,
                resume=True,
            )
            model.save(folder)
            checkpoint.unlink()
        tic = time.perf_counter()
        test = model.predict_stages(test_motions, z=test_z)
        validation = model.predict_stages(val_motions, z=val_z).operator_output
        if row["name"] in members:
            outputs[row["name"]] = (validation, test.operator_output)
        result = {
            "operator": {"name": model.operator_spec.name, **model.operator_spec.params},
            "formulation": model.formulation.model_dump(),
            "training": {key: getattr(model.training, key) for key in TRAINING_FIELDS},
            **scores(test.operator_output, test_u),
            "validation": scores(validation, val_u),
            "best_epoch": model.history_.best_epoch,
            "train_seconds": round(model.history_.seconds, 1),
            "refined": {
                refiner["label"]: refined_scores(model, refiner, splits, test, test_u)
                for refiner in ablation["refiner"]
            },
        }
        result["meets_target"] = max(result["rel_l2"]) <= TARGET
        result["evaluate_seconds"] = round(time.perf_counter() - tic, 1)
        document["rows"][row["name"]] = result
        json_path.parent.mkdir(parents=True, exist_ok=True)
        json_path.write_text(json.dumps(document, indent=2) + "\n")
        print(f"{row['name']}: rel L2 {np.round(result['rel_l2'], 3)}", file=sys.stderr)
    document["ensembles"] = {
        ensemble["name"]: {
            "rows": list(ensemble["rows"]),
            **scores(np.mean([outputs[name][1] for name in ensemble["rows"]], axis=0), test_u),
            "validation": scores(
                np.mean([outputs[name][0] for name in ensemble["rows"]], axis=0), val_u
            ),
        }
        for ensemble in ablation.get("ensemble", [])
    }
    for name, result in document["ensembles"].items():
        result["meets_target"] = max(result["rel_l2"]) <= TARGET
        print(f"{name}: rel L2 {np.round(result['rel_l2'], 3)}", file=sys.stderr)
    document["selection"] = select_on_validation(document)
    json_path.write_text(json.dumps(document, indent=2) + "\n")
    return document


def select_on_validation(document: dict[str, Any]) -> dict[str, Any]:
    """The single-model row with the lowest validation relative L2 (mean over outputs),
    its configuration (the row's name without a trailing ", seed N": a study trains it
    for its own seeds), and its test error, read once after the choice."""
    rows = document["rows"]
    chosen = min(rows, key=lambda name: rows[name]["validation"]["rel_l2_mean"])
    return {
        "selected_on": "validation",
        "criterion": "mean over outputs of the validation relative L2, single models only",
        "row": chosen,
        "configuration": re.sub(r", seed \d+$", "", chosen),
        "validation_rel_l2": rows[chosen]["validation"]["rel_l2"],
        "test_rel_l2": rows[chosen]["rel_l2"],
    }


def chosen_study_config(ablation_path: Path, document: dict[str, Any], seeds: list[int]) -> str:
    """The TOML of a study of the row ``document["selection"]`` chose: the base config
    with the ablation's preprocessor alone, no baseline, the row's operator, formulation
    and training, trained for each of ``seeds`` (``cphysfno study`` runs it)."""
    ablation = tomllib.loads(ablation_path.read_text())
    chosen = document["selection"]["configuration"]
    row = next(r for r in ablation["row"] if r["name"] == chosen)
    config = load_config(ablation_path.parent / ablation["base"]).to_dict()
    config["preprocessor"] = [
        p for p in config["preprocessor"] if p["name"] == ablation["preprocessor"]
    ]
    config["operator"] = {**config["operator"], **row.get("operator", {})}
    config["formulation"] = {**config["formulation"], **row.get("formulation", {})}
    config["training"] = {**config["training"], **row.get("training", {})}
    config["training"].pop("seed", None)
    config["output"]["baseline"] = False
    config["study"] = {"seeds": seeds}
    header = (
        f"# The row of {ablation_path.name} chosen by its validation error: {chosen}\n"
        f"# (written by run_ablation.py --chosen-study; train it with cphysfno study)\n\n"
    )
    return header + parse_config(config).to_toml()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("ablation", type=Path, help="ablation TOML file")
    parser.add_argument("--dataset", type=Path, required=True, help="dataset.h5 of the base")
    parser.add_argument("--out", type=Path, required=True, help="folder of the trained rows")
    parser.add_argument("--json", type=Path, required=True, help="results file to write")
    parser.add_argument(
        "--chosen-study",
        type=Path,
        help="also write the study config (TOML) of the row chosen on validation here",
    )
    parser.add_argument(
        "--seeds", type=int, default=10, help="training seeds 0..N-1 of that study (10)"
    )
    args = parser.parse_args(argv)
    document = run(args.ablation, args.dataset, args.out, args.json)
    if args.chosen_study is not None:
        text = chosen_study_config(args.ablation, document, list(range(args.seeds)))
        args.chosen_study.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
