"""Split-conformal prediction intervals around the operator's prediction.

The refined mean is the operator's prediction û. On a calibration split not used to fit the
operator's weights (the validation split), the nonconformity score of every (record, time)
point of DOF ``i`` is ``|u_i - û_i| / s_i``, with ``s_i`` either 1 (``scale = "constant"``)
or the local amplitude of the physics response (``scale = "physics-envelope"``: the moving
RMS of ``z_i`` over ``window`` samples, floored at ``floor`` times the RMS of ``z_i`` on the
calibration split). The interval of level ``p`` is ``û_i ± q_i s_i`` with ``q_i`` the
``k``-th smallest of the ``N`` calibration scores, ``k = ceil((N + 1) p)`` (read from
quantiles kept on a fine grid of levels, exact to the spacing of neighbouring scores). For records
exchangeable with the calibration records this covers a fraction ``p`` of the (record, time)
points on average; the envelope scale makes the interval wide where the structure moves much
and narrow where it is at rest, instead of one width for the whole record.
"""

from __future__ import annotations

from typing import ClassVar, Literal

import numpy as np
from pydantic import Field
from scipy.ndimage import uniform_filter1d

from cphysfno_core import InputError, NotFittedError
from cphysfno_core.plugin import Params, Refiner

from .arrays import as_responses

ONE_SIGMA = 0.6826894921370859
"""Probability of a standard normal within one standard deviation: the level whose
half-width :meth:`ConformalRefiner.predict` reports as ``std``."""


class ConformalParams(Params):
    """Parameters of :class:`ConformalRefiner`.

    Attributes:
        scale: ``"constant"`` (one width per DOF) or ``"physics-envelope"`` (width
            proportional to the local amplitude of z).
        window: samples of the moving RMS of z (``physics-envelope``).
        floor: smallest envelope, as a fraction of z's calibration RMS per DOF.
        n_quantiles: quantiles of the calibration scores kept, on a uniform grid of levels.
    """

    scale: Literal["constant", "physics-envelope"] = "constant"
    window: int = Field(101, ge=1)
    floor: float = Field(0.1, gt=0)
    n_quantiles: int = Field(2001, ge=11)


class ConformalRefiner(Refiner):
    """Calibrated intervals ``û ± q s`` at any level (see the module docstring).

    Fitted attributes:
        quantiles_: ``[n_quantiles, dof]`` calibration-score quantiles on the level grid
            ``linspace(0, 1, n_quantiles)``.
        floor_: ``[dof]`` envelope floor in m (ones for ``scale = "constant"``).
        n_scores_: number of calibration scores per DOF.
    """

    name = "conformal"
    Params = ConformalParams
    calibration_split: ClassVar[str] = "validation"

    def fit(
        self, z: np.ndarray, u_hat: np.ndarray, u: np.ndarray, rng: np.random.Generator
    ) -> ConformalRefiner:
        """Calibrate on ``[n, T, dof]`` arrays (m) of a split the operator was not fitted
        on; ``rng`` is unused (every point is a score)."""
        z, u_hat, u = as_responses(self.name, z=z, u_hat=u_hat, u=u)
        if self.params.scale == "constant":
            self.floor_ = np.ones(z.shape[2])
        else:
            self.floor_ = self.params.floor * np.sqrt(np.mean(z**2, axis=(0, 1)))
            if not np.all(self.floor_ > 0):
                raise InputError(f"{self.name}: z is zero on a DOF; use scale = 'constant'")
        scores = (np.abs(u - u_hat) / self._scale(z)).reshape(-1, z.shape[2])
        grid = np.linspace(0.0, 1.0, self.params.n_quantiles)
        self.quantiles_ = np.quantile(scores, grid, axis=0)
        self.n_scores_ = scores.shape[0]
        return self

    def _scale(self, z: np.ndarray) -> np.ndarray:
        if self.params.scale == "constant":
            return np.ones_like(z)
        envelope = np.sqrt(uniform_filter1d(z**2, self.params.window, axis=1, mode="nearest"))
        return np.maximum(envelope, self.floor_)

    def _check_fitted(self, z: np.ndarray) -> None:
        if not hasattr(self, "quantiles_"):
            raise NotFittedError(f"refiner '{self.name}' is not fitted: call fit() first")
        if z.shape[-1] != self.quantiles_.shape[1]:
            raise InputError(
                f"{self.name}: fitted for {self.quantiles_.shape[1]} DOFs, got arrays of shape "
                f"{z.shape}"
            )

    def interval(
        self, z: np.ndarray, u_hat: np.ndarray, level: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """``(lower, upper)`` in m, each ``[n, T, dof]``, of nominal coverage ``level``."""
        if not 0.0 < level < 1.0:
            raise InputError(f"{self.name}: level must lie in (0, 1), got {level}")
        z, u_hat = as_responses(self.name, z=z, u_hat=u_hat)
        self._check_fitted(z)
        n = self.n_scores_
        rank = min(int(np.ceil((n + 1) * level)), n)  # k-th smallest score, 1-based
        position = (rank - 1) / max(n - 1, 1)  # its level in numpy's linear quantiles
        grid = np.linspace(0.0, 1.0, self.quantiles_.shape[0])
        q = np.array([np.interp(position, grid, column) for column in self.quantiles_.T])
        half = q * self._scale(z)
        return u_hat - half, u_hat + half

    def predict(self, z: np.ndarray, u_hat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Mean ``û`` and, as ``std``, the half-width of the 68.27 % interval (m)."""
        lower, upper = self.interval(z, u_hat, ONE_SIGMA)
        return np.asarray(u_hat, dtype=np.float64), (upper - lower) / 2.0

    def state_dict(self) -> dict[str, np.ndarray]:
        if not hasattr(self, "quantiles_"):
            raise NotFittedError(f"refiner '{self.name}' is not fitted: call fit() first")
        return {
            "quantiles": self.quantiles_,
            "floor": self.floor_,
            "n_scores": np.array(self.n_scores_),
        }

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        self.quantiles_ = np.asarray(state["quantiles"], dtype=np.float64)
        self.floor_ = np.asarray(state["floor"], dtype=np.float64)
        self.n_scores_ = int(state["n_scores"])
