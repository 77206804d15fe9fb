"""Training speed: one epoch of the paper's Example 1 FNO through ``train_operator``.

Beside it, neuraloperator's ``FNO`` in the same architecture as far as its API allows, run
through the same trainer on the same data with the same optimiser and loss. The epoch is
also put against its FLOP floor: the matrix-product FLOPs of the epoch (forward and
backward passes, validation pass) over this machine's best sustained float32
matrix-product rate (``torch.mm`` or the FNO's oneDNN product, whichever is faster). A
second row times the same epoch of ours with ``precision = "bfloat16"`` (opt-in), beside
ours in float32.
"""

from __future__ import annotations

import copy
import time
from dataclasses import dataclass
from functools import partial

import numpy as np
import torch
from cphysfno_fno import FNO1d
from cphysfno_fno.dense import product

import cphysfno_core as cp
from cphysfno_core.config import TrainingConfig
from cphysfno_core.model.training import (
    Normalizer,
    describe_device,
    resolve_device,
    train_operator,
)

from .common import Row, load_average

ARCHITECTURE = {"layers": 6, "modes": 32, "width": 64, "projection_width": 128}
IN_CHANNELS = 6
OUT_CHANNELS = 5


@dataclass(frozen=True)
class Sizes:
    """Records (training and validation), samples per record and batch size of the run."""

    n_train: int
    n_val: int
    steps: int
    batch: int


FULL = Sizes(n_train=400, n_val=100, steps=3001, batch=20)
QUICK = Sizes(n_train=20, n_val=10, steps=501, batch=10)


def fno_flops(batch: int, steps: int, backward: bool) -> float:
    """Matrix-product FLOPs of one FNO1d pass over ``batch`` records of ``steps`` samples.

    Counts ``2 M N K`` for every product as :mod:`cphysfno_fno` runs it: lifting, per layer
    the truncated forward DFT, mode mixing, pointwise map and inverse DFT, and the
    projection; with ``backward`` also the gradient products (input and weight gradients of
    every map, none for the network input). Element-wise work (GELU, bias, Adam) is left out.
    """
    layers, width = ARCHITECTURE["layers"], ARCHITECTURE["width"]
    hidden = ARCHITECTURE["projection_width"]
    m = min(ARCHITECTURE["modes"], steps // 2 + 1)
    rows = batch * steps
    dft = 2.0 * (2 * m) * steps * batch * width
    pointwise = 2.0 * rows * width * width
    mixing = 4 * 2.0 * m * batch * width * width
    lifting = 2.0 * rows * IN_CHANNELS * width
    projection = 2.0 * rows * width * hidden + 2.0 * rows * hidden * OUT_CHANNELS
    forward = lifting + layers * (2 * dft + pointwise + mixing) + projection
    if not backward:
        return forward
    gradients = lifting + layers * (2 * dft + 2 * pointwise + 2 * mixing) + 2 * projection
    return forward + gradients


def epoch_flops(sizes: Sizes) -> float:
    """FLOPs of one epoch: every training batch forward and backward, validation forward."""
    train = (sizes.n_train // sizes.batch) * fno_flops(sizes.batch, sizes.steps, True)
    full_val, rest = divmod(sizes.n_val, sizes.batch)
    val = full_val * fno_flops(sizes.batch, sizes.steps, False)
    return train + val + (fno_flops(rest, sizes.steps, False) if rest else 0.0)


def synchronize(device: str) -> None:
    """Wait for the work queued on ``device`` (a no-op on the CPU)."""
    if torch.device(device).type == "cuda":
        torch.cuda.synchronize(device)


def best_matmul_rate(
    shapes: list[tuple[int, int, int]],
    repeat: int = 5,
    device: str = "cpu",
    dtype: torch.dtype = torch.float32,
) -> float:
    """Best sustained matrix-product rate (FLOP/s) in ``dtype`` on ``device`` over
    ``[M, K] @ [K, N]`` shapes ``(M, K, N)``, each timed ``repeat`` times after a warm-up
    with ``torch.mm`` into a preallocated output and with the FNO's own product
    (:func:`cphysfno_fno.dense.product`: oneDNN on CPU), whichever is faster."""
    best = 0.0
    for rows, inner, cols in shapes:
        a = torch.randn(rows, inner, device=device).to(dtype)
        b = torch.randn(inner, cols, device=device).to(dtype)
        out = torch.empty(rows, cols, device=device, dtype=dtype)
        for multiply in (partial(torch.mm, a, b, out=out), partial(product, a, b)):
            for _ in range(repeat + 1):
                synchronize(device)
                start = time.perf_counter()
                multiply()
                synchronize(device)
                best = max(best, 2.0 * rows * inner * cols / (time.perf_counter() - start))
    return best


def matmul_rate(sizes: Sizes, device: str = "cpu") -> float:
    """:func:`best_matmul_rate` over the epoch's main GEMM shapes: the truncated DFT
    ``[2m, T] @ [T, batch * width]``, the inverse DFT ``[T, 2m] @ [2m, batch * width]``, the
    pointwise map ``[batch T, width] @ [width, width]`` and a square ``1024^3``."""
    width = ARCHITECTURE["width"]
    m = min(ARCHITECTURE["modes"], sizes.steps // 2 + 1)
    columns = sizes.batch * width
    return best_matmul_rate(
        [
            (2 * m, sizes.steps, columns),
            (sizes.steps, 2 * m, columns),
            (sizes.batch * sizes.steps, width, width),
            (1024, 1024, 1024),
        ],
        device=device,
    )


def neuralop_fno(modes: int) -> torch.nn.Module:
    """neuraloperator's FNO in Example 1's architecture through the ``neuralop-fno`` plugin
    (time-major in and out, as the trainer feeds it).

    Raises:
        CphysfnoError: the plugin or neuraloperator is not installed.
    """
    return cp.create(
        "operator",
        "neuralop-fno",
        in_channels=IN_CHANNELS,
        out_channels=OUT_CHANNELS,
        **{**ARCHITECTURE, "modes": modes},
    )


NEURALOP_DIFFERENCES = (
    "neuraloperator 2.0 through the neuralop-fno plugin (use_channel_mlp=False, no positional "
    "embedding, one linear lifting 6 -> 64, projection 64 -> 128 -> 5 as ours); it differs: "
    "its 1x1 skip has no bias, its spectral convolutions carry a bias, and it applies GELU "
    "twice between layers"
)


def _data(sizes: Sizes) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(0)
    n = sizes.n_train + sizes.n_val
    x = rng.standard_normal((n, sizes.steps, IN_CHANNELS), dtype=np.float32)
    y = 0.01 * rng.standard_normal((n, sizes.steps, OUT_CHANNELS))
    return x[: sizes.n_train], y[: sizes.n_train], x[sizes.n_train :], y[sizes.n_train :]


def epoch_seconds(
    operator: torch.nn.Module,
    data: tuple,
    sizes: Sizes,
    device: str = "cpu",
    precision: str = "float32",
) -> float:
    """Wall time in s of one epoch of :func:`train_operator` on ``device`` in ``precision``
    (training and validation; the data's copy to the device included)."""
    x, y, x_val, y_val = data
    normalizer = Normalizer(np.zeros(OUT_CHANNELS), np.full(OUT_CHANNELS, 0.01))
    settings = TrainingConfig(
        epochs=1, batch_size=sizes.batch, learning_rate=1e-3, device=device, precision=precision
    )
    start = time.perf_counter()
    train_operator(operator, x, y, x_val, y_val, normalizer, settings, progress=None)
    return time.perf_counter() - start


def run(quick: bool = False, device: str = "cpu") -> list[Row]:
    sizes = QUICK if quick else FULL
    repeat = 2 if quick else 5
    data = _data(sizes)
    torch.manual_seed(0)
    ours = FNO1d(IN_CHANNELS, OUT_CHANNELS, **ARCHITECTURE)
    candidates = {"ours": (ours, "float32"), "ours bfloat16": (copy.deepcopy(ours), "bfloat16")}
    missing = ""
    try:
        candidates["neuralop 32 modes"] = (neuralop_fno(ARCHITECTURE["modes"]), "float32")
    except cp.CphysfnoError as error:
        missing = f"neuralop-fno not available ({error}); ours measured alone"
    load_before = load_average()
    times = {label: [] for label in candidates}
    warm_up = _data(QUICK)
    for operator, precision in candidates.values():
        epoch_seconds(operator, warm_up, QUICK, device, precision)
    rates = []
    for _ in range(repeat):
        for label, (operator, precision) in candidates.items():
            times[label].append(epoch_seconds(operator, data, sizes, device, precision))
            rates.append(matmul_rate(sizes, device))
    best = {label: min(values) for label, values in times.items()}
    flops = epoch_flops(sizes)
    rate = max(rates)
    floor = flops / rate
    stage = (
        f"train 1 epoch, Example 1 FNO ({sizes.n_train} x {sizes.steps}, batch {sizes.batch}, "
        f"+ validation {sizes.n_val})"
    )
    notes = [
        f"{describe_device(resolve_device(device))}; best of {repeat}, interleaved; "
        f"load average {load_before} before, {load_average()} after (2 cores)",
        "all epochs: "
        + ", ".join(
            f"{label} " + "/".join(f"{t:.1f}" for t in values) + " s"
            for label, values in times.items()
        ),
        f"FLOP floor: {flops / 1e9:.0f} GFLOP per epoch (matmul and DFT-matmul, forward + "
        f"backward + validation) / {rate / 1e9:.0f} GFLOP/s (best matrix product) = {floor:.2f} s; "
        f"ours = {best['ours'] / floor:.1f}x the floor",
    ]
    low = Row(
        stage="the same epoch with [training] precision = 'bfloat16' (opt-in)",
        ours_s=best["ours bfloat16"],
        alternative="ours in float32",
        alternative_s=best["ours"],
        target="report",
        notes=["weights, gradients, Adam and loss in float32; products under bfloat16 autocast"],
    )
    if missing:
        notes.append(missing)
        return [
            Row(stage=stage, ours_s=best["ours"], target=">= 4x neuraloperator", notes=notes),
            low,
        ]
    notes.append(NEURALOP_DIFFERENCES)
    low.notes.append(
        f"{best['neuralop 32 modes'] / best['ours bfloat16']:.1f}x neuraloperator's float32 "
        "epoch (not the same arithmetic)"
    )
    ratios = sorted(
        theirs / ours
        for theirs, ours in zip(times["neuralop 32 modes"], times["ours"], strict=True)
    )
    notes.append(
        f"ratio within each interleaved round: median {ratios[len(ratios) // 2]:.1f}x, "
        f"range {ratios[0]:.1f}-{ratios[-1]:.1f}x"
    )
    return [
        Row(
            stage=stage,
            ours_s=best["ours"],
            alternative="neuraloperator 2.0 FNO, 32 modes, same trainer",
            alternative_s=best["neuralop 32 modes"],
            target=">= 4x neuraloperator",
            notes=notes,
        ),
        low,
    ]
