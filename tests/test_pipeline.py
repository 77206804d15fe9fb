import json
import os
from pathlib import Path

import numpy as np
import pytest

import cphysfno_core as cp
from cphysfno_core.app import pipeline
from cphysfno_core.app.cli import main
from cphysfno_core.config import precision
from cphysfno_core.data import generation
from cphysfno_core.data.simulation import simulate_chunk

CONFIG = """
[structure]
name = "toy-structure"
cubic = 40.0

[ground_motion]
name = "toy-source"
n_steps = 100
scale = 0.5

[[preprocessor]]
name = "toy-linear"

[operator]
name = "toy-operator"
width = 6

[refiner]
name = "toy-refiner"

[data]
n_train = 12
n_val = 4
n_test = 6
chunk_size = 5
executor = "{executor}"
workers = 2

[training]
epochs = 3
batch_size = 4
"""


def _config(tmp_path: Path, executor: str = "serial") -> Path:
    path = tmp_path / f"toy-{executor}.toml"
    path.write_text(CONFIG.format(executor=executor))
    return path


def test_run_writes_metrics_report_and_figures(toy_registry, tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["run", str(_config(tmp_path)), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "relative L2 error per output" in printed and "c-phystoy-operator-toy-linear" in printed
    document = json.loads((out / "metrics.json").read_text())
    assert document["precision"] == "float32"
    labels = set(document["models"])
    assert labels == {
        "toy-operator",
        "c-phystoy-operator-toy-linear",
        "refined-c-phystoy-operator-toy-linear",
        "physics-toy-linear",
    }
    for row in document["models"].values():
        assert len(row["rmse"]) == len(row["rel_l2"]) == len(row["record_rel_l2"]) == 2
    assert 0.0 < document["largest_record_share"] < 1.0
    refined = document["models"]["refined-c-phystoy-operator-toy-linear"]
    assert len(refined["coverage_68"]) == len(refined["coverage_90"]) == 2
    assert all(a <= b for a, b in zip(refined["coverage_68"], refined["coverage_90"], strict=True))
    assert all(0.0 < se < 0.5 for se in refined["coverage_68_se"] + refined["coverage_90_se"])
    report = (out / "report.md").read_text()
    largest = 100 * max(refined["coverage_68_se"])
    assert f"its standard error is at most {largest:.1f} points at 68 %" in report
    assert "| physics-toy-linear |" in report
    share = document["largest_record_share"]
    assert f"holds {share:.0%} of the test response's sum of squares" in report
    for figure in (
        "trajectories",
        "top_story_models",
        "refined_band",
        "peaks",
        "spectra",
        "training",
        "motion_spectra",
    ):
        assert (out / "figures" / f"{figure}.png").stat().st_size > 1000
        assert f"figures/{figure}.png" in report


def test_the_models_chosen_are_the_only_ones_trained_and_evaluated(toy_registry, tmp_path):
    out, config = tmp_path / "run", str(_config(tmp_path))
    composite = "c-phystoy-operator-toy-linear"
    assert main(["run", config, "--out", str(out), "--models", composite]) == 0
    assert sorted(p.name for p in (out / "models").iterdir()) == [composite, f"refined-{composite}"]
    document = json.loads((out / "metrics.json").read_text())
    assert set(document["models"]) == {composite, f"refined-{composite}", "physics-toy-linear"}
    assert json.loads((out / "config.json").read_text())["output"]["models"] == [composite]
    assert main(["evaluate", config, "--out", str(out)]) == 2  # every model: the baseline too
    assert main(["evaluate", config, "--out", str(out), "--models", composite]) == 0
    with pytest.raises(cp.ConfigError, match=r"\['refined-c-phystoy-operator-toy-linear'\] are"):
        pipeline.model_labels(
            cp.parse_config(
                {**cp.load_config(config).to_dict(), "output": {"models": [f"refined-{composite}"]}}
            )
        )


def test_every_operator_of_the_config_gets_every_model(toy_registry, tmp_path):
    text = CONFIG.format(executor="serial").replace(
        '[operator]\nname = "toy-operator"\nwidth = 6\n',
        '[[operator]]\nname = "toy-operator"\nwidth = 6\n\n'
        '[[operator]]\nname = "other-toy-operator"\nwidth = 3\n',
    )
    path = tmp_path / "two.toml"
    path.write_text(text)
    config = cp.load_config(path)
    expected = [
        "toy-operator",
        "c-phystoy-operator-toy-linear",
        "refined-c-phystoy-operator-toy-linear",
        "other-toy-operator",
        "c-physother-toy-operator-toy-linear",
        "refined-c-physother-toy-operator-toy-linear",
    ]
    assert pipeline.model_labels(config) == expected
    evaluation = pipeline.run(config, tmp_path / "out")
    assert set(evaluation.metrics) == {*expected, "physics-toy-linear"}
    saved = json.loads((tmp_path / "out/models/other-toy-operator/model.json").read_text())
    assert saved["operator"]["width"] == 3
    assert "`other-toy-operator` {'width': 3}" in (tmp_path / "out/report.md").read_text()
    assert cp.parse_config(config.to_dict()).to_dict() == config.to_dict()
    duplicate = {**config.to_dict(), "operator": [{"name": "toy-operator"}] * 2}
    with pytest.raises(cp.ConfigError, match="each operator may appear once"):
        cp.parse_config(duplicate)


def test_physics_row_is_the_preprocessor_error(toy_registry, tmp_path):
    out = tmp_path / "run"
    config = cp.load_config(_config(tmp_path))
    from cphysfno_core.app import pipeline

    pipeline.generate(config, out)
    data = cp.load_dataset(out / "dataset.h5")
    z = data.physics("toy-linear", "test")
    u = data.targets("test")
    expected = np.sqrt(((z - u) ** 2).sum(axis=(0, 1)) / (u**2).sum(axis=(0, 1)))
    pipeline.train(config, out)
    metrics = pipeline.evaluate(config, out).metrics
    np.testing.assert_allclose(metrics["physics-toy-linear"]["rel_l2"], expected)


def test_a_bfloat16_training_says_so_and_records_it(toy_registry, tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(precision, "native_bfloat16", lambda device: True)
    config = tmp_path / "toy-bfloat16.toml"
    config.write_text(CONFIG.format(executor="serial") + 'precision = "bfloat16"\n')
    out = tmp_path / "run"
    assert main(["run", str(config), "--out", str(out)]) == 0
    said = capsys.readouterr().err
    assert "training c-phystoy-operator-toy-linear (3 epochs, 12 records, in bfloat16)" in said
    assert json.loads((out / "metrics.json").read_text())["precision"] == "bfloat16"
    assert "epochs, trained in bfloat16" in (out / "report.md").read_text()


def test_stages_run_separately_and_evaluate_needs_training(toy_registry, tmp_path, capsys):
    out = tmp_path / "staged"
    config = str(_config(tmp_path))
    assert main(["generate", config, "--out", str(out)]) == 0
    assert main(["evaluate", config, "--out", str(out)]) == 2
    assert "no trained model" in capsys.readouterr().err
    assert main(["train", config, "--out", str(out)]) == 0
    assert main(["evaluate", config, "--out", str(out)]) == 0
    assert (out / "report.md").exists()


def test_generation_resumes_and_an_incomplete_dataset_says_so(toy_registry, tmp_path, monkeypatch):
    config = cp.load_config(_config(tmp_path))
    cp.generate_dataset(config, tmp_path / "reference.h5", progress=False)
    reference = cp.load_dataset(tmp_path / "reference.h5")
    calls = []

    def killed_after_two_chunks(*arguments):
        if len(calls) == 2:
            raise KeyboardInterrupt
        calls.append(arguments)
        return simulate_chunk(*arguments)

    path = tmp_path / "data.h5"
    monkeypatch.setattr(generation, "simulate_chunk", killed_after_two_chunks)
    with pytest.raises(KeyboardInterrupt):
        cp.generate_dataset(config, path, progress=False)
    with pytest.raises(cp.DatasetError, match="incomplete.*run the same"):
        cp.load_dataset(path)
    calls.clear()
    monkeypatch.setattr(
        generation, "simulate_chunk", lambda *a: calls.append(a) or simulate_chunk(*a)
    )
    cp.generate_dataset(config, path, progress=False)
    assert len(calls) == 3  # 5 chunks of 5 records: only the 3 missing ones are simulated
    resumed = cp.load_dataset(path)
    np.testing.assert_array_equal(resumed.u, reference.u)
    np.testing.assert_array_equal(resumed.z["toy-linear"], reference.z["toy-linear"])
    assert not (tmp_path / "data.h5.parts").exists()


def test_a_dataset_of_another_config_is_not_overwritten(toy_registry, tmp_path):
    config = cp.load_config(_config(tmp_path))
    path = tmp_path / "data.h5"
    cp.generate_dataset(config, path, progress=False)
    other = config.model_copy(update={"data": config.data.model_copy(update={"seed": 9})})
    with pytest.raises(cp.DatasetError, match="another configuration"):
        cp.generate_dataset(other, path, progress=False)


def test_process_executor_gives_the_same_records(toys_in_workers, tmp_path):
    serial = cp.load_config(_config(tmp_path, "serial"))
    processes = cp.load_config(_config(tmp_path, "processes"))
    cp.generate_dataset(serial, tmp_path / "a.h5", progress=False)
    cp.generate_dataset(processes, tmp_path / "b.h5", progress=False)
    a, b = cp.load_dataset(tmp_path / "a.h5"), cp.load_dataset(tmp_path / "b.h5")
    np.testing.assert_array_equal(a.u, b.u)
    np.testing.assert_array_equal(a.ag, b.ag)


def test_a_bad_config_fails_with_one_line_before_any_work(toy_registry, tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(CONFIG.format(executor="serial").replace("width = 6", "width = -6"))
    out = tmp_path / "never"
    assert main(["run", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "operator.width: Input should be greater than 0" in err
    assert not out.exists()


def test_choose_trains_both_forms_and_reports_each_against_its_physics(
    toy_registry, tmp_path, capsys
):
    text = CONFIG.format(executor="serial") + '\n[formulation]\nresidual = "choose"\n'
    path = tmp_path / "choose.toml"
    path.write_text(text)
    config = cp.load_config(path)
    paper, residual = "c-phystoy-operator-toy-linear", "c-phystoy-operator-toy-linear-residual"
    assert pipeline.model_labels(config) == [
        "toy-operator",
        paper,
        f"refined-{paper}",
        residual,
        f"refined-{residual}",
    ]
    out = tmp_path / "out"
    pipeline.run(config, out)
    document = json.loads((out / "metrics.json").read_text())
    models = document["models"]
    data = cp.load_dataset(out / "dataset.h5")
    z, u = data.physics("toy-linear", "val"), data.targets("val")
    expected = np.sqrt(((z - u) ** 2).sum(axis=(0, 1)) / (u**2).sum(axis=(0, 1)))
    np.testing.assert_allclose(models["physics-toy-linear"]["validation_rel_l2"], expected)
    saved = json.loads((out / "models" / residual / "model.json").read_text())
    assert saved["formulation"]["residual"] is True
    mean_validation = {
        label: np.mean(models[label]["validation_rel_l2"])
        for label in models
        if "validation_rel_l2" in models[label]
    }
    for label in (paper, f"refined-{paper}"):
        twin = label + "-residual"
        better = twin if mean_validation[twin] < mean_validation[label] else label
        assert document["chosen_forms"][label] == better
    physics = models["physics-toy-linear"]
    names = data.output_names
    worse = {
        label: {
            split: [
                name
                for name, ours, theirs in zip(names, row[key], physics[key], strict=True)
                if ours > theirs
            ]
            for split, key in (("validation", "validation_rel_l2"), ("test", "rel_l2"))
        }
        for label, row in models.items()
        if row.get("physics_input") == "physics-toy-linear"
    }
    worse = {label: {s: n for s, n in splits.items() if n} for label, splits in worse.items()}
    worse = {label: splits for label, splits in worse.items() if splits}
    recorded = {
        label: {split: [entry[0] for entry in entries] for split, entries in splits.items()}
        for label, splits in document["worse_than_physics"].items()
    }
    assert recorded == worse
    warned = [line for line in capsys.readouterr().err.splitlines() if "warning:" in line]
    assert len(warned) == len(worse)
    report = (out / "report.md").read_text()
    assert "## Against the physics input" in report
    assert f"- {paper}: `{document['chosen_forms'][paper]}`" in report


def test_a_run_fits_each_preprocessor_once_for_all_its_models(toy_registry, tmp_path, monkeypatch):
    import toy_components

    text = CONFIG.format(executor="serial") + '\n[formulation]\nresidual = "choose"\n'
    path = tmp_path / "choose.toml"
    path.write_text(text)
    config = cp.load_config(path)
    pipeline.generate(config, tmp_path)
    fitted = []
    own = toy_components.ToyPreprocessor.fit

    def counted(self, structure):
        fitted.append(self)
        return own(self, structure)

    monkeypatch.setattr(toy_components.ToyPreprocessor, "fit", counted)
    saved = pipeline.train(config, tmp_path)
    assert len(fitted) == 1  # two forms, each refined: four C-Phys models, one fit
    paper = cp.CompositeModel.load(saved["c-phystoy-operator-toy-linear"])
    residual = cp.CompositeModel.load(saved["c-phystoy-operator-toy-linear-residual"])
    motions = cp.load_dataset(tmp_path / "dataset.h5").motions("test")
    np.testing.assert_array_equal(paper.physics(motions), residual.physics(motions))


def test_a_model_cannot_be_built_to_choose(toy_registry):
    structure = cp.create("structure", "toy-structure")
    with pytest.raises(cp.ConfigError, match="'choose' is for a run"):
        cp.compose(
            structure=structure,
            preprocessor="toy-linear",
            operator="toy-operator",
            formulation={"residual": "choose"},
        )


def test_quiet_shows_no_progress_and_verbose_shows_the_plugins_log(
    toy_registry, tmp_path, capsys, monkeypatch
):
    import logging

    config = _config(tmp_path)
    assert main(["-q", "generate", str(config), "--out", str(tmp_path / "quiet")]) == 0
    assert capsys.readouterr().err == ""
    assert "CPHYSFNO_QUIET" not in os.environ  # put back after the command
    original = pipeline.generate_dataset

    def log_from_a_plugin(*args, **kwargs):
        logging.getLogger("cphysfno_toys.runner").info("record 1 of 1 simulated")
        return original(*args, **kwargs)

    monkeypatch.setattr(pipeline, "generate_dataset", log_from_a_plugin)
    assert main(["generate", str(config), "--out", str(tmp_path / "plain")]) == 0
    plain = capsys.readouterr().err
    assert "generating" in plain and "record 1 of 1" not in plain
    assert main(["-v", "generate", str(config), "--out", str(tmp_path / "loud")]) == 0
    assert "cphysfno_toys.runner: record 1 of 1 simulated" in capsys.readouterr().err
