"""The intensity measures a fragility is fitted against, chosen by a short name.

| name | measure | unit |
|---|---|---|
| ``sa-t1`` | Sa(T1), 5 % damped, at the structure's first elastic period | m/s^2 |
| ``sa:T`` | Sa(T) at any period ``T`` in s, e.g. ``sa:1.5`` (an isolator's period) | m/s^2 |
| ``sa-avg`` | Sa_avg: geometric mean of Sa over 10 periods from 0.2 T1 to 3 T1 | m/s^2 |
| ``sa-avg:A-B`` | the same from ``A`` to ``B`` s, e.g. ``sa-avg:0.5-4`` | m/s^2 |
| ``pga`` | peak ground acceleration | m/s^2 |
| ``pgv`` | peak ground velocity | m/s |
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..signals import GroundMotions
from ..signals.errors import ConfigError
from ..signals.intensity import (
    average_spectral_acceleration,
    peak_ground_acceleration,
    peak_ground_velocity,
    spectral_acceleration,
)

FORMS = ("sa-t1", "sa:T", "sa-avg", "sa-avg:A-B", "pga", "pgv")
"""The names :func:`intensity_measure` reads (``T``, ``A``, ``B``: periods in s)."""

AVERAGE_RANGE = (0.2, 3.0)
"""Sa_avg's default period range in multiples of T1 (Eads, Miranda and Lignos 2015)."""


@dataclass(frozen=True)
class IntensityMeasure:
    """An intensity measure of ground motions.

    Attributes:
        name: the name it was chosen by (``sa-t1``, ``sa:1.5``, ...).
        description: what it is, with its periods in s, for tables and axes.
        unit: its unit.
        periods_s: the oscillator periods it reads, s (empty for PGA and PGV).
    """

    name: str
    description: str
    unit: str
    periods_s: tuple[float, ...]
    _function: Callable[[GroundMotions], np.ndarray]

    def of(self, motions: GroundMotions) -> np.ndarray:
        """``[n]`` the measure of every record, in :attr:`unit`."""
        return self._function(motions)

    def to_dict(self) -> dict:
        """JSON-ready: name, description, unit and periods."""
        return {
            "name": self.name,
            "description": self.description,
            "unit": self.unit,
            "periods_s": list(self.periods_s),
        }


def _period(text: str, what: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not np.isfinite(value) or value <= 0:
        raise ConfigError(f"intensity measure '{what}': periods must be numbers of s > 0")
    return value


def _spectral(name: str, period: float) -> IntensityMeasure:
    def sa(motions: GroundMotions) -> np.ndarray:
        return spectral_acceleration(motions.acceleration, motions.dt, period)

    return IntensityMeasure(name, f"Sa({period:.4g} s), 5 % damped", "m/s^2", (period,), sa)


def _average(name: str, low: float, high: float) -> IntensityMeasure:
    if high <= low:
        raise ConfigError(f"intensity measure '{name}': the range must rise, got {low}-{high} s")

    def sa_avg(motions: GroundMotions) -> np.ndarray:
        return average_spectral_acceleration(motions.acceleration, motions.dt, low, high)

    description = f"Sa_avg({low:.4g}-{high:.4g} s), 5 % damped"
    return IntensityMeasure(name, description, "m/s^2", (low, high), sa_avg)


def intensity_measure(name: str, first_period: float) -> IntensityMeasure:
    """The intensity measure called ``name`` (see :data:`FORMS`) for a structure whose
    first elastic period is ``first_period`` s.

    Raises:
        ConfigError: an unknown name or a period that is not a number > 0 (the message
            lists the forms).
    """
    text = name.strip().lower()
    if text == "sa-t1":
        return _spectral(text, first_period)
    if text.startswith("sa:"):
        return _spectral(text, _period(text[3:], name))
    if text == "sa-avg":
        low, high = (factor * first_period for factor in AVERAGE_RANGE)
        return _average(text, low, high)
    if text.startswith("sa-avg:"):
        bounds = text[len("sa-avg:") :].split("-")
        if len(bounds) != 2:
            raise ConfigError(f"intensity measure '{name}': write the range as sa-avg:A-B (s)")
        return _average(text, _period(bounds[0], name), _period(bounds[1], name))
    if text == "pga":
        return IntensityMeasure(
            text, "PGA", "m/s^2", (), lambda m: peak_ground_acceleration(m.acceleration)
        )
    if text == "pgv":
        return IntensityMeasure(
            text, "PGV", "m/s", (), lambda m: peak_ground_velocity(m.acceleration, m.dt)
        )
    raise ConfigError(
        f"unknown intensity measure '{name}': use one of {', '.join(FORMS)} "
        "(T, A, B: periods in s)"
    )
