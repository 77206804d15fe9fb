"""``cphysfno summarise``: finished run folders summarised as ``study.json`` is."""

import json

import numpy as np
import pytest
from toy_experiment import toy_experiment

import cphysfno_core as cp
from cphysfno_core import ConfigError
from cphysfno_core.app.cli import main
from cphysfno_core.app.study import summarise_runs
from cphysfno_core.app.study_document import StudySummary
from cphysfno_core.app.summary_combination import combine_summaries


def _run(tmp_path, seed, n_test=3):
    config = tmp_path / f"seed-{seed}-{n_test}.toml"
    config.write_text(
        toy_experiment(
            n_steps=60,
            operator={"width": 4},
            data={"n_train": 6, "n_val": 2, "n_test": n_test},
            training={"epochs": 1, "batch_size": 3, "seed": seed},
            output={"figures": False},
        )
    )
    out = tmp_path / f"run-{seed}-{n_test}"
    assert main(["run", str(config), "--out", str(out)]) == 0
    return out


def test_runs_of_two_seeds_give_their_mean_and_spread(toy_registry, tmp_path):
    runs = [_run(tmp_path, seed) for seed in (0, 1)]
    out = tmp_path / "results" / "summary.json"
    assert main(["summarise", *map(str, runs), "--out", str(out)]) == 0
    summary = json.loads(out.read_text())
    first, second = (json.loads((run / "metrics.json").read_text())["models"] for run in runs)
    for label, row in summary["models"].items():
        pair = np.array([first[label]["rel_l2"], second[label]["rel_l2"]])
        np.testing.assert_allclose(row["rel_l2"]["mean"], pair.mean(axis=0))
        np.testing.assert_allclose(row["rel_l2"]["std"], np.abs(pair[0] - pair[1]) / 2)
    assert summary["seeds"] == [0, 1] and summary["epochs"] == 1
    assert summary["sizes"] == {"train": 6, "val": 2, "test": 3}
    assert summary["sweeps"] == {}
    truth = cp.load_dataset(runs[0] / "dataset.h5").targets("test")
    rms = np.sqrt([np.mean(truth[:, :, k] ** 2) for k in range(truth.shape[2])])
    np.testing.assert_allclose(summary["response_rms"], rms, rtol=1e-12)


def test_runs_that_do_not_match_or_are_unfinished_are_refused(toy_registry, tmp_path, capsys):
    three, four = _run(tmp_path, 0, n_test=3), _run(tmp_path, 0, n_test=4)
    out = tmp_path / "s.json"
    assert main(["summarise", str(three), str(four), "--out", str(out)]) != 0
    assert f"{four} has sizes" in capsys.readouterr().err
    with pytest.raises(ConfigError, match="is not a finished run"):
        summarise_runs([tmp_path])
    assert not out.exists()


def _summary_of(rows, seeds, sweep_rows=None):
    """A study.json of per-seed ``rows`` (seed -> label -> [n_outputs]) by hand, its RMSE
    the relative L2 and its rows marked with where they come from."""
    labels = rows[seeds[0]]
    models = {}
    for label in labels:
        values = np.array([rows[s][label] for s in seeds])
        statistics = {"mean": values.mean(axis=0).tolist(), "std": values.std(axis=0).tolist()}
        models[label] = {"rel_l2": statistics, "rmse": statistics, "selected_on": "validation"}
    sweeps = {}
    if sweep_rows is not None:
        sweeps["layers"] = {
            "field": "operator.layers",
            "label": "layers",
            "values": [2, 4],
            "rel_l2": {"fno": {"2": [sweep_rows[s] for s in seeds], "4": []}},
        }
    return StudySummary(
        models=models,
        sweeps=sweeps,
        seeds=list(seeds),
        epochs=100,
        sizes={"train": 400, "val": 100, "test": 200},
        output_names=["story-1", "story-2", "story-3"],
        response_rms=[0.01, 0.02, 0.03],
        device=f"machine {seeds[0]}, CPU (x86_64, {len(seeds)} threads)",
    )


def test_summaries_of_disjoint_seeds_combine_to_the_summary_of_all():
    rng = np.random.default_rng(3)
    rows = {
        s: {"fno": rng.uniform(0.3, 0.5, 3), "c-physfno-els": rng.uniform(0.1, 0.3, 3)}
        for s in range(10)
    }
    sweep_rows = {s: rng.uniform(0.3, 0.5, 3).tolist() for s in range(10)}
    parts = [_summary_of(rows, seeds, sweep_rows) for seeds in ([0, 1, 2, 3, 4, 5], [6, 7], [8, 9])]
    combined = combine_summaries(parts)
    for label in ("fno", "c-physfno-els"):
        values = np.array([rows[s][label] for s in range(10)])
        row = combined.models[label]
        np.testing.assert_allclose(row.rel_l2.mean, values.mean(axis=0), rtol=1e-12)
        np.testing.assert_allclose(row.rel_l2.std, values.std(axis=0), rtol=1e-10)
        assert row.selected_on == "validation"
    assert combined.seeds == list(range(10))
    assert combined.sweeps["layers"].rel_l2["fno"]["2"] == [sweep_rows[s] for s in range(10)]
    devices = "machine 0, CPU (x86_64, 6 threads), machine 6, CPU (x86_64, 2 threads), machine 8"
    assert combined.device == devices
    parts[0].response_rms = None  # written before summaries recorded the test response
    assert combine_summaries(parts).response_rms == [0.01, 0.02, 0.03]
    parts[2].response_rms = [0.01, 0.02, 0.04]  # the two that record it disagree
    with pytest.raises(ConfigError, match="summary 2 has another test response"):
        combine_summaries(parts)


def test_summaries_of_other_models_on_the_same_seeds_combine_to_the_summary_of_all():
    rng = np.random.default_rng(4)
    labels = ("fno", "c-physfno-els", "physics-els")
    rows = {s: {label: rng.uniform(0.1, 0.5, 3) for label in labels} for s in range(4)}
    rows = {s: {**row, "physics-els": np.full(3, 0.6)} for s, row in rows.items()}

    def share(models, seeds):
        summary = _summary_of(rows, seeds)
        summary.models = {label: summary.models[label] for label in models}
        return summary

    parts = [
        share(["fno", "physics-els"], [0, 1]),
        share(["c-physfno-els", "physics-els"], [0, 1]),
        share(labels, [2, 3]),
    ]
    combined, whole = combine_summaries(parts), _summary_of(rows, [0, 1, 2, 3])
    assert combined.seeds == [0, 1, 2, 3]
    for label in labels:
        for key in ("mean", "std"):
            np.testing.assert_allclose(
                getattr(combined.models[label].rel_l2, key),
                getattr(whole.models[label].rel_l2, key),
                rtol=1e-12,
                atol=1e-15,
            )
    # the physics alone does not depend on the seed: another row is other data
    parts[1].models["physics-els"].rel_l2.mean[0] = 0.7
    with pytest.raises(ConfigError, match="physics-els differs between the summaries"):
        combine_summaries(parts)


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda s: setattr(s, "seeds", [5, 6]), r"seeds \[5\] are in more than one summary"),
        (
            lambda s: setattr(s, "sizes", {"train": 300, "val": 100, "test": 200}),
            "summary 1 has sizes",
        ),
        (lambda s: s.models.pop("fno"), r"end on different seeds \(fno \[0, 1, 2, 3, 4, 5\]"),
        (lambda s: setattr(s, "response_rms", [0.01, 0.02, 0.04]), "another test response"),
        (lambda s: setattr(s.models["fno"], "selected_on", "test"), "fno: selected_on differs"),
    ],
)
def test_summaries_that_do_not_combine_are_refused(change, message):
    rows = {s: {"fno": [0.4, 0.4, 0.4], "els": [0.2, 0.2, 0.2]} for s in range(8)}
    first, second = _summary_of(rows, [0, 1, 2, 3, 4, 5]), _summary_of(rows, [6, 7])
    change(second)
    with pytest.raises(ConfigError, match=message):
        combine_summaries([first, second])


def test_summarise_combines_run_folders_with_a_summary_of_other_seeds(toy_registry, tmp_path):
    runs = [_run(tmp_path, seed) for seed in (0, 1, 2)]
    part, whole, combined = (tmp_path / name for name in ("part.json", "all.json", "c.json"))
    assert main(["summarise", str(runs[0]), str(runs[1]), "--out", str(part)]) == 0
    assert main(["summarise", *map(str, runs), "--out", str(whole)]) == 0
    assert main(["summarise", str(runs[2]), str(part), "--out", str(combined)]) == 0
    expected, got = json.loads(whole.read_text()), json.loads(combined.read_text())
    assert got["seeds"] == [2, 0, 1]
    for label, row in expected["models"].items():
        for metric, value in row.items():
            for key in ("mean", "std"):
                np.testing.assert_allclose(
                    got["models"][label][metric][key], value[key], rtol=1e-9, atol=1e-15
                )


def test_a_summary_file_that_is_not_there_is_named(tmp_path, capsys):
    missing = tmp_path / "machine-b" / "study.json"
    out = tmp_path / "all.json"
    assert main(["summarise", str(missing), "--out", str(out)]) != 0
    assert f"no summary file {missing}" in capsys.readouterr().err
    assert not out.exists()
