"""The deep operator network of Lu et al. (2021): a branch net encodes the input function,
a trunk net the output time, and their inner product is the output."""

from __future__ import annotations

from typing import Any, Literal

import torch
from cphysfno_core import InputError
from cphysfno_core.plugin import NeuralOperator, Params
from pydantic import Field

from .encoding import fourier_features, relative_time, resample_to_sensors

ACTIVATIONS = {"gelu": torch.nn.GELU, "relu": torch.nn.ReLU, "tanh": torch.nn.Tanh}


class DeepONetParams(Params):
    """Hyper-parameters of :class:`DeepONet`."""

    sensors: int = Field(
        512,
        ge=2,
        description="points m of the record, equally spaced, at which the branch net reads "
        "every input channel (linear interpolation between samples)",
    )
    latent: int = Field(
        128, gt=0, description="basis functions p per output channel (inner-product size)"
    )
    branch_width: int = Field(256, gt=0, description="hidden units of each branch layer")
    branch_layers: int = Field(2, ge=0, description="hidden layers of the branch net")
    trunk_width: int = Field(128, gt=0, description="hidden units of each trunk layer")
    trunk_layers: int = Field(3, ge=0, description="hidden layers of the trunk net")
    fourier_features: int = Field(
        128,
        ge=0,
        description="frequencies K of the trunk's input [s, cos(pi k s), sin(pi k s)], "
        "k = 1..K, of the relative time s = t / duration (0: s alone); the highest "
        "completes K/2 cycles per record",
    )
    activation: Literal["gelu", "relu", "tanh"] = Field(
        "gelu", description="nonlinearity of both nets"
    )


def mlp(inputs: int, width: int, hidden_layers: int, outputs: int, activation: str) -> list:
    """Layers ``inputs -> width (x hidden_layers, each with activation) -> outputs``."""
    layers: list[torch.nn.Module] = []
    size = inputs
    for _ in range(hidden_layers):
        layers += [torch.nn.Linear(size, width), ACTIVATIONS[activation]()]
        size = width
    return [*layers, torch.nn.Linear(size, outputs)]


class DeepONet(NeuralOperator):
    """Unstacked DeepONet: ``G(v)(s)_o = sum_k b_ok(v) tau_k(s) + c_o``.

    - **Branch** ``b``: the input function ``v`` (every input channel, e.g. ``[z, t]`` or
      ``[a_g, t]``) read at ``sensors`` equally spaced points of the record by linear
      interpolation, flattened, through a fully connected net to ``latent`` coefficients
      per output channel. A flat fully connected branch is the network of the DeepONet
      approximation theorem: the response at one time depends on the whole input history,
      so there is no locality for a convolutional encoder to exploit before the global
      coefficients, and at m = 512 sensors of 6 channels the first layer stays small
      (0.8 M weights at width 256).
    - **Trunk** ``tau``: the relative time ``s = t / duration`` of each requested sample
      (``s_j = j / (T - 1)``), optionally expanded into Fourier features, through a fully
      connected net to ``latent`` basis functions; as in Lu et al., the last trunk layer
      is followed by the activation too.
    - **Outputs**: one shared trunk basis, the branch output split into one group of
      ``latent`` coefficients per output channel (the floors of a building oscillate in the
      same modes with their own amplitudes), plus a learned bias ``c`` per output.

    The trunk needs Fourier features for records that hold many cycles: on Example 1
    (30 s records, first period 0.49 s, ELS input, 100 training records, 20 epochs) a
    trunk on ``s`` alone stayed at relative L2 1.00, the default 128 frequencies reached
    0.91.

    The operator works at any T: the branch reads every record at the same sensors and the
    trunk is evaluated at the record's own sample times, so one function sampled at two
    resolutions over the same duration gives (up to the interpolation error) the same
    output. A record of another duration is read on the same relative axis, i.e.
    stretched to the training duration, which is not the response to it: a trained
    :class:`~cphysfno_core.CompositeModel` predicts only on its training grid.

    Args:
        in_channels: input channels (the output DOFs of z plus the time coordinate).
        out_channels: output channels (the output DOFs).
        **hyper: fields of :class:`DeepONetParams`.
    """

    name = "deeponet"
    Params = DeepONetParams

    def __init__(self, in_channels: int, out_channels: int, **hyper: Any) -> None:
        super().__init__(in_channels, out_channels, **hyper)
        p = self.params
        self.branch = torch.nn.Sequential(
            *mlp(
                self.in_channels * p.sensors,
                p.branch_width,
                p.branch_layers,
                self.out_channels * p.latent,
                p.activation,
            )
        )
        self.trunk = torch.nn.Sequential(
            *mlp(1 + 2 * p.fourier_features, p.trunk_width, p.trunk_layers, p.latent, p.activation),
            ACTIVATIONS[p.activation](),
        )
        self.bias = torch.nn.Parameter(torch.zeros(self.out_channels))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        """``[batch, T, in_channels]`` -> ``[batch, T, out_channels]`` (dtype of the weights)."""
        if x.ndim != 3 or x.shape[-1] != self.in_channels or x.shape[1] < 1:
            raise InputError(
                f"{self.name}: expected input [batch, T, {self.in_channels}] with T >= 1, "
                f"got shape {tuple(x.shape)}"
            )
        p = self.params
        coefficients = self.branch(resample_to_sensors(x, p.sensors).flatten(1))
        coefficients = coefficients.view(x.shape[0], self.out_channels, p.latent)
        s = relative_time(x.shape[1], x.dtype, x.device)
        basis = self.trunk(fourier_features(s, p.fourier_features))
        return torch.einsum("bop,tp->bto", coefficients, basis) + self.bias
