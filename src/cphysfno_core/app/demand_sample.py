"""``cphysfno demands RUN``: the demand sample of a trained run's surrogate, in the CSV that
pelicun 3 (FEMA P-58) reads.

The records are the run's test records (collapsed ones and those whose analysis did not
converge below the collapse flagged from the simulation, ``ERROR`` 1 and 2, which pelicun
drops) or motions from a file; a record whose physics input collapses at prediction (a
``stick`` whose story law lost its strength) is flagged collapsed (``ERROR`` 1). The
demands are the EDPs of the chosen model's predictions
(:mod:`cphysfno_core.reporting.edp`; PFA from the predicted accelerations of a model that
learns them), written by :func:`cphysfno_core.reporting.demands.write_pelicun_demands`.

For a model of a family of structures, a test record is predicted on its own drawn
structure; a record from a file on the parameters of a CSV file (``params``) or, without
one, on parameters drawn from the config's distributions (``seed``): the sample then
carries modelling dispersion beside record-to-record dispersion.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..config.uncertainty import per_record
from ..data.datasets import load_dataset
from ..data.layout import DATASET, run_file
from ..data.record_stories import RecordStories
from ..model.prediction_files import read_motions, read_parameters
from ..model.skipping import predict_skipping_failures
from ..reporting import edp
from ..reporting.demands import PelicunDemands, write_pelicun_demands
from ..signals import GroundMotions
from ..signals.intensity import peak_ground_acceleration, peak_ground_velocity
from .fragility_study import load_trained_run, modelling_uncertainty, surrogate_pfa_source


def write_demand_sample(
    run: Path,
    *,
    motions_file: Path | None = None,
    model_label: str | None = None,
    out: Path | None = None,
    params_file: Path | None = None,
    seed: int = 0,
) -> tuple[PelicunDemands, str]:
    """Predict the records, compute their EDPs and write ``RUN/demands/demands.csv`` (or
    ``out``); ``params_file`` and ``seed``: the structural parameters of the records of
    ``motions_file`` for a model of a family (see the module's text).

    Returns:
        What was written, and the model's label.

    Raises:
        ConfigError: the run is not finished or has no such model.
    """
    trained = load_trained_run(Path(run), model_label)
    model, structure = trained.model, trained.structure
    surrogate_pfa_source(model, trained.label)  # warns where PFA is differentiated
    edp.require_heights(edp.stories_of(structure), "a pelicun demand sample")
    if motions_file is not None:
        motions = read_motions(motions_file)
        collapsed = stopped = np.zeros(motions.n_records, dtype=bool)
        space = modelling_uncertainty(model, trained.config)
        drawn = None
        if params_file is not None:
            drawn = read_parameters(params_file)
        elif space is not None:
            drawn = space.columns(space.draw(motions.n_records, seed))
        model_takes_draws = drawn is not None
    else:
        data = load_dataset(run_file(run, DATASET))
        flagged, unfinished = data.collapsed_rows("test"), data.non_converged_rows("test")
        everything = np.sort(np.concatenate([data.rows("test"), flagged, unfinished]))
        motions = GroundMotions(data.ag[everything], data.dt)
        collapsed = np.isin(everything, flagged)
        stopped = np.isin(everything, unfinished)
        drawn = data.draws_of(everything)
        model_takes_draws = model.parameters is not None
    standing = np.flatnonzero(~collapsed & ~stopped)
    if drawn:  # each standing record's parameters: for its heights, and the model's input
        drawn = {name: v[standing] for name, v in per_record(drawn, motions.n_records).items()}
    heights = RecordStories(structure).heights(drawn, len(standing))
    params = drawn if model_takes_draws else None
    responses = predict_skipping_failures(model, motions[standing], params)[0]
    collapsed = collapsed.copy()
    collapsed[standing[responses.collapsed]] = True
    predicted = edp.compute(responses, structure, motions[standing], heights=heights)
    demands = predicted.map(lambda values: _spread(values, standing, motions.n_records))
    # the ground's own column, every record's
    demands.values["PFA"][:, 0] = peak_ground_acceleration(motions.acceleration)
    demands.values["PFV"][:, 0] = peak_ground_velocity(motions.acceleration, motions.dt)
    path = out or run / "demands" / "demands.csv"
    path.parent.mkdir(parents=True, exist_ok=True)
    written = write_pelicun_demands(path, demands, collapsed, non_converged=stopped)
    return written, trained.label


def _spread(values: np.ndarray, rows: np.ndarray, n: int) -> np.ndarray:
    """``[n, k]`` NaN but for ``values [len(rows), k]`` at ``rows``."""
    found = np.full((n, values.shape[1]), np.nan)
    found[rows] = values
    return found
