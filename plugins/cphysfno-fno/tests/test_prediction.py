"""A composite model's prediction with the FNO runs in chunks and equals the unchunked one."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from cphysfno_fno import FNO1d

import cphysfno_core as cp
from cphysfno_core.model import composite

SMALL = dict(layers=2, modes=8, width=16, projection_width=32)


@pytest.fixture(scope="module")
def trained() -> tuple[cp.CompositeModel, cp.GroundMotions]:
    """A baseline FNO on ``[a_g, t]`` trained for two epochs, and 11 motions to predict."""
    rng = np.random.default_rng(0)
    motions = cp.GroundMotions(rng.standard_normal((19, 90)), 0.02)
    u = 0.01 * np.cumsum(motions.acceleration, axis=1)[:, :, None] * [1.0, -0.5]
    torch.manual_seed(0)
    model = cp.compose(operator=FNO1d(2, 2, **SMALL), training={"batch_size": 4})
    model.fit(motions[:6], u[:6], validation=(motions[6:8], u[6:8]), epochs=2, progress=None)
    return model, motions[8:]


def direct_prediction(model: cp.CompositeModel, motions: cp.GroundMotions) -> np.ndarray:
    """The operator on all records at once, with the model's normalisers."""
    x = np.concatenate(
        [
            motions.acceleration[:, :, None],
            np.broadcast_to(motions.time[None, :, None], (11, 90, 1)),
        ],
        axis=2,
    )
    with torch.no_grad():
        y = model.operator_(torch.as_tensor(model.input_normalizer_.encode(x)))
    return model.output_normalizer_.decode_torch(y).double().numpy()


@pytest.mark.parametrize("chunk", [1, 3, 8, 64])
def test_chunked_prediction_equals_one_pass(trained, monkeypatch, chunk: int) -> None:
    model, motions = trained
    monkeypatch.setattr(composite, "PREDICT_CHUNK", chunk)
    stages = model.predict_stages(motions)
    np.testing.assert_allclose(
        stages.operator_output, direct_prediction(model, motions), rtol=1e-5, atol=1e-7
    )
    assert stages.operator_output.dtype == np.float64
    assert stages.mean is stages.operator_output
    np.testing.assert_array_equal(stages.std, np.broadcast_to(model.validation_rmse_, (11, 90, 2)))


def test_inputs_are_built_one_chunk_at_a_time(trained, monkeypatch) -> None:
    model, motions = trained
    monkeypatch.setattr(composite, "PREDICT_CHUNK", 4)
    sizes = []
    build = cp.CompositeModel._inputs

    def recording(self, chunk_motions, z, channels=None):
        sizes.append(chunk_motions.n_records)
        return build(self, chunk_motions, z, channels)

    monkeypatch.setattr(cp.CompositeModel, "_inputs", recording)
    model.predict(motions)
    assert sizes == [4, 4, 3]


def test_a_physics_response_given_to_the_baseline_is_refused(trained) -> None:
    model, motions = trained
    with pytest.raises(cp.InputError, match="has no physics preprocessor"):
        model.predict_stages(motions, z=np.zeros((10, 90, 2)))


def test_bfloat16_prediction_is_close_to_float32(trained) -> None:
    """Opt-in bfloat16 products move the prediction by about bfloat16's rounding (0.2 %),
    far less than the two-epoch model's own error, and only the operator's part of it."""
    model, motions = trained
    single = model.predict_stages(motions)
    low = model.predict_stages(motions, precision="bfloat16")
    change = np.linalg.norm(low.mean - single.mean) / np.linalg.norm(single.mean)
    assert 1e-5 < change < 1e-2
    np.testing.assert_array_equal(low.std, single.std)


def test_unknown_precision_is_refused(trained) -> None:
    model, motions = trained
    with pytest.raises(cp.InputError, match="precision 'float16': choose one of float32, bfloat16"):
        model.predict(motions, precision="float16")
