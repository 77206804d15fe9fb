"""The building's equations Galerkin-projected onto a basis of floor displacement shapes.

With ``u = Phi q`` (``Phi [d, r]``) and the equations of :mod:`.model` multiplied by
``Phi^T``, the reduced model is

    q'' + C_r q' + diag(kappa) q + B_h h = -p a_g,    h' = g(D q', h),

with story drifts ``v = D q``. The basis is first made mass-orthonormal and diagonalises
the post-yield elastic stiffness (a change of coordinates inside ``span(Phi)``, which leaves
the projection unchanged), so ``M_r = I`` and ``K_r = diag(kappa)``. With ``Phi`` the
identity this is the full model, in the coordinates of its elastic modes.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.linalg

from .model import ShearBuildingModel


class ReducedModel(NamedTuple):
    """Coefficients of a Galerkin-projected building (``r`` coordinates, ``d`` stories).

    ``q`` is in m sqrt(kg); the shapes that map it to metres are in 1/sqrt(kg).

    Attributes:
        stiffness: ``[r]`` kappa, 1/s^2 (post-yield elastic part, ``alpha K``; negative
            where ``alpha`` is).
        damping: ``[r, r]`` C_r, 1/s.
        hysteretic: ``[r, d]`` B_h, from Bouc-Wen displacements h (m) to ``q''``.
        drift: ``[d, r]`` D, from ``q`` to story drifts (m).
        participation: ``[r]`` p, sqrt(kg).
        floors: ``[d, r]`` the shapes, from ``q`` to floor displacements (m).
        story_stiffness: ``[d]`` elastic story stiffnesses k_i, N/m.
        alpha, a, delta, zeta, exponent: the Bouc-Wen parameters.
    """

    stiffness: np.ndarray
    damping: np.ndarray
    hysteretic: np.ndarray
    drift: np.ndarray
    participation: np.ndarray
    floors: np.ndarray
    story_stiffness: np.ndarray
    alpha: float
    a: float
    delta: float
    zeta: float
    exponent: float

    @property
    def n_coordinates(self) -> int:
        """Number r of generalised coordinates."""
        return self.stiffness.shape[0]

    @property
    def n_stories(self) -> int:
        """Number d of stories (Bouc-Wen states)."""
        return self.story_stiffness.shape[0]


def reduce(model: ShearBuildingModel, basis: np.ndarray) -> ReducedModel:
    """Galerkin projection of ``model`` onto ``span(basis)``.

    Args:
        model: the building.
        basis: ``[d, r]`` floor displacement shapes, linearly independent.
    """
    basis = np.asarray(basis, dtype=np.float64)
    compat = model.compatibility
    post_yield = compat.T @ ((model.alpha * model.stiffness)[:, None] * compat)
    mass = np.diag(model.mass)
    reduced_mass = basis.T @ mass @ basis
    kappa, rotation = scipy.linalg.eigh(basis.T @ post_yield @ basis, reduced_mass)
    shapes = basis @ rotation
    hysteretic = shapes.T @ compat.T * ((1.0 - model.alpha) * model.stiffness)
    return ReducedModel(
        stiffness=kappa,
        damping=shapes.T @ model.damping @ shapes,
        hysteretic=hysteretic,
        drift=compat @ shapes,
        participation=shapes.T @ mass @ np.ones(model.n_dof),
        floors=shapes,
        story_stiffness=model.stiffness,
        alpha=model.alpha,
        a=model.a,
        delta=model.delta,
        zeta=model.zeta,
        exponent=model.exponent,
    )
