"""The Bouc-Wen hysteretic shear building of the paper's Example 1 (§5.1)."""

from __future__ import annotations

from functools import cached_property
from typing import Annotated

import numpy as np
from cphysfno_core import (
    ConfigError,
    CphysfnoError,
    GroundMotions,
    InputError,
    LinearSystem,
    Params,
    Responses,
    Structure,
)
from cphysfno_core.signals import check_time_step
from pydantic import Field, ValidationInfo, field_validator

from .explicit import integrate_rk4
from .implicit import StepFailure, integrate_gauss
from .model import (
    ShearBuildingModel,
    build_model,
    classical_damping,
    elastic_modes,
    elastic_stiffness,
    story_shear,
)
from .restoring import BoucWenRestoringForce

Positive = Annotated[float, Field(gt=0.0, allow_inf_nan=False)]


class BoucWenShearBuildingParams(Params):
    """Parameters of :class:`BoucWenShearBuilding` (defaults: DESIGN.md, Example 1)."""

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
    substeps: int = Field(
        3, ge=1, le=1000, description="Runge-Kutta steps per sample of the motion (fine grid)"
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


class BoucWenShearBuilding(Structure):
    """Shear building whose stories follow the Bouc-Wen hysteresis law.

    ``M u'' + C u' + A_f^T r(v, h) = -M 1 a_g`` with story drifts ``v = A_f u``,
    story shears ``r_i = k_i [alpha v_i + (1 - alpha) h_i]`` and
    ``h_i' = -delta |v_i'| |h_i|^(n-1) h_i - zeta v_i' |h_i|^n + A v_i'``; ``C`` gives
    the same damping ratio to every elastic mode. The ground acceleration is linear
    between its samples and the building starts at rest.

    Outputs are the floor displacements relative to the ground (m), bottom floor first;
    :meth:`simulate` also returns the extras ``"story_drift"`` (v, m) and
    ``"story_shear"`` (r, N), each ``[n, T, n_stories]``.
    """

    name = "bouc-wen-shear-building"
    Params = BoucWenShearBuildingParams

    @property
    def output_names(self) -> tuple[str, ...]:
        return tuple(f"story-{i + 1}" for i in range(len(self.params.masses)))

    @property
    def delta(self) -> float:
        """Bouc-Wen delta in 1/m^n: the parameter, or ``1 / (2 u_y^n)``."""
        return self.params.delta or self._default_shape

    @property
    def zeta(self) -> float:
        """Bouc-Wen zeta in 1/m^n: the parameter, or ``1 / (2 u_y^n)``."""
        return self.params.zeta or self._default_shape

    @property
    def _default_shape(self) -> float:
        return 0.5 / self.params.yield_displacement**self.params.exponent

    @cached_property
    def _matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        mass = np.asarray(self.params.masses, dtype=np.float64)
        stiffness = elastic_stiffness(np.asarray(self.params.stiffnesses, dtype=np.float64))
        return mass, stiffness, classical_damping(mass, stiffness, self.params.damping_ratio)

    @cached_property
    def _model(self) -> ShearBuildingModel:
        p = self.params
        mass, _, damping = self._matrices
        return build_model(
            mass, p.stiffnesses, damping, p.alpha, p.A, self.delta, self.zeta, p.exponent
        )

    def simulate(self, motions: GroundMotions, *, dt: float | None = None) -> Responses:
        """Nonlinear response of every record, all records integrated together.

        Args:
            motions: ``[n, T]`` ground accelerations in m/s^2.
            dt: ``None`` integrates with classical Runge-Kutta (``substeps`` steps per
                sample) and returns ``[n, T, n_stories]`` on the motion's grid. A step in s
                no shorter than the motion's own resamples the motion onto that grid
                (linear between samples) and integrates it with the three-stage
                Gauss-Legendre implicit Runge-Kutta method, one step per grid interval,
                stable for any step; the response is on that grid.

        Raises:
            InputError: ``motions`` is not a GroundMotions, or ``dt`` is not a positive
                time step at least the motion's.
            CphysfnoError: the integration failed on a record (named in the message).
        """
        if not isinstance(motions, GroundMotions):
            raise InputError(
                f"{self.name}: motions must be a cphysfno_core.GroundMotions, "
                f"got {type(motions).__name__}"
            )
        if dt is None:
            return self._simulate_fine(motions)
        dt = check_time_step(dt, "dt")
        if dt < motions.dt * (1.0 - 1e-9):
            raise InputError(
                f"{self.name}: a coarse dt must be at least the motion's dt = {motions.dt} s, "
                f"got {dt} s; use dt=None for the motion's own grid"
            )
        return self._simulate_coarse(motions.resample(dt))

    def _simulate_fine(self, motions: GroundMotions) -> Responses:
        substeps = self.params.substeps
        with np.errstate(over="ignore", invalid="ignore"):
            states = integrate_rk4(self._model, motions.acceleration, motions.dt, substeps)
        diverged = ~np.all(np.isfinite(states), axis=(1, 2))
        if diverged.any():
            raise CphysfnoError(
                f"{self.name}: the Runge-Kutta integration diverged for record "
                f"{int(np.argmax(diverged))}: its step dt/substeps = "
                f"{motions.dt / substeps:.3g} s is too long for the shortest period "
                f"{self.periods()[-1]:.3g} s; raise substeps"
            )
        return self._responses(states, motions.dt)

    def _simulate_coarse(self, motions: GroundMotions) -> Responses:
        try:
            states = integrate_gauss(
                self._model, motions.acceleration, motions.dt, self._newton_scale
            )
        except StepFailure as failure:
            detail = f" {motions.metadata[failure.record]}" if motions.metadata else ""
            raise CphysfnoError(f"{self.name}: {failure}{detail}") from None
        return self._responses(states, motions.dt)

    @property
    def _newton_scale(self) -> np.ndarray:
        """Typical magnitudes of ``[u, u', h]``: the Bouc-Wen bound of ``|h|`` (m) and that
        bound times the first circular frequency (m/s)."""
        p = self.params
        bound = (p.A / (self.delta + self.zeta)) ** (1.0 / p.exponent)
        first = 2.0 * np.pi / self.periods(1)[0]
        d = len(p.masses)
        return np.concatenate([np.full(d, bound), np.full(d, bound * first), np.full(d, bound)])

    def _responses(self, states: np.ndarray, dt: float) -> Responses:
        d = self._model.n_dof
        displacement = np.ascontiguousarray(states[..., :d])
        drift = displacement @ self._model.compatibility.T
        shear = story_shear(self._model, drift, states[..., 2 * d :])
        return Responses(displacement, dt, {"story_drift": drift, "story_shear": shear})

    def periods(self, n: int | None = None) -> np.ndarray:
        """First ``n`` (default all) elastic natural periods in s, longest first."""
        d = len(self.params.masses)
        if n is None:
            n = d
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or not 1 <= n <= d:
            raise ConfigError(f"{self.name}: n must be an integer from 1 to {d}, got {n!r}")
        mass, stiffness, _ = self._matrices
        omega, _ = elastic_modes(mass, stiffness)
        return 2.0 * np.pi / omega[: int(n)]

    def linear_system(self) -> LinearSystem:
        """Masses (kg), classical damping (N s/m), elastic stiffness (N/m), influence ones,
        identity output map."""
        mass, stiffness, damping = self._matrices
        d = mass.shape[0]
        return LinearSystem(np.diag(mass), damping, stiffness, np.ones(d), np.eye(d))

    def restoring_force(self) -> BoucWenRestoringForce:
        """The Bouc-Wen floor forces ``A_f^T r(A_f u, h)`` and the rate of ``h``."""
        return BoucWenRestoringForce(self._model)

    def supports_coarse_simulation(self) -> bool:
        return True
