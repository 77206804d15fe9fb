"""Bounded memory: generate a large Example 1 dataset chunk by chunk and report peak RSS."""

from __future__ import annotations

import resource
import tempfile
import time
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


def run(quick: bool = False) -> list[Row]:
    n_records = 500 if quick else 10_000
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "large.h5"
        start = time.perf_counter()
        cp.generate_dataset(_config(n_records), path, progress=False)
        seconds = time.perf_counter() - start
        size_gib = path.stat().st_size / 2**30
    children = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0
    return [
        Row(
            stage=f"generate {n_records} Bouc-Wen records + ELS to HDF5 (chunks of 250)",
            ours_s=seconds,
            target="bounded memory",
            notes=[
                f"peak RSS {peak_rss_mib():.0f} MiB (main), {children:.0f} MiB (largest worker)",
                f"file {size_gib:.2f} GiB",
            ],
        )
    ]
