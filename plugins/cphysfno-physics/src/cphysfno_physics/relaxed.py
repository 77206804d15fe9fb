"""Relaxed solver: the full nonlinear model on a coarse time grid (paper §3.2.3)."""

from __future__ import annotations

import numpy as np
from pydantic import Field

import cphysfno_core
from cphysfno_core import GroundMotions, PhysicsPreprocessor, Structure

from .fitted import check_fitted


class RelaxedSolver(PhysicsPreprocessor):
    """``z``: the structure's own simulation at step ``k dt``, interpolated back onto ``dt``.

    The structure resamples the motion onto the coarse grid and integrates it there with an
    unconditionally stable scheme (capability ``coarse_simulation``); the coarse
    displacements are then interpolated linearly onto the motion's grid.

    Fitted attributes:
        structure_: the structure that simulates.
    """

    name = "relaxed"

    class Params(cphysfno_core.Params):
        factor: int = Field(30, ge=1, description="coarsening k of the time step: dt' = k dt")

    def fit(self, structure: Structure) -> RelaxedSolver:
        """Keep ``structure`` (capability ``coarse_simulation``)."""
        structure.require("coarse_simulation", f"preprocessor '{self.name}'")
        self.structure_ = structure
        return self

    def transform(self, motions: GroundMotions) -> np.ndarray:
        """``[n_records, n_steps, n_outputs]`` displacements in m on the motion's grid."""
        check_fitted(self, "structure_")
        coarse = self.structure_.simulate(motions, dt=self.params.factor * motions.dt)
        return interpolate_in_time(coarse.displacement, coarse.dt, motions.time)


def interpolate_in_time(values: np.ndarray, dt: float, times: np.ndarray) -> np.ndarray:
    """Linear interpolation of histories on a uniform grid, as :func:`numpy.interp` does.

    Args:
        values: ``[n_records, n_coarse, n_channels]`` samples at ``0, dt, 2 dt, ...`` s.
        dt: step of the samples in s.
        times: ``[n_steps]`` times in s at which to evaluate; outside the samples the first
            or last sample is held.

    Returns:
        ``[n_records, n_steps, n_channels]``.
    """
    position = np.clip(np.asarray(times, dtype=np.float64) / dt, 0.0, values.shape[1] - 1)
    left = np.minimum(np.floor(position).astype(int), max(values.shape[1] - 2, 0))
    rise = np.diff(values, axis=1, append=values[:, -1:])
    result = np.take(values, left, axis=1)
    change = np.take(rise, left, axis=1)
    change *= (position - left)[None, :, None]
    result += change
    return result
