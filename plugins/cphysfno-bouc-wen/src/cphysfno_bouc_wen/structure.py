"""The Bouc-Wen hysteretic shear building of the paper's Example 1 (§5.1): a preset of
:class:`~.shear_building.ShearBuilding` with a ``bouc-wen`` story law."""

from __future__ import annotations

from functools import cached_property
from typing import Annotated, Literal

import numpy as np
from cphysfno_core.plugin import Params
from pydantic import Field, ValidationInfo, field_validator

from .laws import BoucWenLaw
from .shear_building import ShearBuilding

Positive = Annotated[float, Field(gt=0.0, allow_inf_nan=False)]


class BoucWenShearBuildingParams(Params):
    """Parameters of :class:`BoucWenShearBuilding` (defaults: Example 1 of the paper, §5.1,
    with the story stiffnesses this project fixes, which the paper leaves out)."""

    masses: tuple[Positive, ...] = Field(
        (3.0e4,) * 5, min_length=1, description="floor masses from the bottom up, kg"
    )
    stiffnesses: tuple[Positive, ...] = Field(
        (7.5e7, 7.0e7, 6.0e7, 4.5e7, 2.5e7),
        min_length=1,
        description="elastic story stiffnesses k_i from the bottom up, N/m",
    )
    alpha: float = Field(0.1, ge=0.0, le=1.0, description="post-yield stiffness ratio")
    exponent: float = Field(3.0, ge=1.0, le=50.0, description="Bouc-Wen exponent n")
    A: Positive = Field(1.0, description="Bouc-Wen amplitude A")
    yield_displacement: Positive = Field(0.01, description="yield drift u_y, m")
    delta: Positive | None = Field(None, description="Bouc-Wen delta, 1/m^n (1/(2 u_y^n))")
    zeta: Positive | None = Field(None, description="Bouc-Wen zeta, 1/m^n (1/(2 u_y^n))")
    damping_ratio: float = Field(
        0.05, ge=0.0, lt=1.0, description="viscous damping ratio of every elastic mode"
    )
    story_heights: Positive | tuple[Positive, ...] = Field(
        3.0, description="story heights, m (for drift ratios)"
    )
    substeps: int | None = Field(
        None,
        ge=1,
        le=1000,
        description="Runge-Kutta steps per sample of the motion (fine grid); None keeps "
        "omega_max h <= 0.45 rad",
    )
    precision: Literal["float32", "float64"] = Field(
        "float32", description="arithmetic of the fine-grid Runge-Kutta integration"
    )

    @field_validator("stiffnesses")
    @classmethod
    def _one_per_floor(cls, stiffnesses: tuple[float, ...], info: ValidationInfo):
        masses = info.data.get("masses")
        if masses is not None and len(masses) != len(stiffnesses):
            raise ValueError(
                f"needs one stiffness per floor: {len(stiffnesses)} stiffnesses for "
                f"{len(masses)} masses"
            )
        return stiffnesses


class BoucWenShearBuilding(ShearBuilding):
    """Shear building whose stories follow the Bouc-Wen hysteresis law (paper Example 1).

    The ``shear-building`` with ``story_law = {name = "bouc-wen", ...}`` and classical
    damping, under the parameter names of the paper: ``delta`` and ``zeta`` are the law's
    ``beta`` and ``gamma``. ``M u'' + C u' + A_f^T r(v, h) = -M 1 a_g`` with story drifts
    ``v = A_f u``, story shears ``r_i = k_i [alpha v_i + (1 - alpha) h_i]`` and
    ``h_i' = -delta |v_i'| |h_i|^(n-1) h_i - zeta v_i' |h_i|^n + A v_i'``.

    Outputs are the floor displacements relative to the ground (m), bottom floor first;
    :meth:`simulate` also returns the extras ``"story_drift"`` (v, m) and
    ``"story_shear"`` (r, N), each ``[n, T, n_stories]``; on the motion's grid they are in
    the arithmetic ``precision`` names (float32 by default), on a coarse grid in float64.
    """

    name = "bouc-wen-shear-building"
    Params = BoucWenShearBuildingParams

    @cached_property
    def story_law(self) -> BoucWenLaw:
        """The ``bouc-wen`` law with this building's parameters."""
        p = self.params
        return BoucWenLaw(
            alpha=p.alpha,
            exponent=p.exponent,
            A=p.A,
            yield_displacement=p.yield_displacement,
            beta=p.delta,
            gamma=p.zeta,
        )

    @property
    def rayleigh_modes(self) -> None:
        """Classical damping: no Rayleigh modes."""
        return None

    @property
    def integrator(self) -> str:
        """Classical Runge-Kutta, on the dedicated kernel."""
        return "runge-kutta"

    @property
    def coupling(self) -> np.ndarray:
        """No stiffness between the floors beside the story springs: zeros."""
        return np.zeros((self.n_stories, self.n_stories))

    @property
    def delta(self) -> float:
        """Bouc-Wen delta in 1/m^n: the parameter, or ``1 / (2 u_y^n)``."""
        return float(self.law_coefficients[0, 3])

    @property
    def zeta(self) -> float:
        """Bouc-Wen zeta in 1/m^n: the parameter, or ``1 / (2 u_y^n)``."""
        return float(self.law_coefficients[0, 4])

    @cached_property
    def masses(self) -> np.ndarray:
        return np.asarray(self.params.masses, dtype=np.float64)

    @cached_property
    def n_stories(self) -> int:
        return len(self.params.masses)
