"""What the conformance checks of every kind share: the failure they raise, the small
inputs they drive a component with, and the checks of an array and of a refusal."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..signals import GroundMotions


def fail(component: Any, message: str) -> AssertionError:
    """The ``AssertionError`` a check raises: ``"<component name>: <message>"``."""
    return AssertionError(f"{getattr(component, 'name', type(component).__name__)}: {message}")


def smooth_random_motions(
    n_records: int, n_steps: int, dt: float, peak: float, seed: int, window: int
) -> GroundMotions:
    """White noise smoothed by a Hann window of ``window`` samples, each record scaled to
    ``peak`` (m/s^2); the same for the same arguments."""
    rng = np.random.default_rng(seed)
    raw = rng.standard_normal((n_records, n_steps))
    kernel = np.hanning(window)
    smooth = np.stack([np.convolve(row, kernel / kernel.sum(), mode="same") for row in raw])
    smooth *= peak / np.max(np.abs(smooth), axis=1, keepdims=True)
    return GroundMotions(smooth, dt)


def small_motions(
    n_records: int = 2, n_steps: int = 301, dt: float = 0.01, peak: float = 0.5, seed: int = 0
) -> GroundMotions:
    """Smooth random accelerations (m/s^2) of moderate amplitude for quick checks."""
    return smooth_random_motions(n_records, n_steps, dt, peak, seed, window=9)


def check_array(component: Any, values: Any, shape: tuple[int, ...], what: str) -> None:
    """Raise unless ``values`` is a finite float64 array of ``shape``."""
    values = np.asarray(values)
    if values.shape != shape:
        raise fail(component, f"{what} has shape {values.shape}, expected {shape}")
    if values.dtype != np.float64:
        raise fail(component, f"{what} must be float64, got {values.dtype}")
    if not np.isfinite(values).all():
        raise fail(component, f"{what} holds NaN or Inf for moderate input")


def expect(
    component: Any, error: type[BaseException], call: Callable[..., Any], *args: Any
) -> None:
    """Raise unless ``call(*args)`` raises ``error``."""
    try:
        call(*args)
    except error:
        return
    except Exception as other:
        message = f"expected {error.__name__}, got {type(other).__name__}: {other}"
        raise fail(component, message) from other
    raise fail(component, f"expected {error.__name__}, nothing was raised")
