"""``neuralop.models.FNO`` behind the cphysfno operator interface."""

from __future__ import annotations

import warnings
from typing import Any, Literal

import torch
from cphysfno_core import InputError, PluginError
from cphysfno_core.plugin import NeuralOperator, Params
from pydantic import Field

ACTIVATIONS = {"gelu": torch.nn.functional.gelu, "relu": torch.nn.functional.relu}
REQUIREMENT = "neuraloperator>=2.0,<2.1"


class NeuralopFNOParams(Params):
    """Hyper-parameters of :class:`NeuralopFNO`, in the names of the built-in ``fno``
    (neuralop's own names in parentheses)."""

    layers: int = Field(6, gt=0, description="Fourier layers (n_layers)")
    modes: int = Field(
        32,
        gt=0,
        description="lowest Fourier frequencies kept by each spectral convolution, as in "
        "fno (passed as n_modes = 2 modes - 1: neuralop counts both signs)",
    )
    width: int = Field(64, gt=0, description="channels of the latent field (hidden_channels)")
    lifting_width: int = Field(
        0,
        ge=0,
        description="hidden channels of a two-layer lifting; 0 lifts with one linear map, "
        "as the paper does (lifting_channel_ratio)",
    )
    projection_width: int = Field(
        128,
        gt=0,
        description="hidden channels of the two-layer projection (projection_channel_ratio)",
    )
    activation: Literal["gelu", "relu"] = Field(
        "gelu",
        description="the nonlinearity (non_linearity); without the channel MLP, "
        "neuraloperator 2.0 applies it twice between Fourier layers",
    )
    domain_padding: float = Field(
        0.0,
        ge=0.0,
        le=1.0,
        description="fraction of T zero-padded at each end of the latent field before the "
        "Fourier layers, removed after them (domain_padding)",
    )
    use_channel_mlp: bool = Field(
        False, description="a channel MLP after each Fourier layer (neuralop's default: on)"
    )
    positional_embedding: Literal["grid"] | None = Field(
        None,
        description='"grid" appends the sample position in [0, 1] as an input channel; '
        "cphysfno already feeds the time",
    )


def neuralop_fno() -> type[torch.nn.Module]:
    """The class ``neuralop.models.FNO``, imported on first use.

    Raises:
        PluginError: neuraloperator is not installed or does not import.
    """
    try:
        with warnings.catch_warnings():
            # importing neuralop makes every UserWarning show once per process
            from neuralop.models import FNO
    except ImportError as error:
        raise PluginError(
            f"operator 'neuralop-fno' needs the neuraloperator package: "
            f"pip install '{REQUIREMENT}' ({error})"
        ) from None
    return FNO


def channel_ratio(channels: int, width: int) -> float:
    """The ratio neuralop multiplies by ``width`` and truncates to get ``channels`` back."""
    return 0.0 if channels == 0 else (channels + 0.5) / width


class NeuralopFNO(NeuralOperator):
    """The n-dimensional FNO of the neuraloperator library, in one dimension (time).

    The defaults follow the paper and the built-in ``fno``: a linear lifting, ``layers``
    Fourier layers ``K v + W v + b`` with the activation between them (not after the
    last), and a two-layer projection; no channel MLP and no positional embedding.
    neuraloperator 2.0 without the channel MLP applies the activation twice between
    Fourier layers, ``sigma(sigma(K v + W v + b))``: with ``activation = "relu"``
    (idempotent) the adapter computes exactly the built-in ``fno`` given the same weights;
    with ``"gelu"`` it computes ``gelu(gelu(.))`` there.

    Inputs and outputs are time-major (``[batch, T, channels]``); neuralop works
    channels-first, so the adapter transposes on the way in and out.

    The state dict holds the learned tensors only: neuralop's models add their
    constructor arguments under ``_metadata``, which is dropped here because cphysfno
    saves the operator's name and parameters beside the weights.

    Args:
        in_channels: input channels (the output DOFs of z plus the time coordinate).
        out_channels: output channels (the output DOFs).
        **hyper: fields of :class:`NeuralopFNOParams`.

    Raises:
        PluginError: neuraloperator is missing.
    """

    name = "neuralop-fno"
    Params = NeuralopFNOParams

    def __init__(self, in_channels: int, out_channels: int, **hyper: Any) -> None:
        super().__init__(in_channels, out_channels, **hyper)
        p = self.params
        self.fno = neuralop_fno()(
            n_modes=(2 * p.modes - 1,),
            in_channels=self.in_channels,
            out_channels=self.out_channels,
            hidden_channels=p.width,
            n_layers=p.layers,
            lifting_channel_ratio=channel_ratio(p.lifting_width, p.width),
            projection_channel_ratio=channel_ratio(p.projection_width, p.width),
            positional_embedding=p.positional_embedding,
            non_linearity=ACTIVATIONS[p.activation],
            use_channel_mlp=p.use_channel_mlp,
            domain_padding=p.domain_padding,
        )

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        """``[batch, T, in_channels]`` -> ``[batch, T, out_channels]`` (float32)."""
        if x.ndim != 3 or x.shape[-1] != self.in_channels or x.shape[1] < 1:
            raise InputError(
                f"{self.name}: expected input [batch, T, {self.in_channels}] with T >= 1, "
                f"got shape {tuple(x.shape)}"
            )
        return self.fno(x.transpose(1, 2)).transpose(1, 2)

    def state_dict(self, *args: Any, **kwargs: Any) -> dict[str, Any]:
        """The learned tensors, without neuralop's ``_metadata`` entry."""
        state = super().state_dict(*args, **kwargs)
        state.pop("_metadata", None)
        return state
