"""Records far outside the range a model was trained on are flagged, not refused."""

from __future__ import annotations

import warnings

import numpy as np

from ..signals import GroundMotions
from ..signals.errors import ExtrapolationWarning
from ..signals.intensity import STANDARD_GRAVITY, peak_ground_acceleration

EXTRAPOLATION_FACTOR = 3.0
"""Records whose PGA lies more than this factor below the weakest or above the strongest
training record are flagged as extrapolations."""


def outside_training(
    motions: GroundMotions, training_pga: tuple[float, float] | None
) -> np.ndarray:
    """``[n]`` whether each record's PGA lies more than :data:`EXTRAPOLATION_FACTOR` beyond
    ``training_pga``, the range (m/s^2) of the records a model was trained on (None:
    nothing is known, nothing is outside)."""
    return _outside(peak_ground_acceleration(motions.acceleration), training_pga)


def _outside(pga: np.ndarray, training_pga: tuple[float, float] | None) -> np.ndarray:
    low, high = training_pga or (0.0, np.inf)
    return (pga < low / EXTRAPOLATION_FACTOR) | (pga > high * EXTRAPOLATION_FACTOR)


def warn_extrapolation(
    motions: GroundMotions, training_pga: tuple[float, float] | None, label: str
) -> None:
    """Warn (:class:`ExtrapolationWarning`) about the records :func:`outside_training` of
    model ``label``; where most records lie outside the training range but inside it
    divided by g, ask whether they are in g."""
    pga = peak_ground_acceleration(motions.acceleration)
    outside = _outside(pga, training_pga)
    if not outside.any():
        return
    low, high = training_pga or (0.0, np.inf)
    message = (
        f"{int(outside.sum())} of {len(pga)} records have a PGA outside "
        f"{low / EXTRAPOLATION_FACTOR:.3g}-{high * EXTRAPOLATION_FACTOR:.3g} m/s^2, "
        f"{EXTRAPOLATION_FACTOR:g} times beyond the {low:.3g}-{high:.3g} m/s^2 of the "
        f"records model '{label}' was trained on: its predictions for them are "
        "extrapolations"
    )
    median = np.median(pga)
    in_g = low / STANDARD_GRAVITY <= median <= high / STANDARD_GRAVITY
    if in_g and not low <= median <= high:
        message += " (their PGA falls in the training range divided by g: are they in g?)"
    warnings.warn(message, ExtrapolationWarning, stacklevel=3)
