"""Linear structural models: the equations of motion of a linear system and Rayleigh
damping."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import InputError


@dataclass(frozen=True)
class LinearSystem:
    """A linear structural model ``M u'' + C u' + K u = -M r a_g``, outputs ``y = L u``.

    Attributes:
        mass: ``[n_dof, n_dof]`` in kg.
        damping: ``[n_dof, n_dof]`` in N s/m.
        stiffness: ``[n_dof, n_dof]`` in N/m.
        influence: ``[n_dof]`` ground-motion influence vector r (ones for a shear building).
        output_map: ``[n_outputs, n_dof]`` map L from DOF displacements to outputs.
    """

    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    influence: np.ndarray
    output_map: np.ndarray

    def __post_init__(self) -> None:
        n = np.asarray(self.mass).shape[0]
        for name in ("mass", "damping", "stiffness"):
            value = np.asarray(getattr(self, name), dtype=np.float64)
            if value.shape != (n, n):
                raise InputError(f"{name} must be [{n}, {n}], got {value.shape}")
            object.__setattr__(self, name, value)
        influence = np.asarray(self.influence, dtype=np.float64).reshape(-1)
        if influence.shape != (n,):
            raise InputError(f"influence must have {n} entries, got {influence.shape}")
        object.__setattr__(self, "influence", influence)
        output_map = np.atleast_2d(np.asarray(self.output_map, dtype=np.float64))
        if output_map.shape[1] != n:
            raise InputError(f"output_map must be [n_outputs, {n}], got {output_map.shape}")
        object.__setattr__(self, "output_map", output_map)

    @property
    def n_dof(self) -> int:
        return self.mass.shape[0]

    def state_space(self) -> tuple[np.ndarray, np.ndarray]:
        """``A [2 n_dof, 2 n_dof]`` and ``B [2 n_dof]`` of ``x' = A x + B a_g`` for the state
        ``x = [u (m), u' (m/s)]``: ``A = [[0, I], [-M^-1 K, -M^-1 C]]``, ``B = [0, -r]``."""
        n = self.n_dof
        a = np.zeros((2 * n, 2 * n))
        a[:n, n:] = np.eye(n)
        a[n:, :n] = -np.linalg.solve(self.mass, self.stiffness)
        a[n:, n:] = -np.linalg.solve(self.mass, self.damping)
        b = np.concatenate([np.zeros(n), -self.influence])
        return a, b


@dataclass(frozen=True)
class Rayleigh:
    """Rayleigh damping ``C = mass_factor M + stiffness_factor K``.

    Attributes:
        mass_factor: coefficient of the mass matrix, 1/s.
        stiffness_factor: coefficient of the stiffness matrix, s.
    """

    mass_factor: float
    stiffness_factor: float

    @classmethod
    def matching(cls, omega_a: float, omega_b: float, ratio: float) -> Rayleigh:
        """The factors that give ``ratio`` of critical damping at the circular frequencies
        ``omega_a`` and ``omega_b`` (rad/s)."""
        if not (omega_a > 0 and omega_b > 0):
            raise InputError(f"Rayleigh frequencies must be > 0 rad/s, got {omega_a}, {omega_b}")
        total = omega_a + omega_b
        return cls(2.0 * ratio * omega_a * omega_b / total, 2.0 * ratio / total)

    def matrix(self, mass: np.ndarray, stiffness: np.ndarray) -> np.ndarray:
        """``C [n, n]`` in N s/m from ``mass`` (kg) and ``stiffness`` (N/m), each ``[n, n]``."""
        return self.mass_factor * np.asarray(mass) + self.stiffness_factor * np.asarray(stiffness)

    def ratio(self, omega: float | np.ndarray) -> float | np.ndarray:
        """The fraction of critical damping at circular frequency ``omega`` (rad/s)."""
        return 0.5 * (self.mass_factor / omega + self.stiffness_factor * omega)
