"""Equations of motion of a shear building whose stories follow the Bouc-Wen law.

``M u'' + C u' + A_f^T r(v, h) = -M 1 a_g`` with story drifts ``v = A_f u``
(``v_i = u_i - u_{i-1}``, ``u_0 = 0``), story shears ``r_i = k_i [alpha v_i + (1 - alpha) h_i]``
and hysteretic displacements
``h_i' = -delta |v_i'| |h_i|^(n-1) h_i - zeta v_i' |h_i|^n + A v_i'``.

Everything here works on batches: a leading axis of records, then the stories.
:class:`ShearBuildingModel` holds only arrays and floats, so the integrators that take it
work on plain data.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.linalg


class ShearBuildingModel(NamedTuple):
    """Coefficients of the first-order equations of a ``d``-story Bouc-Wen shear building.

    The state of each record is ``y = [u, u', h]`` (``3d`` entries: m, m/s, m) and
    ``y' = L y + b a_g + [0, 0, h'(A_f u', h)]``.

    Attributes:
        state_matrix: ``[3d, 3d]`` matrix L of the linear part (kinematics, damping,
            elastic and hysteretic story shears), SI units.
        influence: ``[3d]`` vector b of the ground acceleration (-1 on the velocities).
        compatibility: ``[d, d]`` matrix A_f mapping floor displacements to story drifts.
        stiffness: ``[d]`` elastic story stiffnesses k_i, N/m.
        alpha: post-yield to elastic stiffness ratio.
        a: Bouc-Wen amplitude A.
        delta: Bouc-Wen shape coefficient delta, 1/m^n.
        zeta: Bouc-Wen shape coefficient zeta, 1/m^n.
        exponent: Bouc-Wen smoothness exponent n.
    """

    state_matrix: np.ndarray
    influence: np.ndarray
    compatibility: np.ndarray
    stiffness: np.ndarray
    alpha: float
    a: float
    delta: float
    zeta: float
    exponent: float

    @property
    def n_dof(self) -> int:
        """Number of stories d."""
        return self.stiffness.shape[0]


def build_model(
    mass: np.ndarray,
    stiffness: np.ndarray,
    damping: np.ndarray,
    alpha: float,
    a: float,
    delta: float,
    zeta: float,
    exponent: float,
) -> ShearBuildingModel:
    """Assemble :class:`ShearBuildingModel`.

    Args:
        mass: ``[d]`` floor masses, kg.
        stiffness: ``[d]`` elastic story stiffnesses, N/m.
        damping: ``[d, d]`` damping matrix, N s/m.
        alpha, a, delta, zeta, exponent: the Bouc-Wen parameters.
    """
    mass = np.asarray(mass, dtype=np.float64)
    stiffness = np.asarray(stiffness, dtype=np.float64)
    d = mass.shape[0]
    compat = compatibility_matrix(d)
    inverse_mass = (1.0 / mass)[:, None]
    state_matrix = np.zeros((3 * d, 3 * d))
    state_matrix[:d, d : 2 * d] = np.eye(d)
    state_matrix[d : 2 * d, :d] = -inverse_mass * elastic_stiffness(alpha * stiffness)
    state_matrix[d : 2 * d, d : 2 * d] = -inverse_mass * damping
    state_matrix[d : 2 * d, 2 * d :] = -inverse_mass * (compat.T * ((1.0 - alpha) * stiffness))
    influence = np.zeros(3 * d)
    influence[d : 2 * d] = -1.0
    return ShearBuildingModel(
        state_matrix, influence, compat, stiffness, alpha, a, delta, zeta, exponent
    )


def compatibility_matrix(n_stories: int) -> np.ndarray:
    """``[d, d]`` matrix A_f with ``(A_f u)_i = u_i - u_{i-1}`` and ``u_0 = 0``."""
    return np.eye(n_stories) - np.eye(n_stories, k=-1)


def elastic_stiffness(stiffness: np.ndarray) -> np.ndarray:
    """``[d, d]`` elastic stiffness matrix ``A_f^T diag(k) A_f`` (N/m), tridiagonal."""
    compat = compatibility_matrix(len(stiffness))
    return compat.T @ (np.asarray(stiffness)[:, None] * compat)


def elastic_modes(mass: np.ndarray, stiffness_matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Circular frequencies ``[d]`` (rad/s, ascending) and mass-normalised modes ``[d, d]``.

    Args:
        mass: ``[d]`` floor masses in kg.
        stiffness_matrix: ``[d, d]`` elastic stiffness matrix in N/m.
    """
    eigenvalues, modes = scipy.linalg.eigh(stiffness_matrix, np.diag(mass))
    return np.sqrt(eigenvalues), modes


def classical_damping(
    mass: np.ndarray, stiffness_matrix: np.ndarray, damping_ratio: float
) -> np.ndarray:
    """``[d, d]`` damping ``M Phi diag(2 zeta w_j) Phi^T M`` (N s/m): ``zeta`` in every mode."""
    omega, modes = elastic_modes(mass, stiffness_matrix)
    mass_modes = np.asarray(mass)[:, None] * modes
    return mass_modes @ np.diag(2.0 * damping_ratio * omega) @ mass_modes.T


def story_shear(model: ShearBuildingModel, drift: np.ndarray, hysteretic: np.ndarray) -> np.ndarray:
    """Story shears ``r = k [alpha v + (1 - alpha) h]`` in N, shaped like ``drift`` (m)."""
    return model.stiffness * (model.alpha * drift + (1.0 - model.alpha) * hysteretic)


def hysteretic_rate(
    model: ShearBuildingModel, drift_rate: np.ndarray, hysteretic: np.ndarray
) -> np.ndarray:
    """Bouc-Wen rate ``h'`` (m/s) from drift rates ``v'`` (m/s) and ``h`` (m), same shape."""
    magnitude = np.abs(hysteretic)
    power = magnitude ** (model.exponent - 1.0)
    return drift_rate * (model.a - model.zeta * power * magnitude) - (
        model.delta * np.abs(drift_rate) * power * hysteretic
    )


def _hysteretic_rate_derivatives(
    model: ShearBuildingModel, drift_rate: np.ndarray, hysteretic: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Partial derivatives of :func:`hysteretic_rate` by ``v'`` (-) and by ``h`` (1/s)."""
    magnitude = np.abs(hysteretic)
    power = magnitude ** (model.exponent - 1.0)
    by_drift_rate = (
        model.a
        - model.delta * np.sign(drift_rate) * power * hysteretic
        - model.zeta * power * magnitude
    )
    by_hysteretic = (
        -model.exponent
        * power
        * (model.delta * np.abs(drift_rate) + model.zeta * drift_rate * np.sign(hysteretic))
    )
    return by_drift_rate, by_hysteretic


def rates(
    model: ShearBuildingModel, state: np.ndarray, ground_acceleration: np.ndarray
) -> np.ndarray:
    """Time derivative ``y'`` of the states ``y = [u, u', h]``, ``[n, 3d]``.

    Args:
        model: the building.
        state: ``[n, 3d]`` floor displacements relative to the ground (m), floor
            velocities (m/s) and Bouc-Wen displacements (m).
        ground_acceleration: ``[n]`` a_g in m/s^2.
    """
    d = model.n_dof
    derivative = state @ model.state_matrix.T + ground_acceleration[:, None] * model.influence
    drift_rate = state[:, d : 2 * d] @ model.compatibility.T
    derivative[:, 2 * d :] = hysteretic_rate(model, drift_rate, state[:, 2 * d :])
    return derivative


def rate_jacobian(model: ShearBuildingModel, state: np.ndarray) -> np.ndarray:
    """``[n, 3d, 3d]`` Jacobian of :func:`rates` with respect to the states ``[n, 3d]``."""
    d = model.n_dof
    drift_rate = state[:, d : 2 * d] @ model.compatibility.T
    by_drift_rate, by_hysteretic = _hysteretic_rate_derivatives(
        model, drift_rate, state[:, 2 * d :]
    )
    jacobian = np.repeat(model.state_matrix[None], state.shape[0], axis=0)
    jacobian[:, 2 * d :, d : 2 * d] = by_drift_rate[:, :, None] * model.compatibility
    diagonal = np.arange(2 * d, 3 * d)
    jacobian[:, diagonal, diagonal] = by_hysteretic
    return jacobian
