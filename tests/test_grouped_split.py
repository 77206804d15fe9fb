"""Splits by group (``data.group_by``): every group of records (a station's components and
their scaled copies) lies wholly in train, val or test, with the sizes asked, in an order
that the seed fixes."""

import sys

import numpy as np
import pytest

import cphysfno_core as cp
from cphysfno_core import plugin
from cphysfno_core.data import generation
from cphysfno_core.data.datasets import dataset_hash
from cphysfno_core.data.splits import grouped_order
from cphysfno_core.plugin import GroundMotionSource, hookimpl


class ToyStations(GroundMotionSource):
    """A record set of ``stations`` x ``copies`` records; sample 0 of a record is its
    station, sample 1 its copy, the rest noise; the metadata name the station (and,
    with ``label_last = false``, not for the last record)."""

    name = "toy-stations"
    independent_draws = False

    class Params(plugin.Params):
        stations: int = 6
        copies: int = 2
        n_steps: int = 40
        label_last: bool = True

    def sample(self, n, rng):
        p = self.params
        size = p.stations * p.copies
        ag = np.random.default_rng(0).standard_normal((size, p.n_steps))
        ag[:, 0] = np.repeat(np.arange(p.stations), p.copies)
        ag[:, 1] = np.tile(np.arange(p.copies), p.stations)
        metadata = [{"station": f"S{int(s)}", "component": "H1"} for s in ag[:, 0]]
        if not p.label_last:
            del metadata[-1]["station"]
        return cp.GroundMotions(ag, 0.02, metadata)[rng.permutation(size)[:n]]


@hookimpl
def cphysfno_ground_motions():
    return [ToyStations]


@pytest.fixture
def stations_registry(toy_registry):
    toy_registry.register(sys.modules[__name__])
    return toy_registry


def _config(group_by="station", sizes=(6, 2, 4), seed=0, **source):
    n_train, n_val, n_test = sizes
    return cp.parse_config(
        {
            "structure": {"name": "toy-structure"},
            "ground_motion": {"name": "toy-stations", **source},
            "operator": {"name": "toy-operator"},
            "data": {
                "n_train": n_train,
                "n_val": n_val,
                "n_test": n_test,
                "seed": seed,
                "group_by": group_by,
                "chunk_size": 5,
                "executor": "serial",
            },
        }
    )


def _stations(dataset, split):
    return set(dataset.ag[dataset.rows(split), 0].astype(int))


def test_grouped_order_deals_whole_groups_in_the_sizes_asked():
    # Groups of 5, 4, 3, 3, 2, 2, 1: train 8, val 5, test 7 need e.g. {5, 3} / {4, 1} / ...
    sizes_of_groups = [5, 4, 3, 3, 2, 2, 1]
    groups = [f"g{g}" for g, size in enumerate(sizes_of_groups) for _ in range(size)]
    rng = np.random.default_rng(3)
    labels = np.array(groups)[rng.permutation(len(groups))]
    for seed in range(20):
        order = grouped_order(list(labels), (8, 5, 7), np.random.default_rng(seed))
        assert sorted(order) == list(range(20))
        split = {"train": order[:8], "val": order[8:13], "test": order[13:]}
        members = {name: set(labels[rows]) for name, rows in split.items()}
        assert not members["train"] & members["val"]
        assert not members["train"] & members["test"]
        assert not members["val"] & members["test"]
        for name, rows in split.items():  # every group of a split is there whole
            for group in members[name]:
                assert np.sum(labels[rows] == group) == np.sum(labels == group)
    again = grouped_order(list(labels), (8, 5, 7), np.random.default_rng(11))
    np.testing.assert_array_equal(
        again, grouped_order(list(labels), (8, 5, 7), np.random.default_rng(11))
    )
    dealt = {
        frozenset(labels[grouped_order(list(labels), (8, 5, 7), np.random.default_rng(s))[13:]])
        for s in range(20)
    }
    assert len(dealt) > 1  # the seed chooses among the possible deals


def test_impossible_sizes_say_which_sizes_whole_groups_can_make():
    groups = [f"g{g}" for g in range(6) for _ in range(5)]  # six groups of 5
    with pytest.raises(cp.ConfigError) as error:
        grouped_order(groups, (18, 5, 7), np.random.default_rng(0))
    message = str(error.value)
    assert "the 30 records form 6 groups (sizes 6 x 5)" in message
    assert "multiples of 5 up to 30" in message
    assert "n_train = 18 cannot (nearest: 15 or 20)" in message
    assert "n_test = 7 cannot (nearest: 5 or 10)" in message
    assert "n_val" not in message.split(";", 1)[1]
    one_big = [f"g{g}" for g, size in enumerate([6, 1, 1, 1, 1]) for _ in range(size)]
    with pytest.raises(cp.ConfigError, match="not all three at once"):
        grouped_order(one_big, (3, 3, 4), np.random.default_rng(0))  # no room for the 6
    mixed = [f"g{g}" for g, size in enumerate([4, 4, 3]) for _ in range(size)]
    with pytest.raises(cp.ConfigError, match="can hold 3, 4, 7, 8, 11 records"):
        grouped_order(mixed, (5, 2, 4), np.random.default_rng(0))
    order = grouped_order(mixed, (3, 4, 4), np.random.default_rng(0))
    assert set(np.array(mixed)[order[:3]]) == {"g2"}  # the only deal: the 3 is train


def test_generation_keeps_each_station_in_one_split(stations_registry, monkeypatch, tmp_path):
    monkeypatch.setattr(generation, "SAMPLE_BLOCK", 4)  # the reordering goes block by block
    first = cp.load_dataset(cp.generate_dataset(_config(), tmp_path / "a.h5", progress=False))
    splits = {name: _stations(first, name) for name in ("train", "val", "test")}
    assert [len(first.rows(s)) for s in ("train", "val", "test")] == [6, 2, 4]
    assert [len(splits[s]) for s in ("train", "val", "test")] == [3, 1, 2]
    assert set().union(*splits.values()) == set(range(6))
    again = cp.load_dataset(cp.generate_dataset(_config(), tmp_path / "b.h5", progress=False))
    np.testing.assert_array_equal(first.ag, again.ag)
    np.testing.assert_array_equal(first.u, again.u)
    ungrouped = cp.load_dataset(
        cp.generate_dataset(_config(group_by=None), tmp_path / "c.h5", progress=False)
    )
    assert sorted(map(bytes, first.ag)) == sorted(map(bytes, ungrouped.ag))  # same records
    straddles = [len(_stations(ungrouped, s)) for s in ("train", "val", "test")]
    assert sum(straddles) > 6  # without grouping, copies of a station fall in two splits
    deals = {
        tuple(sorted(_stations(d, "test")))
        for seed in range(1, 5)
        for d in [
            cp.load_dataset(
                cp.generate_dataset(_config(seed=seed), tmp_path / f"s{seed}.h5", progress=False)
            )
        ]
    }
    assert len(deals) > 1
    assert dataset_hash(_config()) != dataset_hash(_config(group_by=None))


def test_generation_refuses_sizes_that_whole_groups_cannot_make(stations_registry, tmp_path):
    with pytest.raises(cp.ConfigError) as error:
        cp.generate_dataset(_config(sizes=(5, 3, 4)), tmp_path / "d.h5", progress=False)
    message = str(error.value)
    assert message.startswith("data.group_by = 'station': n_train = 5, n_val = 3, n_test = 4")
    assert "multiples of 2 up to 12" in message
    assert not list(tmp_path.rglob("*.npy*")) and not (tmp_path / "d.h5").exists()


def test_a_record_without_the_key_is_named(stations_registry, tmp_path):
    with pytest.raises(cp.ConfigError) as error:
        cp.generate_dataset(_config(label_last=False), tmp_path / "d.h5", progress=False)
    message = str(error.value)
    assert "data.group_by = 'station': record " in message
    assert "of ground motion 'toy-stations' has no 'station' in its metadata" in message
    assert "(it has: component)" in message
    assert not list(tmp_path.rglob("*.npy*"))


def test_every_record_keeps_its_provenance_and_every_array_its_units(
    stations_registry, tmp_path, capsys
):
    """Reordered by group, each row of the dataset still carries the metadata of the record
    in that row (the station is also written into the record's first sample)."""
    from cphysfno_core.app.cli import main

    path = tmp_path / "data.h5"
    generation.generate_dataset(_config(), path, progress=False)
    dataset = cp.load_dataset(path)
    assert len(dataset.provenance) == dataset.ag.shape[0] == 12
    for row, record in enumerate(dataset.provenance):
        assert record["station"] == f"S{int(dataset.ag[row, 0])}"
        assert record["source"] == "toy-stations" and record["dt"] == 0.02
    assert sorted(r["draw"] for r in dataset.provenance) == list(range(12))
    import h5py

    with h5py.File(path) as f:
        assert f["ag"].attrs["units"] == "m/s^2" and f["u"].attrs["units"] == "m"
        assert "displacement relative to the ground" in f["u"].attrs["description"]
    assert main(["inspect", str(path), "--records", "2"]) == 0
    printed = capsys.readouterr().out
    assert "[m/s^2] ground acceleration" in printed and "[m] displacement" in printed
    assert "provenance of 2 of 12 records:" in printed
    assert f'"station": "{dataset.provenance[1]["station"]}"' in printed
