"""Structure ``duffing-chain``: a shear building whose story springs have a cubic term."""

from __future__ import annotations

import math
from functools import cached_property
from typing import Annotated

import numpy as np
from cphysfno_core import ConfigError, CphysfnoError, GroundMotions, InputError, Responses
from cphysfno_core.plugin import LinearSystem, Params, Structure
from pydantic import Field, ValidationInfo, field_validator

from .chain import CubicSprings, classical_damping, elastic_modes, elastic_stiffness
from .rk4 import integrate_rk4

Positive = Annotated[float, Field(gt=0.0, allow_inf_nan=False)]

MAX_STEP_ANGLE = 0.2
"""Largest ``omega_max h`` (rad) of an automatically chosen RK4 step ``h``, with
``omega_max`` the highest elastic frequency."""


class DuffingChainParams(Params):
    """Parameters of :class:`DuffingChain`."""

    masses: tuple[Positive, ...] = Field(
        (2.0e4, 2.0e4, 2.0e4), min_length=1, description="floor masses from the bottom up, kg"
    )
    stiffnesses: tuple[Positive, ...] = Field(
        (4.0e7, 3.0e7, 2.0e7),
        min_length=1,
        description="small-amplitude story stiffnesses k_i from the bottom up, N/m",
    )
    cubic: float = Field(
        2.0e4,
        ge=0.0,
        allow_inf_nan=False,
        description="gamma of the story force k_i (v + gamma v^3), 1/m^2 (hardening)",
    )
    damping_ratio: float = Field(
        0.05, ge=0.0, lt=1.0, description="viscous damping ratio of every elastic mode"
    )
    substeps: int | None = Field(
        None,
        ge=1,
        le=1000,
        description="RK4 steps per sample; None keeps omega_max h <= 0.2 rad",
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


class DuffingChain(Structure):
    """Shear building with Duffing story springs, integrated by classical RK4.

    ``M u'' + C u' + A^T r(A u) = -M 1 a_g`` with story drifts ``v = A u``
    (``v_i = u_i - u_{i-1}``), story forces ``r_i = k_i (v_i + gamma v_i^3)`` and ``C``
    giving ``damping_ratio`` to every elastic mode. The building starts at rest and the
    ground acceleration is linear between its samples. All records are integrated together
    (NumPy, vectorised over records).

    Outputs are the floor displacements relative to the ground (m), bottom floor first.
    Capabilities: ``linear_system`` (the small-amplitude model, for ``els``) and
    ``restoring_force`` (for ``modal``).
    """

    name = "duffing-chain"
    capabilities = frozenset({"linear_system", "restoring_force"})
    Params = DuffingChainParams

    @property
    def output_names(self) -> tuple[str, ...]:
        return tuple(f"floor-{i + 1}" for i in range(len(self.params.masses)))

    @cached_property
    def _matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        mass = np.asarray(self.params.masses, dtype=np.float64)
        springs = np.asarray(self.params.stiffnesses, dtype=np.float64)
        stiffness = elastic_stiffness(springs)
        damping = classical_damping(mass, stiffness, self.params.damping_ratio)
        return mass, springs, stiffness, damping

    def simulate(self, motions: GroundMotions, *, dt: float | None = None) -> Responses:
        """Floor displacements ``[n, T, n_floors]`` (m) on the motion's grid.

        Raises:
            InputError: ``motions`` is not a GroundMotions, or a ``dt`` is given (this
                structure has no coarse simulation).
            CphysfnoError: the integration diverged (the step is too long for the
                stiffened springs: raise ``substeps``).
        """
        if not isinstance(motions, GroundMotions):
            raise InputError(
                f"{self.name}: motions must be a cphysfno_core.GroundMotions, "
                f"got {type(motions).__name__}"
            )
        if dt is not None:
            raise InputError(f"{self.name}: simulates on the motion's own grid only: use dt=None")
        mass, _, _, damping = self._matrices
        d = len(mass)
        springs = self.restoring_force()

        def rate(y: np.ndarray, acceleration: np.ndarray) -> np.ndarray:
            u, velocity = y[:, :d], y[:, d:]
            force = springs.force(u) + velocity @ damping.T
            return np.concatenate([velocity, -force / mass - acceleration[:, None]], axis=1)

        states = integrate_rk4(
            rate,
            np.zeros((motions.n_records, 2 * d)),
            motions.acceleration,
            motions.dt,
            self.substeps(motions.dt),
        )
        finite = np.isfinite(states).all(axis=(1, 2))
        if not finite.all():
            raise CphysfnoError(
                f"{self.name}: the RK4 integration diverged for record {int(np.argmin(finite))}: "
                f"raise substeps (now {self.substeps(motions.dt)} per sample)"
            )
        return Responses(states[:, :, :d], motions.dt)

    def substeps(self, dt: float) -> int:
        """RK4 steps per sample of ``dt`` s: the parameter, or enough for
        ``omega_max h <= 0.2`` rad."""
        if self.params.substeps is not None:
            return self.params.substeps
        omega_max = 2.0 * np.pi / self.periods()[-1]
        return max(1, math.ceil(omega_max * dt / MAX_STEP_ANGLE))

    def periods(self, n: int | None = None) -> np.ndarray:
        """First ``n`` (default all, at most one per floor) small-amplitude periods in s,
        longest first."""
        d = len(self.params.masses)
        n = d if n is None else n
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
            raise ConfigError(f"{self.name}: n must be a positive integer, got {n!r}")
        mass, _, stiffness, _ = self._matrices
        omega, _ = elastic_modes(mass, stiffness)
        return 2.0 * np.pi / omega[: int(n)]

    def linear_system(self) -> LinearSystem:
        """The small-amplitude model: masses (kg), classical damping (N s/m), stiffness
        ``A^T diag(k) A`` (N/m), influence ones, identity output map."""
        mass, _, stiffness, damping = self._matrices
        d = len(mass)
        return LinearSystem(np.diag(mass), damping, stiffness, np.ones(d), np.eye(d))

    def restoring_force(self) -> CubicSprings:
        """The cubic springs' floor forces."""
        _, springs, _, _ = self._matrices
        return CubicSprings(springs, self.params.cubic)
