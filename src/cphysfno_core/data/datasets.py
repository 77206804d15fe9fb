"""Datasets of ``(a_g, u, z)`` in HDF5: what identifies one, and reading it back.

File layout: ``ag [N, T]`` (m/s^2), ``u [N, T, n_out]`` (m), ``z/<preprocessor>
[N, T, n_out]`` (m), ``extras/<channel> [N, T, k]`` (float32, for figures); attributes
``dt``, ``config`` (JSON), ``config_hash``, ``seed``, ``versions``, ``output_names``,
``n_train``, ``n_val``, ``n_test``, ``failures`` and ``non_converged`` (JSON: record
index -> cause), ``recoveries`` (JSON: record index -> the hardest measure its analysis
needed to converge), ``response_channels`` (JSON: the named responses among the extras, with
their units) and ``complete``; with random structural parameters also ``params [N, k]``
(float64, each record's draw; attributes ``names`` and ``units``, JSON lists).
:mod:`cphysfno_core.generation` writes it.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from ..config.experiment import ExperimentConfig
from ..config.uncertainty import UncertainParameters
from ..signals import GroundMotions, ResponseChannel
from ..signals.errors import DatasetError
from ..signals.histories import ACCELERATION_EXTRA

SPLITS = ("train", "val", "test")


@dataclass
class Dataset:
    """A complete dataset held in memory.

    Attributes:
        ag: ``[N, T]`` ground accelerations, m/s^2.
        u: ``[N, T, n_out]`` true displacements, m.
        z: preprocessor name -> ``[N, T, n_out]`` physics responses, m.
        extras: channel name -> ``[N, T, k]`` extra structural outputs.
        dt: time step, s.
        output_names: names of the output DOFs.
        sizes: records in the train, val and test splits, in this order in the file.
        failures: record index -> cause, for records whose simulation failed; they are
            left out of every split.
        provenance: one mapping per record: its source, draw, time step and the source's
            metadata (event, station, RSN, scale factor, ...); empty for older files.
        collapsed: ``[N]`` whether each record collapsed the structure; collapsed records
            are left out of :meth:`rows` (training, error tables) and listed by
            :meth:`collapsed_rows`. ``None`` (older files) means none did.
        non_converged: record index -> cause, for records whose analysis stopped
            converging below the collapse (a numerical failure): kept to the stop, left
            out of :meth:`rows`, listed by :meth:`non_converged_rows`.
        response_channels: the named responses the structure recorded (each an extra
            channel ``[N, T, 1]`` in its unit).
        recoveries: record index -> the hardest measure its analysis needed to converge
            (an OpenSees structure's convergence ladder), for the records that needed one.
        params: ``[N, k]`` each record's draw of the structure's random parameters, in
            their units (``k = 0``: a fixed structure).
        param_names: the dotted paths of the random parameters (``stiffnesses.0``), one
            per column of ``params``.
        param_units: the unit label of each column of ``params`` (empty where none).
        calibration_surfaces: preprocessor name -> the calibration surface its records'
            physics responses were made from (``[uncertainty] physics = "surface"``;
            :meth:`~cphysfno_core.config.calibration_surface.CalibrationSurface.to_dict`).
    """

    ag: np.ndarray
    u: np.ndarray
    z: dict[str, np.ndarray]
    extras: dict[str, np.ndarray]
    dt: float
    output_names: tuple[str, ...]
    sizes: dict[str, int]
    failures: dict[int, str] = field(default_factory=dict)
    provenance: tuple[dict, ...] = ()
    collapsed: np.ndarray | None = None
    non_converged: dict[int, str] = field(default_factory=dict)
    response_channels: tuple[ResponseChannel, ...] = ()
    recoveries: dict[int, str] = field(default_factory=dict)
    params: np.ndarray | None = None
    param_names: tuple[str, ...] = ()
    param_units: tuple[str, ...] = ()
    calibration_surfaces: dict[str, dict[str, Any]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.collapsed is None:
            self.collapsed = np.zeros(self.u.shape[0], dtype=bool)
        if self.params is None:
            self.params = np.zeros((self.u.shape[0], 0))

    def _split_rows(self, split: str) -> np.ndarray:
        if split not in SPLITS:
            raise DatasetError(f"unknown split '{split}': use one of {', '.join(SPLITS)}")
        start = sum(self.sizes[s] for s in SPLITS[: SPLITS.index(split)])
        return np.arange(start, start + self.sizes[split])

    def collapsed_rows(self, split: str) -> np.ndarray:
        """The record indices of ``split`` whose record collapsed the structure."""
        rows = self._split_rows(split)
        return rows[self.collapsed[rows]]

    def non_converged_rows(self, split: str) -> np.ndarray:
        """The record indices of ``split`` whose analysis stopped converging below the
        collapse."""
        rows = self._split_rows(split)
        return rows[np.isin(rows, list(self.non_converged))]

    def left_out(self) -> dict[str, dict[str, int]]:
        """How many records of each split collapsed the structure, how many did not
        converge below the collapse and how many failed (``{"collapsed": {"train": 2,
        "val": 0, "test": 1}, "non_converged": {...}, "failed": {...}}``): the records that
        training and the error tables leave out."""
        flags = {}
        for name, indices in (("non_converged", self.non_converged), ("failed", self.failures)):
            flags[name] = np.zeros(self.u.shape[0], dtype=bool)
            flags[name][list(indices)] = True
        return {
            name: {split: int(values[self._split_rows(split)].sum()) for split in SPLITS}
            for name, values in (("collapsed", self.collapsed), *flags.items())
        }

    def rows(self, split: str) -> np.ndarray:
        """The record indices of ``split`` (``train``, ``val`` or ``test``), failed,
        collapsed and non-converged records left out; DatasetError if every record of the
        split is one of those."""
        rows = self._split_rows(split)
        collapsed = self.collapsed[rows]
        if collapsed.all() and rows.size:
            raise DatasetError(
                f"every one of the {rows.size} records of the {split} split collapsed the "
                "structure: scale the ground motions down for a surrogate of its response"
            )
        failed = np.isin(rows, list(self.failures))
        stopped = np.isin(rows, list(self.non_converged))
        if (collapsed | stopped).all() and rows.size:
            first = int(rows[stopped][0])
            raise DatasetError(
                f"every one of the {rows.size} records of the {split} split collapsed the "
                f"structure or did not converge (record {first}: {self.non_converged[first]}): "
                "make the model's analysis more robust, or scale the ground motions down"
            )
        collapsed = collapsed | stopped
        if (failed | collapsed).all() and rows.size:
            first = int(rows[failed][0])
            raise DatasetError(
                f"every one of the {rows.size} records of the {split} split failed in "
                f"simulation (record {first}: {self.failures[first]}); {len(self.failures)} of "
                f"{self.u.shape[0]} records failed in all: fix the cause and generate the "
                "dataset again"
            )
        return rows[~(failed | collapsed)]

    def motions(self, split: str) -> GroundMotions:
        return GroundMotions(self.ag[self.rows(split)], self.dt)

    def targets(self, split: str) -> np.ndarray:
        return self.u[self.rows(split)]

    def accelerations(self, split: str) -> np.ndarray:
        """``[n, T, n_out]`` absolute accelerations (m/s^2) of the split's records, from
        the structure's ``absolute_acceleration`` channel.

        Raises:
            DatasetError: the structure recorded no such channel.
        """
        if ACCELERATION_EXTRA not in self.extras:
            raise DatasetError(
                f"the dataset has no '{ACCELERATION_EXTRA}' channel (its structure records "
                f"{', '.join(self.extras) or 'no extra channels'}): a model can learn "
                "accelerations only from a structure that records them, e.g. opensees-model"
            )
        return np.asarray(self.extras[ACCELERATION_EXTRA][self.rows(split)], dtype=np.float64)

    def named_responses(self, split: str) -> dict[str, np.ndarray]:
        """Name -> ``[n, T, 1]`` each named response (``response_channels``, in its
        channel's unit) of the split's records.

        Raises:
            DatasetError: the structure recorded no named response.
        """
        if not self.response_channels:
            raise DatasetError(
                "the dataset has no named responses: a model can learn them only from a "
                "structure that records them ([structure] responses of opensees-model)"
            )
        rows = self.rows(split)
        return {
            c.name: np.asarray(self.extras[c.name][rows], dtype=np.float64)
            for c in self.response_channels
        }

    def parameter_draws(self, split: str) -> dict[str, np.ndarray]:
        """Parameter path -> ``[n]`` the split's records' draws of each random structural
        parameter, in its unit (empty for a fixed structure); the records of
        :meth:`rows`."""
        return self.draws_of(self.rows(split))

    def draws_of(self, rows: np.ndarray) -> dict[str, np.ndarray]:
        """Parameter path -> ``[len(rows)]`` the draws of the records ``rows``."""
        return {name: self.params[rows, j] for j, name in enumerate(self.param_names)}

    @property
    def parameter_units(self) -> dict[str, str]:
        """Parameter path -> its unit label (empty where none)."""
        return dict(zip(self.param_names, self.param_units, strict=True))

    def physics(self, preprocessor: str, split: str) -> np.ndarray:
        if preprocessor not in self.z:
            raise DatasetError(
                f"dataset has no physics response '{preprocessor}' "
                f"(it has: {', '.join(self.z) or 'none'}); generate it again with that preprocessor"
            )
        return self.z[preprocessor][self.rows(split)]


def versions() -> dict[str, str]:
    out = {}
    for dist in ("cphysfno-core", "numpy", "scipy", "torch", "h5py"):
        try:
            out[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            continue
    return out


def dataset_identity(config: ExperimentConfig) -> dict[str, Any]:
    """The parts of a config that determine the data (not how it is computed)."""
    full = config.to_dict()
    how = ("executor", "workers", "address", "retries", "chunk_size", "on_failure")
    data = {k: v for k, v in full["data"].items() if k not in how}
    identity = {
        "structure": full["structure"],
        "ground_motion": full["ground_motion"],
        "preprocessor": full["preprocessor"],
        "data": data,
    }
    if config.uncertainty is not None:
        identity["uncertainty"] = full["uncertainty"]
    return identity


def dataset_hash(config: ExperimentConfig) -> str:
    """A short fingerprint of :func:`dataset_identity`."""
    text = json.dumps(dataset_identity(config), sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def parts_folder(path: Path) -> Path:
    """Where the unfinished chunks of the dataset ``path`` are kept while it is generated."""
    return path.with_name(path.name + ".parts")


EXTRA_UNITS = {"story_drift": "m", "story_shear": "N", ACCELERATION_EXTRA: "m/s^2"}
"""Units of the extra channels the built-in structures simulate."""


def array_descriptions(output_names: list[str]) -> dict[str, tuple[str, str]]:
    """Array path -> ``(units, description)`` of the arrays every dataset holds."""
    outputs = ", ".join(output_names)
    return {
        "ag": ("m/s^2", "ground acceleration [record, sample], linear between samples"),
        "u": ("m", f"displacement relative to the ground [record, sample, output]: {outputs}"),
        "collapsed": (
            "",
            "whether the record collapsed the structure [record]; its u is NaN after the "
            "collapse and it is left out of training and error tables",
        ),
        "records": (
            "",
            "provenance of each record (JSON: source, draw, dt, the source's "
            "metadata such as event, station, RSN and scale factor)",
        ),
    }


def describe_arrays(
    f: h5py.File, output_names: list[str], channels: tuple[ResponseChannel, ...] = ()
) -> None:
    """Give every array of the open dataset ``f`` its ``units`` and ``description``, the
    named responses ``channels`` theirs."""
    known = array_descriptions(output_names)
    for name in f.get("z", {}):
        known[f"z/{name}"] = (
            "m",
            f"physics response z of preprocessor '{name}' [record, "
            "sample, output], on the records' own grid",
        )
    for name in f.get("extras", {}):
        units = EXTRA_UNITS.get(name, "as the structure defines it")
        known[f"extras/{name}"] = (
            units,
            f"extra channel '{name}' of the structure's "
            "simulation [record, sample, channel], float32",
        )
    for channel in channels:
        known[f"extras/{channel.name}"] = (
            channel.unit,
            f"named response '{channel.name}' [record, sample, 1]"
            + (f": {channel.description}" if channel.description else ""),
        )
    f.attrs["response_channels"] = json.dumps([c.as_dict() for c in channels])
    for path, (units, description) in known.items():
        if path in f:
            f[path].attrs["units"] = units
            f[path].attrs["description"] = description


def write_draws(
    f: h5py.File,
    space: UncertainParameters,
    draws: np.ndarray,
    surfaces: dict[str, dict[str, Any]] | None = None,
) -> None:
    """Keep each record's draw ``draws [N, k]`` of the random parameters ``space`` in the
    open dataset ``f`` as ``params``, with their names and units, and the calibration
    ``surfaces`` (preprocessor name -> surface) its physics came from; nothing for a fixed
    structure."""
    if not space.parameters:
        return
    stored = f.create_dataset("params", data=np.asarray(draws, dtype=np.float64))
    stored.attrs["names"] = json.dumps(list(space.names))
    stored.attrs["units"] = json.dumps(list(space.units))
    stored.attrs["calibration_surfaces"] = json.dumps(surfaces or {})
    stored.attrs["description"] = (
        "each record's draw of the structure's random parameters [record, parameter]: "
        "names (dotted paths) and units in the attributes"
    )


def read_draws(f: h5py.File) -> dict[str, Any]:
    """The :class:`Dataset` fields ``params``, ``param_names``, ``param_units`` and
    ``calibration_surfaces`` of the open dataset ``f`` (none for a fixed structure)."""
    if "params" not in f:
        return {}
    stored = f["params"]
    return {
        "params": stored[...],
        "param_names": tuple(json.loads(stored.attrs["names"])),
        "param_units": tuple(json.loads(stored.attrs["units"])),
        "calibration_surfaces": json.loads(stored.attrs.get("calibration_surfaces", "{}")),
    }


def read_provenance(f: h5py.File) -> tuple[dict, ...]:
    """The ``records`` provenance of the open dataset ``f`` (empty for older files)."""
    if "records" not in f:
        return ()
    return tuple(json.loads(text) for text in f["records"].asstr()[...])


def check_dataset_identity(path: Path, identity: str) -> bool:
    """True if ``path`` is a complete dataset of this identity (False if there is none
    yet); raise DatasetError if it belongs to another configuration or is unreadable."""
    if not path.exists():
        return False
    try:
        with h5py.File(path, "r") as f:
            found = f.attrs.get("config_hash")
    except OSError as error:
        raise DatasetError(f"{path} exists but is not a readable HDF5 dataset: {error}") from None
    if found != identity:
        raise DatasetError(
            f"{path} holds a dataset of another configuration: remove it or choose another "
            "output folder"
        )
    return True


def load_dataset(path: str | Path) -> Dataset:
    """Read a complete dataset; an unfinished or foreign file raises DatasetError."""
    path = Path(path)
    if not path.exists():
        if parts_folder(path).exists():
            raise DatasetError(
                f"{path} is incomplete (generation was interrupted): run the same "
                "`cphysfno generate` command again to finish it"
            )
        raise DatasetError(f"no dataset at {path}: run `cphysfno generate` first")
    try:
        with h5py.File(path, "r") as f:
            if not bool(f.attrs.get("complete", False)):
                raise DatasetError(
                    f"{path} is incomplete (generation was interrupted): run the same "
                    "`cphysfno generate` command again to finish it"
                )
            return Dataset(
                ag=f["ag"][...],
                u=f["u"][...],
                z={name: f[f"z/{name}"][...] for name in f.get("z", {})},
                extras={name: f[f"extras/{name}"][...] for name in f.get("extras", {})},
                dt=float(f.attrs["dt"]),
                output_names=tuple(json.loads(f.attrs["output_names"])),
                sizes={s: int(f.attrs[f"n_{s}"]) for s in SPLITS},
                failures={int(k): v for k, v in json.loads(f.attrs.get("failures", "{}")).items()},
                non_converged={
                    int(k): v for k, v in json.loads(f.attrs.get("non_converged", "{}")).items()
                },
                provenance=read_provenance(f),
                collapsed=f["collapsed"][...] if "collapsed" in f else None,
                recoveries={
                    int(k): v for k, v in json.loads(f.attrs.get("recoveries", "{}")).items()
                },
                response_channels=tuple(
                    ResponseChannel(**c) for c in json.loads(f.attrs.get("response_channels", "[]"))
                ),
                **read_draws(f),
            )
    except (OSError, KeyError) as error:
        raise DatasetError(f"{path} is not a cphysfno dataset: {error}") from None
