"""Linear-regression refinement of operator predictions (paper §4).

Per output DOF ``i``: ``u_i(t) = [1, z_i(t), û_i(t)] · w_i + ε_i(t)`` with
``ε_i ~ N(0, σ_i²)`` white, fitted by ordinary least squares on randomly sampled
``(record, time)`` pairs of the training split (the paper) or of the validation split.

On the training split the residuals are those of records the operator was fitted to: once
it fits them more closely than new records, ``σ_i`` is too small and the intervals cover
less than their level. ``calibration_split = "validation"`` fits on records the operator
has not seen (it only chose the epoch on them).
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field

from cphysfno_core import InputError, NotFittedError
from cphysfno_core.plugin import Params, Refiner

from .arrays import as_responses, record_blocks

N_WEIGHTS = 3


class LinearRegressionParams(Params):
    """Parameters of :class:`LinearRegressionRefiner`.

    Attributes:
        n_points: number of ``(record, time)`` pairs drawn from the calibration split for
            the fit (the paper uses 1000); all pairs are used when there are fewer.
        calibration_split: the split the pairs are drawn from, ``"training"`` (the paper)
            or ``"validation"``.
    """

    n_points: int = Field(1000, gt=N_WEIGHTS)
    calibration_split: Literal["training", "validation"] = "training"


class LinearRegressionRefiner(Refiner):
    """Refined mean ``w_i1 + w_i2 z_i + w_i3 û_i`` and constant standard deviation ``σ_i``.

    Fitted attributes:
        weights_: ``[dof, 3]`` least-squares weights ``(w_i1 in m, w_i2, w_i3)`` per DOF.
        sigma_: ``[dof]`` residual standard deviation in m, ``sqrt(RSS / (m - rank))``
            with ``m`` sampled pairs and ``rank`` of the ``[m, 3]`` design (3 unless the
            design is degenerate), the unbiased estimate.

    A degenerate design (e.g. ``z == û``) is solved by minimum-norm least squares.
    """

    name = "linear-regression"
    Params = LinearRegressionParams

    @property
    def calibration_split(self) -> Literal["training", "validation"]:
        """The split :meth:`fit` is given, as the parameter of that name says."""
        return self.params.calibration_split

    def fit(
        self, z: np.ndarray, u_hat: np.ndarray, u: np.ndarray, rng: np.random.Generator
    ) -> LinearRegressionRefiner:
        """Fit on the split :attr:`calibration_split` names.

        Args:
            z: ``[n, T, dof]`` physics-based intermediate displacements in m.
            u_hat: ``[n, T, dof]`` operator predictions in m.
            u: ``[n, T, dof]`` true displacements in m.
            rng: draws the ``(record, time)`` pairs, the same pairs for every DOF.

        Returns:
            ``self``.
        """
        z, u_hat, u = as_responses(self.name, z=z, u_hat=u_hat, u=u)
        n, steps, dof = z.shape
        available = n * steps
        if available <= N_WEIGHTS:
            raise InputError(
                f"{self.name}: {available} (record, time) pairs in arrays of shape "
                f"{z.shape}; fitting 3 weights and a noise level needs at least 4"
            )
        m = min(self.params.n_points, available)
        flat = rng.choice(available, size=m, replace=False)
        records, times = np.divmod(flat, steps)
        weights = np.empty((dof, N_WEIGHTS))
        sigma = np.empty(dof)
        for i in range(dof):
            design = np.column_stack([np.ones(m), z[records, times, i], u_hat[records, times, i]])
            target = u[records, times, i]
            weights[i], _, rank, _ = np.linalg.lstsq(design, target, rcond=None)
            residual = target - design @ weights[i]
            sigma[i] = np.sqrt(residual @ residual / (m - rank))
        self.weights_ = weights
        self.sigma_ = sigma
        return self

    def predict(self, z: np.ndarray, u_hat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Refined mean and standard deviation, each ``[n, T, dof]`` in m (float64).

        Args:
            z: ``[n, T, dof]`` physics-based intermediate displacements in m.
            u_hat: ``[n, T, dof]`` operator predictions in m.
        """
        self._check_fitted()
        z, u_hat = as_responses(self.name, z=z, u_hat=u_hat)
        dof = self.weights_.shape[0]
        if z.shape[-1] != dof:
            raise InputError(f"{self.name}: fitted for {dof} DOFs, got arrays of shape {z.shape}")
        w = self.weights_
        mean = np.empty(z.shape)
        for rows in record_blocks(z.shape):
            block = mean[rows]
            np.multiply(w[:, 1], z[rows], out=block)
            block += w[:, 0]
            block += w[:, 2] * u_hat[rows]
        std = np.empty(z.shape)
        std[...] = self.sigma_
        return mean, std

    def state_dict(self) -> dict[str, np.ndarray]:
        """``{"weights": [dof, 3], "sigma": [dof]}`` as float64 arrays."""
        self._check_fitted()
        return {"weights": self.weights_.copy(), "sigma": self.sigma_.copy()}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Restore the fitted state from what :meth:`state_dict` returned."""
        missing = {"weights", "sigma"} - set(state)
        if missing:
            raise InputError(f"{self.name}: state lacks {', '.join(sorted(missing))}")
        weights = np.asarray(state["weights"], dtype=np.float64)
        sigma = np.asarray(state["sigma"], dtype=np.float64)
        if weights.ndim != 2 or weights.shape[1] != N_WEIGHTS or sigma.shape != weights.shape[:1]:
            raise InputError(
                f"{self.name}: state needs weights [dof, 3] and sigma [dof], "
                f"got shapes {weights.shape} and {sigma.shape}"
            )
        self.weights_ = weights.copy()
        self.sigma_ = sigma.copy()

    def _check_fitted(self) -> None:
        if not hasattr(self, "weights_"):
            raise NotFittedError(
                f"{self.name} refiner is not fitted: call fit() or load_state_dict() first"
            )
