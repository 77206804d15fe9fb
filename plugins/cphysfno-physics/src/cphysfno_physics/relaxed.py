"""Relaxed solver: the full nonlinear model on a coarse time grid (paper §3.2.3)."""

from __future__ import annotations

import numpy as np
from pydantic import Field

from cphysfno_core import GroundMotions, plugin
from cphysfno_core.plugin import PhysicsPreprocessor, Structure
from cphysfno_core.signals.resampling import resample

from .fitted import check_fitted


class RelaxedSolver(PhysicsPreprocessor):
    """``z``: the structure's own simulation at step ``k dt``, interpolated back onto ``dt``.

    The motion is brought onto the coarse grid first: by default low-passed below the
    coarse grid's Nyquist frequency and decimated (:func:`coarse_motions`), so that content
    the coarse grid cannot carry is removed instead of folding onto the structure's modes;
    with ``anti_alias = false`` the structure samples the motion itself (linear between
    the fine samples). The structure integrates it there with an unconditionally stable
    scheme (capability ``coarse_simulation``); the coarse displacements are then
    interpolated linearly onto the motion's grid.

    Fitted attributes:
        structure_: the structure that simulates.
    """

    name = "relaxed"
    requires = frozenset({"coarse_simulation"})

    class Params(plugin.Params):
        factor: int = Field(30, ge=1, description="coarsening k of the time step: dt' = k dt")
        anti_alias: bool = Field(
            True,
            description="low-pass the motion below the coarse Nyquist frequency before "
            "decimating it (false: sample it on the coarse grid as it is)",
        )

    def fit(self, structure: Structure) -> RelaxedSolver:
        """Keep ``structure`` (capability ``coarse_simulation``)."""
        self.check(structure)
        self.structure_ = structure
        return self

    def transform(self, motions: GroundMotions) -> np.ndarray:
        """``[n_records, n_steps, n_outputs]`` displacements in m on the motion's grid."""
        check_fitted(self, "structure_")
        factor = self.params.factor
        if self.params.anti_alias:
            motions_on_grid = coarse_motions(motions, factor)
        else:
            motions_on_grid = motions
        coarse = self.structure_.simulate(motions_on_grid, dt=factor * motions.dt)
        return interpolate_in_time(coarse.displacement, coarse.dt, motions.time)


def coarse_motions(motions: GroundMotions, factor: int) -> GroundMotions:
    """``motions`` on the grid of step ``factor * dt``, anti-aliased.

    Each record is zero-padded to a whole number of coarse steps and resampled by
    :func:`cphysfno_core.signals.resampling.resample` (a zero-phase polyphase FIR low-pass with its
    cut-off at the coarse Nyquist frequency ``1 / (2 factor dt)``), so coarse sample ``j``
    lies at ``j factor dt`` s.

    Args:
        motions: ``[n, T]`` accelerations in m/s^2 at step ``dt``.
        factor: the integer coarsening ``k >= 1``; 1 returns ``motions`` unchanged.

    Returns:
        ``[n, ceil((T - 1) / k) + 1]`` accelerations in m/s^2 at step ``k dt``, covering
        the record.
    """
    if factor == 1:
        return motions
    n_coarse = int(np.ceil((motions.n_steps - 1) / factor)) + 1
    padded = np.zeros((motions.n_records, (n_coarse - 1) * factor + 1))
    padded[:, : motions.n_steps] = motions.acceleration
    coarse = resample(padded, motions.dt, factor * motions.dt)
    return GroundMotions(coarse, factor * motions.dt, motions.metadata)


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
