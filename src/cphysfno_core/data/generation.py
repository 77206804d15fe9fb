"""Dataset generation that survives being killed at any point.

Work in progress lives in a folder beside the dataset, ``<name>.parts/``: a manifest, the
ground motions (``motions.npy``), and one ``chunk-NNNNN.npz`` per finished chunk, each
written to a temporary name and renamed into place, so a file there is always whole. The
motions are read back a chunk at a time; a source whose records are independent draws is
also sampled block by block, so no stage holds all records in memory. With
``data.group_by`` the motions are reordered, before any simulation, so that every group of
records lies in one split (:func:`.grouped_split.grouped_order`). Started again with the same
configuration, generation simulates only the missing chunks. When all are there they are
assembled into the HDF5 file (again written aside and renamed), and the folder is removed:
a dataset file at the final path is always complete. What the simulator printed for each
record (its warnings) is shown at the end, each distinct message once with its count, and
kept in full in ``<name>-messages.log`` beside the dataset; so are the records counted by
the hardest measure their analysis needed to converge (an OpenSees structure's convergence
ladder), kept by record in the dataset's attribute ``recoveries``. A structure with random
parameters (:mod:`..config.uncertainty`) gets one draw a record, from its own stream under
``data.seed``: drawn again, identically, when generation resumes, and kept in the dataset.
"""

from __future__ import annotations

import json
import logging
import os
import shutil
import time
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from ..api.interfaces import GroundMotionSource, Structure
from ..api.registry import get_registry
from ..config.allocator import tune_memory
from ..config.calibration_surface import ANCHOR_Z, fit_surface
from ..config.experiment import DataConfig, ExperimentConfig
from ..config.uncertainty import UncertainParameters, distinct_draws, with_values
from ..signals import GroundMotions
from ..signals.errors import ConfigError, CphysfnoError, CphysfnoWarning, DatasetError
from ..signals.progress import show_progress, time_left
from .datasets import (
    SPLITS,
    check_dataset_identity,
    dataset_hash,
    describe_arrays,
    parts_folder,
    versions,
    write_draws,
)
from .executors import run_tasks
from .messages import full_log, summary
from .recoveries import convergence_summary
from .simulation import ChunkResult, simulate_chunk
from .splits import grouped_order

logger = logging.getLogger(__name__)

LISTED = ("failures", "non_converged", "recoveries")
"""The chunks' records by index (JSON: record index -> text), kept as attributes of the
dataset: the failed records and their causes, the non-converged ones and theirs, and what
each record that needed it needed to converge."""

SAMPLE_BLOCK = 256
"""Records drawn per call from a source with independent draws. Fixed, so that the records
of a dataset do not depend on the chunk size or the executor."""


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


@dataclass(frozen=True)
class _StoredMotions:
    """The ground motions of a dataset in progress, ``[n, n_steps]`` m/s^2 in an ``.npy``
    file, read back a slice of records at a time."""

    path: Path
    n_records: int
    n_steps: int
    dt: float

    @property
    def provenance_path(self) -> Path:
        """The JSON list beside the records: where each record comes from."""
        return self.path.with_name("records.json")

    def provenance(self) -> list[dict]:
        """One mapping per record: its source, its draw and the source's metadata (event,
        station, scale factor, ...); empty for a run started before they were kept."""
        if not self.provenance_path.exists():
            return []
        return json.loads(self.provenance_path.read_text())

    def rows(self, start: int, stop: int) -> np.ndarray:
        """A copy of records ``start:stop``; the file's pages are released afterwards."""
        mapped = np.load(self.path, mmap_mode="r")
        try:
            return np.array(mapped[start:stop])
        finally:
            del mapped


def _sample_into(source: GroundMotionSource, data: DataConfig, target: Path) -> _StoredMotions:
    """Draw ``data.n_records`` records from ``source`` and write them to ``target``
    (``.npy``); a source with independent draws is sampled :data:`SAMPLE_BLOCK` records at
    a time. With ``data.group_by`` the records are then reordered by :func:`grouped_order`
    (the same generator, continued), so that each group lies in one split. Nothing is left
    at ``target`` or beside it when this fails."""
    rng = np.random.default_rng(data.seed)
    temporary = target.with_name(f".{target.name}.tmp")
    try:
        stored, groups, provenance = _draw(source, data, rng, temporary)
        if data.group_by is not None:
            sizes = (data.n_train, data.n_val, data.n_test)
            try:
                order = grouped_order(groups, sizes, rng)
            except ConfigError as error:
                raise ConfigError(f"data.group_by = '{data.group_by}': {error}") from None
            _reorder(temporary, order)
            provenance = [provenance[i] for i in order]
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
    result = _StoredMotions(target, stored.n_records, stored.n_steps, stored.dt)
    document = json.dumps(provenance, default=str)
    _write_atomic(result.provenance_path, lambda path: path.write_text(document))
    os.replace(temporary, target)
    return result


def _draw(
    source: GroundMotionSource, data: DataConfig, rng: np.random.Generator, temporary: Path
) -> tuple[_StoredMotions, list[str], list[dict]]:
    """The sampling loop of :func:`_sample_into`: the records written to ``temporary`` in
    the order drawn, the ``data.group_by`` key of each (empty without one) and the
    provenance of each (its source, draw, time step and the source's metadata)."""
    n = data.n_records
    block = SAMPLE_BLOCK if source.independent_draws else n
    written, stored, groups, provenance = 0, None, [], []
    while written < n:
        wanted = min(block, n - written)
        motions = source.sample(wanted, rng)[:wanted]
        if stored is None:
            stored = _StoredMotions(temporary, n, motions.n_steps, motions.dt)
            np.lib.format.open_memmap(temporary, mode="w+", dtype="f8", shape=(n, stored.n_steps))
        elif (motions.n_steps, motions.dt) != (stored.n_steps, stored.dt):
            raise DatasetError(
                f"ground motion '{source.name}' changed its grid between draws: "
                f"{motions.n_steps} samples at {motions.dt} s after {stored.n_steps} at "
                f"{stored.dt} s"
            )
        if data.group_by is not None:
            groups += _group_keys(motions, data.group_by, source.name, first=written)
        for i in range(motions.n_records):
            metadata = motions.metadata[i] if motions.metadata else {}
            provenance.append(
                {"source": source.name, "draw": written + i, "dt": motions.dt, **metadata}
            )
        mapped = np.lib.format.open_memmap(temporary, mode="r+")
        mapped[written : written + motions.n_records] = motions.acceleration
        mapped.flush()
        del mapped
        written += motions.n_records
        if motions.n_records < wanted:
            break
    if written < n:
        raise DatasetError(
            f"ground motion '{source.name}' gave {written} records but the data section asks "
            f"for {n} (n_train + n_val + n_test): lower the split sizes, or let the source "
            "give more (a recorded set: replace = true or copies with a scale_range)"
        )
    return stored, groups, provenance


def _group_keys(motions: GroundMotions, key: str, source: str, first: int) -> list[str]:
    """The ``key`` of every record's metadata, as comparable text; a record without it is
    a ConfigError naming the record (numbered from ``first``) and the keys it has."""
    keys = []
    for i in range(motions.n_records):
        metadata = motions.metadata[i] if motions.metadata else {}
        if key not in metadata:
            raise ConfigError(
                f"data.group_by = '{key}': record {first + i} of ground motion '{source}' "
                f"has no '{key}' in its metadata (it has: {', '.join(metadata) or 'none'})"
            )
        keys.append(json.dumps(metadata[key], sort_keys=True, default=str))
    return keys


def _reorder(path: Path, order: np.ndarray) -> None:
    """Rewrite the records of the ``.npy`` file ``path`` in ``order``, a block at a time."""
    rows = np.load(path, mmap_mode="r")
    reordered = path.with_name(f"{path.name}.order")
    out = np.lib.format.open_memmap(reordered, mode="w+", dtype="f8", shape=rows.shape)
    for start in range(0, len(order), SAMPLE_BLOCK):
        chunk = order[start : start + SAMPLE_BLOCK]
        out[start : start + chunk.size] = rows[chunk]
    out.flush()
    del out, rows
    os.replace(reordered, path)


def _start(config: ExperimentConfig, parts: Path, identity: str) -> tuple[_StoredMotions, int]:
    """Sample the motions (or find them from an interrupted run) and the chunk size."""
    manifest = parts / "manifest.json"
    if manifest.exists():
        found = json.loads(manifest.read_text())
        if found["config_hash"] != identity:
            raise DatasetError(
                f"{parts} holds an unfinished dataset of another configuration: remove it or "
                "choose another output folder"
            )
        stored = _StoredMotions(
            parts / "motions.npy", found["n_records"], found["n_steps"], found["dt"]
        )
        return stored, int(found["chunk_size"])
    source_spec = config.ground_motion
    source = get_registry().create("ground_motion", source_spec.name, **source_spec.params)
    parts.mkdir(parents=True, exist_ok=True)
    stored = _sample_into(source, config.data, parts / "motions.npy")
    record = {
        "config_hash": identity,
        "chunk_size": config.data.chunk_size,
        "n_records": stored.n_records,
        "n_steps": stored.n_steps,
        "dt": stored.dt,
    }
    _write_atomic(manifest, lambda temporary: temporary.write_text(json.dumps(record)))
    return stored, config.data.chunk_size


def check_setup(config: ExperimentConfig) -> Structure:
    """Build the config's structure and check, before any motion is drawn or any record
    simulated, what only the structure can tell: its model builds (an OpenSees script's
    nodes, DOFs and gravity function: :meth:`~Structure.periods` builds it), its stories
    can be told (where it declares them; a :class:`CphysfnoWarning` where they cannot),
    and every preprocessor finds the capabilities it needs. Returns the structure.

    Raises:
        ConfigError, CapabilityError, or the structure's own error: what is wrong, naming
            the setting.
    """
    registry = get_registry()
    structure = registry.create("structure", config.structure.name, **config.structure.params)
    structure.periods(1)
    if "stories" in structure.capabilities:
        try:
            structure.stories()
        except ConfigError as error:  # drift ratios and EDPs need them; the run does not
            warnings.warn(
                f"{structure.name}: no stories ({error}): no EDPs, and no collapse by drift",
                CphysfnoWarning,
                stacklevel=2,
            )
    for pp in config.preprocessor:
        registry.create("preprocessor", pp.name, **pp.params).check(structure)
    return structure


def check_draws(config: ExperimentConfig, space: UncertainParameters, draws: np.ndarray) -> None:
    """Build the structure of every distinct draw ``draws [n, k]`` of the config's random
    parameters ``space``, before any record is simulated.

    Raises:
        ConfigError: a draw makes no valid structure (the message names its first record,
            its values and the structure's complaint).
    """
    if not space.parameters:
        return
    spec = config.structure.to_dict()
    name = spec.pop("name")
    registry = get_registry()
    for row, records in distinct_draws(draws):
        record = records[0]
        values = space.values_of(row)
        try:
            registry.create("structure", name, **with_values(spec, values))
        except (CphysfnoError, ValueError) as error:
            drawn = ", ".join(f"{path} = {value:.6g}" for path, value in values.items())
            raise ConfigError(
                f"record {record} draws a structure that is not valid ({drawn}): {error}; "
                "bound the distributions (lower, upper) to the values the structure accepts"
            ) from None


def calibration_surfaces(
    config: ExperimentConfig,
    structure: Structure,
    space: UncertainParameters,
    progress: bool = True,
) -> dict[str, dict[str, Any]]:
    """Preprocessor name -> the calibration surface
    (:func:`~cphysfno_core.config.calibration_surface.fit_surface`, as its ``to_dict``) of
    each preprocessor with a calibration that the chunks make from one: for a fixed
    structure, its calibration fitted once here (a surface over no parameters) instead of
    in every chunk; for a family with ``[uncertainty] physics = "surface"``, its surface
    over ``space`` with the outer members at
    :data:`~cphysfno_core.config.calibration_surface.ANCHOR_Z` standard deviations.

    Every preprocessor is fitted to the nominal ``structure`` here, so that a missing
    capability fails before any simulation.
    """
    family = bool(space.parameters)
    spanned = family and config.uncertainty is not None and config.uncertainty.physics == "surface"
    if spanned:
        names, below, above = space.names, space.values_at(-ANCHOR_Z), space.values_at(ANCHOR_Z)
    else:
        names, below, above = (), np.zeros(0), np.zeros(0)
    tell = show_progress if progress and spanned else None
    found = {}
    for pp in config.preprocessor:
        if family and not spanned:  # each member fits its own
            get_registry().create("preprocessor", pp.name, **pp.params).fit(structure)
            continue
        surface = fit_surface(pp.to_dict(), structure, names, below, above, tell)
        if surface is not None:
            found[pp.name] = surface.to_dict()
    return found


def generate_dataset(config: ExperimentConfig, path: str | Path, progress: bool = True) -> Path:
    """Simulate ``config.data.n_records`` records into the HDF5 file ``path``.

    Records are sampled once from ``config.data.seed`` (seeds belong to records, not to
    workers), simulated in chunks of ``config.data.chunk_size`` on the configured executor,
    and kept chunk by chunk until all are done. Killed and started again with the same
    configuration, it simulates only the chunks that are missing. The process's memory
    allocator is tuned first (:func:`~cphysfno_core.config.allocator.tune_memory`).
    """
    tune_memory()
    path = Path(path)
    identity = dataset_hash(config)
    if check_dataset_identity(path, identity):
        if progress:
            show_progress(f"dataset {path} is complete: nothing to simulate")
        return path
    structure = check_setup(config)
    space = config.uncertain_parameters()
    central = config.data.n_train + config.data.n_val
    draws = space.draw(config.data.n_records, config.data.seed, n_central=central)
    check_draws(config, space, draws)
    surfaces = calibration_surfaces(config, structure, space, progress)
    parts = parts_folder(path)
    motions, chunk = _start(config, parts, identity)
    n = motions.n_records
    bounds = [(s, min(s + chunk, n)) for s in range(0, n, chunk)]
    todo = [i for i in range(len(bounds)) if not _chunk_path(parts, i).exists()]
    if progress and len(todo) < len(bounds):
        show_progress(f"  resuming: {len(bounds) - len(todo)} of {len(bounds)} chunks already done")
    _simulate_chunks(
        config, (space.names, draws, surfaces), motions, bounds, todo, parts, progress
    )
    messages, convergence = _assemble(
        config, structure, (space, draws, surfaces), motions, bounds, parts, path, identity
    )
    shutil.rmtree(parts)
    _report_messages(messages, path, progress)
    if progress and convergence:
        show_progress(convergence)
    return path


def messages_log(path: str | Path) -> Path:
    """The file beside the dataset ``path`` that keeps what the simulator printed for each
    record, in full."""
    path = Path(path)
    return path.with_name(f"{path.stem}-messages.log")


def _report_messages(messages: dict[int, str], path: Path, progress: bool) -> None:
    """Write the simulator's messages in full beside the dataset and show their summary."""
    log = messages_log(path)
    if not messages:
        log.unlink(missing_ok=True)
        return
    log.write_text(full_log(messages))
    if progress:
        show_progress(f"{summary(messages)}\n  (every record's messages in full: {log})")


def progress_line(done: int, total: int, elapsed: float) -> str:
    """``"50/400 records (6.6 s per record, about 38 min left)"`` after ``elapsed`` s.

    The rate is records per second when at least one record a second is made, seconds per
    record otherwise; the time left assumes the rate so far.
    """
    rate = done / max(elapsed, 1e-9)
    speed = f"{rate:.0f} records/s" if rate >= 1.0 else f"{1.0 / rate:.1f} s per record"
    left = (total - done) / rate if rate > 0 else float("inf")
    return f"{done}/{total} records ({speed}, {time_left(left)})"


def _simulate_chunks(config, drawn, motions, bounds, todo, parts, progress) -> None:
    parameters, draws, surfaces = drawn
    structure_spec = config.structure.to_dict()
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
                show_progress(f"  record {index} skipped: {cause}")
        messages = {start + k: text for k, text in result.messages.items()}
        for index, text in messages.items():
            logger.info("record %d: the simulator printed\n%s", index, text.rstrip())
        collapsed = np.flatnonzero(result.collapsed)
        if progress and collapsed.size:
            show_progress(
                f"  records {', '.join(str(start + int(k)) for k in collapsed)} collapsed the "
                "structure (kept, flagged, left out of training)"
            )
        stopped = {start + k: cause for k, cause in result.non_converged.items()}
        recovered = {start + k: measure for k, measure in result.recoveries.items()}
        for index, cause in stopped.items():
            if progress:
                show_progress(
                    f"  record {index} did not converge, below the collapse (kept to the "
                    f"stop, listed, left out of training): {cause}"
                )
        arrays = {
            "u": result.u,
            "collapsed": result.collapsed,
            "failures": np.array(json.dumps(failures)),
            "messages": np.array(json.dumps(messages)),
            "non_converged": np.array(json.dumps(stopped)),
            "recoveries": np.array(json.dumps(recovered)),
        }
        arrays.update({f"z/{name}": values for name, values in result.z.items()})
        arrays.update({f"extras/{name}": values for name, values in result.extras.items()})
        _save_npz(_chunk_path(parts, i), arrays)
        finished += stop - start
        if progress:
            line = progress_line(finished, total, time.perf_counter() - started)
            show_progress(f"  simulated {line}")

    def arguments(i: int) -> tuple[Any, ...]:
        start, stop = bounds[i]
        rows = motions.rows(start, stop)
        return structure_spec, pp_specs, rows, motions.dt, parameters, draws[start:stop], surfaces

    run_tasks(simulate_chunk, todo, arguments, config.data, store)


def _assemble(
    config, structure, drawn, motions, bounds, parts, path, identity
) -> tuple[dict[int, str], str]:
    """Copy the chunks, one at a time, into a new HDF5 file renamed into place at the end,
    with the ``drawn`` random parameters (their :class:`UncertainParameters` and draws
    ``[n, k]``); return what the simulator printed, by record, and the records counted by
    what they needed to converge (:func:`.recoveries.convergence_summary`)."""
    shape = (motions.n_records, motions.n_steps, structure.n_outputs)
    messages: dict[int, str] = {}
    convergence = ""

    def write(temporary: Path) -> None:
        nonlocal convergence
        listed: dict[str, dict[str, str]] = {key: {} for key in LISTED}
        with h5py.File(temporary, "w") as f:
            f.attrs["config_hash"] = identity
            f.attrs["config"] = json.dumps(config.to_dict())
            f.attrs["seed"] = config.data.seed
            f.attrs["dt"] = motions.dt
            f.attrs["versions"] = json.dumps(versions())
            f.attrs["output_names"] = json.dumps(list(structure.output_names))
            for split in SPLITS:
                f.attrs[f"n_{split}"] = getattr(config.data, f"n_{split}")
            f.create_dataset("ag", shape=shape[:2], dtype="f8")
            for start in range(0, shape[0], SAMPLE_BLOCK):
                stop = min(start + SAMPLE_BLOCK, shape[0])
                f["ag"][start:stop] = motions.rows(start, stop)
            f.create_dataset("u", shape=shape, dtype="f8")
            f.create_dataset("collapsed", shape=shape[:1], dtype=bool)
            for pp in config.preprocessor:
                f.create_dataset(f"z/{pp.name}", shape=shape, dtype="f8")
            provenance = [json.dumps(p, default=str) for p in motions.provenance()]
            f.create_dataset("records", data=provenance, dtype=h5py.string_dtype())
            for i, (start, stop) in enumerate(bounds):
                with np.load(_chunk_path(parts, i), allow_pickle=False) as chunk:
                    for key in chunk.files:
                        if key in listed:
                            listed[key].update(json.loads(str(chunk[key])))
                            continue
                        if key == "messages":
                            said = json.loads(str(chunk[key]))
                            messages.update({int(i): text for i, text in said.items()})
                            continue
                        values = chunk[key]
                        if key not in f:  # extras: float32, they serve the figures
                            f.create_dataset(key, shape=(shape[0], *values.shape[1:]), dtype="f4")
                        f[key][start:stop] = values
            for key, records in listed.items():
                f.attrs[key] = json.dumps(records)
            complete = ~f["collapsed"][...]
            complete[[int(i) for i in (*listed["failures"], *listed["non_converged"])]] = False
            recoveries = {int(i): measure for i, measure in listed["recoveries"].items()}
            convergence = convergence_summary(recoveries, complete)
            describe_arrays(f, list(structure.output_names), structure.response_channels())
            write_draws(f, *drawn)
            f.attrs["complete"] = True

    _write_atomic(path, write)
    return messages, convergence
