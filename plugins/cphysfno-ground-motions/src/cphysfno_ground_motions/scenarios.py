"""Record amplitudes drawn from a ground-motion model: each copy of a record scaled so that
its 5%-damped pseudo-spectral acceleration at one period is a BSSA14 draw for a scenario
sampled in a window of magnitude, distance and site."""

from __future__ import annotations

from typing import Annotated

import numpy as np
from cphysfno_core import GroundMotions
from cphysfno_core.plugin import Params
from cphysfno_core.signals.intensity import response_spectrum
from pydantic import Field, field_validator

from .target import bssa14_target

Positive = Annotated[float, Field(gt=0.0, allow_inf_nan=False)]

BSSA14_MAX_VS30 = 1500.0
"""Largest V_S30 (m/s) BSSA14 is recommended for; a draw above it is evaluated there (the
model's site term flattens near it) and recorded as drawn."""


class IntensityScenarios(Params):
    """The window scenarios are drawn from: magnitude and Joyner-Boore distance uniform in
    their ranges, ``V_S30`` log-uniform, and a standard normal ``epsilon`` of ln PSA."""

    magnitude: tuple[float, float] = Field(description="moment magnitude range (BSSA14: 3-8.5)")
    rjb_km: tuple[float, float] = Field(description="Joyner-Boore distance range, km")
    vs30: tuple[Positive, Positive] = Field(description="V_S30 range, m/s")
    period: Positive = Field(description="period of the scaled PSA, s (the structure's T1)")
    mechanism: str = Field("U", description="BSSA14 mechanism: U, SS, NS or RS")
    region: str = Field("global", description="BSSA14 region of pygmm")

    @field_validator("magnitude", "rjb_km", "vs30")
    @classmethod
    def _low_to_high(cls, value: tuple[float, float]) -> tuple[float, float]:
        if value[0] > value[1]:
            raise ValueError(f"give the range low to high, got {list(value)}")
        return value


def scenario_factors(
    motions: GroundMotions,
    rows: np.ndarray,
    scenarios: IntensityScenarios,
    rng: np.random.Generator,
) -> tuple[np.ndarray, list[dict]]:
    """Factors that bring record ``rows[k]`` of ``motions`` to a drawn PSA at
    ``scenarios.period``, and what was drawn for each.

    Returns:
        ``[len(rows)]`` factors and, for each, a mapping with ``scenario_magnitude``,
        ``scenario_rjb_km``, ``scenario_vs30`` (m/s, as drawn; BSSA14 is evaluated at
        most at :data:`BSSA14_MAX_VS30`), ``epsilon`` and ``target_psa`` (m/s^2, at
        ``target_psa_period`` s).
    """
    rows = np.asarray(rows)
    n = rows.size
    magnitude = rng.uniform(*scenarios.magnitude, size=n)
    distance = rng.uniform(*scenarios.rjb_km, size=n)
    vs30 = np.exp(rng.uniform(*np.log(scenarios.vs30), size=n))
    epsilon = rng.standard_normal(n)
    period = np.array([scenarios.period])
    own = response_spectrum(motions.acceleration, motions.dt, period).pseudo_acceleration[:, 0]
    factors = np.empty(n)
    drawn = []
    for k in range(n):
        site = min(vs30[k], BSSA14_MAX_VS30)
        model = bssa14_target(
            magnitude[k], distance[k], site, scenarios.mechanism, scenarios.region, period
        )
        target = float(model.median[0] * np.exp(epsilon[k] * model.ln_std[0]))
        factors[k] = target / own[rows[k]]
        drawn.append(
            {
                "scenario_magnitude": float(magnitude[k]),
                "scenario_rjb_km": float(distance[k]),
                "scenario_vs30": float(vs30[k]),
                "epsilon": float(epsilon[k]),
                "target_psa": target,
                "target_psa_period": float(scenarios.period),
            }
        )
    return factors, drawn
