"""The FNO's matrix products on CPU: pointwise channel maps ``x Wᵀ + b`` with their
gradients, and the truncated Fourier transforms.

A pointwise map of a long time series is a matrix product with many rows and few columns
(e.g. ``[T * batch, 64] @ [64, 64]``); a truncated transform one with few rows or a short
inner dimension and many columns (``[2m, T] @ [T, batch * width]`` and
``[T, 2m] @ [2m, batch * width]``). For float32 on CPU, oneDNN's inner-product kernel runs
both kinds markedly faster than the BLAS ``gemm`` behind ``torch.mm`` (on an AVX-512 AMD
EPYC about twice as fast: MKL takes its AVX2 path there) unless the output is very narrow
(a projection to a handful of DOFs), where BLAS is faster. On a CPU with native bfloat16
(``avx512_bf16`` or AMX) the same holds for bfloat16 products, a few per cent faster than
torch's own bfloat16 matmul (itself oneDNN's); every other dtype or device goes through
``torch.mm`` / ``torch.addmm``. A weight gradient, a product with a long inner dimension
and a small output, is summed over blocks of rows as one batched product (see
:func:`blocked_inner_product`), oriented so that its wider side is the column count: with a
narrow side of a few channels as the column count, BLAS runs several times slower, and
oneDNN is no faster.
"""

from __future__ import annotations

import torch

from cphysfno_core.plugin import native_bfloat16

_ONEDNN = torch.backends.mkldnn.is_available() and hasattr(torch.ops.mkldnn, "_linear_pointwise")
_ONEDNN_DTYPES = (
    (torch.float32, torch.bfloat16)
    if _ONEDNN and native_bfloat16(torch.device("cpu"))
    else (torch.float32,)
)
ONEDNN_MIN_OUT = 16
"""Narrowest output (channels) that :func:`dense` hands to oneDNN."""
INNER_BLOCKS = 4
"""Blocks of rows that :func:`blocked_inner_product` sums over."""


def uses_onednn(x: torch.Tensor, out_features: int) -> bool:
    """Whether :func:`dense` runs ``x`` through oneDNN: float32 (or bfloat16, where the CPU
    computes in it natively) on CPU with oneDNN built in and enabled
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


def add_product_(out: torch.Tensor, a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    """``out += a @ b`` in place: through oneDNN for float32 where :func:`dense` would use
    it; otherwise ``addmm_``, which for bfloat16 accumulates into ``out`` in float32 and
    rounds once (and is faster than a separate oneDNN product and addition).

    Args:
        out: ``[rows, columns]``, contiguous.
        a: ``[rows, inner]``.
        b: ``[inner, columns]`` (any strides).

    Returns:
        ``out``.
    """
    if a.dtype == torch.float32 and uses_onednn(a, b.shape[1]):
        return out.add_(product(a, b))
    return out.addmm_(a, b)


def weight_gradient(grad: torch.Tensor, rows: torch.Tensor) -> torch.Tensor:
    """``gradᵀ rows``, the gradient of ``W`` in ``rows Wᵀ``.

    Args:
        grad: ``[rows, out]`` gradient of the output.
        rows: ``[rows, in]`` input.

    Returns:
        ``[out, in]`` (possibly a transposed view).
    """
    if rows.shape[1] < grad.shape[1]:
        return blocked_inner_product(rows, grad).t()
    return blocked_inner_product(grad, rows)


def blocked_inner_product(a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    """``aᵀ b``, summed over :data:`INNER_BLOCKS` blocks of rows computed as one batched
    product (the rows that do not fill a block are added after).

    A product with a few thousand output entries and an inner dimension of ``T * batch``
    (a weight gradient) is split badly across threads by BLAS; a batch of row blocks is
    split well (1.1 to 2.9 times faster on two cores, depending on the shape).

    Args:
        a: ``[rows, p]``.
        b: ``[rows, q]``.

    Returns:
        ``[p, q]``.
    """
    size = a.shape[0] // INNER_BLOCKS
    if size == 0:
        return torch.mm(a.t(), b)
    whole = size * INNER_BLOCKS
    blocks_a = a[:whole].reshape(INNER_BLOCKS, size, a.shape[1])
    blocks_b = b[:whole].reshape(INNER_BLOCKS, size, b.shape[1])
    out = torch.bmm(blocks_a.transpose(1, 2), blocks_b).sum(0)
    if whole < a.shape[0]:
        out.addmm_(a[whole:].t(), b[whole:])
    return out


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
