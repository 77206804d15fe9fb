"""Prediction of many records that goes on past the records it cannot predict."""

from __future__ import annotations

import numpy as np

from ..config.uncertainty import per_record
from ..signals import GroundMotions, Responses
from ..signals.errors import CphysfnoError
from .composite import CompositeModel
from .parameters import ParameterValues


def predict_skipping_failures(
    model: CompositeModel, motions: GroundMotions, params: ParameterValues | None = None
) -> tuple[Responses, dict[int, str]]:
    """The predicted mean displacement ``[n, T, n_outputs]`` (m) of every record, with the
    predicted absolute accelerations (extra ``absolute_acceleration``, m/s^2) and named
    responses (extras by their names) of a model that learns them, and the records it
    could not predict; ``params``: each record's
    structural parameters, for a model of a family (path -> ``[n]`` values).

    The records are predicted together; if that fails (the physics input of one record
    holds NaN, say), one by one. A record whose physics collapses (a preprocessor that
    :attr:`~cphysfno_core.plugin.PhysicsPreprocessor.collapses`, whose z holds NaN) gets
    NaN and is flagged ``collapsed`` in the responses: a predicted collapse, not a
    failure. Any other record whose prediction raises a package error or is not finite
    gets NaN and is listed with its cause.

    Returns:
        ``(responses, failures)``: ``failures`` maps the index of each failed record in
        ``motions`` to the reason; ``responses.collapsed`` flags the predicted collapses.
    """
    params = per_record(params, motions.n_records)
    try:
        channels = _channels(model, motions, params)
        failures: dict[int, str] = {}
    except CphysfnoError:
        channels, failures = _one_by_one(model, motions, params)
    collapsed = channels.pop(COLLAPSED)[:, 0, 0] > 0.0
    for values in channels.values():
        for i in np.flatnonzero(~np.isfinite(values).all(axis=(1, 2)) & ~collapsed):
            failures.setdefault(int(i), "the prediction is not finite")
    for values in channels.values():
        values[list(failures)] = np.nan
        values[collapsed] = np.nan
    mean = channels.pop("displacement")
    responses = Responses(mean, motions.dt, extras=channels, collapsed=collapsed)
    return responses, dict(sorted(failures.items()))


COLLAPSED = "physics collapsed"
"""The channel, ``[n, 1, 1]`` 1.0 or 0.0, by which :func:`_channels` says which records'
physics collapsed."""


def _channels(
    model: CompositeModel, motions: GroundMotions, params: dict[str, np.ndarray]
) -> dict[str, np.ndarray]:
    stages = model.predict_stages(motions, params=params)
    found = {"displacement": stages.mean, **stages.extras()}
    channels = {name: np.array(values, dtype=np.float64) for name, values in found.items()}
    collapsed = np.zeros(motions.n_records)
    if stages.z is not None and getattr(getattr(model, "preprocessor", None), "collapses", False):
        collapsed[~np.isfinite(stages.z).all(axis=(1, 2))] = 1.0
    channels[COLLAPSED] = collapsed[:, None, None]
    return channels


def _one_by_one(
    model: CompositeModel, motions: GroundMotions, params: dict[str, np.ndarray]
) -> tuple[dict[str, np.ndarray], dict[int, str]]:
    parts: list[dict[str, np.ndarray] | None] = []
    failures = {}
    for i in range(motions.n_records):
        try:
            own = {name: values[i : i + 1] for name, values in params.items()}
            parts.append(_channels(model, motions[i], own))
        except CphysfnoError as error:
            parts.append(None)
            failures[i] = str(error)
    template = next((part for part in parts if part is not None), None)
    if template is None:
        raise CphysfnoError(f"no record could be predicted (record 0: {failures[0]})")
    return {
        name: np.stack(
            [np.full(values.shape[1:], np.nan) if p is None else p[name][0] for p in parts]
        )
        for name, values in template.items()
    }, failures
