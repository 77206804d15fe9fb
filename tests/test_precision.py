"""Predicting in bfloat16: any operator runs under autocast and comes back in float32, with
a warning where the hardware would only emulate it."""

import numpy as np
import pytest
import torch

import cphysfno_core as cp
from cphysfno_core import precision


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
