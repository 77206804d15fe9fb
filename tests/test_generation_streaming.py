"""Ground motions are sampled in blocks when the source allows it and read back a chunk at a
time, without changing which records a dataset holds."""

import numpy as np
import pytest

import cphysfno_core as cp
from cphysfno_core.data import generation
from cphysfno_core.plugin import get_registry

BASE = {
    "structure": {"name": "toy-structure"},
    "ground_motion": {"name": "toy-source", "n_steps": 40},
    "preprocessor": [{"name": "toy-linear"}],
    "operator": {"name": "toy-operator"},
    "data": {"n_train": 7, "n_val": 2, "n_test": 2, "chunk_size": 3, "executor": "serial"},
}


def _config(**changes):
    config = {**BASE, **changes}
    return cp.parse_config(config)


@pytest.fixture
def requested(monkeypatch, toy_registry):
    """Record sizes asked of every source, with blocks of four records."""
    sizes = []
    monkeypatch.setattr(generation, "SAMPLE_BLOCK", 4)
    for cls in (
        toy_registry.entry("ground_motion", n).cls for n in ("toy-source", "toy-record-set")
    ):
        original = cls.sample

        def sample(self, n, rng, original=original):
            sizes.append(n)
            return original(self, n, rng)

        monkeypatch.setattr(cls, "sample", sample)
    return sizes


def test_independent_draws_are_sampled_in_blocks_as_one_generator_stream(requested, tmp_path):
    cp.generate_dataset(_config(), tmp_path / "d.h5", progress=False)
    assert requested == [4, 4, 3]
    source = cp.create("ground_motion", "toy-source", n_steps=40)
    rng = np.random.default_rng(_config().data.seed)
    expected = np.concatenate([source.sample(k, rng).acceleration for k in (4, 4, 3)])
    np.testing.assert_array_equal(cp.load_dataset(tmp_path / "d.h5").ag, expected)


def test_the_records_do_not_depend_on_the_chunk_size(toy_registry, tmp_path):
    one = cp.generate_dataset(_config(), tmp_path / "a.h5", progress=False)
    data = {**BASE["data"], "chunk_size": 5}
    other = cp.generate_dataset(_config(data=data), tmp_path / "b.h5", progress=False)
    np.testing.assert_array_equal(cp.load_dataset(one).ag, cp.load_dataset(other).ag)
    np.testing.assert_array_equal(cp.load_dataset(one).u, cp.load_dataset(other).u)


def test_a_record_set_is_sampled_once(requested, tmp_path):
    config = _config(ground_motion={"name": "toy-record-set", "n_steps": 40, "size": 20})
    cp.generate_dataset(config, tmp_path / "d.h5", progress=False)
    assert requested == [11]
    ag = cp.load_dataset(tmp_path / "d.h5").ag
    assert len({row.tobytes() for row in ag}) == 11  # no record twice


def test_a_source_with_too_few_records_is_refused_and_leaves_no_motions(requested, tmp_path):
    config = _config(ground_motion={"name": "toy-record-set", "n_steps": 40, "size": 9})
    with pytest.raises(cp.DatasetError, match="gave 9 records but the data section asks for 11"):
        cp.generate_dataset(config, tmp_path / "d.h5", progress=False)
    assert not list(tmp_path.rglob("*.npy*"))
    assert not (tmp_path / "d.h5").exists()


def test_a_source_that_changes_its_grid_between_blocks_is_named(requested, monkeypatch, tmp_path):
    cls = get_registry().entry("ground_motion", "toy-source").cls
    sample = cls.sample
    calls = iter(range(100))

    def drifting(self, n, rng):
        motions = sample(self, n, rng)
        return cp.GroundMotions(motions.acceleration, motions.dt * (1 + next(calls)))

    monkeypatch.setattr(cls, "sample", drifting)
    with pytest.raises(cp.DatasetError, match="'toy-source' changed its grid between draws"):
        cp.generate_dataset(_config(), tmp_path / "d.h5", progress=False)


def test_progress_line_gives_the_rate_in_the_unit_that_reads_and_the_time_left():
    assert (
        generation.progress_line(500, 1000, 2.0)
        == "500/1000 records (250 records/s, about 2 s left)"
    )
    assert generation.progress_line(50, 400, 330.0) == (
        "50/400 records (6.6 s per record, about 38 min left)"
    )
    assert generation.progress_line(10, 1000, 3600.0) == (
        "10/1000 records (360.0 s per record, about 99.0 h left)"
    )
