"""Datasets: generate ``(a_g, u, z)`` with the true nonlinear model, write and read HDF5.

File layout: ``ag [N, T]`` (m/s^2), ``u [N, T, n_out]`` (m), ``z/<preprocessor>
[N, T, n_out]`` (m), ``extras/<channel> [N, T, k]`` (float32, for figures),
``chunk_done [n_chunks]``; attributes ``dt``, ``config`` (JSON), ``config_hash``, ``seed``,
``versions``, ``output_names``, ``n_train``, ``n_val``, ``n_test`` and ``complete``, which
is set only once every chunk is written. Generation resumes: chunks already written are
not simulated again.
"""

from __future__ import annotations

import hashlib
import json
import sys
import time
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from .config import ExperimentConfig
from .errors import DatasetError
from .executors import run_tasks
from .registry import get_registry
from .signals import GroundMotions
from .simulation import ChunkResult, simulate_chunk

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
    """

    ag: np.ndarray
    u: np.ndarray
    z: dict[str, np.ndarray]
    extras: dict[str, np.ndarray]
    dt: float
    output_names: tuple[str, ...]
    sizes: dict[str, int]
    failures: dict[int, str] = field(default_factory=dict)

    def rows(self, split: str) -> np.ndarray:
        """The record indices of ``split`` (``train``, ``val`` or ``test``), failed records
        left out."""
        if split not in SPLITS:
            raise DatasetError(f"unknown split '{split}': use one of {', '.join(SPLITS)}")
        start = sum(self.sizes[s] for s in SPLITS[: SPLITS.index(split)])
        rows = np.arange(start, start + self.sizes[split])
        return rows[~np.isin(rows, list(self.failures))]

    def motions(self, split: str) -> GroundMotions:
        return GroundMotions(self.ag[self.rows(split)], self.dt)

    def targets(self, split: str) -> np.ndarray:
        return self.u[self.rows(split)]

    def physics(self, preprocessor: str, split: str) -> np.ndarray:
        if preprocessor not in self.z:
            raise DatasetError(
                f"dataset has no physics response '{preprocessor}' "
                f"(it has: {', '.join(self.z) or 'none'}); generate it again with that preprocessor"
            )
        return self.z[preprocessor][self.rows(split)]


def _versions() -> dict[str, str]:
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
    return {
        "structure": full["structure"],
        "ground_motion": full["ground_motion"],
        "preprocessor": full["preprocessor"],
        "data": data,
    }


def _hash(identity: dict[str, Any]) -> str:
    return hashlib.sha256(json.dumps(identity, sort_keys=True).encode()).hexdigest()[:16]


def _check_existing(path: Path, identity_hash: str) -> bool:
    """True if ``path`` is a complete dataset of this config; raise if it is another's."""
    if not path.exists():
        return False
    try:
        with h5py.File(path, "r") as f:
            found = f.attrs.get("config_hash")
            complete = bool(f.attrs.get("complete", False))
    except OSError as error:
        raise DatasetError(f"{path} exists but is not a readable HDF5 dataset: {error}") from None
    if found != identity_hash:
        raise DatasetError(
            f"{path} holds a dataset of another configuration: remove it or choose another "
            "output folder"
        )
    return complete


def generate_dataset(config: ExperimentConfig, path: str | Path, progress: bool = True) -> Path:
    """Simulate ``config.data.n_records`` records and write them to ``path`` (HDF5).

    Records are sampled once from ``config.data.seed`` (seeds belong to records, not to
    workers), simulated in chunks of ``config.data.chunk_size`` by the configured
    executor, and written chunk by chunk. Started again on an unfinished file of the same
    configuration, it simulates only the chunks that are missing.
    """
    path = Path(path)
    identity = dataset_identity(config)
    identity_hash = _hash(identity)
    if _check_existing(path, identity_hash):
        if progress:
            print(f"dataset {path} is complete: nothing to simulate", file=sys.stderr)
        return path
    registry = get_registry()
    spec = config.structure
    structure = registry.create("structure", spec.name, **spec.params)
    for pp in config.preprocessor:  # fail on a missing capability before any simulation
        registry.create("preprocessor", pp.name, **pp.params).fit(structure)
    source = registry.create(
        "ground_motion", config.ground_motion.name, **config.ground_motion.params
    )
    n = config.data.n_records
    motions = source.sample(n, np.random.default_rng(config.data.seed))
    if motions.n_records < n:
        raise DatasetError(
            f"ground motion '{source.name}' gave {motions.n_records} records but the data "
            f"section asks for {n} (n_train + n_val + n_test): lower the split sizes"
        )
    shape = (n, motions.n_steps, structure.n_outputs)
    path.parent.mkdir(parents=True, exist_ok=True)
    with h5py.File(path, "a") as f:
        if "ag" not in f:
            f.attrs["complete"] = False
            f.attrs["chunk_size"] = config.data.chunk_size
            f.attrs["config_hash"] = identity_hash
            f.attrs["config"] = json.dumps(config.to_dict())
            f.attrs["seed"] = config.data.seed
            f.attrs["dt"] = motions.dt
            f.attrs["versions"] = json.dumps(_versions())
            f.attrs["output_names"] = json.dumps(list(structure.output_names))
            for split in SPLITS:
                f.attrs[f"n_{split}"] = getattr(config.data, f"n_{split}")
            f.create_dataset("ag", data=motions.acceleration)
            f.create_dataset("u", shape=shape, dtype="f8")
            for pp in config.preprocessor:
                f.create_dataset(f"z/{pp.name}", shape=shape, dtype="f8")
        chunk = int(f.attrs["chunk_size"])  # a resumed run keeps the chunks it started with
        bounds = [(s, min(s + chunk, n)) for s in range(0, n, chunk)]
        if "chunk_done" not in f:
            f.create_dataset("chunk_done", data=np.zeros(len(bounds), dtype=bool))
        done = f["chunk_done"][...]
        todo = [i for i in range(len(bounds)) if not done[i]]
        _run_chunks(config, structure, motions, bounds, todo, f, progress)
        f.attrs["complete"] = True
    return path


def _run_chunks(config, structure, motions, bounds, todo, f, progress) -> None:
    structure_spec = {"name": structure.name, **structure.get_params()}
    pp_specs = [p.to_dict() for p in config.preprocessor]
    started = time.perf_counter()
    finished = 0

    def store(i: int, result: ChunkResult) -> None:
        nonlocal finished
        start, stop = bounds[i]
        failures = {start + k: cause for k, cause in result.failures.items()}
        if failures and config.data.on_failure == "raise":
            index, cause = next(iter(failures.items()))
            raise DatasetError(
                f"record {index} failed: {cause} (set data.on_failure = 'skip' to list failed "
                "records in the dataset and go on)"
            )
        if failures:
            recorded = json.loads(f.attrs.get("failures", "{}"))
            recorded.update({str(k): v for k, v in failures.items()})
            f.attrs["failures"] = json.dumps(recorded)
            if progress:
                for index, cause in failures.items():
                    print(f"  record {index} skipped: {cause}", file=sys.stderr, flush=True)
        f["u"][start:stop] = result.u
        for name, values in result.z.items():
            f[f"z/{name}"][start:stop] = values
        for name, values in result.extras.items():
            key = f"extras/{name}"
            if key not in f:
                f.create_dataset(key, shape=(f["u"].shape[0], *values.shape[1:]), dtype="f4")
            f[key][start:stop] = values
        f["chunk_done"][i] = True
        f.flush()
        finished += stop - start
        if progress:
            rate = finished / max(time.perf_counter() - started, 1e-9)
            total = sum(bounds[j][1] - bounds[j][0] for j in todo)
            print(
                f"  simulated {finished}/{total} records ({rate:.0f} records/s)",
                file=sys.stderr,
                flush=True,
            )

    def args(i: int):
        start, stop = bounds[i]
        return structure_spec, pp_specs, motions.acceleration[start:stop], motions.dt

    run_tasks(simulate_chunk, [(i, args(i)) for i in todo], config.data, store)


def load_dataset(path: str | Path) -> Dataset:
    """Read a complete dataset; an unfinished or foreign file raises DatasetError."""
    path = Path(path)
    if not path.exists():
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
            )
    except (OSError, KeyError) as error:
        raise DatasetError(f"{path} is not a cphysfno dataset: {error}") from None
