"""Truncated real discrete Fourier transform as a pair of real matrices.

Keeping only the lowest ``m`` of the ``n // 2 + 1`` frequencies of a real signal of ``n``
samples, the forward transform and its inverse are dense ``[2m, n]`` and ``[n, 2m]``
matrices. Applied as matrix products they run as single GEMMs over all batch entries and
channels, which on CPU is faster than ``torch.fft`` over the whole signal for the mode
counts an FNO keeps.
"""

from __future__ import annotations

import math
from functools import lru_cache

import torch


def n_kept_modes(n: int, modes: int) -> int:
    """How many of the lowest ``modes`` frequencies exist in a real signal of ``n`` samples."""
    return min(modes, n // 2 + 1)


@lru_cache(maxsize=32)
def dft_bases(
    n: int, modes: int, dtype: torch.dtype, device: torch.device
) -> tuple[torch.Tensor, torch.Tensor]:
    """Forward and inverse bases of the real DFT truncated to the lowest ``modes`` frequencies.

    With ``m = n_kept_modes(n, modes)`` and ``x`` of shape ``[n, ...]``:

    - ``forward @ x`` is ``[2m, ...]``: rows ``0..m-1`` hold the real parts and rows
      ``m..2m-1`` the imaginary parts of ``torch.fft.rfft(x, dim=0)[:m]`` (unnormalised).
    - ``inverse @ y`` is ``[n, ...]``: ``torch.fft.irfft(c, n=n, dim=0)`` of the half
      spectrum ``c`` whose first ``m`` entries are ``y[:m] + 1j * y[m:]`` and whose other
      entries are zero. The imaginary parts of the zero and Nyquist frequencies drop out,
      as they do in ``irfft``.

    The bases are built in float64 and cast to ``dtype``; they never require gradients and
    are cached per ``(n, modes, dtype, device)``.

    Returns:
        ``(forward [2m, n], inverse [n, 2m])``.
    """
    m = n_kept_modes(n, modes)
    with torch.inference_mode(False), torch.no_grad():
        k = torch.arange(m, dtype=torch.int64)
        t = torch.arange(n, dtype=torch.int64)
        angle = (2.0 * math.pi / n) * torch.remainder(k[:, None] * t[None, :], n).double()
        cos, sin = torch.cos(angle), torch.sin(angle)
        forward = torch.cat([cos, -sin], dim=0)
        weight = torch.full((m, 1), 2.0, dtype=torch.float64)
        weight[0] = 1.0
        if n % 2 == 0 and m == n // 2 + 1:
            weight[-1] = 1.0
        inverse = (torch.cat([weight * cos, -weight * sin], dim=0) / n).T
        return (
            forward.to(device=device, dtype=dtype).contiguous(),
            inverse.to(device=device, dtype=dtype).contiguous(),
        )
