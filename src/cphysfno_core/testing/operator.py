"""The conformance checks of a neural operator class, each on a fresh instance built
with ``(in_channels=3, out_channels=2, **hyper)`` under a fixed torch seed."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import torch

from ..api.interfaces import NeuralOperator
from ..signals.errors import CphysfnoError
from .helpers import expect, fail


def _built(cls: type[NeuralOperator], hyper: dict[str, Any], seed: int = 0) -> NeuralOperator:
    torch.manual_seed(seed)
    return cls(3, 2, **hyper)


def _input(steps: int = 101) -> torch.Tensor:
    """``[2, steps, 3]`` random input, the same on every call."""
    return torch.randn(2, steps, 3, generator=torch.Generator().manual_seed(0))


def check_output_shape(cls: type[NeuralOperator], **hyper: Any) -> None:
    """The output is ``[b, T, 2]`` for an input ``[b, T, 3]`` at any T."""
    operator = _built(cls, hyper)
    for steps in (64, 101):
        x = _input(steps)
        y = operator(x)
        if tuple(y.shape) != (2, steps, 2):
            raise fail(operator, f"output shape {tuple(y.shape)} for input {tuple(x.shape)}")


def check_gradients_reach_every_parameter(cls: type[NeuralOperator], **hyper: Any) -> None:
    """A loss of the output gives every parameter a non-zero gradient."""
    operator = _built(cls, hyper)
    operator(_input()).square().mean().backward()
    missing = [n for n, p in operator.named_parameters() if p.grad is None or not p.grad.any()]
    if missing:
        raise fail(operator, f"no gradient reaches {', '.join(missing)}")


def check_state_dict_round_trip(cls: type[NeuralOperator], **hyper: Any) -> None:
    """The state dict holds tensors only, and loaded into an instance built under another
    seed it reproduces the output."""
    operator = _built(cls, hyper)
    state = operator.state_dict()
    if not all(isinstance(v, torch.Tensor) for v in state.values()):
        raise fail(operator, "state_dict must hold tensors only")
    rebuilt = _built(cls, hyper, seed=1)
    rebuilt.load_state_dict(state)
    operator.eval()
    rebuilt.eval()
    x = _input()
    with torch.no_grad():
        if not torch.equal(operator(x), rebuilt(x)):
            raise fail(operator, "a state_dict round trip changes the output")


def check_bfloat16_autocast(cls: type[NeuralOperator], **hyper: Any) -> None:
    """Under ``torch.autocast`` to bfloat16 (``precision = "bfloat16"`` in prediction and
    training) the output stays within 5 % of float32's, and the gradients reach every
    parameter in the parameter's dtype, finite and within 25 % of float32's."""
    operator = _built(cls, hyper).eval()
    x = _input()
    with torch.no_grad():
        single = operator(x)
    reference = _gradients(operator, x, autocast=False)
    try:
        with torch.no_grad(), torch.autocast(x.device.type, dtype=torch.bfloat16):
            low = operator(x).float()
        gradients = _gradients(operator, x, autocast=True)
    except Exception as error:
        message = f"fails under torch.autocast to bfloat16: {type(error).__name__}: {error}"
        raise fail(operator, message) from error
    if low.shape != single.shape or not (low - single).norm() <= 0.05 * single.norm():
        raise fail(operator, "under torch.autocast to bfloat16 the output strays from float32's")
    for (name, parameter), grad in zip(operator.named_parameters(), gradients, strict=True):
        if grad is None or grad.dtype != parameter.dtype or not torch.isfinite(grad).all():
            raise fail(operator, f"under bfloat16 autocast, {name} gets no finite gradient")
    exact_all = torch.cat([g.flatten() for g in reference])
    low_all = torch.cat([g.flatten() for g in gradients])
    if not (low_all - exact_all).norm() <= 0.25 * exact_all.norm():
        raise fail(operator, "under bfloat16 autocast the gradients stray from float32's")


def _gradients(operator: NeuralOperator, x: torch.Tensor, autocast: bool) -> list:
    """Gradients of a fixed loss of the operator's output, with or without bfloat16
    autocast."""
    operator.zero_grad(set_to_none=True)
    with torch.autocast(x.device.type, dtype=torch.bfloat16, enabled=autocast):
        y = operator(x)
    y.float().square().mean().backward()
    gradients = [p.grad for p in operator.parameters()]
    operator.zero_grad(set_to_none=True)
    return gradients


def check_zero_output_start(cls: type[NeuralOperator], **hyper: Any) -> None:
    """After ``zero_output_()`` the output is zero, and one optimiser step towards a
    non-zero target moves it (the residual formulation starts from the physics response)."""
    operator = _built(cls, hyper, seed=2)
    operator.zero_output_()
    x = _input()
    with torch.no_grad():
        if operator(x).abs().max() != 0:
            raise fail(operator, "after zero_output_() the output is not zero")
    optimiser = torch.optim.Adam(operator.parameters(), lr=1e-2)
    (operator(x) - 1.0).square().mean().backward()
    optimiser.step()
    with torch.no_grad():
        if operator(x).abs().max() == 0:
            raise fail(operator, "after zero_output_() one optimiser step leaves the output zero")


def check_constant_channel_reaches_output(cls: type[NeuralOperator], **hyper: Any) -> None:
    """A channel constant in time (a structural parameter of a family model) changes the
    output of its own record and of no other: the records of a batch stay independent."""
    operator = _built(cls, hyper).eval()
    x = _input()
    x[:, :, 1] = torch.tensor([[0.5], [-1.0]])
    moved = x.clone()
    moved[0, :, 1] = 1.5
    with torch.no_grad():
        y, y_moved = operator(x), operator(moved)
    if torch.equal(y[0], y_moved[0]):
        raise fail(operator, "a channel constant in time does not change the output")
    if not torch.allclose(y[1], y_moved[1], rtol=1e-5, atol=1e-6):
        raise fail(operator, "changing one record's input changes another record's output")


def check_wrong_input_raises(cls: type[NeuralOperator], **hyper: Any) -> None:
    """An input with the wrong number of channels raises the package's own error
    (:class:`~cphysfno_core.CphysfnoError`)."""
    operator = _built(cls, hyper)
    expect(operator, CphysfnoError, operator, torch.randn(2, 50, 4))


OPERATOR_CHECKS: tuple[Callable[..., None], ...] = (
    check_output_shape,
    check_gradients_reach_every_parameter,
    check_state_dict_round_trip,
    check_bfloat16_autocast,
    check_zero_output_start,
    check_constant_channel_reaches_output,
    check_wrong_input_raises,
)
"""The checks of an operator class, in order; each takes ``(cls, **hyper)``."""


def check_operator(cls: type[NeuralOperator], **hyper: Any) -> None:
    """Run every check of :data:`OPERATOR_CHECKS` on ``cls`` built with ``(in_channels=3,
    out_channels=2, **hyper)``: output ``[b, T, 2]`` at any T, gradients reach every
    parameter, a state-dict round trip reproduces the output, the state dict holds tensors
    only, under bfloat16 autocast (``precision="bfloat16"`` in prediction and training)
    the output stays within 5 % of float32's and the gradients within 25 %,
    ``zero_output_()`` zeroes the output without stopping it from learning, a channel
    constant in time (a structural parameter) changes its own record's output and no
    other's, and a wrong input raises the package's own error."""
    for check in OPERATOR_CHECKS:
        check(cls, **hyper)
