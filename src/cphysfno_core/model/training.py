"""Training of a neural operator: normalisers, the relative-L2 loss of §3.3, the loop.

Arrays are ``[n_records, n_steps, channels]``; the learner works in float32.
"""

from __future__ import annotations

import copy
import os
import platform
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import torch

from ..config.allocator import tune_memory
from ..config.experiment import TrainingConfig
from ..config.precision import operator_precision
from ..signals.errors import ConfigError, DatasetError, InputError
from ..signals.progress import show_progress, time_left

FUSED_ADAM_DEVICES = ("cpu", "cuda")
"""Device types on which Adam runs fused (one kernel over all parameters) when every
parameter is real: the same update, about four times faster per step on the CPU than the
multi-tensor default, which complex parameters (neuraloperator's spectral weights) keep."""


@dataclass
class Normalizer:
    """Per-channel affine map ``(x - mean) / std`` fitted on the training split only.

    Attributes:
        mean: ``[channels]``.
        std: ``[channels]`` (a constant channel gets std 1).
    """

    mean: np.ndarray
    std: np.ndarray

    @classmethod
    def fit(cls, x: np.ndarray) -> Normalizer:
        """Fit to ``x [n, T, channels]`` over records and time."""
        mean = x.mean(axis=(0, 1))
        std = x.std(axis=(0, 1))
        std = np.where(std > 0, std, 1.0)
        return cls(mean.astype(np.float64), std.astype(np.float64))

    @classmethod
    def identity(cls, x: np.ndarray) -> Normalizer:
        """The map that leaves ``x [n, T, channels]`` as it is (mean 0, std 1)."""
        channels = x.shape[-1]
        return cls(np.zeros(channels), np.ones(channels))

    def encode(self, x: np.ndarray) -> np.ndarray:
        return ((x - self.mean) / self.std).astype(np.float32)

    def decode_torch(self, y: torch.Tensor) -> torch.Tensor:
        mean = torch.as_tensor(self.mean, dtype=y.dtype, device=y.device)
        std = torch.as_tensor(self.std, dtype=y.dtype, device=y.device)
        return y * std + mean


def resolve_device(name: str) -> torch.device:
    """The torch device of a ``training.device`` setting.

    ``"auto"`` is the first CUDA device when torch sees one, else the CPU.

    Raises:
        ConfigError: the device is not available to this torch.
    """
    if name == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    device = torch.device(name)
    if device.type == "cuda":
        if not torch.cuda.is_available():
            build = f"CUDA {torch.version.cuda}" if torch.version.cuda else "a CPU-only build"
            raise ConfigError(
                f"training.device = '{name}': torch {torch.__version__} ({build}) sees no "
                "CUDA device; use 'auto' or 'cpu'"
            )
        if device.index is not None and device.index >= torch.cuda.device_count():
            raise ConfigError(
                f"training.device = '{name}': torch sees {torch.cuda.device_count()} CUDA device(s)"
            )
    if device.type == "mps" and not torch.backends.mps.is_available():
        raise ConfigError(f"training.device = '{name}': torch sees no MPS device")
    return device


def describe_device(device: torch.device) -> str:
    """A device in words: the GPU's name, or the CPU with its torch thread count."""
    if device.type == "cuda":
        return torch.cuda.get_device_name(device)
    if device.type == "cpu":
        processor = platform.processor() or platform.machine()
        threads = torch.get_num_threads()
        return f"CPU ({processor}, {threads} thread{'s' if threads != 1 else ''})"
    return device.type


def relative_l2_loss(
    prediction: torch.Tensor, target: torch.Tensor, groups: tuple[int, ...] | None = None
) -> torch.Tensor:
    """Paper Eq. (Loss): sum over records and DOFs of ||pred - u||_2 over sum of ||u||_2.

    Both tensors are ``[batch, T, dof]``; the norms run over time. With ``groups`` (the
    number of channels of each response kind, in order, e.g. ``(5, 5)`` for displacements
    then accelerations), the sum over the kinds of each kind's own relative L2, so that no
    kind weighs more for its unit. A kind whose target is zero throughout the batch (a
    named response no record of it excites) adds nothing: it has no scale there.
    """
    return _relative(*_error_and_norm(prediction, target, groups))


def _relative(error: torch.Tensor, norm: torch.Tensor) -> torch.Tensor:
    """The sum over groups of ``error / norm``, a group of zero ``norm`` left out."""
    return torch.where(norm > 0, error / norm.clamp_min(1e-30), torch.zeros_like(error)).sum()


def _error_and_norm(
    prediction: torch.Tensor, target: torch.Tensor, groups: tuple[int, ...] | None = None
) -> tuple[torch.Tensor, torch.Tensor]:
    """Numerators and denominators ``[n_groups]`` of :func:`relative_l2_loss`."""
    errors = torch.linalg.vector_norm(prediction - target, dim=1).sum(dim=0)
    norms = torch.linalg.vector_norm(target, dim=1).sum(dim=0)
    sizes = list(groups) if groups else [errors.shape[0]]
    error = torch.stack([part.sum() for part in torch.split(errors, sizes)])
    norm = torch.stack([part.sum() for part in torch.split(norms, sizes)])
    return error, norm


@dataclass
class EpochReport:
    """What one epoch did, handed to the progress callback.

    ``seconds`` is the epoch's wall time (s), ``seconds_left`` the estimate for the epochs
    still to run: the mean epoch time since training started (or resumed) times their
    number, 0 after the last.
    """

    epoch: int
    epochs: int
    train_loss: float
    val_loss: float
    learning_rate: float
    seconds: float
    best: bool
    seconds_left: float = 0.0


@dataclass
class TrainingHistory:
    """Loss per epoch, the epoch whose weights were kept (lowest validation loss), the
    training time (s) and where it ran (:func:`describe_device`)."""

    train_loss: list[float] = field(default_factory=list)
    val_loss: list[float] = field(default_factory=list)
    best_epoch: int = 0
    seconds: float = 0.0
    device: str = ""

    def to_dict(self) -> dict:
        return {
            "train_loss": self.train_loss,
            "val_loss": self.val_loss,
            "best_epoch": self.best_epoch,
            "seconds": self.seconds,
            "device": self.device,
        }


def print_progress(report: EpochReport) -> None:
    """Default progress: one line per epoch on stderr (``*``: best validation so far), with
    the time left while epochs remain."""
    mark = " *" if report.best else "  "
    left = f"  {time_left(report.seconds_left)}" if report.epoch < report.epochs else ""
    line = (
        f"  epoch {report.epoch:>4}/{report.epochs}  train {report.train_loss:.4f}  "
        f"val {report.val_loss:.4f}  lr {report.learning_rate:.2e}  "
        f"{report.seconds:.1f}s{mark}{left}"
    )
    show_progress(line.rstrip())


def save_checkpoint(path: str | Path, state: dict) -> None:
    """Write a training checkpoint to a temporary name and rename it into place."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(f".{path.name}.tmp")
    torch.save(state, temporary)
    os.replace(temporary, path)


def load_checkpoint(path: str | Path) -> dict:
    """Read a checkpoint written by :func:`save_checkpoint` (tensors and plain data only)."""
    try:
        return torch.load(path, weights_only=True, map_location="cpu")
    except Exception as error:
        raise DatasetError(
            f"cannot resume from {path}: not a readable checkpoint ({type(error).__name__}); "
            "remove it to train from the start"
        ) from None


def _evaluate(
    forward: Callable[[torch.Tensor], torch.Tensor],
    x: torch.Tensor,
    y: torch.Tensor,
    decode,
    batch_size: int,
    groups: tuple[int, ...] | None = None,
) -> float:
    """Relative L2 over a whole split (the ratio of sums, not a mean of batch ratios),
    summed over the ``groups`` as in :func:`relative_l2_loss`."""
    error = norm = 0.0
    with torch.no_grad():
        for start in range(0, x.shape[0], batch_size):
            prediction = decode(forward(x[start : start + batch_size]))
            part_error, part_norm = _error_and_norm(
                prediction, y[start : start + batch_size], groups
            )
            error, norm = error + part_error, norm + part_norm
    return float(_relative(error, norm))


def train_operator(
    operator: torch.nn.Module,
    x_train: np.ndarray,
    y_train: np.ndarray,
    x_val: np.ndarray,
    y_val: np.ndarray,
    output_normalizer: Normalizer,
    settings: TrainingConfig,
    progress: Callable[[EpochReport], None] | None = print_progress,
    checkpoint: str | Path | None = None,
    resume: bool = False,
    groups: tuple[int, ...] | None = None,
) -> TrainingHistory:
    """Train ``operator`` in place and keep the weights of the best validation epoch.

    Args:
        operator: maps normalised inputs ``[b, T, in]`` to normalised outputs ``[b, T, out]``.
        x_train, x_val: normalised inputs (float32).
        y_train, y_val: targets in physical units (m); the loss is computed on decoded
            outputs so it is the paper's relative L2 of displacements.
        output_normalizer: decodes the operator output to physical units.
        settings: epochs, batch size, Adam learning rate, decoupled (AdamW) weight decay,
            step decay, seed, device (the operator is moved to it and stays there; the
            data are copied to it whole),
            precision of the operator's passes (see :mod:`cphysfno_core.precision`).
        progress: called after every epoch (None for silence).
        checkpoint: file written (atomically) after every epoch with everything needed
            to continue: weights, optimiser, schedule, random states, best epoch so far.
        resume: continue from ``checkpoint`` if it exists; on CPU the result equals that
            of an uninterrupted run with the same seed.
        groups: channels of each response kind the outputs hold, in order (None: one
            kind); the loss is the sum of the kinds' relative L2 (:func:`relative_l2_loss`).
    """
    if x_train.shape[0] != y_train.shape[0] or x_val.shape[0] != y_val.shape[0]:
        raise InputError("inputs and targets must hold the same number of records")
    device = resolve_device(settings.device)
    tune_memory()
    torch.manual_seed(settings.seed)
    generator = torch.Generator().manual_seed(settings.seed)
    operator.to(device)
    xt = torch.as_tensor(x_train, dtype=torch.float32, device=device)
    yt = torch.as_tensor(y_train, dtype=torch.float32, device=device)
    xv = torch.as_tensor(x_val, dtype=torch.float32, device=device)
    yv = torch.as_tensor(y_val, dtype=torch.float32, device=device)
    decode = output_normalizer.decode_torch

    def forward(x: torch.Tensor) -> torch.Tensor:
        """The operator's output in float32, computed in ``settings.precision``."""
        with operator_precision(device, settings.precision):
            return operator(x).float()

    parameters = list(operator.parameters())
    optimiser = torch.optim.AdamW(
        parameters,
        lr=settings.learning_rate,
        weight_decay=settings.weight_decay,
        fused=device.type in FUSED_ADAM_DEVICES and all(p.is_floating_point() for p in parameters),
    )
    schedule = torch.optim.lr_scheduler.StepLR(
        optimiser, step_size=settings.decay_step, gamma=settings.decay_factor
    )
    history = TrainingHistory()
    best_state = copy.deepcopy(operator.state_dict())
    best_val = float("inf")
    first_epoch = 1
    if checkpoint is not None and resume and Path(checkpoint).exists():
        state = load_checkpoint(checkpoint)
        operator.load_state_dict(state["operator"])
        optimiser.load_state_dict(state["optimiser"])
        schedule.load_state_dict(state["schedule"])
        generator.set_state(state["generator"])
        torch.set_rng_state(state["torch_rng"])
        best_state, best_val = state["best_state"], state["best_val"]
        history = TrainingHistory(**state["history"])
        first_epoch = state["epoch"] + 1
    started = time.perf_counter()
    for epoch in range(first_epoch, settings.epochs + 1):
        tic = time.perf_counter()
        operator.train()
        order = torch.randperm(xt.shape[0], generator=generator)
        error_sum = norm_sum = 0.0
        for start in range(0, xt.shape[0], settings.batch_size):
            rows = order[start : start + settings.batch_size].to(device)
            error, norm = _error_and_norm(decode(forward(xt[rows])), yt[rows], groups)
            loss = _relative(error, norm)
            optimiser.zero_grad(set_to_none=True)
            loss.backward()
            optimiser.step()
            error_sum, norm_sum = error_sum + error.detach(), norm_sum + norm.detach()
        learning_rate = optimiser.param_groups[0]["lr"]
        schedule.step()
        operator.eval()
        val_loss = _evaluate(forward, xv, yv, decode, settings.batch_size, groups)
        train_loss = float(_relative(error_sum, norm_sum))
        history.train_loss.append(train_loss)
        history.val_loss.append(val_loss)
        improved = val_loss < best_val
        if improved:
            best_val = val_loss
            history.best_epoch = epoch
            best_state = copy.deepcopy(operator.state_dict())
        if progress is not None:
            now = time.perf_counter()
            per_epoch = (now - started) / (epoch - first_epoch + 1)
            progress(
                EpochReport(
                    epoch,
                    settings.epochs,
                    train_loss,
                    val_loss,
                    learning_rate,
                    now - tic,
                    improved,
                    per_epoch * (settings.epochs - epoch),
                )
            )
        if checkpoint is not None:
            save_checkpoint(
                checkpoint,
                {
                    "epoch": epoch,
                    "operator": operator.state_dict(),
                    "optimiser": optimiser.state_dict(),
                    "schedule": schedule.state_dict(),
                    "generator": generator.get_state(),
                    "torch_rng": torch.get_rng_state(),
                    "best_state": best_state,
                    "best_val": best_val,
                    "history": history.to_dict(),
                },
            )
    operator.load_state_dict(best_state)
    operator.eval()
    history.seconds = time.perf_counter() - started
    history.device = describe_device(device)
    return history
