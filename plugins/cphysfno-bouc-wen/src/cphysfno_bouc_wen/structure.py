"""The Bouc-Wen hysteretic shear building of the paper's Example 1 (§5.1)."""

from __future__ import annotations

import math
from functools import cached_property
from typing import Annotated, Literal

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
from .model import ShearBuildingModel, classical_damping, elastic_modes, elastic_stiffness
from .reduced import ReducedModel, reduce
from .restoring import BoucWenRestoringForce

Positive = Annotated[float, Field(gt=0.0, allow_inf_nan=False)]

MAX_STEP_ANGLE = 0.45
"""Largest ``omega_max h`` (rad) of an automatically chosen Runge-Kutta step ``h``: the
relative L2 error stays near 1e-4 (2e-4 to 3e-4 where the stories yield)."""


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


class BoucWenShearBuilding(Structure):
    """Shear building whose stories follow the Bouc-Wen hysteresis law.

    ``M u'' + C u' + A_f^T r(v, h) = -M 1 a_g`` with story drifts ``v = A_f u``,
    story shears ``r_i = k_i [alpha v_i + (1 - alpha) h_i]`` and
    ``h_i' = -delta |v_i'| |h_i|^(n-1) h_i - zeta v_i' |h_i|^n + A v_i'``; ``C`` gives
    the same damping ratio to every elastic mode. The ground acceleration is linear
    between its samples and the building starts at rest.

    Outputs are the floor displacements relative to the ground (m), bottom floor first;
    :meth:`simulate` also returns the extras ``"story_drift"`` (v, m) and
    ``"story_shear"`` (r, N), each ``[n, T, n_stories]``; on the motion's grid they are in
    the arithmetic ``precision`` names (float32 by default), on a coarse grid in float64.
    """

    name = "bouc-wen-shear-building"
    Params = BoucWenShearBuildingParams
    capabilities = frozenset(
        {"linear_system", "restoring_force", "coarse_simulation", "projected_simulation"}
    )

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
        stiffness = np.asarray(p.stiffnesses, dtype=np.float64)
        return ShearBuildingModel(
            mass, damping, stiffness, p.alpha, p.A, self.delta, self.zeta, p.exponent
        )

    @cached_property
    def _full_model(self) -> ReducedModel:
        """The whole model, in the coordinates of its elastic modes."""
        d = self._model.n_dof
        return reduce(self._model, np.eye(d))

    def simulate(self, motions: GroundMotions, *, dt: float | None = None) -> Responses:
        """Nonlinear response of every record, all records integrated together.

        Args:
            motions: ``[n, T]`` ground accelerations in m/s^2.
            dt: ``None`` integrates with classical Runge-Kutta (``substeps`` steps per
                sample, in the arithmetic ``precision`` names) and returns
                ``[n, T, n_stories]`` on the motion's grid. A step in s no shorter than the
                motion's own resamples the motion onto that grid (linear between samples)
                and integrates it with the three-stage Gauss-Legendre implicit Runge-Kutta
                method in float64, one step per grid interval, stable for any step; the
                response is on that grid.

        Raises:
            InputError: ``motions`` is not a GroundMotions, or ``dt`` is not a positive
                time step at least the motion's.
            CphysfnoError: the integration failed on a record (named in the message).
        """
        self._check_motions(motions)
        if dt is None:
            return self._runge_kutta(self._full_model, motions, self.params.substeps)
        dt = check_time_step(dt, "dt")
        if dt < motions.dt * (1.0 - 1e-9):
            raise InputError(
                f"{self.name}: a coarse dt must be at least the motion's dt = {motions.dt} s, "
                f"got {dt} s; use dt=None for the motion's own grid"
            )
        return self._simulate_coarse(motions.resample(dt))

    def simulate_projected(
        self, motions: GroundMotions, basis: np.ndarray, *, substeps: int | None = None
    ) -> Responses:
        """Nonlinear response of the model Galerkin-projected onto ``basis``.

        With floor displacements ``u = basis q``, the equations of motion multiplied by
        ``basis^T`` are integrated on the motion's grid with classical Runge-Kutta, as
        :meth:`simulate` does with ``dt=None`` (which is the identity basis).

        Args:
            motions: ``[n, T]`` ground accelerations in m/s^2.
            basis: ``[n_stories, r]`` floor displacement shapes, linearly independent.
            substeps: Runge-Kutta steps per sample; ``None`` takes the parameter
                ``substeps``.

        Returns:
            Floor displacements ``[n, T, n_stories]`` (m) with the extras of
            :meth:`simulate`.

        Raises:
            InputError: ``motions`` is not a GroundMotions, or ``basis`` is not a
                ``[n_stories, r]`` array of full column rank, or ``substeps < 1``.
            CphysfnoError: the integration diverged on a record (named in the message).
        """
        self._check_motions(motions)
        d = len(self.params.masses)
        basis = np.asarray(basis, dtype=np.float64)
        if basis.ndim != 2 or basis.shape[0] != d or np.linalg.matrix_rank(basis) < basis.shape[1]:
            raise InputError(
                f"{self.name}: basis must be [{d}, r] with linearly independent columns, "
                f"got shape {basis.shape}"
            )
        if substeps is None:
            substeps = self.params.substeps
        if substeps is not None and (
            isinstance(substeps, bool) or not isinstance(substeps, int | np.integer) or substeps < 1
        ):
            raise InputError(f"{self.name}: substeps must be an integer >= 1, got {substeps!r}")
        return self._runge_kutta(reduce(self._model, basis), motions, substeps)

    def _runge_kutta(
        self, model: ReducedModel, motions: GroundMotions, substeps: int | None
    ) -> Responses:
        if substeps is None:
            omega_max = 2.0 * np.pi / self.periods()[-1]
            substeps = max(1, math.ceil(omega_max * motions.dt / MAX_STEP_ANGLE))
        precision = np.float32 if self.params.precision == "float32" else np.float64
        displacement, drift, shear, finite = integrate_rk4(
            model, motions.acceleration, motions.dt, substeps, precision
        )
        if not finite.all():
            raise CphysfnoError(
                f"{self.name}: the Runge-Kutta integration diverged for record "
                f"{int(np.argmin(finite))}: its step dt/substeps = "
                f"{motions.dt / substeps:.3g} s is too long for the shortest period "
                f"{self.periods()[-1]:.3g} s; raise substeps"
            )
        return Responses(displacement, motions.dt, {"story_drift": drift, "story_shear": shear})

    def _simulate_coarse(self, motions: GroundMotions) -> Responses:
        try:
            displacement, drift, shear = integrate_gauss(
                self._full_model, motions.acceleration, motions.dt, self._newton_scale
            )
        except StepFailure as failure:
            detail = f" {motions.metadata[failure.record]}" if motions.metadata else ""
            raise CphysfnoError(f"{self.name}: {failure}{detail}") from None
        return Responses(displacement, motions.dt, {"story_drift": drift, "story_shear": shear})

    def _check_motions(self, motions: GroundMotions) -> None:
        if not isinstance(motions, GroundMotions):
            raise InputError(
                f"{self.name}: motions must be a cphysfno_core.GroundMotions, "
                f"got {type(motions).__name__}"
            )

    @property
    def _newton_scale(self) -> float:
        """Typical magnitude of the Bouc-Wen displacements: the bound of ``|h|``, m."""
        p = self.params
        return (p.A / (self.delta + self.zeta)) ** (1.0 / p.exponent)

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
