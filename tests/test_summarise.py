"""``cphysfno summarise``: finished run folders summarised as ``study.json`` is."""

import json

import numpy as np
import pytest
from toy_experiment import toy_experiment

import cphysfno_core as cp
from cphysfno_core import ConfigError
from cphysfno_core.app.cli import main
from cphysfno_core.app.study import summarise_runs


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
