"""``cphysfno predict``: ground motions read from a file, a saved model's prediction for
them written to another.

Motions come as ``.npz`` (arrays ``acceleration [N, T]`` in m/s^2 and ``dt`` in s) or as
``.npy`` (``[N, T]`` or ``[T]`` in m/s^2, with the step given separately). The output
``.npz`` holds ``mean`` and ``std`` ``[N, T, dof]`` in m, the operator output, ``z`` for a
C-Phys model, ``dt`` and ``output_names``.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..config.precision import Precision
from ..signals import GroundMotions, TimeGrid, read_at2
from ..signals.errors import DatasetError, InputError
from .composite import CompositeModel

PREDICTION_ARRAYS = {
    "mean": ["m", "predicted displacement [record, sample, output] (refined mean)"],
    "std": ["m", "its standard deviation [record, sample, output]"],
    "operator_output": ["m", "the neural operator's prediction before refinement"],
    "z": ["m", "the physics response z the operator started from"],
    "dt": ["s", "time step of the records"],
    "output_names": ["", "names of the outputs, in the order of the last axis"],
}
"""Units and description of each array of a prediction file; the file holds them as JSON
in its ``descriptions`` entry, with the label of the model that predicted."""


def read_motions(
    path: str | Path, dt: float | None = None, grid: TimeGrid | None = None
) -> GroundMotions:
    """Ground motions from ``path``: a PEER ``.AT2`` file or a folder of them (in g, read
    into m/s^2, each record's header kept as its metadata), ``.npz`` with ``acceleration``
    and ``dt``, or ``.npy`` with ``dt`` given here (s).

    AT2 records of different lengths are zero-padded at the end to the longest; records
    of different time steps need ``grid``, onto which each is then resampled (so does any
    input with ``grid``).

    Raises:
        DatasetError: the file is missing, unreadable or lacks an array; a folder holds no
            AT2 file.
        InputError: ``dt`` is missing for a ``.npy`` file or given twice, AT2 records of
            different time steps without ``grid``, or the values are not ground motions
            (see :class:`GroundMotions`).
    """
    path = Path(path)
    if path.is_dir() or path.suffix.lower() == ".at2":
        return _read_at2_records(path, dt, grid)
    motions = _read_arrays(path, dt)
    return motions if grid is None else motions.on_grid(grid)


def _read_at2_records(path: Path, dt: float | None, grid: TimeGrid | None) -> GroundMotions:
    """The AT2 file ``path``, or every AT2 file of the folder ``path`` in name order."""
    if dt is not None:
        raise InputError(f"{path}: AT2 files hold their own time step: do not give --dt")
    files = (
        sorted(p for p in path.iterdir() if p.suffix.lower() == ".at2") if path.is_dir() else [path]
    )
    if not files:
        raise DatasetError(f"{path}: a folder of ground motions must hold .AT2 files")
    records = [read_at2(f) for f in files]
    steps = sorted({r.dt for r in records})
    if grid is None and len(steps) > 1:
        raise InputError(
            f"{path}: the records have different time steps ({', '.join(map(str, steps))} s): "
            "bring them onto the model's grid (cphysfno predict --on-grid, or "
            "read_motions(..., grid=model.grid))"
        )
    if grid is not None:
        rows = [
            GroundMotions(r.acceleration[None, :], r.dt, [r.metadata]).on_grid(grid)
            for r in records
        ]
        return GroundMotions(
            np.concatenate([m.acceleration for m in rows]), grid.dt, [r.metadata for r in records]
        )
    length = max(r.acceleration.size for r in records)
    ag = np.stack([np.pad(r.acceleration, (0, length - r.acceleration.size)) for r in records])
    return GroundMotions(ag, steps[0], [r.metadata for r in records])


def _read_arrays(path: Path, dt: float | None) -> GroundMotions:
    """Ground motions from an ``.npz`` or ``.npy`` file (see :func:`read_motions`)."""
    if not path.is_file():
        raise DatasetError(f"{path}: no such file of ground motions")
    suffix = path.suffix.lower()
    if suffix not in (".npz", ".npy"):
        raise DatasetError(
            f"{path}: give ground motions as .AT2 (a file or a folder), .npz (acceleration, "
            "dt) or .npy"
        )
    try:
        if suffix == ".npz":
            with np.load(path, allow_pickle=False) as stored:
                arrays = dict(stored)
        else:
            arrays = {"acceleration": np.load(path, allow_pickle=False)}
    except (OSError, ValueError) as error:
        raise DatasetError(f"{path}: not a readable NumPy file ({error})") from None
    if suffix == ".npy":
        if dt is None:
            raise InputError(f"{path} is a bare array: give its time step (--dt, s)")
        return GroundMotions(arrays["acceleration"], dt)
    missing = {"acceleration", "dt"} - set(arrays)
    if missing:
        raise DatasetError(
            f"{path} lacks {', '.join(sorted(missing))}: it needs 'acceleration' [N, T] in "
            "m/s^2 and 'dt' in s"
        )
    if dt is not None:
        raise InputError(f"{path} holds its own dt: do not give another")
    return GroundMotions(arrays["acceleration"], float(arrays["dt"]))


@dataclass
class PredictionRun:
    """What :func:`predict_file` did: records, seconds of prediction (physics, operator and
    refiner), the output file, and per output the median over records of the peak absolute
    mean displacement (m)."""

    records: int
    seconds: float
    out: Path
    peaks: dict[str, float]


def predict_file(
    model_dir: str | Path,
    motions_path: str | Path,
    out: str | Path,
    *,
    dt: float | None = None,
    on_grid: bool = False,
    device: str = "auto",
    precision: Precision = "float32",
) -> PredictionRun:
    """Load the model in ``model_dir``, predict the motions of ``motions_path`` and write
    ``out`` (``.npz``).

    Args:
        on_grid: bring motions on another time grid onto the model's (anti-aliased
            resampling, then cut or zero-padded at the end); otherwise they are refused.
        device: where the operator runs (a ``training.device`` setting).
        precision: the operator's arithmetic, ``"float32"`` or ``"bfloat16"`` (see
            :meth:`CompositeModel.predict_stages`).

    Raises:
        InputError: ``out`` is not an ``.npz`` name, or the motions are on another grid
            than the model's and ``on_grid`` is off (see :meth:`CompositeModel.grid`).
    """
    out = Path(out)
    if out.suffix != ".npz":
        raise InputError(f"--out {out}: name an .npz file")
    model = CompositeModel.load(model_dir).to(device)
    motions = read_motions(motions_path, dt, model.grid if on_grid else None)
    started = time.perf_counter()
    stages = model.predict_stages(motions, precision=precision)
    seconds = time.perf_counter() - started
    names = list(model.structure.output_names) if model.structure is not None else []
    names = names or [f"output-{k}" for k in range(stages.mean.shape[2])]
    arrays = {
        "mean": stages.mean,
        "std": stages.std,
        "operator_output": stages.operator_output,
        "dt": np.float64(motions.dt),
        "output_names": np.array(names),
    }
    if stages.z is not None:
        arrays["z"] = stages.z
    described = {k: v for k, v in PREDICTION_ARRAYS.items() if k in arrays}
    arrays["descriptions"] = np.array(json.dumps({**described, "model": model.label}))
    out.parent.mkdir(parents=True, exist_ok=True)
    np.savez(out, **arrays)
    peaks = np.median(np.abs(stages.mean).max(axis=1), axis=0)
    return PredictionRun(
        motions.n_records, seconds, out, dict(zip(names, peaks.tolist(), strict=True))
    )
