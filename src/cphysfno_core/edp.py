"""Engineering demand parameters: peak and residual story drift ratios and peak absolute
floor accelerations of simulated or predicted responses (see
:mod:`cphysfno_core.reporting.edp`, where they are computed)::

    from cphysfno_core import edp

    true = edp.compute(structure.simulate(motions), structure, motions)
    mean, std = model.predict(motions)
    predicted = edp.compute(mean, structure, motions)
    bounds = edp.interval(mean, std, structure, motions, k=1.0)
    edp.log_errors(predicted, true)["PID"]["median"]  # per story
"""

from .reporting.edp import (
    ACCELERATION_EXTRA,
    LOG_ERROR_QUANTILES,
    DriftInterval,
    EDPs,
    band_interval,
    compute,
    interval,
    log_errors,
    pad_free_vibration,
    require_heights,
    stories_of,
)
from .signals.stories import Stories

__all__ = [
    "ACCELERATION_EXTRA",
    "LOG_ERROR_QUANTILES",
    "DriftInterval",
    "EDPs",
    "Stories",
    "band_interval",
    "compute",
    "interval",
    "log_errors",
    "pad_free_vibration",
    "require_heights",
    "stories_of",
]
