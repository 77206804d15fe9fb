"""Dataset generation that survives being killed at any point.

Work in progress lives in a folder beside the dataset, ``<name>.parts/``: a manifest, the
ground motions, and one ``chunk-NNNNN.npz`` per finished chunk, each written to a temporary
name and renamed into place, so a file there is always whole. Started again with the same
configuration, generation simulates only the missing chunks. When all are there they are
assembled into the HDF5 file (again written aside and renamed), and the folder is removed:
a dataset file at the final path is always complete.
"""

from __future__ import annotations

import json
import os
import shutil
import sys
import time
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from .config import ExperimentConfig
from .data import SPLITS, check_dataset_identity, dataset_hash, parts_folder, versions
from .errors import DatasetError
from .executors import run_tasks
from .registry import get_registry
from .signals import GroundMotions
from .simulation import ChunkResult, simulate_chunk


def _write_atomic(path: Path, write) -> None:
    """Write through ``write(handle_path)`` to a temporary name, then rename into place."""
    temporary = path.with_name(f".{path.name}.tmp")
    write(temporary)
    os.replace(temporary, path)


def _save_npz(path: Path, arrays: dict[str, np.ndarray]) -> None:
    def write(temporary: Path) -> None:
        with open(temporary, "wb") as f:
            np.savez(f, **arrays)
            f.flush()
            os.fsync(f.fileno())

    _write_atomic(path, write)


def _chunk_path(parts: Path, index: int) -> Path:
    return parts / f"chunk-{index:05d}.npz"


def _start(config: ExperimentConfig, parts: Path, identity: str) -> tuple[GroundMotions, int]:
    """Sample the motions (or read them back from an interrupted run) and the chunk size."""
    manifest = parts / "manifest.json"
    if manifest.exists():
        found = json.loads(manifest.read_text())
        if found["config_hash"] != identity:
            raise DatasetError(
                f"{parts} holds an unfinished dataset of another configuration: remove it or "
                "choose another output folder"
            )
        with np.load(parts / "motions.npz", allow_pickle=False) as stored:
            motions = GroundMotions(stored["ag"], float(stored["dt"]))
        return motions, int(found["chunk_size"])
    source_spec = config.ground_motion
    source = get_registry().create("ground_motion", source_spec.name, **source_spec.params)
    n = config.data.n_records
    motions = source.sample(n, np.random.default_rng(config.data.seed))
    if motions.n_records < n:
        raise DatasetError(
            f"ground motion '{source.name}' gave {motions.n_records} records but the data "
            f"section asks for {n} (n_train + n_val + n_test): lower the split sizes"
        )
    parts.mkdir(parents=True, exist_ok=True)
    _save_npz(parts / "motions.npz", {"ag": motions.acceleration, "dt": np.array(motions.dt)})
    record = {"config_hash": identity, "chunk_size": config.data.chunk_size}
    _write_atomic(manifest, lambda temporary: temporary.write_text(json.dumps(record)))
    return motions, config.data.chunk_size


def generate_dataset(config: ExperimentConfig, path: str | Path, progress: bool = True) -> Path:
    """Simulate ``config.data.n_records`` records into the HDF5 file ``path``.

    Records are sampled once from ``config.data.seed`` (seeds belong to records, not to
    workers), simulated in chunks of ``config.data.chunk_size`` on the configured executor,
    and kept chunk by chunk until all are done. Killed and started again with the same
    configuration, it simulates only the chunks that are missing.
    """
    path = Path(path)
    identity = dataset_hash(config)
    if check_dataset_identity(path, identity):
        if progress:
            print(f"dataset {path} is complete: nothing to simulate", file=sys.stderr)
        return path
    registry = get_registry()
    structure = registry.create("structure", config.structure.name, **config.structure.params)
    for pp in config.preprocessor:  # fail on a missing capability before any simulation
        registry.create("preprocessor", pp.name, **pp.params).fit(structure)
    parts = parts_folder(path)
    motions, chunk = _start(config, parts, identity)
    n = motions.n_records
    bounds = [(s, min(s + chunk, n)) for s in range(0, n, chunk)]
    todo = [i for i in range(len(bounds)) if not _chunk_path(parts, i).exists()]
    if progress and len(todo) < len(bounds):
        print(
            f"  resuming: {len(bounds) - len(todo)} of {len(bounds)} chunks already done",
            file=sys.stderr,
        )
    _simulate_chunks(config, structure, motions, bounds, todo, parts, progress)
    _assemble(config, structure, motions, bounds, parts, path, identity)
    shutil.rmtree(parts)
    return path


def _simulate_chunks(config, structure, motions, bounds, todo, parts, progress) -> None:
    structure_spec = {"name": structure.name, **structure.get_params()}
    pp_specs = [p.to_dict() for p in config.preprocessor]
    total = sum(bounds[i][1] - bounds[i][0] for i in todo)
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
        for index, cause in failures.items():
            if progress:
                print(f"  record {index} skipped: {cause}", file=sys.stderr, flush=True)
        arrays = {"u": result.u, "failures": np.array(json.dumps(failures))}
        arrays.update({f"z/{name}": values for name, values in result.z.items()})
        arrays.update({f"extras/{name}": values for name, values in result.extras.items()})
        _save_npz(_chunk_path(parts, i), arrays)
        finished += stop - start
        if progress:
            rate = finished / max(time.perf_counter() - started, 1e-9)
            print(
                f"  simulated {finished}/{total} records ({rate:.0f} records/s)",
                file=sys.stderr,
                flush=True,
            )

    def arguments(i: int) -> tuple[Any, ...]:
        start, stop = bounds[i]
        return structure_spec, pp_specs, motions.acceleration[start:stop], motions.dt

    run_tasks(simulate_chunk, [(i, arguments(i)) for i in todo], config.data, store)


def _assemble(config, structure, motions, bounds, parts, path, identity) -> None:
    """Copy the chunks, one at a time, into a new HDF5 file renamed into place at the end."""
    shape = (motions.n_records, motions.n_steps, structure.n_outputs)

    def write(temporary: Path) -> None:
        failures: dict[str, str] = {}
        with h5py.File(temporary, "w") as f:
            f.attrs["config_hash"] = identity
            f.attrs["config"] = json.dumps(config.to_dict())
            f.attrs["seed"] = config.data.seed
            f.attrs["dt"] = motions.dt
            f.attrs["versions"] = json.dumps(versions())
            f.attrs["output_names"] = json.dumps(list(structure.output_names))
            for split in SPLITS:
                f.attrs[f"n_{split}"] = getattr(config.data, f"n_{split}")
            f.create_dataset("ag", data=motions.acceleration)
            f.create_dataset("u", shape=shape, dtype="f8")
            for pp in config.preprocessor:
                f.create_dataset(f"z/{pp.name}", shape=shape, dtype="f8")
            for i, (start, stop) in enumerate(bounds):
                with np.load(_chunk_path(parts, i), allow_pickle=False) as chunk:
                    for key in chunk.files:
                        if key == "failures":
                            failures.update(json.loads(str(chunk[key])))
                            continue
                        values = chunk[key]
                        if key not in f:  # extras: float32, they serve the figures
                            f.create_dataset(key, shape=(shape[0], *values.shape[1:]), dtype="f4")
                        f[key][start:stop] = values
            f.attrs["failures"] = json.dumps(failures)
            f.attrs["complete"] = True

    _write_atomic(path, write)
