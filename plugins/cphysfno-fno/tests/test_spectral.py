"""The matrix-product spectral convolution against torch.fft, and its resolution property."""

from __future__ import annotations

import math

import pytest
import torch
from cphysfno_fno import SpectralConv1d


def fft_spectral_conv(conv: SpectralConv1d, v: torch.Tensor) -> torch.Tensor:
    """Reference: rfft over time, complex weights on the lowest modes, irfft (``[n, b, c]``)."""
    n = v.shape[0]
    m = min(conv.modes, n // 2 + 1)
    weight = torch.complex(conv.weight_real, conv.weight_imag)[:m]
    v_ft = torch.fft.rfft(v, dim=0)
    out_ft = torch.zeros(n // 2 + 1, v.shape[1], conv.out_channels, dtype=v_ft.dtype)
    out_ft[:m] = torch.einsum("kbi,kio->kbo", v_ft[:m], weight)
    return torch.fft.irfft(out_ft, n=n, dim=0)


def random_conv(in_channels: int, out_channels: int, modes: int) -> SpectralConv1d:
    conv = SpectralConv1d(in_channels, out_channels, modes).double()
    with torch.no_grad():
        conv.weight_real.normal_()
        conv.weight_imag.normal_()
    return conv


@pytest.mark.parametrize("n", [101, 100, 3001])
@pytest.mark.parametrize("modes", [7, 32, 80])
def test_equals_fft_reference(n: int, modes: int) -> None:
    torch.manual_seed(n + modes)
    conv = random_conv(3, 4, modes)
    v = torch.randn(n, 2, 3, dtype=torch.float64)
    expected = fft_spectral_conv(conv, v)
    actual = conv(v)
    assert actual.shape == (n, 2, 4)
    torch.testing.assert_close(actual, expected, rtol=1e-10, atol=1e-10)


def test_float32_is_close_to_float64_reference() -> None:
    torch.manual_seed(1)
    conv = random_conv(4, 4, 32)
    v = torch.randn(3001, 2, 4, dtype=torch.float64)
    expected = fft_spectral_conv(conv, v)
    actual = conv.float()(v.float()).double()
    scale = expected.abs().max()
    assert (actual - expected).abs().max() < 1e-5 * scale


def band_limited(n: int, channels: int = 2) -> torch.Tensor:
    """``[n, 1, channels]`` samples on ``t = j / n`` of a periodic signal with frequencies <= 5."""
    t = torch.arange(n, dtype=torch.float64) / n
    columns = []
    for c in range(channels):
        signal = 0.3 * (c + 1) + sum(
            math.cos(0.7 * f + c) / f * torch.cos(2 * math.pi * f * t + 0.4 * f * (c + 1))
            for f in range(1, 6)
        )
        columns.append(signal)
    return torch.stack(columns, dim=-1)[:, None, :]


@pytest.mark.parametrize("modes", [4, 8])
def test_same_function_at_two_resolutions(modes: int) -> None:
    torch.manual_seed(2)
    conv = random_conv(2, 3, modes)
    coarse = conv(band_limited(64))
    fine = conv(band_limited(256))
    torch.testing.assert_close(fine[::4], coarse, rtol=1e-10, atol=1e-10)


def test_input_gradient_equals_fft_reference_gradient() -> None:
    torch.manual_seed(3)
    conv = random_conv(3, 3, 10)
    v = torch.randn(51, 2, 3, dtype=torch.float64, requires_grad=True)
    weight = torch.randn(51, 2, 3, dtype=torch.float64)
    (grad,) = torch.autograd.grad((conv(v) * weight).sum(), v)
    (expected,) = torch.autograd.grad((fft_spectral_conv(conv, v) * weight).sum(), v)
    torch.testing.assert_close(grad, expected, rtol=1e-10, atol=1e-10)


def test_added_field_is_added_to_the_output() -> None:
    torch.manual_seed(4)
    conv = random_conv(3, 2, 12)
    v = torch.randn(40, 3, 3, dtype=torch.float64)
    extra = torch.randn(40, 3, 2, dtype=torch.float64)
    expected = fft_spectral_conv(conv, v) + extra
    torch.testing.assert_close(conv(v, add=extra), expected, rtol=1e-10, atol=1e-10)
