"""Models that learn the outputs' absolute accelerations beside their displacements: each
kind weighted on its own in the loss, its own error table, and PFA from the predicted
accelerations rather than from second differences of the predicted displacements."""

import json

import numpy as np
import pytest
import torch

import cphysfno_core as cp
from cphysfno_core import edp
from cphysfno_core.app import pipeline
from cphysfno_core.config import ComponentSpec, FormulationConfig
from cphysfno_core.model.prediction_files import predict_file
from cphysfno_core.model.training import relative_l2_loss

CONFIG = {
    "structure": {"name": "toy-accelerating", "cubic": 40.0},
    "ground_motion": {"name": "toy-source", "n_steps": 80, "scale": 0.5},
    "preprocessor": [{"name": "toy-linear"}],
    "operator": {"name": "toy-operator", "width": 4},
    "refiner": {"name": "toy-refiner"},
    "formulation": {"accelerations": True},
    "data": {"n_train": 8, "n_val": 4, "n_test": 6, "chunk_size": 9, "executor": "serial"},
    "training": {"epochs": 2, "batch_size": 4},
    "output": {"figures": False},
}


def test_the_loss_of_several_kinds_is_the_sum_of_their_own_relative_l2():
    rng = np.random.default_rng(0)
    truth = torch.tensor(rng.normal(size=(3, 20, 4)))
    truth[:, :, 2:] *= 1000.0  # accelerations in m/s^2 beside displacements in m
    prediction = truth + torch.tensor(rng.normal(size=(3, 20, 4)))
    by_kind = [
        relative_l2_loss(prediction[:, :, k : k + 2], truth[:, :, k : k + 2]) for k in (0, 2)
    ]
    grouped = relative_l2_loss(prediction, truth, groups=(2, 2))
    np.testing.assert_allclose(grouped.item(), sum(v.item() for v in by_kind), rtol=1e-12)
    pooled = relative_l2_loss(prediction, truth)
    assert abs(pooled.item() - by_kind[1].item()) < 0.01 * by_kind[0].item()  # one kind rules


def test_a_kind_that_is_zero_throughout_the_batch_adds_nothing_to_the_loss():
    truth = torch.zeros(2, 5, 2, dtype=torch.float64)
    truth[:, :, 0] = torch.tensor([[3.0, 0.0, 0.0, 0.0, 4.0], [0.0, 0.0, 0.0, 0.0, 0.0]])
    prediction = truth.clone()
    prediction[0, 0, 0] = 4.0  # an error of norm 1 against norms 5 and 0: 1 / 5
    prediction[:, :, 1] = 2.0  # a response no record of the batch excites
    loss = relative_l2_loss(prediction, truth, groups=(1, 1))
    assert loss.item() == pytest.approx(0.2, rel=1e-12)


def test_a_run_learns_accelerations_and_takes_pfa_from_them(toy_registry, tmp_path):
    evaluation = pipeline.run(cp.parse_config(CONFIG), tmp_path)
    document = json.loads((tmp_path / "metrics.json").read_text())
    learned = ["toy-operator", "c-phystoy-operator-toy-linear",
               "refined-c-phystoy-operator-toy-linear"]  # fmt: skip
    for label in learned:
        row = document["models"][label]
        assert len(row["acceleration"]["rel_l2"]) == 2 and row["acceleration"]["rmse"][0] > 0
        assert row["pfa_from"] == "predicted acceleration"
    assert document["models"]["physics-toy-linear"]["pfa_from"] == "displacement"

    # the PFA errors are those of the predicted accelerations, on the test records
    data = evaluation.data
    motions = data.motions("test")
    model = cp.CompositeModel.load(tmp_path / "models" / "c-phystoy-operator-toy-linear")
    stages = model.predict_stages(motions, z=data.physics("toy-linear", "test"))
    assert stages.acceleration.shape == stages.mean.shape
    structure = cp.create("structure", "toy-accelerating", cubic=40.0)
    truth = edp.compute(
        cp.Responses(data.targets("test"), data.dt,
                     extras={"absolute_acceleration": data.accelerations("test")}),
        structure, motions,
    )  # fmt: skip
    expected = np.median(
        np.abs(np.log(np.abs(stages.acceleration).max(axis=1) / truth.pfa[:, 1:])), axis=0
    )
    row = document["models"]["c-phystoy-operator-toy-linear"]
    np.testing.assert_allclose(row["edp"]["PFA"]["median"], expected, rtol=1e-5)
    rel = np.sqrt(
        ((stages.acceleration - data.accelerations("test")) ** 2).sum(axis=(0, 1))
        / (data.accelerations("test") ** 2).sum(axis=(0, 1))
    )
    np.testing.assert_allclose(row["acceleration"]["rel_l2"], rel, rtol=1e-5)

    report = (tmp_path / "report.md").read_text()
    assert "## Absolute acceleration (test split)" in report

    # cphysfno predict writes the predicted accelerations beside the displacements
    motions_file = tmp_path / "motions.npz"
    np.savez(motions_file, acceleration=motions.acceleration, dt=motions.dt, units="m/s2")
    folder = tmp_path / "models" / "c-phystoy-operator-toy-linear"
    predict_file(folder, motions_file, tmp_path / "predicted.npz")
    with np.load(tmp_path / "predicted.npz") as written:
        np.testing.assert_allclose(written["acceleration"], stages.acceleration, rtol=1e-6)
    assert "comes from the accelerations they predict" in report


def test_accelerations_need_a_structure_that_records_them(toy_registry, tmp_path):
    config = cp.parse_config({**CONFIG, "structure": {"name": "toy-storied"}})
    pipeline.generate(config, tmp_path)
    with pytest.raises(cp.DatasetError, match="no 'absolute_acceleration' channel"):
        pipeline.train(config, tmp_path)


def test_a_model_refuses_accelerations_it_does_not_learn_and_wants_those_it_does(toy_registry):
    source = cp.create("ground_motion", "toy-source", n_steps=40)
    motions = source.sample(4, np.random.default_rng(0))
    structure = cp.create("structure", "toy-accelerating")
    responses = structure.simulate(motions)
    u, a = responses.displacement, responses.extras["absolute_acceleration"]
    plain = cp.CompositeModel(ComponentSpec.of("toy-operator", {"width": 2}))
    with pytest.raises(cp.ConfigError, match="does not learn them"):
        plain.fit(motions, u, (motions, u), acceleration=a, validation_acceleration=a)
    learning = cp.CompositeModel(
        ComponentSpec.of("toy-operator", {"width": 2}),
        formulation=FormulationConfig(accelerations=True),
    )
    with pytest.raises(cp.ConfigError, match="give the training records' absolute"):
        learning.fit(motions, u, (motions, u))
    learning.fit(motions, u, (motions, u), acceleration=a, validation_acceleration=a,
                 epochs=1, progress=None)  # fmt: skip
    assert learning.predict_stages(motions).acceleration.shape == u.shape
