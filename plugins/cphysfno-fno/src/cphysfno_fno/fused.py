"""A whole Fourier layer before its activation, ``K v + W v + b``, with its own backward pass.

Written out by hand, the forward pass is three large matrix products (forward DFT,
pointwise map with its bias, inverse DFT accumulated into the pointwise result) and the
backward pass four (inverse DFT's transpose, weight gradient, pointwise input gradient,
forward DFT's transpose accumulated into it). Compared with autograd over separate modules
this removes the tensor that sums the two input gradients and the bias gradient's reduction
over time: the inverse basis maps a real zero-frequency coefficient ``c`` to the constant
``c / n``, so the time sum of the output gradient is ``n`` times the zero-frequency row of
the inverse DFT's transpose, which is computed anyway.
"""

from __future__ import annotations

import torch

from .dense import add_product_, dense, product, weight_gradient
from .dft import dft_bases, n_kept_modes
from .spectral import mix_modes


def fourier_layer(
    v: torch.Tensor,
    weight: torch.Tensor,
    bias: torch.Tensor,
    weight_real: torch.Tensor,
    weight_imag: torch.Tensor,
) -> torch.Tensor:
    """``K v + v Wᵀ + b`` for a time-major field, differentiable in every tensor argument.

    The transforms and the pointwise map compute in the dtype of ``v`` (``weight`` and
    ``bias`` in it too); the mode mixing computes in the spectral weights' dtype, into
    which the few kept modes are cast (so that bfloat16 transforms can keep float32
    spectral weights, which are the larger part of the parameters).

    Args:
        v: ``[n, batch, in]`` input field.
        weight: ``[out, in]`` pointwise matrix W.
        bias: ``[out]`` pointwise bias b.
        weight_real, weight_imag: ``[modes, in, out]`` spectral weights of K; the lowest
            ``min(modes, n // 2 + 1)`` are used.

    Returns:
        ``[n, batch, out]``, the layer's pre-activation.
    """
    return _FourierLayer.apply(v, weight, bias, weight_real, weight_imag)


class _FourierLayer(torch.autograd.Function):
    @staticmethod
    def forward(ctx, v, weight, bias, weight_real, weight_imag):
        n, batch, width = v.shape
        out_channels = weight.shape[0]
        m = n_kept_modes(n, weight_real.shape[0])
        forward_basis, inverse_basis = dft_bases(n, weight_real.shape[0], v.dtype, v.device)
        v = v.contiguous()
        spectrum = product(forward_basis, v.view(n, batch * width))
        spectrum = spectrum.view(2, m, batch, width).to(weight_real.dtype)
        mixed = mix_modes(spectrum, weight_real[:m], weight_imag[:m]).to(v.dtype)
        out = dense(v.view(n * batch, width), weight, bias)
        add_product_(
            out.view(n, batch * out_channels),
            inverse_basis,
            mixed.view(2 * m, batch * out_channels),
        )
        ctx.save_for_backward(v, weight, weight_real, weight_imag, spectrum)
        return out.view(n, batch, out_channels)

    @staticmethod
    def backward(ctx, grad_out):
        v, weight, weight_real, weight_imag, spectrum = ctx.saved_tensors
        n, batch, width = v.shape
        out_channels = weight.shape[0]
        modes = weight_real.shape[0]
        m = n_kept_modes(n, modes)
        forward_basis, inverse_basis = dft_bases(n, modes, v.dtype, v.device)
        grad = grad_out.contiguous().view(n * batch, out_channels)
        grad_mixed = product(inverse_basis.t(), grad.view(n, batch * out_channels))
        grad_mixed = grad_mixed.view(2, m, batch, out_channels)
        grad_spectrum, grad_real, grad_imag = _mix_modes_backward(
            spectrum, grad_mixed.to(weight_real.dtype), weight_real[:m], weight_imag[:m]
        )
        grad_v = grad_weight = grad_bias = None
        if ctx.needs_input_grad[0]:
            grad_v = dense(grad, weight.t())
            add_product_(
                grad_v.view(n, batch * width),
                forward_basis.t(),
                grad_spectrum.view(2 * m, batch * width).to(v.dtype),
            )
            grad_v = grad_v.view(n, batch, width)
        if ctx.needs_input_grad[1]:
            grad_weight = weight_gradient(grad, v.view(n * batch, width))
        if ctx.needs_input_grad[2]:
            grad_bias = n * grad_mixed[0, 0].sum(0)
        if m < modes:
            grad_real = torch.nn.functional.pad(grad_real, (0, 0, 0, 0, 0, modes - m))
            grad_imag = torch.nn.functional.pad(grad_imag, (0, 0, 0, 0, 0, modes - m))
        return grad_v, grad_weight, grad_bias, grad_real, grad_imag


def _mix_modes_backward(
    spectrum: torch.Tensor,
    grad_mixed: torch.Tensor,
    weight_real: torch.Tensor,
    weight_imag: torch.Tensor,
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Gradients of :func:`~cphysfno_fno.spectral.mix_modes`.

    Args:
        spectrum: ``[2, m, batch, in]`` the input of the mixing.
        grad_mixed: ``[2, m, batch, out]`` gradient of its output.
        weight_real, weight_imag: ``[m, in, out]``.

    Returns:
        ``(grad_spectrum [2, m, batch, in], grad_weight_real, grad_weight_imag [m, in, out])``.
    """
    real, imag = spectrum[0], spectrum[1]
    grad_re, grad_im = grad_mixed[0], grad_mixed[1]
    grad_spectrum = torch.empty_like(spectrum)
    torch.bmm(grad_re, weight_real.mT, out=grad_spectrum[0])
    grad_spectrum[0].baddbmm_(grad_im, weight_imag.mT)
    torch.bmm(grad_im, weight_real.mT, out=grad_spectrum[1])
    grad_spectrum[1].baddbmm_(grad_re, weight_imag.mT, alpha=-1.0)
    grad_real = torch.baddbmm(torch.bmm(real.mT, grad_re), imag.mT, grad_im)
    grad_imag = torch.baddbmm(torch.bmm(real.mT, grad_im), imag.mT, grad_re, alpha=-1.0)
    return grad_spectrum, grad_real, grad_imag
