"""Data generation on a real Dask LocalCluster: the same records as a serial run, even
when a worker dies mid-run."""

import os

import numpy as np
import pytest

import cphysfno_core as cp

CONFIG = {
    "structure": {"name": "toy-structure", "cubic": 20.0},
    "ground_motion": {"name": "toy-source", "n_steps": 80},
    "preprocessor": [{"name": "toy-linear"}],
    "operator": {"name": "toy-operator"},
    "data": {"n_train": 10, "n_val": 4, "n_test": 6, "chunk_size": 4},
}


def _config(structure=None, **data):
    config = {**CONFIG, "data": {**CONFIG["data"], **data}}
    if structure:
        config["structure"] = structure
    return cp.parse_config(config)


def test_local_cluster_gives_the_serial_records(toys_in_workers, tmp_path):
    cp.generate_dataset(_config(executor="serial"), tmp_path / "serial.h5", progress=False)
    cp.generate_dataset(_config(executor="dask", workers=2), tmp_path / "dask.h5", progress=False)
    serial, dask = cp.load_dataset(tmp_path / "serial.h5"), cp.load_dataset(tmp_path / "dask.h5")
    np.testing.assert_array_equal(dask.u, serial.u)
    np.testing.assert_array_equal(dask.z["toy-linear"], serial.z["toy-linear"])


def test_a_killed_worker_loses_nothing(toys_in_workers, tmp_path):
    marker = tmp_path / "died"
    dying = {"name": "toy-dying-once", "cubic": 20.0, "marker": str(marker)}
    cp.generate_dataset(
        _config(dying, executor="dask", workers=2), tmp_path / "d.h5", progress=False
    )
    assert marker.exists() and int(marker.read_text()) != os.getpid()  # a worker did die
    cp.generate_dataset(_config(executor="serial"), tmp_path / "ref.h5", progress=False)
    survived, reference = cp.load_dataset(tmp_path / "d.h5"), cp.load_dataset(tmp_path / "ref.h5")
    np.testing.assert_array_equal(survived.u, reference.u)
    np.testing.assert_array_equal(survived.ag, reference.ag)


def test_address_is_only_for_dask(toy_registry):
    with pytest.raises(cp.ConfigError, match="data: Value error, address is for executor"):
        _config(address="tcp://127.0.0.1:8786")
