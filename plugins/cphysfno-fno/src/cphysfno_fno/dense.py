"""The FNO's matrix products on CPU: pointwise channel maps ``x Wᵀ + b`` with their
gradients, and the truncated Fourier transforms.

A pointwise map of a long time series is a matrix product with many rows and few columns
(e.g. ``[T * batch, 64] @ [64, 64]``); a truncated transform one with few rows or a short
inner dimension and many columns (``[2m, T] @ [T, batch * width]`` and
``[T, 2m] @ [2m, batch * width]``). For float32 on CPU, oneDNN's inner-product kernel runs
both kinds markedly faster than the BLAS ``gemm`` behind ``torch.mm`` (on an AVX-512 AMD
EPYC about twice as fast: MKL takes its AVX2 path there) unless the output is very narrow
(a projection to a handful of DOFs), where BLAS is faster. bfloat16 takes oneDNN as well
where the CPU computes in it natively (``avx512_bf16`` or AMX), at about twice to 2.5 times
the float32 rate; every other dtype or device goes through ``torch.mm`` / ``torch.addmm``.
A product plus a tensor runs as one oneDNN call with the sum as its post-op, which saves a
pass over the result. The weight gradient is a BLAS product oriented so that its wider side
is the BLAS column count: with a narrow side of a few channels as the column count, BLAS
runs several times slower, and oneDNN is no faster.
"""

from __future__ import annotations

import torch

_ONEDNN = torch.backends.mkldnn.is_available() and hasattr(torch.ops.mkldnn, "_linear_pointwise")
_ONEDNN_DTYPES = (
    (torch.float32, torch.bfloat16)
    if _ONEDNN and torch.ops.mkldnn._is_mkldnn_bf16_supported()
    else (torch.float32,)
)
ONEDNN_MIN_OUT = 16
"""Narrowest output (channels) that :func:`dense` hands to oneDNN."""


def uses_onednn(x: torch.Tensor, out_features: int) -> bool:
    """Whether :func:`dense` runs ``x`` through oneDNN: float32 (or bfloat16, where the CPU
    has native bfloat16 arithmetic) on CPU with oneDNN built in and enabled
    (``torch.backends.mkldnn.enabled``), and at least :data:`ONEDNN_MIN_OUT` output
    channels."""
    return (
        _ONEDNN
        and torch.backends.mkldnn.enabled
        and x.dtype in _ONEDNN_DTYPES
        and x.device.type == "cpu"
        and out_features >= ONEDNN_MIN_OUT
    )


def dense(x: torch.Tensor, weight: torch.Tensor, bias: torch.Tensor | None = None) -> torch.Tensor:
    """``x Wᵀ + b`` without autograd.

    Args:
        x: ``[rows, in]``.
        weight: ``[out, in]`` (any strides).
        bias: ``[out]`` or None.

    Returns:
        ``[rows, out]``, a new contiguous tensor.
    """
    if uses_onednn(x, weight.shape[0]):
        return torch.ops.mkldnn._linear_pointwise(x, weight, bias, "none", [], "")
    if bias is None:
        return torch.mm(x, weight.t())
    return torch.addmm(bias, x, weight.t())


def product(a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    """``a @ b`` through :func:`dense`.

    Args:
        a: ``[rows, inner]``.
        b: ``[inner, columns]`` (any strides).

    Returns:
        ``[rows, columns]``, a new contiguous tensor.
    """
    return dense(a, b.t())


def product_plus(a: torch.Tensor, b: torch.Tensor, add: torch.Tensor) -> torch.Tensor:
    """``a @ b + add`` in one pass: through oneDNN with the sum as its post-op where
    :func:`dense` would use oneDNN (one rounding in bfloat16), else ``torch.addmm``.

    Args:
        a: ``[rows, inner]``.
        b: ``[inner, columns]`` (any strides).
        add: ``[rows, columns]``, contiguous.

    Returns:
        ``[rows, columns]``, a new contiguous tensor.
    """
    if uses_onednn(a, b.shape[1]):
        return torch.ops.mkldnn._linear_pointwise.binary(a, add, b.t(), None, "add")
    return torch.addmm(add, a, b)


def weight_gradient(grad: torch.Tensor, rows: torch.Tensor) -> torch.Tensor:
    """``gradᵀ rows``, the gradient of ``W`` in ``rows Wᵀ``.

    Args:
        grad: ``[rows, out]`` gradient of the output.
        rows: ``[rows, in]`` input.

    Returns:
        ``[out, in]`` (possibly a transposed view).
    """
    if rows.shape[1] < grad.shape[1]:
        return torch.mm(rows.t(), grad).t()
    return torch.mm(grad.t(), rows)


def pointwise_linear(
    x: torch.Tensor, weight: torch.Tensor, bias: torch.Tensor | None = None
) -> torch.Tensor:
    """``x Wᵀ + b`` over the last axis, differentiable, through :func:`dense`.

    Args:
        x: ``[..., in]``.
        weight: ``[out, in]``.
        bias: ``[out]`` or None.

    Returns:
        ``[..., out]``.
    """
    return _PointwiseLinear.apply(x, weight, bias)


class _PointwiseLinear(torch.autograd.Function):
    @staticmethod
    def forward(ctx, x, weight, bias):
        rows = x.reshape(-1, x.shape[-1])
        ctx.save_for_backward(rows, weight)
        ctx.has_bias = bias is not None
        return dense(rows, weight, bias).view(*x.shape[:-1], weight.shape[0])

    @staticmethod
    def backward(ctx, grad_out):
        rows, weight = ctx.saved_tensors
        grad = grad_out.reshape(-1, weight.shape[0])
        grad_x = grad_weight = grad_bias = None
        if ctx.needs_input_grad[0]:
            grad_x = dense(grad, weight.t()).view(*grad_out.shape[:-1], weight.shape[1])
        if ctx.needs_input_grad[1]:
            grad_weight = weight_gradient(grad, rows)
        if ctx.has_bias and ctx.needs_input_grad[2]:
            grad_bias = grad.sum(0)
        return grad_x, grad_weight, grad_bias
