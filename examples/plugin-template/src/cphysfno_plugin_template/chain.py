"""A chain of masses joined by springs with a cubic term (a shear building whose stories
are Duffing springs)::

    M u'' + C u' + A^T r(A u) = -M 1 a_g,    r_i(v_i) = k_i (v_i + gamma v_i^3)

with floor displacements ``u`` relative to the ground, story drifts ``v = A u``
(``v_i = u_i - u_{i-1}``, ``u_0 = 0``) and ``C`` classical damping.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg


def compatibility(n_floors: int) -> np.ndarray:
    """``[d, d]`` matrix A with ``(A u)_i = u_i - u_{i-1}`` and ``u_0 = 0``."""
    return np.eye(n_floors) - np.eye(n_floors, k=-1)


def elastic_stiffness(stiffness: np.ndarray) -> np.ndarray:
    """``[d, d]`` small-amplitude stiffness matrix ``A^T diag(k) A`` in N/m."""
    a = compatibility(len(stiffness))
    return a.T @ (np.asarray(stiffness)[:, None] * a)


def elastic_modes(mass: np.ndarray, stiffness: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Circular frequencies ``[d]`` (rad/s, ascending) and mass-normalised modes ``[d, d]``.

    Args:
        mass: ``[d]`` floor masses in kg.
        stiffness: ``[d, d]`` stiffness matrix in N/m.
    """
    eigenvalues, modes = scipy.linalg.eigh(stiffness, np.diag(mass))
    return np.sqrt(eigenvalues), modes


def classical_damping(mass: np.ndarray, stiffness: np.ndarray, ratio: float) -> np.ndarray:
    """``[d, d]`` damping ``M Phi diag(2 ratio w_j) Phi^T M`` (N s/m): ``ratio`` in every
    elastic mode."""
    omega, modes = elastic_modes(mass, stiffness)
    mass_modes = np.asarray(mass)[:, None] * modes
    return mass_modes @ np.diag(2.0 * ratio * omega) @ mass_modes.T


class CubicSprings:
    """The story springs' forces on the floors, ``A^T r(A u)``; they have no internal state.

    Satisfies :class:`cphysfno_core.plugin.RestoringForce`.

    Args:
        stiffness: ``[d]`` small-amplitude story stiffnesses k_i in N/m.
        cubic: gamma in 1/m^2.
    """

    n_states = 0

    def __init__(self, stiffness: np.ndarray, cubic: float) -> None:
        self._stiffness = np.asarray(stiffness, dtype=np.float64)
        self._cubic = float(cubic)
        self._compatibility = compatibility(len(self._stiffness))

    def initial_state(self, n_records: int) -> np.ndarray:
        """``[n_records, 0]``: nothing to remember."""
        return np.zeros((n_records, 0))

    def force(self, u: np.ndarray, state: np.ndarray | None = None) -> np.ndarray:
        """``[n, d]`` floor forces in N from floor displacements ``u [n, d]`` in m."""
        drift = np.asarray(u) @ self._compatibility.T
        return (self._stiffness * drift * (1.0 + self._cubic * drift * drift)) @ self._compatibility

    def state_rate(self, u: np.ndarray, velocity: np.ndarray, state: np.ndarray) -> np.ndarray:
        """``[n, 0]``: nothing evolves."""
        return np.zeros((np.shape(u)[0], 0))
