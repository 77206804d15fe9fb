"""FNO1d: shapes at any T, training, save/load, registry and parameter validation."""

from __future__ import annotations

import io

import pytest
import torch
from cphysfno_fno import FNO1d

from cphysfno_core import ConfigError, InputError
from cphysfno_core.plugin import Registry

SMALL = dict(layers=2, modes=8, width=16, projection_width=32)


@pytest.fixture(scope="module")
def registry() -> Registry:
    return Registry(autoload=True)


def test_output_shape_at_two_lengths_with_one_module() -> None:
    torch.manual_seed(0)
    model = FNO1d(6, 5)
    for steps in (3001, 500):
        out = model(torch.randn(2, steps, 6))
        assert out.shape == (2, steps, 5)
        assert out.dtype == torch.float32


@pytest.mark.parametrize("steps", [1, 2, 5, 9])
def test_fewer_samples_than_modes(steps: int) -> None:
    model = FNO1d(2, 3, **SMALL)
    assert model(torch.randn(3, steps, 2)).shape == (3, steps, 3)


def test_batch_entries_are_independent() -> None:
    torch.manual_seed(1)
    model = FNO1d(3, 2, **SMALL)
    x = torch.randn(4, 50, 3)
    together = model(x)
    alone = torch.cat([model(x[i : i + 1]) for i in range(4)])
    torch.testing.assert_close(together, alone, rtol=1e-5, atol=1e-6)


def reference_forward(model: FNO1d, x: torch.Tensor) -> torch.Tensor:
    """FNO1d of Li et al. written channels-first with torch.fft, from ``model``'s weights."""
    act = {"gelu": torch.nn.functional.gelu, "relu": torch.relu}[model.params.activation]
    steps = x.shape[1]
    v = torch.nn.functional.linear(x, model.lifting.weight, model.lifting.bias).permute(0, 2, 1)
    v = torch.nn.functional.pad(v, [0, model.params.padding])
    n = v.shape[-1]
    for index, layer in enumerate(model.layers):
        m = min(model.params.modes, n // 2 + 1)
        weight = torch.complex(layer.spectral.weight_real, layer.spectral.weight_imag)[:m]
        v_ft = torch.fft.rfft(v)
        out_ft = torch.zeros_like(v_ft)
        out_ft[..., :m] = torch.einsum("bik,kio->bok", v_ft[..., :m], weight)
        pointwise = torch.nn.functional.conv1d(
            v, layer.pointwise.weight[..., None], layer.pointwise.bias
        )
        v = torch.fft.irfft(out_ft, n=n) + pointwise
        if index < len(model.layers) - 1 or model.params.activate_last_layer:
            v = act(v)
    v = v[..., :steps].permute(0, 2, 1)
    v = act(
        torch.nn.functional.linear(v, model.projection_hidden.weight, model.projection_hidden.bias)
    )
    return torch.nn.functional.linear(v, model.projection_out.weight, model.projection_out.bias)


@pytest.mark.parametrize(
    "hyper",
    [
        {},
        {"activation": "relu", "padding": 7},
        {"modes": 40, "padding": 3, "layers": 3},
        {"activation": "relu", "activate_last_layer": True, "init": "glorot"},
    ],
)
def test_equals_channels_first_fft_reference(hyper: dict) -> None:
    torch.manual_seed(2)
    model = FNO1d(3, 2, **{**SMALL, **hyper}).double()
    with torch.no_grad():
        for layer in model.layers:
            layer.spectral.weight_real.normal_(std=0.1)
            layer.spectral.weight_imag.normal_(std=0.1)
    x = torch.randn(2, 61, 3, dtype=torch.float64)
    torch.testing.assert_close(model(x), reference_forward(model, x), rtol=1e-10, atol=1e-10)


def test_activating_the_last_layer_changes_the_output() -> None:
    torch.manual_seed(6)
    plain = FNO1d(3, 2, **SMALL, activation="relu")
    activated = FNO1d(3, 2, **SMALL, activation="relu", activate_last_layer=True)
    activated.load_state_dict(plain.state_dict())
    x = torch.randn(2, 40, 3)
    assert not torch.allclose(plain(x), activated(x))


def test_glorot_init_bounds_weights_and_zeroes_biases() -> None:
    torch.manual_seed(7)
    model = FNO1d(3, 2, **SMALL, init="glorot")
    linears = [m for m in model.modules() if isinstance(m, torch.nn.Linear)]
    assert len(linears) == 2 + SMALL["layers"] + 1
    for linear in linears:
        fan_out, fan_in = linear.weight.shape
        bound = (6.0 / (fan_in + fan_out)) ** 0.5
        assert linear.weight.abs().max() <= bound
        assert linear.weight.abs().max() > 0.5 * bound
        assert torch.count_nonzero(linear.bias) == 0
    torch.manual_seed(7)
    default = FNO1d(3, 2, **SMALL)
    assert torch.count_nonzero(default.lifting.bias) > 0
    torch.testing.assert_close(
        model.layers[0].spectral.weight_real, default.layers[0].spectral.weight_real
    )


def test_overfits_a_few_samples() -> None:
    torch.manual_seed(3)
    t = torch.linspace(0.0, 1.0, 64)[:, None]
    frequency = torch.arange(1, 5)[:, None, None]
    a = torch.randn(4, 1, 1) * torch.sin(2 * torch.pi * frequency * t)
    x = torch.cat([a, t.expand(4, 64, 1)], dim=-1)
    y = torch.tanh(2.0 * a) + 0.5 * torch.cumsum(a, dim=1) / 64
    model = FNO1d(2, 1, **SMALL)
    optimizer = torch.optim.Adam(model.parameters(), lr=1e-2)
    losses = []
    for _ in range(40):
        optimizer.zero_grad()
        loss = torch.linalg.vector_norm(model(x) - y) / torch.linalg.vector_norm(y)
        loss.backward()
        optimizer.step()
        losses.append(loss.item())
    assert losses[-1] < 0.2 * losses[0]


def test_every_parameter_receives_a_gradient() -> None:
    torch.manual_seed(4)
    model = FNO1d(2, 2, **SMALL)
    model(torch.randn(2, 40, 2)).square().sum().backward()
    for name, parameter in model.named_parameters():
        assert parameter.grad is not None and parameter.grad.abs().sum() > 0, name


def test_training_after_inference_mode_evaluation() -> None:
    model = FNO1d(2, 2, **SMALL)
    x = torch.randn(2, 37, 2)
    with torch.inference_mode():
        model(x)
    model(x).sum().backward()
    assert model.layers[0].spectral.weight_real.grad is not None


def test_state_dict_holds_only_parameters() -> None:
    model = FNO1d(6, 5, **SMALL)
    model(torch.randn(1, 20, 6))
    state = model.state_dict()
    assert set(state) == {name for name, _ in model.named_parameters()}
    assert all(isinstance(value, torch.Tensor) for value in state.values())


def test_save_and_rebuild_from_name_and_params(registry: Registry) -> None:
    torch.manual_seed(5)
    model = registry.create("operator", "fno", in_channels=6, out_channels=5, **SMALL, padding=4)
    buffer = io.BytesIO()
    torch.save(model.state_dict(), buffer)
    buffer.seek(0)
    params = model.get_params()
    torch.manual_seed(6)
    rebuilt = registry.create("operator", "fno", in_channels=6, out_channels=5, **params)
    rebuilt.load_state_dict(torch.load(buffer, weights_only=True))
    x = torch.randn(3, 77, 6)
    assert torch.equal(model(x), rebuilt(x))


def test_registry_creates_fno_by_name(registry: Registry) -> None:
    assert registry.get("operator", "fno") is FNO1d
    model = registry.create("operator", "fno", in_channels=2, out_channels=5)
    assert isinstance(model, FNO1d)
    assert model.get_params() == {
        "layers": 6,
        "modes": 32,
        "width": 64,
        "projection_width": 128,
        "activation": "gelu",
        "activate_last_layer": False,
        "init": "torch",
        "padding": 0,
    }


@pytest.mark.parametrize(
    ("hyper", "field"),
    [
        ({"modes": 0}, "modes"),
        ({"layers": -1}, "layers"),
        ({"width": 0}, "width"),
        ({"padding": -2}, "padding"),
        ({"activation": "tanh"}, "activation"),
        ({"mode": 16}, "mode"),
    ],
)
def test_bad_hyper_names_the_field(hyper: dict, field: str) -> None:
    with pytest.raises(ConfigError, match=rf"fno\.{field}:"):
        FNO1d(6, 5, **hyper)


def test_wrong_input_channels() -> None:
    model = FNO1d(6, 5, **SMALL)
    with pytest.raises(InputError, match=r"\[batch, T, 6\].*\(2, 10, 4\)"):
        model(torch.randn(2, 10, 4))
