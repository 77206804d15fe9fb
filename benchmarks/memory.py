"""Bounded memory: generate a large Example 1 dataset chunk by chunk and report peak RSS."""

from __future__ import annotations

import multiprocessing
import resource
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import cphysfno_core as cp

from .common import Row, peak_rss_mib


def _config(n_records: int) -> cp.ExperimentConfig:
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


def run(quick: bool = False) -> list[Row]:
    """Generate each record count in a fresh process: peak memory must not grow with it."""
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
        )
    ]
