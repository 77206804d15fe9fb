"""Where the operator trains and predicts: ``training.device``, checked before any work,
and a model's predictions the same wherever its operator sits."""

import platform

import numpy as np
import pytest
import torch

import cphysfno_core as cp
from cphysfno_core.config import TrainingConfig
from cphysfno_core.model.training import describe_device, resolve_device

CUDA = torch.cuda.is_available()


@pytest.fixture
def toy_model(toy_records):
    structure, gm, u = toy_records
    model = cp.compose(structure=structure, preprocessor="toy-linear", operator="toy-operator")
    return model, gm, u


@pytest.mark.parametrize("name", ["auto", "cpu", "cuda", "cuda:1", "mps"])
def test_device_names_are_validated_by_the_config(name):
    assert TrainingConfig(device=name).device == name


@pytest.mark.parametrize("name", ["gpu", "cuda:x", "CPU", ""])
def test_unknown_device_names_are_refused_naming_the_field(name):
    with pytest.raises(cp.ConfigError, match="training.device"):
        cp.parse_config(
            {
                "structure": {"name": "s"},
                "ground_motion": {"name": "g"},
                "training": {"device": name},
            }
        )


def test_auto_is_the_gpu_when_torch_sees_one_else_the_cpu():
    assert resolve_device("auto").type == ("cuda" if CUDA else "cpu")
    assert resolve_device("cpu") == torch.device("cpu")


def test_a_gpu_that_is_not_there_is_refused_before_training(toy_model):
    model, gm, u = toy_model
    fit = dict(validation=(gm[8:], u[8:]), epochs=1, progress=None, device="cuda:7")
    if torch.cuda.device_count() > 7:
        assert model.fit(gm[:8], u[:8], **fit).device == torch.device("cuda:7")
        return
    with pytest.raises(cp.ConfigError, match="training.device = 'cuda:7'"):
        model.fit(gm[:8], u[:8], **fit)
    assert not hasattr(model, "history_")


def test_predictions_do_not_depend_on_where_the_operator_sits(toy_model):
    model, gm, u = toy_model
    model.fit(gm[:8], u[:8], validation=(gm[8:], u[8:]), epochs=2, progress=None, device="auto")
    assert model.device == resolve_device("auto")
    assert model.history_.device == describe_device(model.device)
    threads = torch.get_num_threads()
    processor = platform.processor() or platform.machine()
    try:
        for count, words in ((2, "2 threads"), (1, "1 thread")):
            torch.set_num_threads(count)
            assert describe_device(torch.device("cpu")) == f"CPU ({processor}, {words})"
    finally:
        torch.set_num_threads(threads)
    here = model.predict(gm[8:])
    moved = model.to("cpu")
    assert moved is model and model.device == torch.device("cpu")
    np.testing.assert_allclose(model.predict(gm[8:]), here, rtol=1e-5, atol=1e-9)


def test_an_untrained_model_has_no_device(toy_model):
    model, _, _ = toy_model
    with pytest.raises(cp.NotFittedError):
        model.to("cpu")


def test_where_a_model_trained_is_saved_with_it(toy_model, tmp_path):
    model, gm, u = toy_model
    model.fit(gm[:8], u[:8], validation=(gm[8:], u[8:]), epochs=1, progress=None, device="cpu")
    loaded = cp.CompositeModel.load(model.save(tmp_path / "m"))
    assert loaded.history_.device == model.history_.device
    assert loaded.history_.device.startswith("CPU (")
    assert loaded.device == torch.device("cpu")
