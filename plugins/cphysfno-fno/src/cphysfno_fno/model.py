"""The one-dimensional Fourier neural operator of paper §2.1 (Li et al., 2020)."""

from __future__ import annotations

from typing import Any, Literal

import torch
from pydantic import Field

from cphysfno_core import InputError
from cphysfno_core.plugin import NeuralOperator, Params

from .dense import pointwise_linear
from .fused import fourier_layer
from .spectral import SpectralConv1d

ACTIVATIONS = {"gelu": torch.nn.functional.gelu, "relu": torch.nn.functional.relu}


class FNOParams(Params):
    """Hyper-parameters of :class:`FNO1d`.

    Attributes:
        layers: number of Fourier layers L.
        modes: lowest Fourier modes K kept by each spectral convolution.
        width: channels of the latent field v.
        projection_width: hidden channels of the two-layer projection P.
        activation: the nonlinearity sigma.
        activate_last_layer: also apply sigma after the last Fourier layer (the authors'
            published MATLAB code applies ReLU after every Fourier layer; the reference
            FNO1d of Li et al. does not after the last).
        init: initial weights of the lifting, pointwise and projection maps: ``"torch"``
            (``torch.nn.Linear``'s default) or ``"glorot"`` (Glorot-uniform weights and
            zero biases, MATLAB's default for ``convolution1dLayer``, which the published
            code uses). The spectral weights start the same either way.
        padding: zero samples appended at the end of the latent field before the Fourier
            layers and removed after them, for signals that are not periodic.
    """

    layers: int = Field(6, gt=0)
    modes: int = Field(32, gt=0)
    width: int = Field(64, gt=0)
    projection_width: int = Field(128, gt=0)
    activation: Literal["gelu", "relu"] = "gelu"
    activate_last_layer: bool = False
    init: Literal["torch", "glorot"] = "torch"
    padding: int = Field(0, ge=0)


class FourierLayer(torch.nn.Module):
    """``K(v) + W v``: a spectral convolution plus a pointwise linear map, before sigma.

    The modules hold the weights; the layer runs as one
    :func:`~cphysfno_fno.fused.fourier_layer` with a hand-written backward pass.
    """

    def __init__(self, width: int, modes: int) -> None:
        super().__init__()
        self.spectral = SpectralConv1d(width, width, modes)
        self.pointwise = torch.nn.Linear(width, width)

    def forward(self, v: torch.Tensor) -> torch.Tensor:
        """``[n, batch, width]`` -> ``[n, batch, width]``, in the dtype of ``v`` (the mode
        mixing in the spectral weights' own)."""
        return fourier_layer(
            v,
            self.pointwise.weight.to(v.dtype),
            self.pointwise.bias.to(v.dtype),
            self.spectral.weight_real,
            self.spectral.weight_imag,
        )


class FNO1d(NeuralOperator):
    """Lifting Q, ``layers`` Fourier layers ``v <- sigma(K v + W v)`` and projection P.

    As in the reference FNO1d of Li et al., the last Fourier layer has no activation
    (unless ``activate_last_layer``) and P is
    ``Linear(width, projection_width) -> sigma -> Linear(projection_width, out)``.
    The paper's sizes are lifting 2 -> 64 (baseline, input ``[a_g, t]``) or 6 -> 64
    (C-PhysFNO, input ``[z, t]``), 6 layers of 32 modes and projection 64 -> 128 -> 5.

    Works at any number of time samples T; where ``modes > T // 2 + 1`` every available
    mode is used. The state dict holds only the learned parameters.

    Under ``torch.autocast`` (e.g. bfloat16 on CPU), the Fourier layers' transforms and
    pointwise maps and the projection's hidden layer compute in autocast's dtype; the mode
    mixing, the lifting and the projection's output layer stay in the weights' dtype, so
    that the time coordinate enters and the prediction leaves without being rounded to the
    lower precision, and the spectral weights are not cast for every call.

    Args:
        in_channels: input channels (e.g. the output DOFs of z plus the time coordinate).
        out_channels: output channels (the output DOFs).
        **hyper: fields of :class:`FNOParams`.
    """

    name = "fno"
    Params = FNOParams

    def __init__(self, in_channels: int, out_channels: int, **hyper: Any) -> None:
        super().__init__(in_channels, out_channels, **hyper)
        p = self.params
        self.activation = ACTIVATIONS[p.activation]
        self.padding = p.padding
        self.lifting = torch.nn.Linear(self.in_channels, p.width)
        self.layers = torch.nn.ModuleList(FourierLayer(p.width, p.modes) for _ in range(p.layers))
        self.projection_hidden = torch.nn.Linear(p.width, p.projection_width)
        self.projection_out = torch.nn.Linear(p.projection_width, self.out_channels)
        if p.init == "glorot":
            self._glorot_init()

    def _glorot_init(self) -> None:
        """Glorot-uniform weights and zero biases for every linear map (not the spectral
        weights)."""
        for module in self.modules():
            if isinstance(module, torch.nn.Linear):
                torch.nn.init.xavier_uniform_(module.weight)
                torch.nn.init.zeros_(module.bias)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        """``[batch, T, in_channels]`` -> ``[batch, T, out_channels]`` (same dtype as weights)."""
        if x.ndim != 3 or x.shape[-1] != self.in_channels:
            raise InputError(
                f"{self.name}: expected input [batch, T, {self.in_channels}], "
                f"got shape {tuple(x.shape)}"
            )
        steps = x.shape[1]
        compute = autocast_dtype(x)
        with torch.autocast(x.device.type, enabled=False):
            v = pointwise_linear(x.transpose(0, 1), self.lifting.weight, self.lifting.bias)
            v = v.to(compute)
            if self.padding:
                v = torch.nn.functional.pad(v, (0, 0, 0, 0, 0, self.padding))
            last = len(self.layers) - 1
            for index, layer in enumerate(self.layers):
                v = layer(v)
                if index < last or self.params.activate_last_layer:
                    v = self.activation(v)
            if self.padding:
                v = v[:steps]
            hidden = self.projection_hidden
            v = pointwise_linear(v, hidden.weight.to(compute), hidden.bias.to(compute))
            v = self.activation(v).to(x.dtype)
            out = pointwise_linear(v, self.projection_out.weight, self.projection_out.bias)
        return out.transpose(0, 1).contiguous()


def autocast_dtype(x: torch.Tensor) -> torch.dtype:
    """The dtype ``torch.autocast`` asks for on ``x``'s device, or ``x.dtype`` outside it."""
    device = x.device.type
    return torch.get_autocast_dtype(device) if torch.is_autocast_enabled(device) else x.dtype
