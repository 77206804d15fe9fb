"""``cphysfno predict``: ground motions read from a file, a saved model's prediction for
them written to another.

Motions come as ``.npz`` (arrays ``acceleration [N, T]``, ``dt`` in s and ``units``) or
as ``.npy`` (``[N, T]`` or ``[T]``, with the step and the unit given separately), in any
unit of :data:`ACCELERATION_UNITS` (m/s^2 with a warning where none is said), or as AT2
records (g). The output ``.npz`` holds ``mean`` and ``std`` ``[N, T, dof]`` in m, the
operator output, ``z`` for a C-Phys model, ``acceleration`` (m/s^2) for a model that
learns it, ``responses`` ``[N, T, k]`` with ``response_names`` and ``response_units`` for a
model that learns named responses, ``dt`` and ``output_names``. A model of a family of
structures takes each record's structural parameters from a CSV file
(:func:`read_parameters`); the file then also holds them (``params``, ``param_names``).
"""

from __future__ import annotations

import csv
import json
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..config.precision import Precision
from ..config.uncertainty import per_record
from ..signals import STANDARD_GRAVITY, GroundMotions, TimeGrid, read_at2
from ..signals.errors import CphysfnoWarning, DatasetError, InputError
from .composite import CompositeModel

PREDICTION_ARRAYS = {
    "mean": ["m", "predicted displacement [record, sample, output] (refined mean)"],
    "std": ["m", "its standard deviation [record, sample, output]"],
    "operator_output": ["m", "the neural operator's prediction before refinement"],
    "z": ["m", "the physics response z the operator started from"],
    "acceleration": [
        "m/s^2",
        "predicted absolute acceleration [record, sample, output] (a model that learns it)",
    ],
    "responses": [
        "response_units",
        "predicted named responses [record, sample, response] (a model that learns them)",
    ],
    "response_names": ["", "the named responses, in the order of responses' last axis"],
    "response_units": ["", "the unit of each named response"],
    "params": ["", "structural parameters [record, parameter] given, in their units"],
    "param_names": ["", "the parameters' dotted paths, in the order of params' last axis"],
    "dt": ["s", "time step of the records"],
    "output_names": ["", "names of the outputs, in the order of the last axis"],
}
"""Units and description of each array of a prediction file; the file holds them as JSON
in its ``descriptions`` entry, with the label of the model that predicted."""


ACCELERATION_UNITS = {
    "m/s2": 1.0,
    "g": STANDARD_GRAVITY,
    "cm/s2": 0.01,
    "mm/s2": 0.001,
    "in/s2": 0.0254,
    "ft/s2": 0.3048,
}
"""The units ground motions in a file may be given in, with the m/s^2 in one of each."""


def read_motions(
    path: str | Path,
    dt: float | None = None,
    grid: TimeGrid | None = None,
    units: str | None = None,
) -> GroundMotions:
    """Ground motions from ``path``, in m/s^2: a PEER ``.AT2`` file or a folder of them (in
    g by the format, each record's header kept as its metadata), ``.npz`` with
    ``acceleration`` and ``dt`` (and ``units``, one of :data:`ACCELERATION_UNITS`), or
    ``.npy`` with ``dt`` given here (s).

    The unit of an ``.npz`` or ``.npy`` file is its ``units`` entry or ``units`` here; a
    file with neither is taken as m/s^2 with a :class:`CphysfnoWarning` that says so
    (records in g read as m/s^2 would be predicted ten times too weak).

    AT2 records of different lengths are zero-padded at the end to the longest; records
    of different time steps need ``grid``, onto which each is then resampled (so does any
    input with ``grid``).

    Raises:
        DatasetError: the file is missing, unreadable or lacks an array; a folder holds no
            AT2 file.
        InputError: ``dt`` is missing for a ``.npy`` file or given twice, AT2 records of
            different time steps without ``grid``, a unit that is unknown, given for AT2
            records in another unit than g, or given here against the file's own, or the
            values are not ground motions (see :class:`GroundMotions`).
    """
    path = Path(path)
    if units is not None and _unit_name(units) not in ACCELERATION_UNITS:
        raise InputError(f"--units {units}: give one of {', '.join(ACCELERATION_UNITS)} (or m/s^2)")
    if path.is_dir() or path.suffix.lower() == ".at2":
        if units is not None and _unit_name(units) != "g":
            raise InputError(f"{path}: AT2 records are in g by the format, not {units}")
        return _read_at2_records(path, dt, grid)
    motions = _read_arrays(path, dt, units)
    return motions if grid is None else motions.on_grid(grid)


def _unit_name(unit: str) -> str:
    """``unit`` with ``^`` and spaces dropped: ``m/s^2`` is ``m/s2``."""
    return str(unit).replace("^", "").replace(" ", "")


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


def _read_arrays(path: Path, dt: float | None, units: str | None) -> GroundMotions:
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
    stored_unit = str(arrays["units"]) if "units" in arrays else None
    if (
        stored_unit is not None
        and units is not None
        and _unit_name(stored_unit) != _unit_name(units)
    ):
        raise InputError(f"{path} holds motions in {stored_unit}: do not give --units {units}")
    factor = _factor(path, stored_unit or units)
    if suffix == ".npy":
        if dt is None:
            raise InputError(f"{path} is a bare array: give its time step (--dt, s)")
        return GroundMotions(factor * np.asarray(arrays["acceleration"], dtype=np.float64), dt)
    missing = {"acceleration", "dt"} - set(arrays)
    if missing:
        raise DatasetError(
            f"{path} lacks {', '.join(sorted(missing))}: it needs 'acceleration' [N, T] in "
            "m/s^2 and 'dt' in s"
        )
    if dt is not None:
        raise InputError(f"{path} holds its own dt: do not give another")
    acceleration = factor * np.asarray(arrays["acceleration"], dtype=np.float64)
    return GroundMotions(acceleration, float(arrays["dt"]))


def _factor(path: Path, unit: str | None) -> float:
    """m/s^2 in one ``unit`` (a warning and 1 where there is no unit)."""
    if unit is None:
        warnings.warn(
            f"{path} says nothing of its unit: its ground motions are taken as m/s^2 (give "
            "--units, or a 'units' entry in the .npz, e.g. 'g')",
            CphysfnoWarning,
            stacklevel=4,
        )
        return 1.0
    if _unit_name(unit) not in ACCELERATION_UNITS:
        raise InputError(
            f"{path}: unit '{unit}' is not one of {', '.join(ACCELERATION_UNITS)} (or m/s^2)"
        )
    return ACCELERATION_UNITS[_unit_name(unit)]


def read_parameters(path: str | Path) -> dict[str, np.ndarray]:
    """Structural parameters from a CSV file: a header of parameter paths
    (``stiffnesses.0``), then rows of numbers, one a record (or one for every record).

    Returns:
        path -> ``[rows]`` float64 values (a one-row file gives one value each).

    Raises:
        DatasetError: the file is missing, has no header or no row, a row of another
            length, a name twice, or a cell that is no number.
    """
    path = Path(path)
    try:
        with path.open(newline="") as stream:
            rows = [row for row in csv.reader(stream) if any(cell.strip() for cell in row)]
    except OSError as error:
        raise DatasetError(f"{path}: cannot read the parameters ({error})") from None
    if len(rows) < 2:
        raise DatasetError(
            f"{path}: give a header of parameter paths and at least one row of values"
        )
    header = [cell.strip() for cell in rows[0]]
    if len(set(header)) != len(header) or not all(header):
        raise DatasetError(f"{path}: the header must name each parameter once: {header}")
    values = np.empty((len(rows) - 1, len(header)))
    for i, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise DatasetError(f"{path}, line {i}: {len(row)} values for {len(header)} names")
        try:
            values[i - 2] = [float(cell) for cell in row]
        except ValueError:
            raise DatasetError(f"{path}, line {i}: a value is not a number: {row}") from None
    if values.shape[0] == 1:
        return {name: values[0, j] for j, name in enumerate(header)}
    return {name: values[:, j] for j, name in enumerate(header)}


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
    units: str | None = None,
    params: str | Path | None = None,
) -> PredictionRun:
    """Load the model in ``model_dir``, predict the motions of ``motions_path`` and write
    ``out`` (``.npz``).

    Args:
        on_grid: bring motions on another time grid onto the model's (anti-aliased
            resampling, then cut or zero-padded at the end); otherwise they are refused.
        device: where the operator runs (a ``training.device`` setting).
        precision: the operator's arithmetic, ``"float32"`` or ``"bfloat16"`` (see
            :meth:`CompositeModel.predict_stages`).
        units: the unit of the motions in the file (see :func:`read_motions`).
        params: a CSV file of each record's structural parameters, for a model of a
            family of structures (see :func:`read_parameters`).

    Raises:
        InputError: ``out`` is not an ``.npz`` name, the motions are on another grid
            than the model's and ``on_grid`` is off (see :meth:`CompositeModel.grid`), or
            the parameters do not fit the model or the records
            (:meth:`CompositeModel.predict_stages`).
        DatasetError: a file is missing or malformed.
    """
    out = Path(out)
    if out.suffix != ".npz":
        raise InputError(f"--out {out}: name an .npz file")
    model = CompositeModel.load(model_dir).to(device)
    motions = read_motions(motions_path, dt, model.grid if on_grid else None, units)
    given = None if params is None else read_parameters(params)
    started = time.perf_counter()
    stages = model.predict_stages(motions, params=given, precision=precision)
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
    if stages.acceleration is not None:
        arrays["acceleration"] = stages.acceleration
    if stages.responses:
        channels = () if model.structure is None else model.structure.response_channels()
        unit_of = {c.name: c.unit for c in channels}
        arrays["responses"] = np.concatenate(list(stages.responses.values()), axis=2)
        arrays["response_names"] = np.array(list(stages.responses))
        arrays["response_units"] = np.array([unit_of.get(n, "") for n in stages.responses])
    if given:
        arrays["params"] = np.column_stack(list(per_record(given, motions.n_records).values()))
        arrays["param_names"] = np.array(list(given))
    described = {k: v for k, v in PREDICTION_ARRAYS.items() if k in arrays}
    arrays["descriptions"] = np.array(json.dumps({**described, "model": model.label}))
    out.parent.mkdir(parents=True, exist_ok=True)
    np.savez(out, **arrays)
    peaks = np.median(np.abs(stages.mean).max(axis=1), axis=0)
    return PredictionRun(
        motions.n_records, seconds, out, dict(zip(names, peaks.tolist(), strict=True))
    )
