"""Predicting in bfloat16: any operator runs under autocast and comes back in float32, with
a warning where the hardware would only emulate it."""

import math

import numpy as np
import pytest
import torch
import toy_components
from toy_training import toy_data

import cphysfno_core as cp
from cphysfno_core.config import precision


def test_an_operator_of_plain_modules_predicts_in_bfloat16(trained_toy, monkeypatch):
    model, gm = trained_toy
    dtypes = []
    model.operator_.register_forward_hook(lambda module, args, out: dtypes.append(out.dtype))
    monkeypatch.setattr(precision, "native_bfloat16", lambda device: True)
    single = model.predict_stages(gm).operator_output
    low = model.predict_stages(gm, precision="bfloat16").operator_output
    chunks = len(dtypes) // 2
    assert dtypes == [torch.float32] * chunks + [torch.bfloat16] * chunks
    assert low.dtype == np.float64
    np.testing.assert_allclose(low, single, rtol=0, atol=1e-2 * np.abs(single).max())


def test_emulated_bfloat16_is_warned_about(trained_toy, monkeypatch):
    model, gm = trained_toy
    monkeypatch.setattr(precision, "native_bfloat16", lambda device: False)
    with pytest.warns(cp.CphysfnoWarning, match="cpu has no native bfloat16 arithmetic"):
        mean, _ = model.predict(gm, precision="bfloat16")
    assert np.isfinite(mean).all()


def test_float32_is_not_warned_about(trained_toy, monkeypatch, recwarn):
    model, gm = trained_toy
    monkeypatch.setattr(precision, "native_bfloat16", lambda device: False)
    model.predict(gm)
    assert not [w for w in recwarn if issubclass(w.category, cp.CphysfnoWarning)]


def test_training_in_bfloat16_runs_the_operator_under_autocast(toy_registry, monkeypatch):
    structure, gm, u = toy_data()
    monkeypatch.setattr(precision, "native_bfloat16", lambda device: True)
    seen = []
    forward = toy_components.ToyOperator.forward

    def recording_forward(self, x):
        out = forward(self, x)
        seen.append(out.dtype)
        return out

    monkeypatch.setattr(toy_components.ToyOperator, "forward", recording_forward)
    models, dtypes = {}, {}
    for arithmetic in ("float32", "bfloat16"):
        seen.clear()
        models[arithmetic] = cp.compose(
            structure=structure,
            preprocessor="toy-linear",
            operator="toy-operator",
            training={"batch_size": 3, "seed": 5, "precision": arithmetic},
        )
        models[arithmetic].fit(
            gm[:10], u[:10], validation=(gm[10:], u[10:]), epochs=6, progress=None
        )
        dtypes[arithmetic] = list(seen)
    single, low = models["float32"], models["bfloat16"]
    training_calls = 6 * (math.ceil(10 / 3) + math.ceil(4 / 3))
    assert dtypes["float32"] == [torch.float32] * len(dtypes["float32"])
    assert dtypes["bfloat16"][:training_calls] == [torch.bfloat16] * training_calls
    assert torch.bfloat16 not in dtypes["bfloat16"][training_calls:]
    assert all(p.dtype == torch.float32 for p in low.operator_.parameters())
    assert low.history_.train_loss[-1] < low.history_.train_loss[0]
    np.testing.assert_allclose(low.history_.val_loss, single.history_.val_loss, rtol=0.05)


def test_emulated_bfloat16_training_is_warned_about(toy_registry, monkeypatch):
    monkeypatch.setattr(precision, "native_bfloat16", lambda device: False)
    structure, gm, u = toy_data()
    model = cp.compose(
        structure=structure,
        preprocessor="toy-linear",
        operator="toy-operator",
        training={"precision": "bfloat16"},
    )
    with pytest.warns(cp.CphysfnoWarning, match="cpu has no native bfloat16 arithmetic"):
        model.fit(gm[:10], u[:10], validation=(gm[10:], u[10:]), epochs=1, progress=None)


def test_an_unknown_training_precision_names_the_field():
    with pytest.raises(cp.ConfigError, match="training.precision: Input should be 'float32'"):
        cp.compose(
            structure="toy-structure",
            preprocessor="toy-linear",
            operator="toy-operator",
            training={"precision": "float16"},
        )
