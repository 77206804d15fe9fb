"""What every OpenSees structure shares: records analysed in worker processes, coarse-grid
simulation by resampling the motion, and elastic periods from the linear representation."""

from __future__ import annotations

from abc import abstractmethod
from collections.abc import Callable

import numpy as np
import scipy.linalg
from pydantic import Field

from cphysfno_core import (
    ConfigError,
    GroundMotions,
    InputError,
    Params,
    Responses,
    Structure,
    check_time_step,
)

from .runner import run_records


class OpenSeesParams(Params):
    """Parameters every OpenSees structure has: how its records are run."""

    workers: int = Field(1, ge=1, description="worker processes analysing records in parallel")
    records_per_worker: int = Field(
        20, ge=1, description="records a worker process analyses before a fresh one replaces it"
    )


class OpenSeesStructure(Structure):
    """A structure whose nonlinear model is an OpenSees analysis, one record at a time.

    A subclass provides :meth:`analysis` (a picklable function that builds its model and
    analyses one record), ``output_names`` and ``linear_system``; this class gives it

    - :meth:`simulate`: every record analysed in worker processes
      (:func:`~cphysfno_opensees.runner.run_records`, ``workers`` at a time, each worker
      replaced after ``records_per_worker`` records); a record that does not converge,
      or whose worker dies, comes back as NaN rows named in ``Responses.failures``;
    - the ``coarse_simulation`` capability: ``simulate(motions, dt=coarse)`` resamples the
      motion onto the coarse grid (linear between samples) and analyses it there, which
      the subclass's implicit, unconditionally stable integrator must allow;
    - :meth:`periods` from the linear representation's ``(K, M)``.

    A record that is zero throughout leaves the structure at rest in its gravity state:
    its displacements are zero without an analysis (an analysis would return round-off).
    """

    Params = OpenSeesParams
    capabilities = frozenset({"coarse_simulation"})

    @abstractmethod
    def analysis(self) -> Callable[[np.ndarray, float], np.ndarray]:
        """A picklable ``analyse(a_g [T] m/s^2, dt s) -> [T, n_outputs]`` (m) that builds
        the model in the calling process and raises
        :class:`~cphysfno_opensees.transient.AnalysisFailed` when it does not converge."""

    def simulate(self, motions: GroundMotions, *, dt: float | None = None) -> Responses:
        """Nonlinear response of every record, analysed in worker processes.

        Args:
            motions: ``[n, T]`` ground accelerations in m/s^2.
            dt: ``None`` analyses on the motion's grid; a step in s no shorter than the
                motion's resamples the motion onto that grid and analyses it there.

        Returns:
            ``[n, T', n_outputs]`` displacements in m on the analysed grid, NaN for the
            records named in ``failures`` (each cause followed by the record's metadata,
            where the motions have some: ``did not converge at t = 7.31 s after ...
            (rsn = 953, scale = 1.4)``).

        Raises:
            InputError: ``motions`` is not a GroundMotions, or ``dt`` is not a time step at
                least the motion's.
        """
        if not isinstance(motions, GroundMotions):
            raise InputError(
                f"{self.name}: motions must be a cphysfno_core.GroundMotions, "
                f"got {type(motions).__name__}"
            )
        if dt is not None:
            dt = check_time_step(dt, "dt")
            if dt < motions.dt * (1.0 - 1e-9):
                raise InputError(
                    f"{self.name}: a coarse dt must be at least the motion's dt = "
                    f"{motions.dt} s, got {dt} s; use dt=None for the motion's own grid"
                )
            motions = motions.resample(dt)
        moving = np.flatnonzero(np.any(motions.acceleration != 0.0, axis=1))
        u = np.zeros((motions.n_records, motions.n_steps, self.n_outputs))
        u[moving], failures = run_records(
            self.analysis(),
            motions.acceleration[moving],
            motions.dt,
            self.n_outputs,
            workers=self.params.workers,
            records_per_worker=self.params.records_per_worker,
            description=f"{self.name} at dt = {motions.dt:g} s",
        )
        failures = {
            int(moving[i]): _with_metadata(cause, motions.metadata, int(moving[i]))
            for i, cause in failures.items()
        }
        return Responses(u, motions.dt, failures=failures)

    def periods(self, n: int | None = None) -> np.ndarray:
        """First ``n`` (default all) elastic periods in s, longest first, from the
        ``(K, M)`` of :meth:`equivalent_linear_system`."""
        system = self.equivalent_linear_system()
        if n is None:
            n = system.n_dof
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or not 1 <= n <= system.n_dof:
            raise ConfigError(
                f"{self.name}: n must be an integer from 1 to {system.n_dof}, got {n!r}"
            )
        squares = scipy.linalg.eigh(
            system.stiffness, system.mass, eigvals_only=True, subset_by_index=(0, int(n) - 1)
        )
        return 2.0 * np.pi / np.sqrt(squares)


def _with_metadata(cause: str, metadata, index: int) -> str:
    """``cause`` followed by record ``index``'s metadata (``key = value, ...``), if any."""
    if not metadata or not metadata[index]:
        return cause
    described = ", ".join(f"{key} = {value}" for key, value in metadata[index].items())
    return f"{cause} ({described})"
