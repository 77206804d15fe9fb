"""The restoring force of a shear building with any story law, for NumPy integrators."""

from __future__ import annotations

import numpy as np
from cphysfno_core.plugin import StoryLaw

from .generic import law_evaluator
from .model import compatibility_matrix


class StoryLawRestoringForce:
    """Restoring force ``f(u, s) = A_f^T F(A_f u, s) + K_c u`` with the story law's state
    ``s``.

    Satisfies :class:`cphysfno_core.plugin.RestoringForce`: the building obeys
    ``M u'' + C u' + f(u, s) = -M 1 a_g`` and ``s' = rate(A_f u, A_f u', s)``. The state of
    a batch is ``[n, d * n_states]``, story after story.

    Args:
        law: the story law.
        coefficients: ``[d, n_c]`` its coefficients for each story.
        coupling: ``[d, d]`` the linear stiffness ``K_c`` beside the story springs, N/m
            (zeros: none).
    """

    def __init__(self, law: StoryLaw, coefficients: np.ndarray, coupling: np.ndarray) -> None:
        self._coefficients = np.ascontiguousarray(coefficients, dtype=np.float64)
        self._d = self._coefficients.shape[0]
        self._width = max(law.n_states, 1)
        self._law_states = law.n_states
        self._evaluate = law_evaluator(law.functions(), law.n_states)
        self._compat = compatibility_matrix(self._d)
        self._coupling = coupling
        self.n_states = self._d * law.n_states

    def initial_state(self, n_records: int) -> np.ndarray:
        """``[n_records, d * n_states]`` state of a building at rest: zeros."""
        return np.zeros((n_records, self.n_states))

    def _states(self, state: np.ndarray) -> np.ndarray:
        n = state.shape[0]
        full = np.zeros((n, self._d, self._width))
        full[:, :, : self._law_states] = np.asarray(state, dtype=np.float64).reshape(
            n, self._d, self._law_states
        )
        return full

    def force(self, u: np.ndarray, state: np.ndarray) -> np.ndarray:
        """``[n, d]`` floor forces in N from floor displacements ``u [n, d]`` (m)."""
        u = np.atleast_2d(np.asarray(u, dtype=np.float64))
        drift = u @ self._compat.T
        shear, _ = self._evaluate(
            self._coefficients, drift, np.zeros_like(drift), self._states(state)
        )
        return shear @ self._compat + u @ self._coupling

    def state_rate(self, u: np.ndarray, velocity: np.ndarray, state: np.ndarray) -> np.ndarray:
        """``[n, d * n_states]`` rate of the law's state from displacements (m) and
        velocities (m/s), ``[n, d]`` each."""
        u = np.atleast_2d(np.asarray(u, dtype=np.float64))
        drift = u @ self._compat.T
        drift_rate = np.atleast_2d(np.asarray(velocity, dtype=np.float64)) @ self._compat.T
        _, rates = self._evaluate(self._coefficients, drift, drift_rate, self._states(state))
        return rates[:, :, : self._law_states].reshape(u.shape[0], self.n_states)
