"""The hand-written Fourier layer and pointwise maps against autograd over plain torch ops."""

from __future__ import annotations

import pytest
import torch
from cphysfno_fno import FNO1d, SpectralConv1d
from cphysfno_fno.dense import (
    ONEDNN_MIN_OUT,
    add_product_,
    dense,
    pointwise_linear,
    product,
    uses_onednn,
    weight_gradient,
)
from cphysfno_fno.fused import fourier_layer


def layer_tensors(n: int, batch: int, width: int, modes: int, dtype: torch.dtype) -> list:
    """``v, W, b, R_re, R_im`` with gradients, drawn so that every term is of order one."""
    generator = torch.Generator().manual_seed(n + modes)
    shapes = [(n, batch, width), (width, width), (width,), (modes, width, width)]
    shapes.append(shapes[-1])
    return [
        (torch.randn(shape, generator=generator, dtype=dtype) / (1 if i == 0 else width**0.5))
        .detach()
        .requires_grad_()
        for i, shape in enumerate(shapes)
    ]


def reference_layer(v, weight, bias, weight_real, weight_imag) -> torch.Tensor:
    """``K v + v Wᵀ + b`` through SpectralConv1d and F.linear, differentiated by autograd."""
    conv = SpectralConv1d(v.shape[-1], weight.shape[0], weight_real.shape[0])
    spectral = {"weight_real": weight_real, "weight_imag": weight_imag}
    add = torch.nn.functional.linear(v, weight, bias)
    return torch.func.functional_call(conv, spectral, (v,), {"add": add})


def gradients(function, tensors: list, weight: torch.Tensor) -> list[torch.Tensor]:
    out = function(*tensors)
    return [out, *torch.autograd.grad((out * weight).sum(), tensors)]


@pytest.mark.parametrize(("n", "modes"), [(61, 8), (60, 40), (7, 12)])
def test_forward_and_every_gradient_equal_autograd_reference(n: int, modes: int) -> None:
    tensors = layer_tensors(n, 3, 5, modes, torch.float64)
    weight = torch.randn(n, 3, 5, dtype=torch.float64)
    fused = gradients(fourier_layer, tensors, weight)
    expected = gradients(reference_layer, tensors, weight)
    for name, a, b in zip(["out", "v", "W", "b", "R_re", "R_im"], fused, expected, strict=True):
        torch.testing.assert_close(a, b, rtol=1e-10, atol=1e-10, msg=name)


def test_gradcheck() -> None:
    tensors = layer_tensors(13, 2, 3, 4, torch.float64)
    assert torch.autograd.gradcheck(fourier_layer, tensors)


def test_float32_forward_and_gradients_close_to_float64() -> None:
    tensors = layer_tensors(3001, 2, 64, 32, torch.float32)
    weight = torch.randn(3001, 2, 64)
    single = gradients(fourier_layer, tensors, weight)
    doubled = [t.detach().double().requires_grad_() for t in tensors]
    expected = gradients(reference_layer, doubled, weight.double())
    for name, a, b in zip(["out", "v", "W", "b", "R_re", "R_im"], single, expected, strict=True):
        assert (a.double() - b).abs().max() < 1e-5 * b.abs().max(), name


def test_only_requested_gradients_are_computed() -> None:
    v, weight, bias, weight_real, weight_imag = layer_tensors(20, 2, 4, 6, torch.float64)
    v = v.detach()
    out = fourier_layer(v, weight, bias, weight_real, weight_imag)
    out.sum().backward()
    assert v.grad is None and weight.grad is not None and bias.grad is not None


@pytest.mark.parametrize("out_features", [ONEDNN_MIN_OUT - 1, ONEDNN_MIN_OUT, 64])
@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_dense_equals_addmm(out_features: int, dtype: torch.dtype) -> None:
    x = torch.randn(500, 48, dtype=dtype)
    weight = torch.randn(out_features, 48, dtype=dtype)
    bias = torch.randn(out_features, dtype=dtype)
    tolerance = 1e-5 if dtype == torch.float32 else 1e-12
    torch.testing.assert_close(
        dense(x, weight, bias), torch.addmm(bias, x, weight.t()), rtol=tolerance, atol=tolerance
    )
    torch.testing.assert_close(dense(x, weight), x @ weight.t(), rtol=tolerance, atol=tolerance)
    torch.testing.assert_close(
        dense(x, weight.t().contiguous().t()), x @ weight.t(), rtol=tolerance, atol=tolerance
    )


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
@pytest.mark.parametrize("contiguous_basis", [True, False])
def test_product_and_add_product_equal_mm_for_transform_shapes(
    dtype: torch.dtype, contiguous_basis: bool
) -> None:
    """Both transform shapes: ``[2m, T] @ [T, columns]`` and ``[T, 2m] @ [2m, columns]``,
    the basis contiguous or a transposed view (as in the backward pass)."""
    generator = torch.Generator().manual_seed(3)
    basis = torch.randn(40, 997, dtype=dtype, generator=generator)
    basis = basis if contiguous_basis else basis.t().contiguous().t()
    field = torch.randn(997, 3 * 64, dtype=dtype, generator=generator)
    spectrum = torch.randn(40, 3 * 64, dtype=dtype, generator=generator)
    tolerance = {"rtol": 1e-5, "atol": 1e-4} if dtype == torch.float32 else {}
    assert uses_onednn(basis, field.shape[1]) == (dtype == torch.float32)
    for a, b in [(basis, field), (basis.t(), spectrum)]:
        expected = (a.double() @ b.double()).to(dtype)
        torch.testing.assert_close(product(a, b), expected, **tolerance)
        start = torch.randn(expected.shape, dtype=dtype, generator=generator)
        out = start.clone()
        assert add_product_(out, a, b) is out
        torch.testing.assert_close(out, start + expected, **tolerance)


@pytest.mark.parametrize("n_rows", [3, 300, 303])
@pytest.mark.parametrize(("inputs", "outputs"), [(6, 64), (64, 5), (32, 32)])
def test_weight_gradient_in_both_orientations(n_rows: int, inputs: int, outputs: int) -> None:
    """Fewer rows than blocks, whole blocks, and rows left over after the blocks."""
    rows = torch.randn(n_rows, inputs, dtype=torch.float64)
    grad = torch.randn(n_rows, outputs, dtype=torch.float64)
    torch.testing.assert_close(weight_gradient(grad, rows), grad.t() @ rows, rtol=1e-12, atol=1e-13)


@pytest.mark.parametrize("bias", [True, False])
def test_pointwise_linear_gradients(bias: bool) -> None:
    x = torch.randn(3, 2, 6, dtype=torch.float64, requires_grad=True)
    weight = torch.randn(20, 6, dtype=torch.float64, requires_grad=True)
    b = torch.randn(20, dtype=torch.float64, requires_grad=True) if bias else None
    inputs = (x, weight, b) if bias else (x, weight)
    assert torch.autograd.gradcheck(pointwise_linear, inputs)
    torch.testing.assert_close(
        pointwise_linear(x, weight, b), torch.nn.functional.linear(x, weight, b), rtol=0, atol=0
    )


def test_float32_model_is_the_same_with_onednn_disabled(monkeypatch) -> None:
    torch.manual_seed(8)
    model = FNO1d(3, 2, layers=2, modes=8, width=32, projection_width=32)
    x = torch.randn(2, 150, 3)
    outputs = []
    for enabled in (True, False):
        monkeypatch.setattr(torch.backends.mkldnn, "enabled", enabled)
        assert uses_onednn(x, 32) == enabled
        model.zero_grad()
        out = model(x)
        out.square().sum().backward()
        outputs.append([out, *(p.grad.clone() for p in model.parameters())])
    for with_onednn, without in zip(*outputs, strict=True):
        torch.testing.assert_close(with_onednn, without, rtol=1e-4, atol=1e-5)


def test_float32_model_gradients_close_to_float64() -> None:
    torch.manual_seed(7)
    model = FNO1d(6, 5, layers=2, modes=16, width=32, projection_width=64)
    x = torch.randn(2, 400, 6)
    weight = torch.randn(2, 400, 5)
    (model(x) * weight).sum().backward()
    single = {name: p.grad.double() for name, p in model.named_parameters()}
    model = model.double()
    model.zero_grad()
    (model(x.double()) * weight.double()).sum().backward()
    for name, p in model.named_parameters():
        assert (single[name] - p.grad).abs().max() < 1e-4 * p.grad.abs().max(), name
