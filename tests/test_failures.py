"""Records whose simulation fails are named, and either stop the run or are skipped and
listed; a plugin returning a wrong shape is named."""

import numpy as np
import pytest
import toy_components

import cphysfno_core as cp
from cphysfno_core.app import pipeline
from cphysfno_core.data import Dataset

CONFIG = {
    "ground_motion": {"name": "toy-source", "n_steps": 60, "scale": 0.2},
    "preprocessor": [{"name": "toy-linear"}],
    "operator": {"name": "toy-operator"},
    "data": {"n_train": 8, "n_val": 3, "n_test": 4, "chunk_size": 5, "executor": "serial"},
    "training": {"epochs": 1, "batch_size": 4},
}


def _config(structure, **data):
    return cp.parse_config({**CONFIG, "structure": structure, "data": {**CONFIG["data"], **data}})


def _peaks(config):
    source = cp.create("ground_motion", "toy-source", n_steps=60, scale=0.2)
    motions = source.sample(config.data.n_records, np.random.default_rng(config.data.seed))
    return np.max(np.abs(motions.acceleration), axis=1)


@pytest.mark.parametrize("mode", ["nan", "raise", "report"])
def test_a_failed_record_stops_the_run_with_its_index_and_cause(toy_registry, tmp_path, mode):
    config = _config({"name": "toy-fragile", "limit": 1.0, "mode": mode})
    peaks = _peaks(config)
    limit = float(np.sort(peaks)[-3])  # the two records with the largest peaks fail
    config = _config({"name": "toy-fragile", "limit": limit, "mode": mode})
    first = int(np.flatnonzero(peaks > limit)[0])
    cause = {"nan": "NaN or Inf", "raise": "Newton", "report": "Newton .* at t = 1.5 s"}[mode]
    with pytest.raises(cp.DatasetError, match=f"record {first} failed: .*{cause}"):
        cp.generate_dataset(config, tmp_path / "d.h5", progress=False)
    with pytest.raises(cp.DatasetError, match="incomplete"):
        cp.load_dataset(tmp_path / "d.h5")


def test_skipped_records_are_listed_and_left_out_of_the_splits(toy_registry, tmp_path):
    probe = _config({"name": "toy-fragile"})
    peaks = _peaks(probe)
    limit = float(np.sort(peaks)[-3])
    failed = set(np.flatnonzero(peaks > limit).tolist())
    config = _config({"name": "toy-fragile", "limit": limit, "mode": "raise"}, on_failure="skip")
    cp.generate_dataset(config, tmp_path / "run" / "dataset.h5", progress=False)
    data = cp.load_dataset(tmp_path / "run" / "dataset.h5")
    assert set(data.failures) == failed
    assert all("Newton did not converge" in cause for cause in data.failures.values())
    kept = np.concatenate([data.rows(s) for s in ("train", "val", "test")])
    assert sorted(kept.tolist() + sorted(failed)) == list(range(15))
    assert np.isfinite(data.targets("test")).all() and np.isfinite(data.targets("train")).all()
    assert np.isnan(data.u[sorted(failed)]).all()
    pipeline.train(config, tmp_path / "run")  # the good records are still usable


def test_failures_a_structure_reports_are_kept_without_rerunning_records(toy_registry, tmp_path):
    probe = _config({"name": "toy-fragile"})
    limit = float(np.sort(_peaks(probe))[-3])
    config = _config({"name": "toy-fragile", "limit": limit, "mode": "report"}, on_failure="skip")
    toy_components.FragileStructure.calls = 0
    cp.generate_dataset(config, tmp_path / "dataset.h5", progress=False)
    data = cp.load_dataset(tmp_path / "dataset.h5")
    assert (
        toy_components.FragileStructure.calls == 3
    )  # 15 records in chunks of 5, none simulated twice
    assert set(data.failures) == set(np.flatnonzero(_peaks(probe) > limit).tolist())
    assert all("at t = 1.5 s" in cause for cause in data.failures.values())
    assert np.isnan(data.u[sorted(data.failures)]).all()


def test_a_record_whose_physics_response_fails_is_listed_without_rerunning_the_chunk(
    toy_registry, tmp_path
):
    probe = _config({"name": "toy-structure"})
    peaks = _peaks(probe)
    limit = float(np.sort(peaks)[-3])
    config = cp.parse_config(
        {
            **CONFIG,
            "structure": {"name": "toy-structure"},
            "preprocessor": [{"name": "toy-fragile-linear", "limit": limit}],
            "data": {**CONFIG["data"], "on_failure": "skip"},
        }
    )
    toy_components.FragilePreprocessor.calls = 0
    cp.generate_dataset(config, tmp_path / "dataset.h5", progress=False)
    data = cp.load_dataset(tmp_path / "dataset.h5")
    assert toy_components.FragilePreprocessor.calls == 3  # once per chunk of 5, no reruns
    assert set(data.failures) == set(np.flatnonzero(peaks > limit).tolist())
    assert all("toy-fragile-linear" in cause for cause in data.failures.values())
    assert np.isnan(data.u[sorted(data.failures)]).all()


def test_a_plugin_returning_a_wrong_shape_is_named(toy_registry, tmp_path):
    config = _config({"name": "toy-wrong-shape"}, on_failure="skip")
    with pytest.raises(
        cp.CphysfnoError,
        match=r"structure 'toy-wrong-shape' from \(registered "
        r"in code\) returned displacement of shape \(5, 60, 1\), expected "
        r"\(5, 60, 2\)",
    ):
        cp.generate_dataset(config, tmp_path / "d.h5", progress=False)


def test_a_split_whose_records_all_failed_is_refused_with_the_cause():
    data = Dataset(
        ag=np.zeros((5, 10)),
        u=np.zeros((5, 10, 1)),
        z={},
        extras={},
        dt=0.01,
        output_names=("x",),
        sizes={"train": 3, "val": 1, "test": 1},
        failures={1: "worker died", 3: "worker died"},
    )
    assert data.rows("train").tolist() == [0, 2]
    assert data.rows("test").tolist() == [4]
    with pytest.raises(
        cp.DatasetError, match=r"every one of the 1 records of the val split.*record 3: worker"
    ):
        data.rows("val")


def test_training_without_validation_records_is_refused(toy_registry):
    model = cp.compose(
        structure="toy-structure", preprocessor="toy-linear", operator="toy-operator"
    )
    motions = cp.create("ground_motion", "toy-source", n_steps=20).sample(
        4, np.random.default_rng(0)
    )
    u = model.structure.simulate(motions).displacement
    with pytest.raises(cp.InputError, match="validation u holds no records"):
        model.fit(motions, u, (motions[:0], u[:0]), epochs=1, progress=None)
