"""Engineering demand parameters: peak and residual story drift ratios, peak absolute
floor accelerations and velocities, peak output displacements and peaks of named responses
of simulated or predicted responses, each defined once in :data:`EDP_TABLE` (see
:mod:`cphysfno_core.reporting.edp`, where they are computed)::

    from cphysfno_core import edp

    true = edp.compute(structure.simulate(motions), structure, motions)
    mean, std = model.predict(motions)
    predicted = edp.compute(mean, structure, motions)
    bounds = edp.interval(mean, std, structure, motions, k=1.0)
    edp.log_errors(predicted, true)["PID"]["median"]  # per story
    true["PFV"], true.columns["PFV"], true.units["PFV"]  # any EDP by name
"""

from .reporting.edp import (
    ACCELERATION_EXTRA,
    EDP_TABLE,
    LOG_ERROR_QUANTILES,
    DriftInterval,
    EDPs,
    band_interval,
    compute,
    interval,
    log_errors,
    pad_free_vibration,
    require_heights,
    scored_columns,
    scored_names,
    stories_of,
)
from .reporting.edp_table import EDPDefinition, definition
from .signals.stories import Stories

__all__ = [
    "ACCELERATION_EXTRA",
    "EDP_TABLE",
    "LOG_ERROR_QUANTILES",
    "DriftInterval",
    "EDPDefinition",
    "EDPs",
    "Stories",
    "band_interval",
    "compute",
    "definition",
    "interval",
    "log_errors",
    "pad_free_vibration",
    "require_heights",
    "scored_columns",
    "scored_names",
    "stories_of",
]
