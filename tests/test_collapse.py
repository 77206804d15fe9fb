"""A record that collapses the structure is data: flagged, kept with NaN after the
collapse, left out of training, counted in the file."""

import sys

import numpy as np
import pytest
import toy_components

import cphysfno_core as cp
from cphysfno_core.api.registry import set_registry
from cphysfno_core.app import pipeline
from cphysfno_core.app.inspection import describe_file

CONFIG = {
    "ground_motion": {"name": "toy-source", "n_steps": 60, "scale": 0.2},
    "preprocessor": [{"name": "toy-linear"}],
    "operator": {"name": "toy-operator"},
    "data": {"n_train": 8, "n_val": 3, "n_test": 4, "chunk_size": 5, "executor": "serial"},
    "training": {"epochs": 1, "batch_size": 4},
}


class CollapsingStructure(toy_components.ToyStructure):
    """The toy structure; a record whose peak |a_g| exceeds ``limit`` collapses it at its
    30th sample."""

    name = "toy-collapsing"

    class Params(toy_components.ToyStructure.Params):
        limit: float = 1.0

    def simulate(self, motions, *, dt=None):
        responses = super().simulate(motions, dt=dt)
        collapsed = np.max(np.abs(motions.acceleration), axis=1) > self.params.limit
        displacement = responses.displacement.copy()
        displacement[collapsed, 30:] = np.nan
        return cp.Responses(displacement, responses.dt, collapsed=collapsed)


@cp.hookimpl
def cphysfno_structures():
    return [CollapsingStructure]


@pytest.fixture
def registry():
    registry = cp.Registry(autoload=False, plugins=(toy_components, sys.modules[__name__]))
    set_registry(registry)
    yield registry
    set_registry(None)


def test_collapsed_records_are_kept_flagged_and_left_out_of_training(registry, tmp_path):
    source = cp.create("ground_motion", "toy-source", n_steps=60, scale=0.2)
    peaks = np.max(np.abs(source.sample(15, np.random.default_rng(0)).acceleration), axis=1)
    limit = float(np.sort(peaks)[-4])  # three records collapse
    structure = {"name": "toy-collapsing", "limit": limit}
    config = cp.parse_config({**CONFIG, "structure": structure})
    # a collapse is not a failure: the default on_failure = "raise" goes on
    cp.generate_dataset(config, tmp_path / "run" / "dataset.h5", progress=False)
    data = cp.load_dataset(tmp_path / "run" / "dataset.h5")
    collapsed = np.flatnonzero(peaks > limit)
    assert data.failures == {}
    assert np.flatnonzero(data.collapsed).tolist() == collapsed.tolist()
    assert np.isfinite(data.u[collapsed, :30]).all() and np.isnan(data.u[collapsed, 30:]).all()
    kept = np.concatenate([data.rows(s) for s in ("train", "val", "test")])
    assert sorted(kept.tolist() + collapsed.tolist()) == list(range(15))
    flagged = np.concatenate([data.collapsed_rows(s) for s in ("train", "val", "test")])
    assert flagged.tolist() == collapsed.tolist()
    assert "collapsed records: 3" in describe_file(tmp_path / "run" / "dataset.h5")
    pipeline.train(config, tmp_path / "run")  # trains on the records that did not collapse


def test_a_split_that_only_collapses_says_so(registry, tmp_path):
    config = cp.parse_config({**CONFIG, "structure": {"name": "toy-collapsing", "limit": 0.0}})
    cp.generate_dataset(config, tmp_path / "dataset.h5", progress=False)
    with pytest.raises(cp.DatasetError, match="collapsed the structure: scale the ground"):
        cp.load_dataset(tmp_path / "dataset.h5").rows("train")


def test_collapsed_flags_must_be_one_bool_per_record():
    with pytest.raises(cp.InputError, match="one flag per record"):
        cp.Responses(np.zeros((2, 5, 1)), 0.01, collapsed=np.array([True]))
    assert cp.Responses(np.zeros((2, 5, 1)), 0.01).collapsed.tolist() == [False, False]
