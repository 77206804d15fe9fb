"""The Bouc-Wen story forces seen from the floors, for projection onto a reduced basis."""

from __future__ import annotations

import numpy as np

from .model import ShearBuildingModel, hysteretic_rate, story_shear


class BoucWenRestoringForce:
    """Restoring force ``f(u, h) = A_f^T r(A_f u, h)`` with Bouc-Wen state ``h``.

    Satisfies :class:`cphysfno_core.plugin.RestoringForce`: the building obeys
    ``M u'' + C u' + f(u, h) = -M 1 a_g`` and ``h' = g(A_f u', h)``.

    Args:
        model: the building.
    """

    def __init__(self, model: ShearBuildingModel) -> None:
        self._model = model
        self.n_states = model.n_dof

    def initial_state(self, n_records: int) -> np.ndarray:
        """``[n_records, d]`` Bouc-Wen displacements (m) of a building at rest: zeros."""
        return np.zeros((n_records, self.n_states))

    def force(self, u: np.ndarray, state: np.ndarray) -> np.ndarray:
        """``[n, d]`` floor forces in N from displacements ``u`` and ``h`` (m), ``[n, d]``."""
        compat = self._model.compatibility
        return story_shear(self._model, np.asarray(u) @ compat.T, np.asarray(state)) @ compat

    def state_rate(self, u: np.ndarray, velocity: np.ndarray, state: np.ndarray) -> np.ndarray:
        """``[n, d]`` rate ``h'`` in m/s from floor velocities (m/s) and ``h`` (m).

        ``u`` is accepted for the protocol; the Bouc-Wen law does not depend on it.
        """
        drift_rate = np.asarray(velocity) @ self._model.compatibility.T
        return hysteretic_rate(self._model, drift_rate, np.asarray(state))
