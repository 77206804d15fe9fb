"""Equations of motion of a shear building whose stories follow the Bouc-Wen law.

``M u'' + C u' + A_f^T r(v, h) = -M 1 a_g`` with story drifts ``v = A_f u``
(``v_i = u_i - u_{i-1}``, ``u_0 = 0``), story shears ``r_i = k_i [alpha v_i + (1 - alpha) h_i]``
and hysteretic displacements
``h_i' = -delta |v_i'| |h_i|^(n-1) h_i - zeta v_i' |h_i|^n + A v_i'``.

:class:`ShearBuildingModel` holds only arrays and floats. The functions on the Bouc-Wen law
work on batches: a leading axis of records, then the stories.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.linalg


class ShearBuildingModel(NamedTuple):
    """A ``d``-story Bouc-Wen shear building.

    Attributes:
        mass: ``[d]`` floor masses, kg.
        damping: ``[d, d]`` damping matrix, N s/m.
        stiffness: ``[d]`` elastic story stiffnesses k_i, N/m.
        alpha: post-yield to elastic stiffness ratio.
        a: Bouc-Wen amplitude A.
        delta: Bouc-Wen shape coefficient delta, 1/m^n.
        zeta: Bouc-Wen shape coefficient zeta, 1/m^n.
        exponent: Bouc-Wen smoothness exponent n.
    """

    mass: np.ndarray
    damping: np.ndarray
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

    @property
    def compatibility(self) -> np.ndarray:
        """``[d, d]`` matrix A_f from floor displacements to story drifts."""
        return compatibility_matrix(self.n_dof)


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
