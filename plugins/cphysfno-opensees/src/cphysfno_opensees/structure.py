"""What every OpenSees structure shares: records analysed in worker processes, collapse
marked where an analysis stops converging or a story drifts past a limit, coarse-grid
simulation by resampling the motion, and elastic periods from the linear representation."""

from __future__ import annotations

import logging
from abc import abstractmethod
from collections.abc import Callable

import numpy as np
import scipy.linalg
from pydantic import Field

from cphysfno_core import ConfigError, GroundMotions, InputError, Responses, edp
from cphysfno_core.plugin import Params, Structure, check_time_step

from .convergence import ConvergenceParams
from .runner import run_records

logger = logging.getLogger(__name__)


class OpenSeesParams(Params):
    """Parameters every OpenSees structure has: how its records are run, and the
    convergence ladder of their transient analyses."""

    workers: int = Field(1, ge=1, description="worker processes analysing records in parallel")
    records_per_worker: int = Field(
        20, ge=1, description="records a worker process analyses before a fresh one replaces it"
    )
    collapse_drift: float | None = Field(
        0.10,
        gt=0.0,
        description="story drift ratio past which a record collapsed the structure (for a "
        "structure with stories); None: only an analysis that stops converging is a collapse",
    )
    convergence: ConvergenceParams = Field(
        default_factory=ConvergenceParams,
        description="what a step that does not converge tries, in order: substeps, other "
        "algorithms, a looser test",
    )


class OpenSeesStructure(Structure):
    """A structure whose nonlinear model is an OpenSees analysis, one record at a time.

    A subclass provides :meth:`analysis` (a picklable function that builds its model and
    analyses one record), ``output_names`` and ``linear_system``; this class gives it

    - :meth:`simulate`: every record analysed in worker processes
      (:func:`~cphysfno_opensees.runner.run_records`, ``workers`` at a time, each worker
      replaced after ``records_per_worker`` records); a record in which a story drifts
      past ``collapse_drift`` collapsed the structure (``Responses.collapsed``), one whose
      analysis stops converging below it did not converge (``Responses.non_converged``;
      a collapse where there is no drift criterion), and one whose worker dies comes back
      as NaN rows named in ``Responses.failures``; what OpenSees printed comes back in
      ``Responses.messages``, and the hardest rung of the convergence ladder
      (``convergence``) each record needed in ``Responses.recoveries``;
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
        the model in the calling process, steps it with
        :func:`~cphysfno_opensees.transient.integrate` and the ladder ``convergence`` of
        the parameters, and raises :class:`~cphysfno_opensees.transient.AnalysisFailed`
        when it does not converge.

        A structure whose :meth:`ground_influence` is not None returns ``[T, 2
        n_outputs]`` instead: the displacements, then the outputs' accelerations relative
        to the ground as OpenSees computes them (``nodeAccel``; m/s^2, rad/s^2). The
        values of its :meth:`response_channels`, if any, follow, one column each."""

    def ground_influence(self) -> np.ndarray | None:
        """``[n_outputs]`` how much of the ground acceleration each output takes on (1 for
        a translation along the excitation, 0 otherwise), for a structure whose analysis
        records accelerations; None (the default) for one whose analysis does not."""
        return None

    def simulate(self, motions: GroundMotions, *, dt: float | None = None) -> Responses:
        """Nonlinear response of every record, analysed in worker processes.

        Args:
            motions: ``[n, T]`` ground accelerations in m/s^2.
            dt: ``None`` analyses on the motion's grid; a step in s no shorter than the
                motion's resamples the motion onto that grid and analyses it there.

        Returns:
            ``[n, T', n_outputs]`` displacements in m on the analysed grid, and for a
            structure whose analysis records accelerations (:meth:`ground_influence`) the
            absolute accelerations of the outputs as the extra ``absolute_acceleration``
            (``[n, T', n_outputs]``, m/s^2: OpenSees' relative ``nodeAccel`` plus the
            ground's share, NaN where the displacement is), and each of its
            :meth:`response_channels` as the extra of its name (``[n, T', 1]``, NaN where
            the displacement is). Each record has one of three
            outcomes. *Complete*. *Collapsed* (``collapsed``): a story's drift ratio passed
            ``collapse_drift`` (its history up to the first sample past the limit, NaN
            after), or, for a structure without that criterion (``collapse_drift`` None,
            stories without heights), its analysis stopped converging. *Non-converged*
            (``non_converged``, with the cause and the peak story drift ratio at the stop):
            its analysis stopped converging below the collapse drift, a numerical failure
            rather than a collapse (its history up to the last converged step, NaN after).
            Causes are logged (logger ``cphysfno_opensees.structure``, INFO) with the
            record's metadata, where the motions have some: ``did not converge at t =
            7.31 s after ... (rsn = 953, scale = 1.4)``. A record whose worker died is NaN
            throughout and named in ``failures``. ``messages`` holds what OpenSees printed
            for each record, ``recoveries`` the hardest rung of the convergence ladder each
            record that needed one climbed to (``"substeps dt/4"``).

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
        influence = self.ground_influence()
        channels = self.response_channels()
        kinematic = self.n_outputs * (1 if influence is None else 2)
        columns = kinematic + len(channels)
        recorded = np.zeros((motions.n_records, motions.n_steps, columns))
        collapsed = np.zeros(motions.n_records, dtype=bool)
        runs = run_records(
            self.analysis(),
            motions.acceleration[moving],
            motions.dt,
            columns,
            workers=self.params.workers,
            records_per_worker=self.params.records_per_worker,
            description=f"{self.name} at dt = {motions.dt:g} s",
        )
        recorded[moving] = runs.displacement
        u = recorded[:, :, : self.n_outputs]
        stopped = {int(moving[i]): cause for i, cause in runs.collapse_causes.items()}
        causes = self._drift_collapses(u, collapsed, motions.dt)
        by_drift = causes is not None
        causes = causes or {}
        non_converged = {}
        for index, cause in stopped.items():
            if collapsed[index]:
                continue  # past the collapse drift before the analysis stopped
            if not by_drift:  # no drift criterion: a stop is the collapse
                collapsed[index], causes[index] = True, cause
                continue
            peak = self._peak_drift_ratio(u[index])
            non_converged[index] = _with_metadata(
                f"{cause}; peak story drift ratio {peak:.3g} at the stop, below "
                f"collapse_drift = {self.params.collapse_drift:g}",
                motions.metadata,
                index,
            )
        extras = {}
        if influence is not None:
            relative = recorded[:, :, self.n_outputs : kinematic]
            absolute = relative + motions.acceleration[:, :, None] * influence
            extras[edp.ACCELERATION_EXTRA] = np.where(np.isnan(u), np.nan, absolute)
        stopped_rows = np.isnan(u).any(axis=2, keepdims=True)
        for j, channel in enumerate(channels):
            values = recorded[:, :, kinematic + j : kinematic + j + 1]
            extras[channel.name] = np.where(stopped_rows, np.nan, values)
        for index, cause in sorted(causes.items()):
            described = _with_metadata(cause, motions.metadata, index)
            logger.info("%s: record %d collapsed the structure: %s", self.name, index, described)
        for index, cause in sorted(non_converged.items()):
            logger.info("%s: record %d did not converge: %s", self.name, index, cause)
        failures = {
            int(moving[i]): _with_metadata(cause, motions.metadata, int(moving[i]))
            for i, cause in runs.failures.items()
        }
        messages = {int(moving[i]): text for i, text in runs.messages.items()}
        recoveries = {int(moving[i]): rung for i, rung in runs.recoveries.items()}
        return Responses(
            np.ascontiguousarray(u),
            motions.dt,
            extras=extras,
            failures=failures,
            collapsed=collapsed,
            messages=messages,
            non_converged=non_converged,
            recoveries=recoveries,
        )

    def _drift_collapses(
        self, u: np.ndarray, collapsed: np.ndarray, dt: float
    ) -> dict[int, str] | None:
        """Mark the records in which a story drifts past ``collapse_drift`` as collapsed
        (in place: NaN after the first sample past it, also in a record whose analysis
        stopped converging later); their causes, by record. None where there is no drift
        criterion (``collapse_drift`` None, or stories without heights or that cannot be
        told, which a warning says): a record then collapses only by non-convergence."""
        limit = self.params.collapse_drift
        if limit is None or "stories" not in self.capabilities:
            return None
        try:
            stories = self.stories()
        except ConfigError as error:
            logger.warning("%s: no collapse by drift (%s)", self.name, error)
            return None
        if not stories.has_heights:
            logger.warning(
                "%s: no collapse by drift (%s have no height)",
                self.name,
                ", ".join(stories.without_height()),
            )
            return None
        first = stories.first_past(np.nan_to_num(u, nan=0.0), limit)
        causes = {}
        for index in np.flatnonzero(first >= 0):
            step = int(first[index])
            u[index, step + 1 :] = np.nan
            collapsed[index] = True
            causes[int(index)] = (
                f"a story drift ratio passed collapse_drift = {limit:g} at t = {step * dt:.2f} s"
            )
        return causes

    def _peak_drift_ratio(self, u: np.ndarray) -> float:
        """The largest story drift ratio of one record's ``[T, n_outputs]`` history (m)
        before it ends in NaN."""
        kept = u[np.all(np.isfinite(u), axis=1)]
        if kept.size == 0:
            return 0.0
        stories = self.stories()
        drift = stories.drifts(kept[None])[0]
        return float(np.max(np.abs(drift) / np.asarray(stories.heights_m)))

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
