"""Models that learn the structure's named responses (a base shear) beside their
displacements: each response its own group of the loss and its own error table, PR scored
from the predicted histories, and the responses in prediction files, demand samples and
fragility."""

import csv
import json
import shutil
import warnings

import numpy as np
import pytest
import toy_components

import cphysfno_core as cp
from cphysfno_core import edp
from cphysfno_core.api.registry import set_registry
from cphysfno_core.app import pipeline
from cphysfno_core.app.demand_sample import write_demand_sample
from cphysfno_core.app.fragility_study import parse_limit_states, run_fragility
from cphysfno_core.model.prediction_files import predict_file
from cphysfno_core.plugin import Registry

CONFIG = {
    "structure": {"name": "toy-reacting", "cubic": 40.0},
    "ground_motion": {"name": "toy-source", "n_steps": 80, "scale": 0.5},
    "preprocessor": [{"name": "toy-linear"}],
    "operator": {"name": "toy-operator", "width": 4},
    "formulation": {"accelerations": True, "responses": True},
    "data": {"n_train": 8, "n_val": 4, "n_test": 6, "chunk_size": 9, "executor": "serial"},
    "training": {"epochs": 2, "batch_size": 4},
    "output": {"figures": False},
}
C_PHYS = "c-phystoy-operator-toy-linear"


@pytest.fixture(scope="module", autouse=True)
def toys():
    """The toy components for every test of this module (a run is shared between them)."""
    set_registry(Registry(autoload=False, plugins=(toy_components,)))
    yield
    set_registry(None)


@pytest.fixture(scope="module")
def reacting_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("reacting")
    return folder, pipeline.run(cp.parse_config(CONFIG), folder)


def _rel_l2(predicted, truth):
    return np.sqrt(((predicted - truth) ** 2).sum(axis=(0, 1)) / (truth**2).sum(axis=(0, 1)))


def test_a_run_learns_the_named_responses_and_scores_their_peaks(reacting_run):
    folder, evaluation = reacting_run
    document = json.loads((folder / "metrics.json").read_text())
    data = evaluation.data
    truth = data.named_responses("test")["base_shear"]
    model = cp.CompositeModel.load(folder / "models" / C_PHYS)
    assert model.response_names == ("base_shear",)
    stages = model.predict_stages(data.motions("test"), z=data.physics("toy-linear", "test"))
    predicted = stages.responses["base_shear"]
    assert predicted.shape == truth.shape == (6, 80, 1)
    assert stages.extras().keys() == {"absolute_acceleration", "base_shear"}

    row = document["models"][C_PHYS]
    np.testing.assert_allclose(row["responses"]["base_shear"]["rel_l2"], _rel_l2(predicted, truth),
                               rtol=1e-5)  # fmt: skip
    peaks = np.abs(predicted[:, :, 0]).max(axis=1)
    expected = np.median(np.abs(np.log(peaks / np.abs(truth[:, :, 0]).max(axis=1))))
    np.testing.assert_allclose(row["edp"]["PR"]["median"], [expected], rtol=1e-5)
    assert "responses" in document["models"]["toy-operator"]  # the baseline learns them too
    assert "PR" not in document["models"]["physics-toy-linear"]["edp"]  # z has none
    assert {"PR", "PID", "PFA"} <= set(document["baselines"]["baseline-cloud"]["edp"])
    assert "PR" in document["edp"]["edps"] and "PR" not in document["edp"]["not_scored"]

    report = (folder / "report.md").read_text()
    assert "## Named responses (test split)" in report and "base_shear in kN" in report
    assert "### Peak of each named response" in report


def test_the_responses_reach_prediction_files_and_demand_samples(reacting_run, tmp_path):
    folder, evaluation = reacting_run
    data = evaluation.data
    np.save(tmp_path / "ag.npy", data.ag[:3])
    predict_file(folder / "models" / C_PHYS, tmp_path / "ag.npy", tmp_path / "out.npz",
                 dt=data.dt, units="m/s2")  # fmt: skip
    with np.load(tmp_path / "out.npz") as saved:
        assert saved["responses"].shape == (3, 80, 1)
        assert saved["response_names"].tolist() == ["base_shear"]
        assert saved["response_units"].tolist() == ["kN"]
        descriptions = json.loads(str(saved["descriptions"]))
    assert "named responses" in descriptions["responses"][1]

    write_demand_sample(folder, model_label=C_PHYS, out=tmp_path / "d.csv")
    with open(tmp_path / "d.csv", newline="") as f:
        header, units, *rows = list(csv.reader(f))
    column = header.index("1-VB-0-1")
    assert units[column] == "kN"
    written = np.array([float(row[column]) for row in rows])
    model = cp.CompositeModel.load(folder / "models" / C_PHYS)
    shear = model.predict_stages(data.motions("test")).responses["base_shear"]
    np.testing.assert_allclose(written, np.abs(shear[:, :, 0]).max(axis=1), rtol=1e-6)


def test_fragility_on_a_named_response_needs_a_model_that_learns_it(reacting_run):
    folder, _ = reacting_run
    states = parse_limit_states("pr:base_shear=0.5")
    document = run_fragility(folder, limit_states=states, records=40, model_label=C_PHYS,
                             n_bootstrap=5, progress=False)  # fmt: skip
    assert list(document["limit_states"]) == ["pr:base_shear > 0.5"]
    plain = dict(CONFIG, formulation={"accelerations": True})
    with pytest.raises(cp.ConfigError, match="need a model that learns them"):
        _fragility_without_responses(folder, plain, states)


def _fragility_without_responses(folder, config, states):
    """Fragility on PR with a model of the same run trained without named responses."""
    cfg = cp.parse_config(config)
    pipeline.train(cfg, folder.parent / "plain", dataset=folder / "dataset.h5")
    plain = folder / "models" / "plain-model"
    (folder.parent / "plain" / "models" / C_PHYS).rename(plain)
    try:
        run_fragility(folder, limit_states=states, records=20, model_label="plain-model",
                      n_bootstrap=5, progress=False)  # fmt: skip
    finally:
        shutil.rmtree(plain)


def test_named_responses_are_checked_when_a_model_fits():
    rng = np.random.default_rng(0)
    motions = cp.GroundMotions(rng.normal(size=(4, 40)), 0.02)
    u = rng.normal(size=(4, 40, 2))
    shear = {"base_shear": rng.normal(size=(4, 40, 1))}
    learning = cp.compose(operator=("toy-operator", {"width": 4}),
                          formulation={"responses": True})  # fmt: skip
    with pytest.raises(cp.ConfigError, match="give the training records' named responses"):
        learning.fit(motions, u, validation=(motions, u), epochs=1, progress=None)
    with pytest.raises(cp.InputError, match=r"must be \[4, 40, 1\]"):
        learning.fit(motions, u, validation=(motions, u), responses={"base_shear": u},
                     validation_responses=shear, epochs=1, progress=None)  # fmt: skip
    with pytest.raises(cp.ConfigError, match="not those the model learns: base_shear"):
        learning.fit(motions, u, validation=(motions, u), responses=shear,
                     validation_responses={"drift": shear["base_shear"]}, epochs=1,
                     progress=None)  # fmt: skip
    plain = cp.compose(operator=("toy-operator", {"width": 4}))
    with pytest.raises(cp.ConfigError, match="set formulation.responses = true"):
        plain.fit(motions, u, validation=(motions, u), responses=shear, epochs=1, progress=None)


def test_each_named_response_is_its_own_group_of_the_loss(tmp_path):
    rng = np.random.default_rng(1)
    motions = cp.GroundMotions(rng.normal(size=(4, 40)), 0.02)
    u = rng.normal(size=(4, 40, 2))
    responses = {"shear": 1e6 * rng.normal(size=(4, 40, 1)), "force": rng.normal(size=(4, 40, 1))}
    model = cp.compose(operator=("toy-operator", {"width": 4}),
                       formulation={"accelerations": True, "responses": True})  # fmt: skip
    model.fit(motions, u, validation=(motions, u), acceleration=100 * u,
              validation_acceleration=100 * u, responses=responses,
              validation_responses=responses, epochs=1, progress=None)  # fmt: skip
    assert model._groups(2) == (2, 2, 1, 1)
    stages = model.predict_stages(motions)
    assert stages.mean.shape == (4, 40, 2) and stages.acceleration.shape == (4, 40, 2)
    assert list(stages.responses) == ["shear", "force"]
    again = cp.CompositeModel.load(model.save(tmp_path / "m"))
    assert again.response_names == ("shear", "force")
    for name, values in again.predict_stages(motions).responses.items():
        np.testing.assert_allclose(values, stages.responses[name], rtol=1e-6)
    saved = json.loads((tmp_path / "m" / "model.json").read_text())
    saved["responses"] = ["shear"]  # one channel left unaccounted for
    (tmp_path / "m" / "model.json").write_text(json.dumps(saved))
    with pytest.raises(cp.DatasetError, match="output channels are not the model's"):
        cp.CompositeModel.load(tmp_path / "m")
    assert edp.EDP_TABLE["PR"].scored


def test_a_surrogate_whose_pfa_is_differentiated_is_flagged(reacting_run):
    from cphysfno_core.app.fragility_study import surrogate_pfa_source

    folder, _ = reacting_run
    learning = cp.CompositeModel.load(folder / "models" / C_PHYS)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert surrogate_pfa_source(learning, C_PHYS) == "predicted acceleration"
    plain = cp.compose(operator=("toy-operator", {"width": 4}))
    with pytest.warns(cp.CphysfnoWarning, match="second difference of its predicted displ"):
        assert surrogate_pfa_source(plain, "plain") == "displacement"
