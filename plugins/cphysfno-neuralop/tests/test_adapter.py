"""The adapter computes the paper's FNO, at any T, trains, and saves without metadata."""

from __future__ import annotations

import io
import sys

import cphysfno_core as cp
import numpy as np
import pytest
import torch
from cphysfno_core import ConfigError, InputError, PluginError
from cphysfno_core.model.training import relative_l2_loss
from cphysfno_core.plugin import Registry
from cphysfno_fno import FNO1d

from cphysfno_neuralop import NeuralopFNO

SMALL = dict(layers=3, modes=8, width=16, projection_width=32)


def copy_weights(source: FNO1d, target: NeuralopFNO) -> None:
    """Load the built-in FNO's weights into the adapter's neuralop model."""
    fno = target.fno
    with torch.no_grad():
        fno.lifting.fcs[0].weight.copy_(source.lifting.weight[:, :, None])
        fno.lifting.fcs[0].bias.copy_(source.lifting.bias)
        for index, layer in enumerate(source.layers):
            spectral = torch.complex(layer.spectral.weight_real, layer.spectral.weight_imag)
            fno.fno_blocks.convs[index].weight.tensor.copy_(spectral.permute(1, 2, 0))
            fno.fno_blocks.convs[index].bias.copy_(layer.pointwise.bias[:, None])
            fno.fno_blocks.fno_skips[index].conv.weight.copy_(layer.pointwise.weight[:, :, None])
        fno.projection.fcs[0].weight.copy_(source.projection_hidden.weight[:, :, None])
        fno.projection.fcs[0].bias.copy_(source.projection_hidden.bias)
        fno.projection.fcs[1].weight.copy_(source.projection_out.weight[:, :, None])
        fno.projection.fcs[1].bias.copy_(source.projection_out.bias)


def fno_pair(activation: str) -> tuple[FNO1d, NeuralopFNO]:
    """A built-in FNO with random spectral weights and the adapter holding its weights."""
    torch.manual_seed(0)
    builtin = FNO1d(3, 2, **SMALL, activation=activation)
    with torch.no_grad():
        for layer in builtin.layers:
            layer.spectral.weight_real.normal_(std=0.2)
            layer.spectral.weight_imag.normal_(std=0.2)
    adapter = NeuralopFNO(3, 2, **SMALL, activation=activation)
    copy_weights(builtin, adapter)
    return builtin, adapter


def assert_close(actual: torch.Tensor, expected: torch.Tensor) -> None:
    scale = float(expected.abs().max())
    torch.testing.assert_close(actual, expected, rtol=1e-4, atol=1e-5 * scale)


@pytest.mark.parametrize("steps", [64, 101, 9])
def test_relu_adapter_computes_the_builtin_fno(steps: int) -> None:
    builtin, adapter = fno_pair("relu")
    x = torch.randn(4, steps, 3)
    with torch.no_grad():
        assert_close(adapter(x), builtin(x))


def test_gelu_adapter_applies_gelu_twice_between_fourier_layers() -> None:
    builtin, adapter = fno_pair("gelu")
    x = torch.randn(4, 64, 3)
    gelu = torch.nn.functional.gelu
    with torch.no_grad():
        v = builtin.lifting(x).transpose(0, 1)
        for index, layer in enumerate(builtin.layers):
            v = layer(v)
            if index < len(builtin.layers) - 1:
                v = gelu(gelu(v))
        v = gelu(builtin.projection_hidden(v))
        expected = builtin.projection_out(v).transpose(0, 1)
        actual = adapter(x)
        assert_close(actual, expected)
        assert (actual - builtin(x)).abs().max() > 1e-3 * expected.abs().max()


def test_keeps_the_lowest_modes_like_the_builtin_fno() -> None:
    adapter = NeuralopFNO(3, 2, **SMALL)
    for conv in adapter.fno.fno_blocks.convs:
        assert conv.weight.tensor.shape == (16, 16, 8)


@pytest.mark.parametrize("steps", [1, 2, 15, 500])
def test_output_shape_at_any_length(steps: int) -> None:
    model = NeuralopFNO(3, 2, **SMALL, domain_padding=0.25)
    assert model(torch.randn(2, steps, 3)).shape == (2, steps, 2)


def test_state_dict_holds_the_learned_tensors_only() -> None:
    model = NeuralopFNO(3, 2, **SMALL)
    state = model.state_dict()
    assert set(state) == {name for name, _ in model.named_parameters()}
    buffer = io.BytesIO()
    torch.save(state, buffer)
    buffer.seek(0)
    rebuilt = NeuralopFNO(3, 2, **SMALL)
    rebuilt.load_state_dict(torch.load(buffer, weights_only=True))
    x = torch.randn(2, 30, 3)
    assert torch.equal(model(x), rebuilt(x))


def test_learns_a_nonlinear_map() -> None:
    torch.manual_seed(3)
    t = torch.linspace(0.0, 1.0, 64)[:, None]
    a = torch.randn(8, 1, 1) * torch.sin(2 * torch.pi * torch.arange(1, 9)[:, None, None] * t)
    x = torch.cat([a, t.expand(8, 64, 1)], dim=-1)
    y = torch.tanh(2.0 * a) + 0.5 * torch.cumsum(a, dim=1) / 64
    model = NeuralopFNO(2, 1, layers=2, modes=16, width=16, projection_width=32)
    optimizer = torch.optim.Adam(model.parameters(), lr=1e-2)
    losses = []
    for _ in range(60):
        optimizer.zero_grad()
        loss = relative_l2_loss(model(x), y)
        loss.backward()
        optimizer.step()
        losses.append(loss.item())
    assert losses[-1] < 0.2 * losses[0]


def test_composite_model_trains_saves_and_loads_it_by_name(tmp_path) -> None:
    rng = np.random.default_rng(0)
    motions = cp.GroundMotions(rng.standard_normal((14, 80)), 0.02)
    u = 0.01 * np.cumsum(motions.acceleration, axis=1)[:, :, None] * [1.0, -0.5]
    model = cp.compose(operator=("neuralop-fno", SMALL), training={"batch_size": 4})
    model.fit(motions[:8], u[:8], validation=(motions[8:11], u[8:11]), epochs=3, progress=None)
    assert model.history_.train_loss[-1] < model.history_.train_loss[0]
    mean, _ = model.predict(motions[11:])
    loaded = cp.CompositeModel.load(model.save(tmp_path / "model"))
    assert loaded.label == "neuralop-fno"
    np.testing.assert_array_equal(loaded.predict(motions[11:])[0], mean)


def test_registry_builds_it_by_name() -> None:
    model = Registry(autoload=True).create(
        "operator", "neuralop-fno", in_channels=2, out_channels=5
    )
    assert isinstance(model, NeuralopFNO)
    assert model.fno.n_layers == 6 and model.fno.hidden_channels == 64
    assert model.fno.positional_embedding is None and not model.fno.fno_blocks.use_channel_mlp


@pytest.mark.parametrize(
    ("hyper", "field"),
    [
        ({"modes": 0}, "modes"),
        ({"domain_padding": -0.1}, "domain_padding"),
        ({"positional_embedding": "sine"}, "positional_embedding"),
        ({"n_modes": 16}, "n_modes"),
    ],
)
def test_bad_hyper_names_the_field(hyper: dict, field: str) -> None:
    with pytest.raises(ConfigError, match=rf"neuralop-fno\.{field}:"):
        NeuralopFNO(3, 2, **hyper)


def test_wrong_input_is_refused() -> None:
    with pytest.raises(InputError, match=r"\[batch, T, 3\].*\(2, 10, 4\)"):
        NeuralopFNO(3, 2, **SMALL)(torch.randn(2, 10, 4))


def test_missing_library_is_named(monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "neuralop.models", None)
    with pytest.raises(PluginError, match=r"pip install 'neuraloperator>=2.0,<2.1'"):
        NeuralopFNO(3, 2)
