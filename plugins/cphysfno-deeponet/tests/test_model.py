"""DeepONet: shapes at any T, resolution, training on a linear filter, parameter checks."""

from __future__ import annotations

import math

import pytest
import torch
from cphysfno_core import ConfigError, InputError
from cphysfno_core.model.training import relative_l2_loss
from cphysfno_core.plugin import Registry

from cphysfno_deeponet import DeepONet

SMALL = dict(sensors=32, latent=16, branch_width=32, trunk_width=32, fourier_features=4)


@pytest.mark.parametrize("steps", [1, 2, 31, 32, 500])
def test_output_shape_at_any_length(steps: int) -> None:
    model = DeepONet(3, 2, **SMALL)
    out = model(torch.randn(4, steps, 3))
    assert out.shape == (4, steps, 2)
    assert out.dtype == torch.float32


def test_batch_entries_are_independent() -> None:
    torch.manual_seed(1)
    model = DeepONet(3, 2, **SMALL)
    x = torch.randn(5, 50, 3)
    alone = torch.cat([model(x[i : i + 1]) for i in range(5)])
    torch.testing.assert_close(model(x), alone, rtol=1e-5, atol=1e-6)


def smooth(steps: int, phase: float = 0.0) -> torch.Tensor:
    """``[1, steps, 2]``: two smooth functions of ``s in [0, 1]`` (at most 3 cycles)."""
    s = torch.linspace(0.0, 1.0, steps, dtype=torch.float64)
    first = torch.sin(2 * math.pi * s + phase) + 0.5 * torch.cos(6 * math.pi * s)
    second = s**2 - 0.3 * torch.sin(4 * math.pi * s + phase)
    return torch.stack([first, second], dim=-1)[None]


def test_one_function_at_two_resolutions_gives_one_output() -> None:
    torch.manual_seed(2)
    model = DeepONet(2, 3, **SMALL).double()
    coarse = model(smooth(201))
    fine = model(smooth(801))
    difference = (fine[:, ::4] - coarse).abs().max()
    other = (model(smooth(201, phase=1.0)) - coarse).abs().max()
    assert difference < 1e-3 * other


def random_inputs(n: int, steps: int, generator: torch.Generator) -> torch.Tensor:
    """``[n, steps, 1]`` random smooth functions: 6 sinusoids of random amplitude and phase."""
    s = torch.linspace(0.0, 1.0, steps)
    amplitude = torch.randn(n, 1, 6, generator=generator) / torch.arange(1, 7)
    phase = 2 * math.pi * torch.rand(n, 1, 6, generator=generator)
    waves = torch.sin(2 * math.pi * torch.arange(1, 7) * s[None, :, None] + phase)
    return (amplitude * waves).sum(-1, keepdim=True)


def exponential_filter(a: torch.Tensor, decay: float = 6.0) -> torch.Tensor:
    """Causal linear filter ``y_j = sum_{i <= j} exp(-(j - i) / decay) a_i / decay``."""
    steps = a.shape[1]
    lag = torch.arange(steps)[:, None] - torch.arange(steps)[None, :]
    kernel = torch.where(lag >= 0, torch.exp(-lag.clamp_min(0) / decay) / decay, 0.0)
    return torch.einsum("ji,bic->bjc", kernel, a)


def test_learns_a_linear_filter() -> None:
    torch.manual_seed(4)
    generator = torch.Generator().manual_seed(5)
    steps = 64
    a_train, a_test = random_inputs(64, steps, generator), random_inputs(32, steps, generator)
    y_train, y_test = exponential_filter(a_train), exponential_filter(a_test)
    time = torch.linspace(-1.0, 1.0, steps)[None, :, None]
    x_train = torch.cat([a_train, time.expand(64, steps, 1)], dim=-1)
    x_test = torch.cat([a_test, time.expand(32, steps, 1)], dim=-1)
    model = DeepONet(
        2,
        1,
        sensors=steps,
        latent=32,
        branch_width=64,
        branch_layers=1,
        trunk_width=64,
        fourier_features=8,
    )
    optimizer = torch.optim.Adam(model.parameters(), lr=3e-3)
    with torch.no_grad():
        before = relative_l2_loss(model(x_test), y_test).item()
    for _ in range(300):
        optimizer.zero_grad()
        relative_l2_loss(model(x_train), y_train).backward()
        optimizer.step()
    with torch.no_grad():
        after = relative_l2_loss(model(x_test), y_test).item()
    assert before > 0.5
    assert after < 0.12


def test_registry_builds_it_by_name_with_the_documented_defaults() -> None:
    registry = Registry(autoload=True)
    model = registry.create("operator", "deeponet", in_channels=6, out_channels=5)
    assert isinstance(model, DeepONet)
    assert model.get_params() == {
        "sensors": 512,
        "latent": 128,
        "branch_width": 256,
        "branch_layers": 2,
        "trunk_width": 128,
        "trunk_layers": 3,
        "fourier_features": 128,
        "activation": "gelu",
    }


@pytest.mark.parametrize(
    ("hyper", "field"),
    [
        ({"sensors": 1}, "sensors"),
        ({"latent": 0}, "latent"),
        ({"branch_layers": -1}, "branch_layers"),
        ({"fourier_features": -3}, "fourier_features"),
        ({"activation": "sigmoid"}, "activation"),
        ({"width": 16}, "width"),
    ],
)
def test_bad_hyper_names_the_field(hyper: dict, field: str) -> None:
    with pytest.raises(ConfigError, match=rf"deeponet\.{field}:"):
        DeepONet(3, 2, **hyper)


@pytest.mark.parametrize("shape", [(2, 10, 4), (10, 3), (2, 0, 3)])
def test_wrong_input_shape_is_refused(shape: tuple) -> None:
    model = DeepONet(3, 2, **SMALL)
    with pytest.raises(InputError, match=r"\[batch, T, 3\]"):
        model(torch.randn(*shape))
