"""A 10 000-record fragility analysis from a trained SAC9 surrogate, against the simulations
the same analysis would need.

The surrogate side is ``cphysfno fragility RUN --records 10000`` (drawing the motions from
the run's source, the physics, the prediction, the EDPs and the fits; one cold run, as a
user runs it). RUN is a trained run of ``examples/sac9-frame-fragility.toml`` given by
``CPHYSFNO_FRAGILITY_RUN``; without it, the benchmark makes one: the same configuration
with 16 records and one epoch (the same network, so the same cost per prediction; its
accuracy is not the point here). The simulation side is the ``sac9-frame`` analysis of
records drawn from the same source, ``workers`` = the cores, timed per record on a sample
and multiplied by the number of records: what generating them for the fragility
analysis would take on the same cores.

Run alone with ``python -m benchmarks fragility [--quick]``.
"""

from __future__ import annotations

import json
import os
import re
import tempfile
import time
from pathlib import Path

import numpy as np

import cphysfno_core as cp
from cphysfno_core.app import pipeline
from cphysfno_core.app.fragility_study import draw, parse_limit_states, run_fragility
from cphysfno_core.config import ExperimentConfig

from .common import Row, Timing, cores, load_average

CONFIG = Path(__file__).parents[1] / "examples" / "sac9-frame-fragility.toml"
TARGET = "10 000 records in <= 10 min on 2 cores"
SMALL = {"n_train": 8, "n_val": 4, "n_test": 4, "epochs": 1, "chunk_size": 16, "copies": 1}
"""The sizes of the run the benchmark makes when it is given none."""


def _trained_run(folder: Path) -> Path:
    """A run of the example with :data:`SMALL` sizes, trained for one epoch."""
    text = CONFIG.read_text()
    for key, value in SMALL.items():
        text, count = re.subn(rf"(?m)^{key} = [^#\n]*", f"{key} = {value} ", text)
        assert count == 1, key
    config_path = folder / "config.toml"
    config_path.write_text(text)
    out = folder / "run"
    pipeline.run(cp.load_config(config_path), out)
    return out


def _median_peak_drift(run_folder: Path, config: ExperimentConfig) -> float:
    """The median over the run's simulated test records of their peak story drift ratio:
    a limit state that half of them exceed."""
    data = cp.load_dataset(run_folder / "dataset.h5")
    structure = cp.create("structure", config.structure.name, **config.structure.params)
    demands = cp.edp.compute(data.targets("test"), structure, data.motions("test"))
    return float(np.median(demands.pid.max(axis=1)))


def run(quick: bool = False) -> list[Row]:
    records = 500 if quick else 10_000
    sample = 4 if quick else 20
    given = os.environ.get("CPHYSFNO_FRAGILITY_RUN")
    with tempfile.TemporaryDirectory() as scratch:
        run_folder = Path(given) if given else _trained_run(Path(scratch))
        config = cp.parse_config(json.loads((run_folder / "config.json").read_text()))
        threshold = _median_peak_drift(run_folder, config)
        load_before = load_average()
        started = time.perf_counter()
        document = run_fragility(
            run_folder,
            limit_states=parse_limit_states(f"pid={threshold:.6g}"),
            records=records,
            n_bootstrap=50,
            progress=False,
            out=Path(scratch) / "fragility",
        )
        ours = time.perf_counter() - started
    source = cp.create("ground_motion", config.ground_motion.name, **config.ground_motion.params)
    motions, _ = draw(source, sample, np.random.default_rng(11))
    frame = cp.create("structure", "sac9-frame", workers=cores())
    started = time.perf_counter()
    frame.simulate(motions)
    per_record = (time.perf_counter() - started) / sample
    one_run = Timing(cores(), False, 1, "single")
    return [
        Row(
            f"fragility from a trained SAC9 surrogate (C-PhysFNO-ELS, FNO 8 x 128), "
            f"{records} records",
            ours,
            f"sac9-frame simulations of the same number of records (timed on {sample})",
            per_record * records,
            TARGET,
            [
                f"surrogate: {document['large_seconds']} s of it drawing, predicting and "
                "computing EDPs; the rest fitting the test records and bootstrapping",
                f"simulation: {per_record:.2f} s per record with {cores()} workers",
                "run: " + ("given" if given else "16 records, 1 epoch (same network)"),
                f"load average {load_before}",
            ],
            ours_timing=one_run,
            alternative_timing=Timing(cores(), False, sample, "mean"),
        )
    ]
