"""``cphysfno demands RUN``: the demand sample of a trained run's surrogate, in the CSV that
pelicun 3 (FEMA P-58) reads.

The records are the run's test records (collapsed ones flagged from the simulation, which
pelicun drops) or motions from a file; the demands are the EDPs of the chosen model's
predictions (:mod:`cphysfno_core.reporting.edp`), written by
:func:`cphysfno_core.reporting.demands.write_pelicun_demands`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..data.datasets import load_dataset
from ..data.layout import DATASET
from ..model.prediction_files import read_motions
from ..reporting import edp
from ..reporting.demands import PelicunDemands, write_pelicun_demands
from ..signals import GroundMotions
from .fragility_study import load_trained_run


def write_demand_sample(
    run: Path,
    *,
    motions_file: Path | None = None,
    model_label: str | None = None,
    out: Path | None = None,
) -> tuple[PelicunDemands, str]:
    """Predict the records, compute their EDPs and write ``RUN/demands/demands.csv`` (or
    ``out``).

    Returns:
        What was written, and the model's label.

    Raises:
        ConfigError: the run is not finished or has no such model.
    """
    trained = load_trained_run(Path(run), model_label)
    model, structure = trained.model, trained.structure
    if motions_file is not None:
        motions = read_motions(motions_file)
        collapsed = np.zeros(motions.n_records, dtype=bool)
    else:
        data = load_dataset(run / DATASET)
        rows = data.rows("test")
        flagged = data.collapsed_rows("test")
        everything = np.sort(np.concatenate([rows, flagged]))
        motions = GroundMotions(data.ag[everything], data.dt)
        collapsed = np.isin(everything, flagged)
    mean = np.full((motions.n_records, motions.n_steps, structure.n_outputs), np.nan)
    standing = np.flatnonzero(~collapsed)
    mean[standing], _ = model.predict(motions[standing])
    demands = edp.compute(mean, structure, motions)
    path = out or run / "demands" / "demands.csv"
    path.parent.mkdir(parents=True, exist_ok=True)
    written = write_pelicun_demands(path, demands.pid, demands.rid, demands.pfa, collapsed)
    return written, trained.label
