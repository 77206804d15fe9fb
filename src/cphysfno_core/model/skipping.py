"""Prediction of many records that goes on past the records it cannot predict."""

from __future__ import annotations

import numpy as np

from ..signals import GroundMotions
from ..signals.errors import CphysfnoError
from .composite import CompositeModel


def predict_skipping_failures(
    model: CompositeModel, motions: GroundMotions
) -> tuple[np.ndarray, dict[int, str]]:
    """The predicted mean ``[n, T, n_outputs]`` (m) of every record, and the records it
    could not predict.

    The records are predicted together; if that fails (the physics input of one record
    holds NaN, say), one by one. A record whose prediction raises a package error or is
    not finite gets NaN and is listed with its cause.

    Returns:
        ``(mean, failures)``: ``failures`` maps the index of each failed record in
        ``motions`` to the reason.
    """
    try:
        mean = np.asarray(model.predict(motions)[0], dtype=np.float64)
        failures: dict[int, str] = {}
    except CphysfnoError:
        mean, failures = _one_by_one(model, motions)
    for i in np.flatnonzero(~np.isfinite(mean).all(axis=(1, 2))):
        failures.setdefault(int(i), "the prediction is not finite")
        mean[i] = np.nan
    return mean, failures


def _one_by_one(model: CompositeModel, motions: GroundMotions) -> tuple[np.ndarray, dict[int, str]]:
    parts, failures = [], {}
    shape = None
    for i in range(motions.n_records):
        try:
            part = np.asarray(model.predict(motions[i])[0], dtype=np.float64)
            shape = part.shape[1:]
        except CphysfnoError as error:
            part = None
            failures[i] = str(error)
        parts.append(part)
    if shape is None:
        first = next(iter(failures.values()))
        raise CphysfnoError(f"no record could be predicted (record 0: {first})")
    mean = np.stack([np.full(shape, np.nan) if p is None else p[0] for p in parts])
    return mean, failures
