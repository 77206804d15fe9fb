"""bfloat16 products and the FNO under ``torch.autocast``: lower precision where it is asked
for, float32 at the ends, and errors of the size bfloat16 rounding explains."""

from __future__ import annotations

import numpy as np
import torch
from cphysfno_fno import FNO1d
from cphysfno_fno import dense as dense_module
from cphysfno_fno.dense import add_product_, dense, product, uses_onednn
from cphysfno_fno.fused import fourier_layer

from cphysfno_core.config import TrainingConfig
from cphysfno_core.model.training import Normalizer, train_operator

BFLOAT16_STEP = 2.0**-7
"""Spacing of bfloat16 numbers relative to their value, at most (8-bit significand)."""


def assert_rounded(low: torch.Tensor, exact: torch.Tensor) -> None:
    """``low`` (bfloat16) is ``exact`` rounded once, give or take float32 accumulation."""
    assert low.dtype == torch.bfloat16
    error = (low.double() - exact).abs()
    bound = 0.5 * BFLOAT16_STEP * exact.abs() + 1e-5 * exact.abs().max()
    assert (error <= bound).all()


def test_bfloat16_goes_through_onednn_where_the_cpu_computes_in_it() -> None:
    x = torch.randn(10, 8, dtype=torch.bfloat16)
    assert uses_onednn(x, 64) == torch.ops.mkldnn._is_mkldnn_bf16_supported()


def test_bfloat16_products_are_one_rounding_from_exact() -> None:
    """Products of bfloat16 numbers accumulate in float32, the tensor a product is added
    into included, and round once at the end: each entry is the exact result rounded once."""
    generator = torch.Generator().manual_seed(5)

    def draw(*shape: int) -> torch.Tensor:
        return torch.randn(shape, generator=generator).bfloat16()

    field, basis, spectrum, start = draw(997, 192), draw(40, 997), draw(40, 192), draw(997, 192)
    weight, bias = draw(64, 192), draw(64)
    assert_rounded(product(basis, field), basis.double() @ field.double())
    pointwise = field.double() @ weight.double().t() + bias.double()
    assert_rounded(dense(field, weight, bias), pointwise)
    exact = basis.double().t() @ spectrum.double() + start.double()
    assert_rounded(add_product_(start.clone(), basis.t(), spectrum), exact)


def fno_and_input() -> tuple[FNO1d, torch.Tensor]:
    torch.manual_seed(3)
    model = FNO1d(4, 3, layers=3, modes=16, width=32, projection_width=32).eval()
    return model, torch.randn(2, 500, 4)


def test_fno_under_autocast_computes_its_layers_in_bfloat16() -> None:
    model, x = fno_and_input()
    seen = []
    model.layers[0].register_forward_hook(lambda module, args, out: seen.append(out.dtype))
    with torch.no_grad():
        single = model(x)
        with torch.autocast("cpu", dtype=torch.bfloat16):
            low = model(x)
        again = model(x)
    assert seen == [torch.float32, torch.bfloat16, torch.float32]
    assert low.dtype == torch.float32
    torch.testing.assert_close(again, single, rtol=0, atol=0)
    relative = ((low - single).norm() / single.norm()).item()
    assert 1e-4 < relative < 2e-2


def test_fno_under_autocast_leaves_the_prediction_unrounded() -> None:
    """The projection's output layer runs in float32: nearly every output lies between
    bfloat16 numbers."""
    model, x = fno_and_input()
    with torch.no_grad(), torch.autocast("cpu", dtype=torch.bfloat16):
        low = model(x)
    off_grid = (low != low.bfloat16().float()).float().mean().item()
    assert off_grid > 0.9


def test_fno_under_autocast_without_onednn_bfloat16(monkeypatch) -> None:
    """On a CPU without native bfloat16 the products go through torch's matmul instead:
    the same numbers to within bfloat16 rounding."""
    model, x = fno_and_input()
    with torch.no_grad(), torch.autocast("cpu", dtype=torch.bfloat16):
        native = model(x)
        monkeypatch.setattr(dense_module, "_ONEDNN_DTYPES", (torch.float32,))
        assert not uses_onednn(x.bfloat16(), 64)
        fallback = model(x)
    assert ((fallback - native).norm() / native.norm()).item() < 1e-2


def test_bfloat16_fourier_layer_mixes_modes_in_the_spectral_weights_dtype() -> None:
    """A bfloat16 field with float32 spectral weights: the output is bfloat16 and close to
    the float32 layer's, and the spectral weights' gradients come back in float32."""
    generator = torch.Generator().manual_seed(2)
    v = torch.randn(300, 2, 16, generator=generator)
    weight, bias = (
        torch.randn(16, 16, generator=generator) / 4,
        torch.randn(16, generator=generator),
    )
    spectral = [
        (torch.randn(8, 16, 16, generator=generator) / 16).requires_grad_() for _ in range(2)
    ]
    single = fourier_layer(v, weight, bias, *spectral)
    low = fourier_layer(v.bfloat16(), weight.bfloat16(), bias.bfloat16(), *spectral)
    assert low.dtype == torch.bfloat16
    assert ((low.float() - single).norm() / single.norm()).item() < 1e-2
    low.float().square().sum().backward()
    assert all(w.grad is not None and w.grad.dtype == torch.float32 for w in spectral)


def test_training_in_bfloat16_learns_as_float32_does() -> None:
    """An FNO trained with ``precision = "bfloat16"`` learns a causal smoothing filter as
    well as in float32: the gradients' rounding does not show in the validation error."""
    rng = np.random.default_rng(3)
    x = rng.standard_normal((64, 256, 1))
    kernel = np.exp(-np.arange(40) / 8.0)
    y = np.stack([np.convolve(r[:, 0], kernel)[:256] for r in x])[..., None] / 4.0
    t = np.broadcast_to(np.linspace(0.0, 1.0, 256)[None, :, None], x.shape)
    inputs = np.concatenate([x, t], axis=2).astype(np.float32)
    histories = {}
    for precision in ("float32", "bfloat16"):
        torch.manual_seed(0)
        operator = FNO1d(2, 1, layers=2, modes=64, width=16, projection_width=32)
        settings = TrainingConfig(
            epochs=25,
            batch_size=8,
            learning_rate=1e-2,
            decay_step=10,
            precision=precision,
            device="cpu",
        )
        histories[precision] = train_operator(
            operator,
            inputs[:48],
            y[:48],
            inputs[48:],
            y[48:],
            Normalizer(np.zeros(1), np.ones(1)),
            settings,
            progress=None,
        )
        assert all(p.dtype == torch.float32 for p in operator.parameters())
    single, low = min(histories["float32"].val_loss), min(histories["bfloat16"].val_loss)
    assert single < 0.3 * histories["float32"].val_loss[0]
    assert low <= 1.1 * single + 0.005, (low, single)
