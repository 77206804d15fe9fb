"""A record that collapses the structure is data: flagged, kept with NaN after the
collapse, left out of training, counted in the file and the report. What the simulator
printed is shown once per distinct message and kept in full."""

import json
import logging
import sys

import numpy as np
import pytest
import toy_components

import cphysfno_core as cp
from cphysfno_core.app import pipeline
from cphysfno_core.app.cli import main
from cphysfno_core.app.inspection import describe_file
from cphysfno_core.plugin import hookimpl

CONFIG = {
    "ground_motion": {"name": "toy-source", "n_steps": 60, "scale": 0.2},
    "preprocessor": [{"name": "toy-linear"}],
    "operator": {"name": "toy-operator"},
    "data": {"n_train": 8, "n_val": 3, "n_test": 4, "chunk_size": 5, "executor": "serial"},
    "training": {"epochs": 1, "batch_size": 4},
}


class CollapsingStructure(toy_components.StoriedToyStructure):
    """The toy structure; a record whose peak |a_g| exceeds ``limit`` collapses it at its
    30th sample. It prints a warning with the record's peak for every record, and one
    more line for a collapse."""

    name = "toy-collapsing"

    class Params(toy_components.StoriedToyStructure.Params):
        limit: float = 1.0

    def _stopped(self, motions):
        """``(peaks [n], whether each record stops at its 30th sample [n], displacement
        with NaN after the stop)``."""
        displacement = super().simulate(motions).displacement.copy()
        peaks = np.max(np.abs(motions.acceleration), axis=1)
        stops = peaks > self.params.limit
        displacement[stops, 30:] = np.nan
        return peaks, stops, displacement

    def simulate(self, motions, *, dt=None):
        peaks, collapsed, displacement = self._stopped(motions)
        messages = {
            i: f"WARNING: peak {peak:.4f} m/s^2\n"
            + ("Newton failed at t = 0.30 s\n" if collapsed[i] else "")
            for i, peak in enumerate(peaks)
        }
        return cp.Responses(displacement, motions.dt, collapsed=collapsed, messages=messages)


class StallingStructure(CollapsingStructure):
    """The same, but the record whose peak exceeds ``limit`` stops converging at its 30th
    sample below any collapse: a non-converged record."""

    name = "toy-stalling"

    def simulate(self, motions, *, dt=None):
        _, stalls, displacement = self._stopped(motions)
        stopped = {int(i): "did not converge at t = 0.30 s" for i in np.flatnonzero(stalls)}
        return cp.Responses(displacement, motions.dt, non_converged=stopped)


@hookimpl
def cphysfno_structures():
    return [CollapsingStructure, StallingStructure]


@pytest.fixture
def registry():
    with toy_components.registered(sys.modules[__name__]) as registry:
        yield registry


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


def test_the_run_reports_how_many_records_collapsed_and_fits_their_fragility(
    registry, tmp_path, capsys
):
    source = cp.create("ground_motion", "toy-source", n_steps=60, scale=0.2)
    peaks = np.max(np.abs(source.sample(15, np.random.default_rng(0)).acceleration), axis=1)
    limit = float(np.sort(peaks)[-4])
    config = cp.parse_config({**CONFIG, "structure": {"name": "toy-collapsing", "limit": limit}})
    pipeline.run(config, tmp_path / "run")
    collapsed = peaks > limit
    expected = {
        split: int(collapsed[rows].sum())
        for split, rows in (("train", slice(0, 8)), ("val", slice(8, 11)), ("test", slice(11, 15)))
    }
    metrics = json.loads((tmp_path / "run" / "metrics.json").read_text())
    assert metrics["left_out"]["collapsed"] == expected
    assert metrics["left_out"]["failed"] == {"train": 0, "val": 0, "test": 0}
    report = (tmp_path / "run" / "report.md").read_text()
    line = (
        "- left out of training and of the error tables: 3 collapsed the structure "
        f"({expected['train']} train / {expected['val']} validation / {expected['test']} test)"
    )
    assert line in report
    data = cp.load_dataset(tmp_path / "run" / "dataset.h5")
    standing = cp.edp.compute(data.targets("test"), registry.create("structure", "toy-storied"),
                              data.motions("test"))  # fmt: skip
    threshold = float(np.median(standing.pid.max(axis=1)))
    arguments = ["fragility", str(tmp_path / "run"), "--records", "30", "--bootstrap", "5"]
    assert main([*arguments, "--limit-states", f"pid={threshold:.6g}"]) == 0, capsys.readouterr()
    document = json.loads((tmp_path / "run" / "fragility" / "fragility.json").read_text())
    assert document["collapsed_test_records"] == expected["test"]
    assert document["collapse"]["median"] > 0 and document["collapse"]["beta"] > 0


def test_the_simulators_messages_are_shown_once_each_and_kept_in_full(
    registry, tmp_path, capsys, caplog
):
    source = cp.create("ground_motion", "toy-source", n_steps=60, scale=0.2)
    peaks = np.max(np.abs(source.sample(15, np.random.default_rng(0)).acceleration), axis=1)
    limit = float(np.sort(peaks)[-4])
    config = cp.parse_config({**CONFIG, "structure": {"name": "toy-collapsing", "limit": limit}})
    path = tmp_path / "dataset.h5"
    with caplog.at_level(logging.INFO, logger="cphysfno_core.data.generation"):
        cp.generate_dataset(config, path, progress=True)
    assert f"record 0: the simulator printed\nWARNING: peak {peaks[0]:.4f} m/s^2" in caplog.text
    shown = capsys.readouterr().err
    assert "the simulator printed 2 distinct messages" in shown
    assert "15 times in    15 records: WARNING: peak # m/s^2" in shown
    assert "3 times in     3 records: Newton failed at t = # s" in shown
    assert shown.count("WARNING: peak") == 1
    log = (tmp_path / "dataset-messages.log").read_text()
    for i, peak in enumerate(peaks):
        assert f"record {i}:\nWARNING: peak {peak:.4f} m/s^2\n" in log
    assert log.count("Newton failed at t = 0.30 s") == 3


def test_a_split_that_only_collapses_says_so(registry, tmp_path):
    config = cp.parse_config({**CONFIG, "structure": {"name": "toy-collapsing", "limit": 0.0}})
    cp.generate_dataset(config, tmp_path / "dataset.h5", progress=False)
    with pytest.raises(cp.DatasetError, match="collapsed the structure: scale the ground"):
        cp.load_dataset(tmp_path / "dataset.h5").rows("train")


def test_collapsed_flags_must_be_one_bool_per_record():
    with pytest.raises(cp.InputError, match="one flag per record"):
        cp.Responses(np.zeros((2, 5, 1)), 0.01, collapsed=np.array([True]))
    assert cp.Responses(np.zeros((2, 5, 1)), 0.01).collapsed.tolist() == [False, False]


def test_a_record_that_did_not_converge_is_neither_a_failure_nor_a_collapse(
    registry, tmp_path, capsys
):
    source = cp.create("ground_motion", "toy-source", n_steps=60, scale=0.2)
    peaks = np.max(np.abs(source.sample(15, np.random.default_rng(0)).acceleration), axis=1)
    limit = float(np.sort(peaks)[-4])  # three records stop converging
    config = cp.parse_config({**CONFIG, "structure": {"name": "toy-stalling", "limit": limit}})
    pipeline.run(config, tmp_path / "run")  # the default on_failure = "raise" goes on
    data = cp.load_dataset(tmp_path / "run" / "dataset.h5")
    stalled = np.flatnonzero(peaks > limit)
    assert data.failures == {} and not data.collapsed.any()
    assert sorted(data.non_converged) == stalled.tolist()
    assert np.isfinite(data.u[stalled, :30]).all() and np.isnan(data.u[stalled, 30:]).all()
    kept = np.concatenate([data.rows(s) for s in ("train", "val", "test")])
    assert sorted(kept.tolist() + stalled.tolist()) == list(range(15))
    in_test = data.non_converged_rows("test")
    assert in_test.size > 0  # record 12 of the test split stops converging
    left_out = json.loads((tmp_path / "run" / "metrics.json").read_text())["left_out"]
    assert sum(left_out["non_converged"].values()) == 3
    assert left_out["non_converged"]["test"] == in_test.size
    assert sum(left_out["collapsed"].values()) == 0
    report = (tmp_path / "run" / "report.md").read_text()
    assert "3 did not converge below the collapse (a numerical failure)" in report
    assert "non-converged records (below the collapse): 3" in describe_file(
        tmp_path / "run" / "dataset.h5"
    )

    standing = cp.edp.compute(data.targets("test"), registry.create("structure", "toy-storied"),
                              data.motions("test"))  # fmt: skip
    threshold = float(np.median(standing.pid.max(axis=1)))
    arguments = ["fragility", str(tmp_path / "run"), "--records", "10", "--bootstrap", "5",
                 "--limit-states", f"pid={threshold:.6g}"]  # fmt: skip
    documents = {}
    for choice in ("exclude", "collapse"):
        out = tmp_path / choice
        assert main([*arguments, "--non-converged", choice, "--out", str(out)]) == 0
        documents[choice] = json.loads((out / "fragility.json").read_text())
    excluded, counted = documents["exclude"], documents["collapse"]
    assert excluded["non_converged_test_records"] == {"count": int(in_test.size),
                                                      "treated_as": "left out"}  # fmt: skip
    assert counted["non_converged_test_records"]["treated_as"] == "collapse"
    (fit_excluded,), (fit_counted,) = (d["limit_states"].values() for d in (excluded, counted))
    n_test = data.sizes["test"]
    assert fit_excluded["simulation"]["n_records"] == n_test - in_test.size
    assert fit_counted["simulation"]["n_records"] == n_test
    assert main(["demands", str(tmp_path / "run")]) == 0
    lines = (tmp_path / "run" / "demands" / "demands.csv").read_text().splitlines()
    errors = [line.split(",")[-1] for line in lines[2:]]
    assert errors.count("2") == in_test.size and errors.count("1") == 0
