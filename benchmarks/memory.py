"""Memory: generate a large Example 1 dataset chunk by chunk and report peak RSS; and what a
fresh process pays to write its first output arrays, with and without NumPy's huge-page
advice (:mod:`cphysfno_core.config.allocator`)."""

from __future__ import annotations

import multiprocessing
import resource
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
from numpy._core.multiarray import _set_madvise_hugepage

import cphysfno_core as cp
from cphysfno_core.config import ExperimentConfig
from cphysfno_core.config.allocator import retain_freed_memory

from .common import Row, peak_rss_mib

FIRST_CALL_PROCESSES = 3
"""Fresh processes timed per setting in :func:`first_call_row`."""


def _config(n_records: int) -> ExperimentConfig:
    return cp.parse_config(
        {
            "structure": {"name": "bouc-wen-shear-building"},
            "ground_motion": {"name": "white-noise"},
            "preprocessor": [{"name": "els"}],
            "operator": {"name": "fno"},
            "data": {
                "n_train": n_records - 2,
                "n_val": 1,
                "n_test": 1,
                "chunk_size": 250,
                "executor": "processes",
            },
        }
    )


def _generate(n_records: int) -> tuple[float, float, float, float]:
    """Generate ``n_records`` in a temporary folder: seconds, peak RSS of this process and of
    its largest worker (MiB), file size (GiB)."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "large.h5"
        start = time.perf_counter()
        cp.generate_dataset(_config(n_records), path, progress=False)
        seconds = time.perf_counter() - start
        size_gib = path.stat().st_size / 2**30
    children = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0
    return seconds, peak_rss_mib(), children, size_gib


def _first_simulation(n_records: int, huge_page_advice: bool) -> float:
    """In a fresh process with freed memory retained: seconds of its first simulation of
    ``n_records`` Example 1 records (after 32 records that compile the kernel and warm up)."""
    retain_freed_memory()
    _set_madvise_hugepage(huge_page_advice)
    motions = cp.create("ground_motion", "white-noise").sample(n_records, np.random.default_rng(0))
    structure = cp.create("structure", "bouc-wen-shear-building")
    structure.simulate(motions[:32])
    start = time.perf_counter()
    structure.simulate(motions)
    return time.perf_counter() - start


def first_call_row(n_records: int) -> Row:
    """The Bouc-Wen fine grid's first call in a fresh process, without NumPy's huge-page
    advice (as :func:`cphysfno_core.config.allocator.tune_memory` sets) and with it (NumPy's
    default), :data:`FIRST_CALL_PROCESSES` processes each, alternating; the medians."""
    context = multiprocessing.get_context("spawn")
    times: dict[bool, list[float]] = {False: [], True: []}
    for _ in range(FIRST_CALL_PROCESSES):
        for advice in times:
            with ProcessPoolExecutor(1, mp_context=context) as pool:
                times[advice].append(pool.submit(_first_simulation, n_records, advice).result())
    ours, default = (float(np.median(times[advice])) for advice in (False, True))
    listed = {advice: " / ".join(f"{t:.3f}" for t in times[advice]) for advice in times}
    return Row(
        stage=f"Bouc-Wen fine grid, {n_records} records, first call in a fresh process",
        ours_s=ours,
        alternative="NumPy's default huge-page advice",
        alternative_s=default,
        target="report",
        notes=[
            f"medians of {FIRST_CALL_PROCESSES} processes each: without the advice "
            f"{listed[False]} s, with it {listed[True]} s",
        ],
    )


def run(quick: bool = False) -> list[Row]:
    """Generate each record count in a fresh process: peak memory must not grow with it;
    and the first simulation in a fresh process with and without huge-page advice."""
    counts = (500, 1000) if quick else (1000, 10_000)
    context = multiprocessing.get_context("spawn")
    notes, seconds = [], 0.0
    for n_records in counts:
        with ProcessPoolExecutor(1, mp_context=context) as pool:  # its workers may fork
            took, main, worker, size_gib = pool.submit(_generate, n_records).result()
        seconds = took
        notes.append(
            f"{n_records} records: peak RSS {main:.0f} MiB (main), {worker:.0f} MiB (largest "
            f"worker); file {size_gib:.2f} GiB; {took:.1f} s"
        )
    return [
        Row(
            stage=f"generate {counts[-1]} Bouc-Wen records + ELS to HDF5 (chunks of 250)",
            ours_s=seconds,
            target="bounded memory",
            notes=[*notes, "each count in a fresh process; time: the largest count"],
        ),
        first_call_row(100 if quick else 1000),
    ]
