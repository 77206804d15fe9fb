"""A shear building with any story law, in the coordinates of a basis of floor shapes.

With floor displacements ``u = Phi q`` (``Phi [d, r]``, mass-orthonormal) the equations
``M u'' + C u' + K_c u + A_f^T F(A_f u, s) = -M 1 a_g`` multiplied by ``Phi^T`` read

    q'' + C_r q' + K_r q + B F(D q, s) = -p a_g,    s' = rate(D q, D q', s),

with ``K_r = Phi^T K_c Phi`` (the linear coupling beside the story springs),
``B = Phi^T A_f^T``, ``D = A_f Phi`` and ``p = Phi^T M 1``. With ``Phi`` the
(mass-normalised) elastic modes of the whole building this is the full model.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.linalg

from .model import compatibility_matrix


class StoryChain(NamedTuple):
    """Coefficients of a (projected) shear building whose story law is separate.

    ``q`` is in m sqrt(kg); the shapes that map it to metres are in 1/sqrt(kg).

    Attributes:
        damping: ``[r, r]`` C_r, 1/s.
        coupling: ``[r, r]`` K_r, 1/s^2.
        force_map: ``[r, d]`` B, from story shears (N) to ``q''``.
        drift: ``[d, r]`` D, from ``q`` to story drifts (m).
        participation: ``[r]`` p, sqrt(kg).
        floors: ``[d, r]`` the shapes, from ``q`` to floor displacements (m).
        coefficients: ``[d, n_c]`` the story law's coefficients of each story.
    """

    damping: np.ndarray
    coupling: np.ndarray
    force_map: np.ndarray
    drift: np.ndarray
    participation: np.ndarray
    floors: np.ndarray
    coefficients: np.ndarray


def project_chain(
    mass: np.ndarray,
    damping: np.ndarray,
    stiffness_matrix: np.ndarray,
    coupling: np.ndarray,
    coefficients: np.ndarray,
    basis: np.ndarray,
) -> StoryChain:
    """Galerkin projection of a shear building onto ``span(basis)``.

    The basis is first made mass-orthonormal and to diagonalise the initial stiffness (a
    change of coordinates inside its span, which leaves the projection unchanged).

    Args:
        mass: ``[d]`` floor masses, kg.
        damping: ``[d, d]`` damping matrix, N s/m.
        stiffness_matrix: ``[d, d]`` initial stiffness matrix, N/m (coupling included).
        coupling: ``[d, d]`` the linear stiffness beside the story springs, N/m.
        coefficients: ``[d, n_c]`` story law coefficients.
        basis: ``[d, r]`` floor displacement shapes, linearly independent.
    """
    basis = np.asarray(basis, dtype=np.float64)
    d = mass.shape[0]
    compat = compatibility_matrix(d)
    _, rotation = scipy.linalg.eigh(
        basis.T @ stiffness_matrix @ basis, basis.T @ (mass[:, None] * basis)
    )
    shapes = basis @ rotation
    return StoryChain(
        damping=shapes.T @ damping @ shapes,
        coupling=shapes.T @ coupling @ shapes,
        force_map=shapes.T @ compat.T,
        drift=compat @ shapes,
        participation=shapes.T @ mass,
        floors=shapes,
        coefficients=np.ascontiguousarray(coefficients, dtype=np.float64),
    )
