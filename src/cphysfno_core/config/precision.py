"""The arithmetic an operator trains or predicts in: float32, or bfloat16 products.

bfloat16 keeps float32's exponent range with an 8-bit significand (relative rounding
``2^-9``, about 0.2 %). On a CPU with native bfloat16 arithmetic (``avx512_bf16`` or AMX),
and on recent GPUs, its matrix products run about twice as fast as float32's; what that
costs in accuracy is measured in ``benchmarks/RESULTS.md``. It is opt-in, for training
(``[training] precision``) and for prediction (``model.predict(..., precision=)``) alike:
the operator runs under ``torch.autocast``, and each operator decides which of its steps
take the lower precision. Parameters, their gradients, the optimiser and the loss stay in
float32.
"""

from __future__ import annotations

import contextlib
import warnings
from collections.abc import Iterator
from typing import Literal

import torch

from ..signals.errors import CphysfnoWarning, InputError

Precision = Literal["float32", "bfloat16"]
PRECISIONS: tuple[str, ...] = ("float32", "bfloat16")


def native_bfloat16(device: torch.device) -> bool:
    """Whether ``device`` computes bfloat16 products in hardware (on CPU: oneDNN finds
    ``avx512_bf16`` or AMX; on CUDA: compute capability 8.0 or higher)."""
    if device.type == "cuda":
        return torch.cuda.is_bf16_supported(including_emulation=False)
    if device.type == "cpu":
        return torch.backends.mkldnn.is_available() and torch.ops.mkldnn._is_mkldnn_bf16_supported()
    return False


@contextlib.contextmanager
def operator_precision(device: torch.device, precision: str) -> Iterator[None]:
    """Run the operator calls inside in ``precision`` on ``device``.

    ``"float32"`` changes nothing; ``"bfloat16"`` enters ``torch.autocast(device.type,
    dtype=torch.bfloat16)``, with a :class:`~cphysfno_core.errors.CphysfnoWarning` where the
    device has no native bfloat16 arithmetic (the results are the same, only slower).

    Raises:
        InputError: ``precision`` is not one of :data:`PRECISIONS`.
    """
    if precision not in PRECISIONS:
        raise InputError(f"precision '{precision}': choose one of {', '.join(PRECISIONS)}")
    if precision == "float32":
        yield
        return
    if not native_bfloat16(device):
        warnings.warn(
            f"{device.type} has no native bfloat16 arithmetic: computing in bfloat16 is "
            "emulated there and slower than float32",
            CphysfnoWarning,
            stacklevel=4,
        )
    with torch.autocast(device.type, dtype=torch.bfloat16):
        yield
