"""``cphysfno study``: seeds and sweeps over one dataset, summarised by hand-checkable means,
resumed without retraining, and refused with a clear message when ill-posed."""

import json
import shutil

import numpy as np
import pytest
import torch
import toy_components
from toy_experiment import toy_experiment

import cphysfno_core as cp
from cphysfno_core.api.registry import set_registry
from cphysfno_core.app import pipeline, study
from cphysfno_core.app.cli import main
from cphysfno_core.app.study_document import StudySummary
from cphysfno_core.app.study_report import write_study_report
from cphysfno_core.plugin import Registry

BASE = {
    "structure": {"name": "toy-structure", "cubic": 40.0},
    "ground_motion": {"name": "toy-source", "n_steps": 60, "scale": 0.5},
    "preprocessor": [{"name": "toy-linear"}],
    "operator": {"name": "toy-operator", "width": 4},
    "refiner": {"name": "toy-refiner"},
    "data": {"n_train": 10, "n_val": 4, "n_test": 5, "chunk_size": 10, "executor": "serial"},
    "training": {"epochs": 2, "batch_size": 4},
    "study": {
        "seeds": [0, 1],
        "sweeps": {
            "size": {"field": "training.train_records", "values": [4, 10], "label": "records"},
            "width": {"field": "operator.width", "values": [2, 4]},
        },
        "sweep_preprocessors": ["toy-linear"],
    },
}
TOML = toy_experiment(
    n_steps=60,
    operator={"width": 4},
    data={"n_train": 8, "n_val": 3, "n_test": 4, "chunk_size": 8},
    training={"epochs": 1, "batch_size": 4},
    study={
        "seeds": [3, 4],
        "sweeps": {"size": {"field": "training.train_records", "values": [2, 8]}},
    },
)


def _config(**changes):
    return cp.parse_config({**BASE, **changes})


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A study run once for the module, with the toy components registered."""
    set_registry(Registry(autoload=False, plugins=(toy_components,)))
    out = tmp_path_factory.mktemp("study")
    summary = study.run_study(_config(), out)
    yield out, summary
    set_registry(None)


def test_the_summary_is_the_mean_and_std_of_the_table_runs(finished):
    out, summary = finished
    runs = [json.loads((out / f"runs/table/seed-{s}/metrics.json").read_text()) for s in (0, 1)]
    label = "c-phystoy-operator-toy-linear"
    per_seed = np.array([r["models"][label]["rel_l2"] for r in runs])
    np.testing.assert_allclose(summary.models[label].rel_l2.mean, per_seed.mean(0))
    np.testing.assert_allclose(summary.models[label].rel_l2.std, per_seed.std(0))
    assert summary.models["physics-toy-linear"].rmse.std == [0.0, 0.0]
    assert summary.seeds == [0, 1] and summary.epochs == 2
    assert summary.sizes == {"train": 10, "val": 4, "test": 5}
    assert summary.device == runs[0]["models"][label]["device"]
    assert summary.device.startswith("CPU (")
    written = json.loads((out / "study.json").read_text())
    assert written["schema_version"] == 1 and StudySummary.read(out / "study.json") == summary
    refined = written["models"]["refined-c-phystoy-operator-toy-linear"]
    assert set(refined) == {"rel_l2", "rmse", "record_rel_l2", "coverage_68", "coverage_90"}


def test_sweeps_train_the_baseline_and_the_chosen_physics_per_value_and_seed(finished):
    out, summary = finished
    size = summary.sweeps["size"]
    assert size.field == "training.train_records" and size.label == "records"
    assert set(size.rel_l2) == {
        "toy-operator",
        "c-phystoy-operator-toy-linear",
        "physics-toy-linear",
    }
    assert {v: len(seeds) for v, seeds in size.rel_l2["toy-operator"].items()} == {
        "4": 2,
        "10": 2,
    }
    small = json.loads((out / "runs/size/4/seed-1/metrics.json").read_text())
    assert small["sizes"]["train"] == 4
    saved = json.loads((out / "runs/width/2/seed-0/models/toy-operator/model.json").read_text())
    assert saved["operator"]["width"] == 2
    assert not (out / "runs/size/4/seed-0/models/refined-c-phystoy-operator-toy-linear").exists()


def test_a_finished_study_resumes_without_training_and_reruns_only_what_is_missing(
    finished, monkeypatch
):
    out, summary = finished
    trained = []
    original = pipeline.train
    monkeypatch.setattr(pipeline, "train", lambda config, folder, **kw: trained.append(folder))
    assert study.run_study(_config(), out) == summary
    assert trained == []
    (out / "runs/width/4/seed-1/metrics.json").unlink()
    monkeypatch.setattr(
        pipeline, "train", lambda *a, **kw: trained.append(a[1]) or original(*a, **kw)
    )
    study.run_study(_config(), out)
    assert trained == [out / "runs/width/4/seed-1"]


def test_a_study_in_progress_is_summarised_from_its_finished_runs(finished, tmp_path):
    out, summary = finished
    partial = tmp_path / "partial"
    shutil.copytree(out, partial)
    (partial / "runs/table/seed-1/metrics.json").unlink()
    for seed in (0, 1):
        (partial / f"runs/width/2/seed-{seed}/metrics.json").unlink()
    config = _config()
    label = "c-phystoy-operator-toy-linear"
    now = study.summarise_finished(config, partial)
    assert now.seeds == [0]
    assert now.models[label].rel_l2.std == [0.0, 0.0]
    seed_0 = json.loads((out / "runs/table/seed-0/metrics.json").read_text())
    assert now.models[label].rel_l2.mean == seed_0["models"][label]["rel_l2"]
    assert now.sweeps["width"].values == [4]
    assert now.sweeps["size"] == summary.sweeps["size"]
    report = write_study_report(config, now, partial).read_text()
    assert "in progress: 1 of the config's 2 seeds have finished" in report
    for seed in (0, 1):
        (partial / f"runs/width/4/seed-{seed}/metrics.json").unlink()
    assert "width" not in study.summarise_finished(config, partial).sweeps
    (partial / "runs/table/seed-0/metrics.json").unlink()
    with pytest.raises(cp.ConfigError, match="no table run of the study in .* has finished"):
        study.summarise_finished(config, partial)


def test_runs_in_parallel_processes_give_the_serial_study(
    finished, toys_in_workers, tmp_path, capsys
):
    out, summary = finished
    with pytest.raises(cp.ConfigError, match="jobs = 0: at least one run"):
        study.run_study(_config(), tmp_path, jobs=0)
    parallel = tmp_path / "parallel"
    parallel.mkdir()
    shutil.copy(out / "dataset.h5", parallel / "dataset.h5")
    result = study.run_study(_config(), parallel, jobs=2)
    for label, row in summary.models.items():
        for metric in ("rel_l2", "rmse"):
            np.testing.assert_allclose(
                getattr(result.models[label], metric).mean, getattr(row, metric).mean, rtol=1e-5
            )
    for name, sweep in summary.sweeps.items():
        for label, per_value in sweep.rel_l2.items():
            for value, seeds in per_value.items():
                np.testing.assert_allclose(
                    result.sweeps[name].rel_l2[label][value], seeds, rtol=1e-5
                )
    printed = capsys.readouterr().err
    assert "10 of 10 study runs left" in printed
    one_each = f"2 at a time with {study.threads_per_run(2)} thread"
    assert f"2 table runs, {one_each}" in printed and f"8 sweep runs, {one_each}" in printed
    assert printed.count("finished in") == 10 and "epoch" not in printed
    assert "training toy-operator" in (parallel / "runs/size/4/seed-1/study.log").read_text()
    assert (
        "the same training as seed-1 of the table, copied"
        in (parallel / "runs/width/4/seed-1/study.log").read_text()
    )
    assert (parallel / "runs/table/seed-0/report.md").exists()


def test_a_run_training_alone_gets_every_core(finished, toys_in_workers, tmp_path, capsys):
    out, _ = finished
    shutil.copy(out / "dataset.h5", tmp_path / "dataset.h5")
    before = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        study.run_study(_config(study={"seeds": [0]}), tmp_path, jobs=2)
        trained_with = torch.get_num_threads()  # a lone run trains in this process
    finally:
        torch.set_num_threads(before)
    cores = study.threads_per_run(1)
    assert trained_with == cores
    printed = capsys.readouterr().err
    assert f"1 table run, 1 at a time with {cores} thread" in printed
    assert "sweep run" not in printed


@pytest.mark.parametrize(
    ("workers", "cores", "threads"), [(1, 2, 2), (2, 2, 1), (3, 2, 1), (2, 16, 8)]
)
def test_runs_side_by_side_share_the_cores(workers, cores, threads):
    assert study.threads_per_run(workers, cores) == threads


def test_the_cli_writes_the_report_with_sweep_figures(toy_registry, tmp_path, capsys):
    path = tmp_path / "study.toml"
    path.write_text(TOML)
    assert main(["study", str(path), "--out", str(tmp_path / "out")]) == 0
    printed = capsys.readouterr().out
    assert "mean of 2 seeds" in printed and "c-phystoy-operator-toy-linear" in printed
    report = (tmp_path / "out/study.md").read_text()
    assert " ± " in report and "figures/sweep-size.png" in report
    assert (tmp_path / "out/figures/sweep-size.png").stat().st_size > 10_000
    assert (tmp_path / "out/runs/table/seed-3/report.md").exists()
    (tmp_path / "out/runs/table/seed-4/metrics.json").unlink()
    (tmp_path / "out/study.md").unlink()
    command = ["study", str(path), "--out", str(tmp_path / "out"), "--summary-only"]
    assert main(command) == 0
    assert "mean of 1 seed" in capsys.readouterr().out
    assert json.loads((tmp_path / "out/study.json").read_text())["seeds"] == [3]
    assert "in progress" in (tmp_path / "out/study.md").read_text()
    assert not (tmp_path / "out/runs/table/seed-4/metrics.json").exists()
    assert main(["study", str(path), "--out", str(tmp_path / "out"), "--jobs", "0"]) == 2
    assert "jobs = 0: at least one run must train at a time" in capsys.readouterr().err


def test_a_study_split_between_machines_by_seeds_combines_to_the_whole(toy_registry, tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(TOML)
    outs = {name: tmp_path / name for name in ("whole", "machine-a", "machine-b")}
    assert main(["study", str(path), "--out", str(outs["whole"])]) == 0
    assert main(["study", str(path), "--out", str(outs["machine-a"]), "--seeds", "3"]) == 0
    assert main(["study", str(path), "--out", str(outs["machine-b"]), "--seeds", "4"]) == 0
    shares = [str(outs[name] / "study.json") for name in ("machine-a", "machine-b")]
    assert main(["summarise", *shares, "--out", str(tmp_path / "all.json")]) == 0
    whole = json.loads((outs["whole"] / "study.json").read_text())
    combined = json.loads((tmp_path / "all.json").read_text())
    assert combined["seeds"] == whole["seeds"] == [3, 4]
    for label, row in whole["models"].items():
        for metric, value in row.items():
            for key in ("mean", "std"):
                np.testing.assert_allclose(
                    combined["models"][label][metric][key], value[key], rtol=1e-9, atol=1e-15
                )
    assert combined["sweeps"] == whole["sweeps"]


def test_a_study_split_between_machines_by_models_combines_to_the_whole(
    toy_registry, tmp_path, capsys
):
    path = tmp_path / "study.toml"
    path.write_text(
        toy_experiment(
            n_steps=60,
            operator={"width": 4},
            refiner={"name": "toy-refiner"},
            data={"n_train": 8, "n_val": 3, "n_test": 4, "chunk_size": 8},
            training={"epochs": 1, "batch_size": 4},
            study={"seeds": [3, 4]},
        )
    )
    composite = "c-phystoy-operator-toy-linear"
    shares = {
        "whole": [],
        "baseline": ["--models", "toy-operator"],
        "composite-3": ["--models", composite, "--seeds", "3"],
        "composite-4": ["--models", composite, "--seeds", "4"],
    }
    for name, options in shares.items():  # the shares in one folder: one dataset for all
        out = tmp_path / ("whole" if name == "whole" else "shares")
        assert main(["study", str(path), "--out", str(out), *options]) == 0
        shutil.copy(out / "study.json", tmp_path / f"{name}.json")
    summary = {name: json.loads((tmp_path / f"{name}.json").read_text()) for name in shares}
    assert set(summary["baseline"]["models"]) == {"toy-operator", "physics-toy-linear"}
    assert set(summary["composite-3"]["models"]) == {
        composite,
        f"refined-{composite}",
        "physics-toy-linear",
    }
    files = [str(tmp_path / f"{name}.json") for name in list(shares)[1:]]
    assert main(["summarise", *files, "--out", str(tmp_path / "all.json")]) == 0
    combined = json.loads((tmp_path / "all.json").read_text())
    whole = summary["whole"]
    assert combined["seeds"] == whole["seeds"] == [3, 4]
    assert set(combined["models"]) == set(whole["models"])
    for label, row in whole["models"].items():
        for metric, value in row.items():
            for key in ("mean", "std"):
                np.testing.assert_allclose(
                    combined["models"][label][metric][key], value[key], rtol=1e-9, atol=1e-15
                )
    capsys.readouterr()
    assert main(["summarise", *files[:2], "--out", str(tmp_path / "part.json")]) != 0
    message = capsys.readouterr().err
    assert "the models end on different seeds" in message
    assert f"(toy-operator [3, 4]; {composite} [3]; refined-{composite} [3])" in message
    assert main(["study", str(path), "--out", str(tmp_path / "x"), "--models", "els"]) == 2
    assert "output.models: ['els'] are not models this config trains" in capsys.readouterr().err


def test_seeds_given_on_the_command_line_must_be_distinct(toy_registry, tmp_path, capsys):
    path = tmp_path / "study.toml"
    path.write_text(TOML)
    assert main(["study", str(path), "--out", str(tmp_path / "out"), "--seeds", "3", "3"]) == 2
    assert "seeds must be distinct and at least one, got [3, 3]" in capsys.readouterr().err


def test_sweep_values_that_train_like_the_table_reuse_its_models(
    toy_registry, tmp_path, monkeypatch
):
    fits = []
    original = cp.CompositeModel.fit
    monkeypatch.setattr(
        cp.CompositeModel,
        "fit",
        lambda self, *a, **kw: fits.append(self.label) or original(self, *a, **kw),
    )
    config = _config(study={**BASE["study"], "seeds": [0]})
    planned = {(r.group, r.value): r.shares for r in study.plan(config, tmp_path)}
    table = tmp_path / "runs/table/seed-0"
    assert planned == {
        ("table", None): None,
        ("size", 4): None,
        ("size", 10): table,  # train_records = n_train: the table's training split
        ("width", 2): None,
        ("width", 4): table,
    }
    study.run_study(config, tmp_path)
    assert len(fits) == 6  # baseline and C-Phys model for the table, size 4 and width 2
    shared = json.loads((tmp_path / "runs/size/10/seed-0/metrics.json").read_text())["models"]
    own = json.loads((table / "metrics.json").read_text())["models"]
    for label in ("toy-operator", "c-phystoy-operator-toy-linear"):
        assert shared[label]["rel_l2"] == own[label]["rel_l2"]


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"study": None}, "no \\[study\\] section"),
        (
            {"study": {"sweeps": {"n": {"field": "data.n_train", "values": [4]}}}},
            "runs share one dataset",
        ),
        (
            {"study": {"sweeps": {"w": {"field": "operator.width", "values": [0]}}}},
            "study sweep 'w' = 0: operator.width",
        ),
        (
            {"study": {"sweeps": {"w": {"field": "optimizer.rate", "values": [1]}}}},
            "no \\[optimizer\\] section",
        ),
        ({"output": {"models": ["toy-operator"]}}, "this study also has sweeps"),
    ],
)
def test_ill_posed_studies_are_refused_before_any_simulation(
    toy_registry, tmp_path, change, message
):
    with pytest.raises(cp.ConfigError, match=message):
        study.run_study(_config(**change), tmp_path)
    assert not (tmp_path / "dataset.h5").exists()


def test_train_records_beyond_the_training_split_is_refused(toy_registry):
    with pytest.raises(cp.ConfigError, match="train_records = 11 exceeds data.n_train = 10"):
        _config(training={"train_records": 11})
    with pytest.raises(cp.ConfigError, match="sweep_preprocessors"):
        _config(study={"sweep_preprocessors": ["els"]})


def test_the_time_left_is_the_pace_of_the_finished_runs_times_those_left():
    now = iter([100.0, 700.0, 1000.0, 1900.0])  # start, then three runs finish
    remaining = study.TimeLeft(3, clock=lambda: next(now))
    assert remaining.one_done() == "; about 20 min left for the study (2 runs)"  # 600 s a run
    assert remaining.one_done() == "; about 8 min left for the study (1 run)"  # 450 s a run
    assert remaining.one_done() == ""


def test_a_training_size_sweep_draws_the_edp_learning_curve_with_the_baselines(
    toy_registry, tmp_path
):
    config = _config(
        structure={"name": "toy-storied", "cubic": 40.0},
        study={
            "seeds": [0],
            "sweeps": {"size": {"field": "training.train_records", "values": [6, 10]}},
            "sweep_preprocessors": ["toy-linear"],
        },
    )
    summary = study.run_study(config, tmp_path)
    curve = summary.sweeps["size"].edp
    assert {"baseline-cloud", "baseline-gp", "toy-operator", "physics-toy-linear"} <= set(curve)
    small = json.loads((tmp_path / "runs/size/6/seed-0/metrics.json").read_text())
    cloud = small["baselines"]["baseline-cloud"]["edp"]
    assert curve["baseline-cloud"]["6"] == [{key: cloud[key]["median"] for key in cloud}]
    assert {"PID", "PFA", "PFV", "PD"} <= set(cloud)
    # the baselines are fitted on the sweep's training records, not the whole split
    large = json.loads((tmp_path / "runs/size/10/seed-0/metrics.json").read_text())
    assert large["baselines"]["baseline-cloud"]["edp"] != cloud
    table = json.loads((tmp_path / "runs/table/seed-0/metrics.json").read_text())
    pid = table["models"]["toy-operator"]["edp"]["PID"]["median"]
    np.testing.assert_allclose(summary.models["toy-operator"].pid_median.mean, pid)
    row = table["models"]["toy-operator"]
    np.testing.assert_allclose(
        summary.models["toy-operator"].pd_median.mean, row["edp"]["PD"]["median"]
    )
    np.testing.assert_allclose(
        summary.models["toy-operator"].record_rel_l2.mean, row["record_rel_l2"]
    )
    assert set(summary.baselines) == {"baseline-cloud", "baseline-gp"}
    assert summary.baselines["baseline-gp"].pfv_median is not None

    report = write_study_report(config, summary, tmp_path).read_text()
    assert "## EDP errors (test split)" in report and "| baseline-gp |" in report
    assert "### Peak floor velocity" in report and "### Peak output displacement" in report
    assert "## Relative L2 error record by record (test split)" in report
    assert "figures/learning-curve-size.png" in report
    assert (tmp_path / "figures/learning-curve-size.png").stat().st_size > 10_000
