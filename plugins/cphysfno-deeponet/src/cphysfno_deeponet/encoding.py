"""How the DeepONet sees its inputs: the input function at fixed sensors, and the time at
which the output is asked for.

Both live on the record's relative time ``s = t / duration`` in ``[0, 1]``: the ``T``
samples of a record sit at ``s_j = j / (T - 1)``, and the ``m`` sensors of the branch net
at ``s_i = i / (m - 1)``.
"""

from __future__ import annotations

import math

import torch


def resample_to_sensors(x: torch.Tensor, sensors: int) -> torch.Tensor:
    """The input function at ``sensors`` equally spaced points of ``[0, 1]``.

    Linear interpolation between the samples, end points included (so a record of
    ``sensors`` samples is returned unchanged). A record longer than ``sensors`` samples
    is read at the sensors only, without low-pass filtering: content above the sensors'
    Nyquist frequency ``(sensors - 1) / (2 duration)`` aliases.

    Args:
        x: ``[batch, T, channels]`` samples at ``s_j = j / (T - 1)`` (a single sample is
            held constant).
        sensors: number of sensors m.

    Returns:
        ``[batch, channels, sensors]``.
    """
    return torch.nn.functional.interpolate(
        x.transpose(1, 2), size=sensors, mode="linear", align_corners=True
    )


def relative_time(steps: int, dtype: torch.dtype, device: torch.device) -> torch.Tensor:
    """``[steps]`` relative times ``s_j = j / (steps - 1)`` (``[0]`` for one sample)."""
    return torch.linspace(0.0, 1.0, steps, dtype=dtype, device=device)


def fourier_features(s: torch.Tensor, frequencies: int) -> torch.Tensor:
    """``[s, cos(pi k s), sin(pi k s)]`` for ``k = 1..frequencies``.

    On ``[0, 1]`` the cosines alone are a complete basis of smooth functions without
    assuming periodicity; the sines make each frequency shift-able. The highest feature
    completes ``frequencies / 2`` cycles over the record.

    Args:
        s: ``[T]`` relative times.
        frequencies: number K of frequencies (0 gives ``s`` alone).

    Returns:
        ``[T, 1 + 2 K]``.
    """
    angle = s[:, None] * (
        math.pi * torch.arange(1, frequencies + 1, dtype=s.dtype, device=s.device)
    )
    return torch.cat([s[:, None], torch.cos(angle), torch.sin(angle)], dim=1)
