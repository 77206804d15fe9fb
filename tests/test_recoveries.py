"""What a structure's analyses needed to converge (``Responses.recoveries``): counted at
the end of a generation and kept by record in the dataset."""

import json
import sys

import h5py
import numpy as np
import pytest
import toy_components

import cphysfno_core as cp
from cphysfno_core.app.inspection import describe_file
from cphysfno_core.data.recoveries import convergence_summary
from cphysfno_core.plugin import hookimpl

CONFIG = {
    "ground_motion": {"name": "toy-source", "n_steps": 60, "scale": 0.2},
    "preprocessor": [{"name": "toy-linear"}],
    "operator": {"name": "toy-operator"},
    "data": {"n_train": 8, "n_val": 3, "n_test": 4, "chunk_size": 5, "executor": "serial"},
}


class StrugglingStructure(toy_components.ToyStructure):
    """The toy structure, whose analysis of a record needs substeps where the record's
    peak |a_g| passes ``substeps_above``, a looser test where it passes ``looser_above``,
    and stops converging at the 30th sample where it passes ``stops_above``."""

    name = "toy-struggling"

    class Params(toy_components.ToyStructure.Params):
        substeps_above: float
        looser_above: float
        stops_above: float

    def simulate(self, motions, *, dt=None):
        p = self.params
        displacement = super().simulate(motions).displacement.copy()
        peaks = np.max(np.abs(motions.acceleration), axis=1)
        recoveries = {}
        for i, peak in enumerate(peaks):
            if peak > p.looser_above:
                recoveries[i] = "a looser test"
            elif peak > p.substeps_above:
                recoveries[i] = "substeps dt/4"
        stops = np.flatnonzero(peaks > p.stops_above)
        displacement[stops, 30:] = np.nan
        stopped = {int(i): "did not converge at t = 0.30 s" for i in stops}
        return cp.Responses(displacement, motions.dt, non_converged=stopped, recoveries=recoveries)


@hookimpl
def cphysfno_structures():
    return [StrugglingStructure]


@pytest.fixture
def registry():
    with toy_components.registered(sys.modules[__name__]) as registry:
        yield registry


def test_generation_counts_the_records_by_what_they_needed_and_keeps_it(registry, tmp_path, capsys):
    source = cp.create("ground_motion", "toy-source", n_steps=60, scale=0.2)
    peaks = np.sort(np.max(np.abs(source.sample(15, np.random.default_rng(0)).acceleration), 1))
    # four records need substeps, three a looser test, of which the last stops converging
    structure = {"name": "toy-struggling", "substeps_above": float(peaks[-8]),
                 "looser_above": float(peaks[-4]), "stops_above": float(peaks[-2])}  # fmt: skip
    config = cp.parse_config({**CONFIG, "structure": structure})
    path = tmp_path / "dataset.h5"
    cp.generate_dataset(config, path, progress=True)
    shown = capsys.readouterr().err
    assert (
        "convergence: 8 complete records needed no retry; 4 needed substeps dt/4, "
        "3 needed a looser test"
    ) in shown
    with h5py.File(path, "r") as f:
        recoveries = {int(i): r for i, r in json.loads(f.attrs["recoveries"]).items()}
    peak_of = np.max(np.abs(cp.load_dataset(path).ag), axis=1)
    assert sorted(recoveries) == np.flatnonzero(peak_of > peaks[-8]).tolist()
    assert {i for i, r in recoveries.items() if r == "a looser test"} == set(
        np.flatnonzero(peak_of > peaks[-4]).tolist()
    )
    assert cp.load_dataset(path).recoveries == recoveries
    described = describe_file(path)
    assert "convergence: 8 complete records needed no retry; 4 needed substeps dt/4" in described


def test_a_generation_whose_records_needed_nothing_says_nothing(registry, tmp_path, capsys):
    structure = {"name": "toy-struggling", "substeps_above": 1e9, "looser_above": 1e9,
                 "stops_above": 1e9}  # fmt: skip
    config = cp.parse_config({**CONFIG, "structure": structure})
    cp.generate_dataset(config, tmp_path / "dataset.h5", progress=True)
    assert "convergence:" not in capsys.readouterr().err
    assert convergence_summary({}, np.ones(3, dtype=bool)) == ""


def test_recoveries_must_name_records_of_the_responses():
    with pytest.raises(cp.InputError, match=r"recoveries names records \[2\] outside 0..1"):
        cp.Responses(np.zeros((2, 5, 1)), 0.01, recoveries={2: "substeps dt/2"})
    responses = cp.Responses(np.zeros((2, 5, 1)), 0.01, recoveries={np.int64(1): "Broyden"})
    assert responses.recoveries == {1: "Broyden"}
