"""Modal reduction: the nonlinear structure projected on its lowest elastic modes (paper §3.2.2)."""

from __future__ import annotations

import math

import numpy as np
from pydantic import Field
from scipy.linalg import eigh

from cphysfno_core import ConfigError, GroundMotions, plugin
from cphysfno_core.plugin import LinearSystem, PhysicsPreprocessor, Structure

from .fitted import check_fitted
from .linear_response import linear_response

MAX_STEP_ANGLE = 0.25
"""Largest ``omega_r h`` (rad) of an automatically chosen Runge-Kutta sub-step ``h``."""


class ModalReduction(PhysicsPreprocessor):
    """``z = L Phi_r q`` with ``q`` from the nonlinear equations projected on ``r`` modes.

    ``Phi_r [n_dof, r]`` holds the ``r`` lowest undamped elastic modes of ``(M, K)``,
    mass-normalised (``Phi_r^T M Phi_r = I``). The reduced system is::

        q'' + C_r q' + Phi_r^T f(Phi_r q, s) = -Phi_r^T M r a_g,   s' = g(Phi_r q, Phi_r q', s)

    with ``C_r = Phi_r^T C Phi_r`` and ``f``, ``g`` the structure's restoring force and the
    rate of its internal state. It is integrated from rest with the classical explicit
    Runge-Kutta scheme, ``substeps`` steps per sample, with ``a_g`` linear between samples.
    With ``r = n_dof`` it is the full nonlinear model.

    A structure with the capability ``projected_simulation`` integrates the reduced model
    itself (:meth:`Structure.simulate_projected`, typically compiled); otherwise this class
    does, in NumPy, from the structure's ``restoring_force``.

    A structure without ``restoring_force`` (an OpenSees model, whose forces only OpenSees
    knows) gets the linear modal truncation: ``f = K u`` and no internal state, so
    ``q_i'' + (C_r q')_i + omega_i^2 q_i = -Gamma_i a_g``, solved exactly for ``a_g`` linear
    between samples. It is the ELS restricted to ``r`` modes: it carries no yielding.

    Fitted attributes (``q`` is in m sqrt(kg)):
        shapes_: ``[n_dof, r]`` mass-normalised mode shapes in 1/sqrt(kg).
        frequencies_: ``[r]`` elastic circular frequencies in rad/s, ascending.
        modal_damping_: ``[r, r]`` ``C_r`` in 1/s.
        participation_: ``[r]`` ``Phi_r^T M r`` in sqrt(kg).
        output_shapes_: ``[n_outputs, r]`` ``L Phi_r`` in 1/sqrt(kg).
        restoring_force_: the structure's restoring force; None for the linear truncation.
        reduced_system_: the reduced linear system ``(I, C_r, diag(omega^2))`` in ``q``
            with the outputs ``L Phi_r``, which the linear truncation solves; None where
            the structure has a restoring force.
        structure_: the structure, which integrates the reduced model where it can.
    """

    name = "modal"
    requires = frozenset({"linear_system"})

    class Params(plugin.Params):
        modes: int = Field(2, ge=1, description="number r of retained modes, 1 <= r <= n_dof")
        substeps: int | None = Field(
            None,
            ge=1,
            description="Runge-Kutta steps per sample; None keeps omega_r h <= 0.25 rad",
        )

    def fit(self, structure: Structure) -> ModalReduction:
        """Compute the modes and reduced matrices (capability ``linear_system``; with
        ``restoring_force`` the reduced model is nonlinear, without it linear)."""
        self.check(structure)
        system = structure.linear_system()
        r = self.params.modes
        if r > system.n_dof:
            raise ConfigError(
                f"{self.name}.modes: must be at most the {system.n_dof} degrees of freedom "
                f"of structure '{structure.name}', got {r}"
            )
        eigenvalues, vectors = eigh(system.stiffness, system.mass, subset_by_index=(0, r - 1))
        self.shapes_ = vectors
        self.frequencies_ = np.sqrt(np.clip(eigenvalues, 0.0, None))
        self.modal_damping_ = vectors.T @ system.damping @ vectors
        self.participation_ = vectors.T @ system.mass @ system.influence
        self.output_shapes_ = system.output_map @ vectors
        self.structure_ = structure
        if "restoring_force" in structure.capabilities:
            self.restoring_force_ = structure.restoring_force()
            self.reduced_system_ = None
        else:
            self.restoring_force_ = None
            self.reduced_system_ = LinearSystem(
                mass=np.eye(r),
                damping=self.modal_damping_,
                stiffness=np.diag(self.frequencies_**2),
                influence=self.participation_,
                output_map=self.output_shapes_,
            )
        return self

    def substeps_for(self, dt: float) -> int:
        """Runge-Kutta steps per sample of step ``dt`` (s)."""
        check_fitted(self, "frequencies_")
        if self.params.substeps is not None:
            return self.params.substeps
        return max(1, math.ceil(self.frequencies_[-1] * dt / MAX_STEP_ANGLE))

    def transform(self, motions: GroundMotions) -> np.ndarray:
        """``[n_records, n_steps, n_outputs]`` reduced-model displacements in m."""
        check_fitted(self, "shapes_")
        if self.reduced_system_ is not None:
            return linear_response(self.reduced_system_, motions.acceleration, motions.dt)
        n_sub = self.substeps_for(motions.dt)
        if "projected_simulation" in self.structure_.capabilities:
            projected = self.structure_.simulate_projected(motions, self.shapes_, substeps=n_sub)
            return projected.displacement
        ag = motions.acceleration
        n_records, n_steps = ag.shape
        h = motions.dt / n_sub
        r = self.params.modes
        state = np.concatenate(
            [np.zeros((n_records, 2 * r)), self.restoring_force_.initial_state(n_records)],
            axis=1,
        )
        coordinates = np.zeros((n_steps, n_records, r))
        for k in range(n_steps - 1):
            start, slope = ag[:, k], (ag[:, k + 1] - ag[:, k]) / n_sub
            for i in range(n_sub):
                state = self._rk4_step(state, start + i * slope, slope, h)
            coordinates[k + 1] = state[:, :r]
        return coordinates.transpose(1, 0, 2) @ self.output_shapes_.T

    def _rk4_step(
        self, state: np.ndarray, ag_start: np.ndarray, ag_rise: np.ndarray, h: float
    ) -> np.ndarray:
        """One Runge-Kutta step of ``h`` s with ``a_g`` rising by ``ag_rise`` (m/s^2) over it."""
        ag_mid = ag_start + 0.5 * ag_rise
        k1 = self._rate(state, ag_start)
        k2 = self._rate(state + 0.5 * h * k1, ag_mid)
        k3 = self._rate(state + 0.5 * h * k2, ag_mid)
        k4 = self._rate(state + h * k3, ag_start + ag_rise)
        return state + (h / 6.0) * (k1 + 2.0 * (k2 + k3) + k4)

    def _rate(self, state: np.ndarray, ag: np.ndarray) -> np.ndarray:
        """Time derivative of ``[q, q', s]`` ``[n_records, 2 r + n_states]`` at ``a_g`` ``[n]``."""
        r = self.params.modes
        q, q_rate, internal = state[:, :r], state[:, r : 2 * r], state[:, 2 * r :]
        u, velocity = q @ self.shapes_.T, q_rate @ self.shapes_.T
        force = self.restoring_force_.force(u, internal)
        q_accel = -(q_rate @ self.modal_damping_.T) - force @ self.shapes_
        q_accel -= ag[:, None] * self.participation_
        internal_rate = self.restoring_force_.state_rate(u, velocity, internal)
        return np.concatenate([q_rate, q_accel, internal_rate], axis=1)
