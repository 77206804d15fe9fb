"""The spectral convolution K of an FNO layer (paper §2.1, Eq. FNO_filter)."""

from __future__ import annotations

import torch

from .dft import dft_bases, n_kept_modes


def mix_modes(
    spectrum: torch.Tensor, weight_real: torch.Tensor, weight_imag: torch.Tensor
) -> torch.Tensor:
    """Multiply each kept Fourier mode by its complex channel matrix.

    Args:
        spectrum: ``[2, m, batch, in]``, real parts in ``[0]`` and imaginary parts in ``[1]``.
        weight_real, weight_imag: ``[m, in, out]`` real and imaginary parts of ``R(k)``.

    Returns:
        ``[2, m, batch, out]``: real and imaginary parts of ``v̂(k) R(k)`` per mode ``k``.
    """
    real, imag = spectrum[0], spectrum[1]
    mixed_real = torch.baddbmm(torch.bmm(real, weight_real), imag, weight_imag, alpha=-1.0)
    mixed_imag = torch.baddbmm(torch.bmm(real, weight_imag), imag, weight_real)
    return torch.stack([mixed_real, mixed_imag])


class SpectralConv1d(torch.nn.Module):
    """Multiply the lowest ``modes`` Fourier modes by learned complex matrices, drop the rest.

    For a signal ``v`` of ``n`` samples with Fourier coefficients ``v̂(k)``, the output is
    the inverse real DFT of ``R(k) v̂(k)`` for ``k < min(modes, n // 2 + 1)`` and of zero
    above, with ``R(k)`` an ``in_channels x out_channels`` complex matrix per mode. The
    transforms are real matrix products (see :mod:`cphysfno_fno.dft`).

    Activations are time-major and channels-last, ``[n, batch, channels]``, so that each
    transform is one GEMM over ``batch * channels`` columns without a copy.

    Args:
        in_channels: channels of the input.
        out_channels: channels of the output.
        modes: number of lowest frequencies kept (fewer where the signal has fewer).
    """

    def __init__(self, in_channels: int, out_channels: int, modes: int) -> None:
        super().__init__()
        self.in_channels = in_channels
        self.out_channels = out_channels
        self.modes = modes
        scale = 1.0 / (in_channels * out_channels)
        self.weight_real = torch.nn.Parameter(scale * torch.rand(modes, in_channels, out_channels))
        self.weight_imag = torch.nn.Parameter(scale * torch.rand(modes, in_channels, out_channels))

    def forward(self, v: torch.Tensor, add: torch.Tensor | None = None) -> torch.Tensor:
        """``[n, batch, in_channels]`` -> ``[n, batch, out_channels]``.

        Args:
            v: the input field.
            add: optional ``[n, batch, out_channels]`` field added to the output inside the
                inverse transform's matrix product.
        """
        n, batch, _ = v.shape
        m = n_kept_modes(n, self.modes)
        forward, inverse = dft_bases(n, self.modes, v.dtype, v.device)
        spectrum = (forward @ v.reshape(n, -1)).view(2, m, batch, self.in_channels)
        mixed = mix_modes(spectrum, self.weight_real[:m], self.weight_imag[:m])
        mixed = mixed.view(2 * m, batch * self.out_channels)
        if add is None:
            out = inverse @ mixed
        else:
            out = torch.addmm(add.reshape(n, -1), inverse, mixed)
        return out.view(n, batch, self.out_channels)

    def extra_repr(self) -> str:
        return (
            f"in_channels={self.in_channels}, out_channels={self.out_channels}, modes={self.modes}"
        )
